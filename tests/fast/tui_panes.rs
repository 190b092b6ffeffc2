//! The workbench's panes at 80×24 with a deep tree whose labels do not fit: the tree
//! scrolled sideways with keys and the horizontal wheel, and the mouse beyond the tree —
//! a click focuses a pane, the wheel scrolls the pane under it (the world's facts, the
//! log, a proposal too long for its pane), the navigation keys scroll the focused one.
//! Key and mouse events go through the app's handlers as the event loop hands them over;
//! the screens are ratatui `TestBackend` + insta snapshots.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::sync::Arc;

use crossterm::event::{KeyCode, KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::style::Color;

use betr::session::Event;
use betr::tui::{Pane, ui};
use support::repo::runtime as rt;
use support::workbench::Bench;

/// A tree fourteen levels deep over scenario 1's objects, whose deepest labels run past an
/// 80-column screen's tree pane.
fn deep_tree() -> Arc<betr::bt::Tree> {
    let mut text = String::new();
    for depth in 0..13 {
        let kind = if depth % 2 == 0 {
            "fallback"
        } else {
            "sequence"
        };
        text.push_str(&format!("{}{kind}\n", "  ".repeat(depth)));
        text.push_str(&format!(
            "{}\"red cube\" on \"blue cube\"?\n",
            "  ".repeat(depth + 1)
        ));
    }
    let leaf = "  ".repeat(13);
    text.push_str(&format!("{leaf}~\"any object\" on \"blue cube\"?\n"));
    text.push_str(&format!("{leaf}place \"blue cube\" \"green cube\"!\n"));
    Arc::new(betr::bt::text::parse(&text).unwrap())
}

fn with_deep_tree(b: &mut Bench) {
    b.app.on_session(Event::TreeChanged {
        tree: deep_tree(),
        new_nodes: Vec::new(),
        learned: Vec::new(),
        why: "a tree for the test".into(),
    });
}

fn mouse(kind: MouseEventKind, column: u16, row: u16, modifiers: KeyModifiers) -> MouseEvent {
    MouseEvent {
        kind,
        column,
        row,
        modifiers,
    }
}

/// The rows of a screen as `TestBackend` prints them, without the quotes.
fn rows(screen: &str) -> Vec<String> {
    screen
        .lines()
        .map(|l| l.trim_matches('"').to_string())
        .collect()
}

#[test]
fn a_deep_tree_scrolls_sideways_at_80x24() {
    rt().block_on(async {
        let mut b = Bench::start();
        with_deep_tree(&mut b);
        // The widget selects the last row among the rows it drew.
        b.screen(80, 24);
        b.key(KeyCode::End);
        let before = b.screen(80, 24);
        // The deepest action is cut; the border says the rows go on to the right.
        assert!(!before.contains("\"green cube\"!"), "{before}");
        assert!(rows(&before)[0].contains(" » "), "{before}");
        assert_eq!(b.app.tree.column(), 0);
        insta::assert_snapshot!("deep_tree_80x24_not_scrolled", before);

        b.key(KeyCode::Char('L'));
        b.key(KeyCode::Char('L'));
        let scrolled = b.screen(80, 24);
        assert_eq!(b.app.tree.column(), 16);
        assert!(rows(&scrolled)[0].contains("«16"), "{scrolled}");
        insta::assert_snapshot!("deep_tree_80x24_scrolled", scrolled);

        // As far right as the widest row needs, no further: the whole label is in view.
        for _ in 0..20 {
            b.key(KeyCode::Char('L'));
        }
        let end = b.screen(80, 24);
        assert!(end.contains("place \"blue cube\" \"green cube\"!"), "{end}");
        assert!(!rows(&end)[0].contains(" » "), "{end}");
        let furthest = b.app.tree.column();
        assert!(furthest > 16 && furthest < 40, "{furthest}");

        // The selection moves with the rows: still the deepest action.
        let selected = b.app.tree.selected().unwrap();
        assert!(
            b.app
                .tree
                .label(selected, &b.app.theme)
                .starts_with("place"),
        );

        // H back to the start; the horizontal wheel and Shift with the wheel scroll too.
        for _ in 0..20 {
            b.key(KeyCode::Char('H'));
        }
        assert_eq!(b.app.tree.column(), 0);
        assert_eq!(b.screen(80, 24), before);
        b.app.on_mouse(mouse(
            MouseEventKind::ScrollRight,
            10,
            5,
            KeyModifiers::NONE,
        ));
        assert_eq!(b.app.tree.column(), 8);
        b.app.on_mouse(mouse(
            MouseEventKind::ScrollDown,
            10,
            5,
            KeyModifiers::SHIFT,
        ));
        assert_eq!(b.app.tree.column(), 16);
        b.app
            .on_mouse(mouse(MouseEventKind::ScrollUp, 10, 5, KeyModifiers::SHIFT));
        b.app
            .on_mouse(mouse(MouseEventKind::ScrollLeft, 10, 5, KeyModifiers::NONE));
        assert_eq!(b.app.tree.column(), 0);
        // A click selects the row under it, scrolled or not: the third row from the top
        // is the first sequence.
        b.key(KeyCode::Home);
        b.key(KeyCode::Char('L'));
        b.screen(80, 24);
        b.app.on_mouse(mouse(
            MouseEventKind::Down(MouseButton::Left),
            20,
            3,
            KeyModifiers::NONE,
        ));
        let selected = b.app.tree.selected().unwrap();
        assert!(
            b.app
                .tree
                .label(selected, &b.app.theme)
                .ends_with("Sequence"),
        );
        assert_eq!(b.app.tree.column(), 8);
    });
}

#[test]
fn the_help_lists_the_sideways_and_focus_keys() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('?'));
        let screen = b.screen(160, 40);
        for text in [
            "scroll the tree left",
            "scroll the tree right",
            "focus the next pane",
            "shift-wheel",
            "click: focus a pane",
        ] {
            assert!(screen.contains(text), "{text} missing:\n{screen}");
        }
    });
}

