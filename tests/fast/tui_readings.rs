//! The readings of an instruction a person chooses among in the workbench: drawn over the
//! screen (TestBackend + insta), and chosen in the real binary driven in tmux.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

mod support;

use std::sync::Arc;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Terminal;
use ratatui::backend::TestBackend;

use betr::scenario::Scenario;
use betr::session::{Command, Event};
use betr::tui::{App, Info, KeyBindings, Request, Theme, ui};
use support::cli::tmp;
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::tmux::{Tmux, workbench_command_on};

/// A workbench on `scenario` that has just been offered `readings`.
fn offered(
    scenario: Arc<Scenario>,
    readings: Vec<betr::session::Reading>,
    doubt: Option<String>,
) -> App {
    let mut app = App::new(
        scenario,
        Info::default(),
        KeyBindings::default(),
        Theme::default(),
    );
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
    let readings = betr::session::readings::distinct_readings(&scenario, world.as_ref(), &goals);
    assert_eq!(readings.len(), 2);
    let mut app = offered(scenario, readings, None);
    let draw = |app: &mut App| {
        let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
        terminal.draw(|f| ui::draw(f, app)).unwrap();
        terminal.backend().to_string()
    };
    let screen = draw(&mut app);
    assert!(screen.contains("Readings of the instruction"), "{screen}");
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

/// A request that names no object of the scene ("something sweet") read two ways by the
/// model's candidates, a dessert and a chocolate: the workbench offers both, and the
/// person takes the second.
#[test]
fn a_person_chooses_the_second_reading_of_an_instruction() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-readings");
    let tmux = Tmux::start(&workbench_command_on(
        "scenarios/cafe/cafe.toml",
        &dir,
        &server,
        ("", ""),
    ));
    tmux.wait_for(&["Behavior tree", "press i to type an instruction"], 20);
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("Bring something sweet to table 3.");
    tmux.keys(&["Enter"]);
    // Drawn whole: both readings with their first actions.
    let wanted = [
        "Readings of the instruction",
        "goal: On_Dessert_Table3",
        "goal: On_Chocolate_Table3",
    ];
    let screen = tmux.wait_until(&wanted, 30, |s| {
        wanted.iter().all(|w| s.contains(w)) && s.matches("first: ").count() == 2
    });
    let first = screen
        .lines()
        .position(|l| l.contains("goal: On_Dessert_Table3"));
    let second = screen
        .lines()
        .position(|l| l.contains("goal: On_Chocolate_Table3"));
    assert!(
        matches!((first, second), (Some(a), Some(b)) if a < b),
        "the dessert (two votes) first, the chocolate second:\n{screen}"
    );
    // Other keys leave the choice open; the number chooses.
    tmux.keys(&["Space"]);
    std::thread::sleep(std::time::Duration::from_millis(300));
    assert!(tmux.screen().contains("Readings of the instruction"));
    tmux.keys(&["2"]);
    // The tree's last action (not among the first actions the overlay lists), and the
    // overlay gone: the screen is read once it has been redrawn whole.
    let wanted = [
        "Goal: On_Chocolate_Table3",
        "PutDown \"Chocolate\" \"Table3\"!",
    ];
    let screen = tmux.wait_until(&wanted, 20, |s| {
        wanted.iter().all(|w| s.contains(w)) && !s.contains("Readings of the instruction")
    });
    assert!(
        !screen.contains("Readings of the instruction")
            && !screen.contains("On_Dessert_Table3?")
            && !screen.contains("PickUp \"Dessert\"!"),
        "the tree is the second reading's:\n{screen}"
    );
}

#[test]
fn a_doubted_reading_waits_for_the_person() {
    let path = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    let goal = scenario
        .parse_goal(r#""blue cube" on "green cube""#)
        .unwrap();
    let readings =
        betr::session::readings::distinct_readings_in_scenario(&scenario, &[goal]).unwrap();
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
