//! The screen as a function of the app state: tree on the left, LLM and world on the
//! right, the input line and the status bar below; overlays on top. Narrow terminals
//! stack the panes.

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout};

use super::app::{App, Overlay};
use super::components::help::{draw_help, draw_readings, draw_report};
use super::components::llm_pane::PaneHints;
use super::keys::{Action, KeyMode};
use super::strings;

pub fn draw(frame: &mut Frame, app: &mut App) {
    let area = frame.area();
    let [main, input, status] = Layout::vertical([
        Constraint::Min(3),
        Constraint::Length(app.input.height(area.width)),
        Constraint::Length(1),
    ])
    .areas(area);
    let (tree_area, llm_area, world_area) = if main.width >= 70 {
        let [left, right] =
            Layout::horizontal([Constraint::Percentage(55), Constraint::Percentage(45)])
                .areas(main);
        let [llm, world] =
            Layout::vertical([Constraint::Percentage(60), Constraint::Percentage(40)]).areas(right);
        (left, llm, world)
    } else {
        let [tree, llm, world] = Layout::vertical([
            Constraint::Percentage(50),
            Constraint::Percentage(30),
            Constraint::Percentage(20),
        ])
        .areas(main);
        (tree, llm, world)
    };
    app.place_panes(super::app::PaneAreas {
        tree: tree_area,
        llm: llm_area,
        world: world_area,
    });
    let theme = app.theme;
    let key = |a: Action| app.keys.key(a).map(|k| k.to_string()).unwrap_or_default();
    let hint = match app.mode {
        KeyMode::Workbench => format!(
            "{} approve · {} reject · {} edit · {} whole",
            key(Action::Approve),
            key(Action::Reject),
            key(Action::Edit),
            key(Action::Details)
        ),
        KeyMode::Replay => strings::REPLAY_PROPOSAL_HINT.to_string(),
    };
    let help_key = key(Action::Help);
    app.tree.draw(frame, tree_area, &theme);
    let cancel = (app.mode == KeyMode::Workbench).then(|| key(Action::Cancel));
    app.llm.draw(
        frame,
        llm_area,
        &theme,
        &PaneHints {
            proposal: &hint,
            cancel: cancel.as_deref(),
        },
    );
    app.world.draw(frame, world_area, &theme);
    if app.dictation.is_shown() && !app.input.is_open() {
        app.dictation
            .draw(frame, input, &theme, &key(Action::Dictate));
    } else {
        app.input.draw(frame, input, &theme);
    }
    app.status.draw(frame, status, &theme, &help_key);
    match &app.overlay {
        Some(Overlay::Help(first)) => draw_help(
            frame,
            area,
            (&app.keys, app.mode),
            app.viewer_page.as_deref(),
            *first,
            &theme,
        ),
        Some(Overlay::Report { title, lines }) => draw_report(frame, area, title, lines, &theme),
        Some(Overlay::ConfirmQuit(lines)) => {
            draw_report(frame, area, strings::CONFIRM_QUIT_TITLE, lines, &theme);
        }
        Some(Overlay::PlanAgain(lines)) => {
            draw_report(frame, area, strings::PLAN_AGAIN_TITLE, lines, &theme);
        }
        Some(Overlay::Readings(readings, doubt)) => {
            draw_readings(frame, area, readings, doubt.as_deref(), &theme);
        }
        None => {}
    }
}
