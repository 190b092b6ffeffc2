//! The readings of an instruction a person chooses among, chosen in the real binary driven
//! in tmux (drawn over the screen: the fast tier's `tui_readings`).

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use support::cli::tmp;
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::tmux::{Tmux, workbench_command_on};

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
