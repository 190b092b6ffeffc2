//! The readings of an instruction a person chooses among in the workbench, drawn over the
//! screen (TestBackend + insta). (Chosen in the real binary driven in tmux: the slow
//! tier's `tui_readings`.)

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::sync::Arc;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Terminal;
use ratatui::backend::TestBackend;

use betr::scenario::Scenario;
use betr::session::{Command, Event};
use betr::tui::{App, Info, KeyBindings, Request, Theme, ui};
use support::fixtures;

/// A workbench on `scenario` that has just been offered `readings`.
fn offered(
    scenario: Arc<Scenario>,
    readings: Vec<betr::session::Reading>,
    doubt: Option<String>,
) -> App {
    let mut app = App::new(
        scenario.clone(),
        Info::default(),
        KeyBindings::default(),
        Theme::default(),
    );
    // The model's answer comes first; the readings follow it when they differ.
    if let Some(first) = readings.first() {
        app.on_session(Event::Goal {
            goal: first.goal.clone(),
            reasoning: Some("the first reading".into()),
            matches_expected: None,
            author: "model".into(),
            first_answer: None,
            doubt: None,
        });
    }
    app.on_session(Event::Readings {
        instruction: "a request".into(),
        readings,
        doubt,
    });
    app
}

#[test]
fn readings_to_choose_among_are_shown_over_the_screen() {
    let path = fixtures::root().join("scenarios/cafe/cafe.toml");
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    let world = betr::world::load(&scenario).unwrap();
    let goals = [
        scenario.parse_goal("On_Dessert_Table3").unwrap(),
        scenario.parse_goal("On_Chocolate_Table3").unwrap(),
    ];
    let readings =
        betr::session::interpret::readings::distinct_readings(&scenario, world.as_ref(), &goals);
    assert_eq!(readings.len(), 2);
    let mut app = offered(scenario, readings, None);
    let draw = |app: &mut App| {
        let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
        terminal.draw(|f| ui::draw(f, app)).unwrap();
        terminal.backend().to_string()
    };
    let screen = draw(&mut app);
    assert!(screen.contains("Readings of the instruction"), "{screen}");
    // While the choice waits, no goal is shown as the one worked on.
    assert_eq!(app.llm.goal, None);
    insta::assert_snapshot!("readings_overlay", screen);
    // Keys other than a reading's number leave the choice open.
    for code in [KeyCode::Char(' '), KeyCode::Char('9'), KeyCode::Enter] {
        app.on_key(KeyEvent::new(code, KeyModifiers::NONE));
    }
    assert!(app.take_requests().is_empty());
    assert!(draw(&mut app).contains("Readings of the instruction"));
    app.on_key(KeyEvent::new(KeyCode::Char('2'), KeyModifiers::NONE));
    assert_eq!(
        app.take_requests(),
        vec![Request::Session(Command::ChooseReading(1))]
    );
    assert!(!draw(&mut app).contains("Readings of the instruction"));
}

#[test]
fn a_doubted_reading_waits_for_the_person() {
    let path = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    let goal = scenario
        .parse_goal(r#""blue cube" on "green cube""#)
        .unwrap();
    let readings =
        betr::session::interpret::readings::distinct_readings_in_scenario(&scenario, &[goal])
            .unwrap();
    let doubt = "no word of the request names anything it is about";
    let mut app = offered(scenario, readings, Some(doubt.into()));
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
    terminal.draw(|f| ui::draw(f, &mut app)).unwrap();
    let screen = terminal.backend().to_string();
    assert!(screen.contains("is doubtful; press 1"), "{screen}");
    assert!(screen.contains("no word of the request names"), "{screen}");
    app.on_key(KeyEvent::new(KeyCode::Char('1'), KeyModifiers::NONE));
    assert_eq!(
        app.take_requests(),
        vec![Request::Session(Command::ChooseReading(0))]
    );
}