/// At 80×24 the key list does not fit: it shows in one column, says which rows show, and
/// scrolls with the arrow and page keys down to its last key; another key closes it.
#[test]
fn the_help_scrolls_at_80x24() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('?'));
        let top = b.screen(80, 24);
        assert!(top.contains("rows 1\u{2013}"), "{top}");
        assert!(top.contains("any other key closes"), "{top}");
        insta::assert_snapshot!("help_80x24_top", top);
        // Every key of the list is reachable: the last one shows after scrolling down.
        let last = b
            .app
            .keys
            .help_lines(b.app.mode)
            .last()
            .map(|(_, what)| what.to_string())
            .unwrap();
        assert!(!top.contains(&last), "{top}");
        for _ in 0..10 {
            b.key(KeyCode::PageDown);
        }
        let bottom = b.screen(80, 24);
        assert!(bottom.contains(&last), "{last} missing:\n{bottom}");
        assert!(!bottom.contains("rows 1\u{2013}"), "{bottom}");
        b.key(KeyCode::Up);
        assert!(
            b.app.overlay.is_some(),
            "an arrow scrolls, it does not close"
        );
        b.key(KeyCode::Char('x'));
        assert!(b.app.overlay.is_none(), "another key closes the list");
    });
}

/// The column and row where `text` starts on a screen (its characters are one cell
/// wide each).
fn top_left_of(screen: &str, text: &str) -> (u16, u16) {
    rows(screen)
        .iter()
        .enumerate()
        .find_map(|(y, row)| {
            let at = row.find(text)?;
            let x = row[..at].chars().count();
            Some((u16::try_from(x).unwrap(), u16::try_from(y).unwrap()))
        })
        .unwrap_or_else(|| panic!("{text} not on the screen:\n{screen}"))
}

/// The colour of the border cell at the top-left corner of a pane.
fn border_colour(b: &mut Bench, column: u16, row: u16) -> Option<Color> {
    let mut terminal = Terminal::new(TestBackend::new(80, 24)).unwrap();
    terminal.draw(|f| ui::draw(f, &mut b.app)).unwrap();
    terminal
        .backend()
        .buffer()
        .cell((column, row))
        .and_then(|c| c.style().fg)
}

