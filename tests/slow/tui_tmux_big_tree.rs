//! A tree of 301 nodes in the real workbench (tmux, 120×40): loaded from a tree file on
//! scenario 1's vocabulary, searched with `/`, then the next and previous match; each match
//! is selected and scrolled into view, and the status bar says which of how many it is.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use support::cli::tmp;
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::tmux::{Tmux, quote};

/// A fallback of 100 sequences, each a condition and an action: 301 nodes. Three of the
/// actions place the red cube on the green cube; the rest grasp a cube.
fn big_tree() -> String {
    let cubes = ["blue cube", "green cube", "red cube"];
    let mut text = String::from("fallback\n");
    for i in 0..100 {
        let cube = cubes[i % 3];
        text.push_str("  sequence\n");
        text.push_str(&format!("    \"{cube}\" on \"table\"?\n"));
        if [20, 60, 95].contains(&i) {
            text.push_str("    place \"red cube\" \"green cube\"!\n");
        } else {
            text.push_str(&format!("    grasp \"{cube}\"!\n"));
        }
    }
    text
}

#[test]
fn search_finds_each_match_of_a_300_node_tree() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-big-tree");
    let tree = dir.join("big.bt");
    std::fs::write(&tree, big_tree()).unwrap();
    let command = support::tmux::workbench_command_on(
        "scenarios/cell/red_on_blue.toml",
        &dir,
        &server,
        ("", &format!("--tree {}", quote(&tree))),
    );
    let tmux = Tmux::start(&command);
    tmux.wait_for(&["Behavior tree", "grasp \"blue cube\"!"], 20);
    let screen = tmux.screen();
    assert!(!screen.contains("place \"red cube\""), "{screen}");

    tmux.keys(&["/"]);
    tmux.wait_for(&["Search the tree"], 10);
    tmux.text("place");
    tmux.keys(&["Enter"]);
    tmux.wait_for(
        &["/place: match 1 of 3", "place \"red cube\" \"green cube\"!"],
        10,
    );
    tmux.keys(&[">"]);
    tmux.wait_for(
        &["/place: match 2 of 3", "place \"red cube\" \"green cube\"!"],
        10,
    );
    tmux.keys(&[">"]);
    tmux.wait_for(&["/place: match 3 of 3"], 10);
    tmux.keys(&[">"]);
    tmux.wait_for(&["/place: match 1 of 3"], 10);
    tmux.keys(&["<"]);
    tmux.wait_for(
        &["/place: match 3 of 3", "place \"red cube\" \"green cube\"!"],
        10,
    );

    // Collapse all: one row under the root's; the search finds its way back in.
    tmux.keys(&["C"]);
    tmux.wait_until(&["every sequence closed"], 10, |s| {
        s.contains("▾  [ ] [o] Fallback") && !s.contains("▾  [ ] [-] Sequence")
    });
    tmux.keys(&[">"]);
    tmux.wait_for(
        &["/place: match 1 of 3", "place \"red cube\" \"green cube\"!"],
        10,
    );
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
}
