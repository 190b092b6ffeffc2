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

/// A hand-written reply for the goal question of `request` when the prompt holds all of
/// `shown` too (not what any model answered).
fn reply_when(request: &str, shown: &[&str], goal: &str, note: &str) -> fixtures::FixtureReply {
    let mut when = vec![
        "# Task: goal interpretation".to_string(),
        request.to_string(),
    ];
    when.extend(shown.iter().map(|s| s.to_string()));
    fixtures::FixtureReply {
        when,
        seed: None,
        text: format!("Goal: {goal}\n"),
        note: note.into(),
    }
}

/// A person corrects a reading by choosing the second one; the workbench keeps the
/// correction as an example of the cafe. A new workbench on the same data directory reads
/// a request phrased like it with the kept example shown to the model (the log says which),
/// and `betr knowledge` lists the example and revokes it.
#[test]
fn a_reading_corrected_once_is_read_right_next_time() {
    let kept = "Instruction: Bring something sweet to table 3.\nGoal: On_Chocolate_Table3";
    let later = "Bring something sweet to table 1.";
    // The fake model answers the later request the way its prompt's examples show: the
    // chocolate when the kept correction is among them, else the dessert.
    let mut replies = vec![
        reply_when(
            later,
            &[kept],
            "On_Chocolate_Table1",
            "hand-written: as the kept example shows",
        ),
        reply_when(
            later,
            &[],
            "On_Dessert_Table1",
            "hand-written: the reading before the correction",
        ),
    ];
    replies.extend(fixtures::every_reply());
    let server = FakeServer::start(vec![], Behavior::Fixtures(replies));
    let dir = tmp("tmux-correction");
    let first = Tmux::start(&workbench_command_on(
        "scenarios/cafe/cafe.toml",
        &dir,
        &server,
        ("", ""),
    ));
    first.wait_for(&["Behavior tree", "press i to type an instruction"], 20);
    first.keys(&["i"]);
    first.wait_for(&["Instruction or goal"], 10);
    first.text("Bring something sweet to table 3.");
    first.keys(&["Enter"]);
    first.wait_for(
        &["Readings of the instruction", "goal: On_Chocolate_Table3"],
        30,
    );
    first.keys(&["2"]);
    first.wait_for(
        &["Goal: On_Chocolate_Table3", "correction kept as example e1"],
        20,
    );
    first.keys(&["q"]);
    drop(first);

    let policies = dir.join("policies");
    let policy_dir = policies.to_string_lossy().to_string();
    let list = support::cli::betr(&dir, &["knowledge", "list", "--policy-dir", &policy_dir]);
    let listed = support::cli::text(&list);
    assert!(
        listed.contains("e1")
            && listed.contains("Bring something sweet to table 3.")
            && listed.contains("On_Chocolate_Table3"),
        "{listed}"
    );

    let second = Tmux::start(&workbench_command_on(
        "scenarios/cafe/cafe.toml",
        &dir,
        &server,
        ("", ""),
    ));
    second.wait_for(&["Behavior tree", "press i to type an instruction"], 20);
    second.keys(&["i"]);
    second.wait_for(&["Instruction or goal"], 10);
    second.text(later);
    second.keys(&["Enter"]);
    let screen = second.wait_for(
        &["Goal: On_Chocolate_Table1", "read with the kept example"],
        30,
    );
    assert!(
        screen.contains("e1") && !screen.contains("Readings of the instruction"),
        "read right at once, with the kept example named:\n{screen}"
    );
    second.keys(&["q"]);
    drop(second);

    let revoke = support::cli::betr(
        &dir,
        &["knowledge", "revoke", "e1", "--policy-dir", &policy_dir],
    );
    assert!(revoke.status.success(), "{}", support::cli::text(&revoke));
    let list = support::cli::betr(&dir, &["knowledge", "list", "--policy-dir", &policy_dir]);
    let listed = support::cli::text(&list);
    assert!(listed.contains("No kept examples"), "{listed}");
}