#[test]
fn a_click_focuses_a_pane_and_the_wheel_scrolls_the_one_under_it() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        for n in 1..=40 {
            b.app.llm.log(format!("log line {n}"));
        }
        b.screen(80, 24);
        // At 80×24: the tree on the left (44 columns), the LLM pane top right (rows 0-11),
        // the world below it (rows 12-19).
        let (llm_x, proposal_row) = (50, 3);
        assert_eq!(b.app.pane_at(llm_x, proposal_row), Some(Pane::Proposal));
        assert_eq!(b.app.pane_at(50, 15), Some(Pane::World));
        assert_eq!(b.app.focus, Pane::Tree);
        let theme = b.app.theme;
        assert_eq!(border_colour(&mut b, 0, 0), theme.focused.fg);
        assert_eq!(border_colour(&mut b, 44, 12), theme.border.fg);

        // The world pane (its last error in one row at 80×24, so its facts have rows): a
        // click focuses it, the wheel scrolls its facts.
        let world_before = b.screen(80, 24);
        let (world_x, world_row) = top_left_of(&world_before, "┌ World");
        let (world_x, world_row) = (world_x + 2, world_row + 2);
        b.app.on_mouse(mouse(
            MouseEventKind::Down(MouseButton::Left),
            world_x,
            world_row,
            KeyModifiers::NONE,
        ));
        assert_eq!(b.app.focus, Pane::World);
        b.screen(80, 24);
        assert_eq!(border_colour(&mut b, 44, 12), theme.focused.fg);
        assert_eq!(border_colour(&mut b, 0, 0), theme.border.fg);
        b.screen(80, 24);
        b.app.on_mouse(mouse(
            MouseEventKind::ScrollDown,
            world_x,
            world_row,
            KeyModifiers::NONE,
        ));
        let world_scrolled = b.screen(80, 24);
        assert!(
            world_scrolled.contains("↑ 3 row(s) above"),
            "{world_scrolled}"
        );
        insta::assert_snapshot!("world_scrolled_by_the_wheel_80x24", world_scrolled);
        // Keys scroll the focused pane: ↑ one row back.
        b.key(KeyCode::Up);
        assert!(b.screen(80, 24).contains("↑ 2 row(s) above"));
        b.key(KeyCode::Home);
        assert_eq!(b.screen(80, 24), world_before);

        // The proposal does not fit its pane at 80×24: it says which rows it shows, and the
        // wheel over it scrolls it without moving the focus.
        let proposal_before = b.screen(80, 24);
        assert!(proposal_before.contains("↕ rows 1–"), "{proposal_before}");
        b.app.on_mouse(mouse(
            MouseEventKind::ScrollDown,
            llm_x,
            proposal_row,
            KeyModifiers::NONE,
        ));
        assert_eq!(b.app.focus, Pane::World);
        let proposal_scrolled = b.screen(80, 24);
        assert!(
            proposal_scrolled.contains("↕ rows 4–"),
            "{proposal_scrolled}"
        );
        insta::assert_snapshot!("proposal_scrolled_by_the_wheel_80x24", proposal_scrolled);
        b.app.on_mouse(mouse(
            MouseEventKind::Down(MouseButton::Left),
            llm_x,
            proposal_row,
            KeyModifiers::NONE,
        ));
        assert_eq!(b.app.focus, Pane::Proposal);
        b.key(KeyCode::Home);
        assert_eq!(b.screen(80, 24), proposal_before);

        // The log has rows at 160×60: the wheel over it goes back in it, a click focuses
        // it and End returns to the newest line.
        let screen = b.screen(160, 60);
        assert!(screen.contains("log line 40"), "{screen}");
        let log = b.app.llm.log_area();
        assert!(log.height > 2, "{log:?}");
        let (log_x, log_y) = (log.x + 2, log.y + 1);
        assert_eq!(b.app.pane_at(log_x, log_y), Some(Pane::Log));
        b.app.on_mouse(mouse(
            MouseEventKind::ScrollUp,
            log_x,
            log_y,
            KeyModifiers::NONE,
        ));
        let screen = b.screen(160, 60);
        assert!(!screen.contains("log line 40"), "{screen}");
        assert!(screen.contains("↓ 3 more row(s) below"), "{screen}");
        b.app.on_mouse(mouse(
            MouseEventKind::Down(MouseButton::Left),
            log_x,
            log_y,
            KeyModifiers::NONE,
        ));
        assert_eq!(b.app.focus, Pane::Log);
        b.key(KeyCode::End);
        assert!(b.screen(160, 60).contains("log line 40"));

        // Tab goes round the panes; the tree takes the arrows again.
        b.key(KeyCode::Tab);
        assert_eq!(b.app.focus, Pane::World);
        b.key(KeyCode::Tab);
        assert_eq!(b.app.focus, Pane::Tree);
        let selected = b.app.tree.selected();
        b.key(KeyCode::Up);
        assert_ne!(b.app.tree.selected(), selected);

        // Under an overlay the mouse does nothing.
        b.key(KeyCode::Char('?'));
        b.screen(120, 40);
        b.app.on_mouse(mouse(
            MouseEventKind::Down(MouseButton::Left),
            world_x,
            world_row,
            KeyModifiers::NONE,
        ));
        assert_eq!(b.app.focus, Pane::Tree);
    });
}

/// A goal kept other than the model's first answer (here turned round) says so in the
/// log pane, with both goals.
#[test]
fn a_goal_other_than_the_first_answer_is_said_in_the_log() {
    rt().block_on(async {
        let mut b = Bench::start();
        let goal = |text: &str| betr::goal::Formula::parse(text).unwrap();
        b.app.on_session(Event::Goal {
            goal: goal("\"blue cube\" on \"green cube\""),
            reasoning: None,
            matches_expected: None,
            author: "model".into(),
            first_answer: Some(goal("\"green cube\" on \"blue cube\"")),
            doubt: Some("doubtful: the model's first answer failed its checks".into()),
        });
        let screen = b.screen(160, 50);
        assert!(
            screen.contains("doubtful: the model's first answer failed its checks"),
            "the doubt level is shown beside the goal: {screen}"
        );
        assert!(
            screen.contains("the model answered \"green cube\" on \"blue cube\" first"),
            "{screen}"
        );
    });
}

/// The quit question names the save key for the fixes not saved: that key saves them
/// (and closes the question) instead of only closing it.
#[test]
fn the_quit_question_saves_with_the_key_it_names() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        b.key(KeyCode::Char('a'));
        // The engine counts the fix as unsaved once the approval is carried out.
        b.until(|e| matches!(e, Event::FixCounts(c) if c.unsaved == 1))
            .await;
        b.key(KeyCode::Char('q'));
        let screen = b.screen(120, 40);
        assert!(screen.contains("(s saves them)"), "{screen}");
        b.key(KeyCode::Char('s'));
        assert!(
            b.sent
                .iter()
                .any(|c| matches!(c, betr::session::Command::SavePolicy)),
            "{:?}",
            b.sent
        );
        assert!(!b.screen(120, 40).contains("again to quit"));
    });
}
