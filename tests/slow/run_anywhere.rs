//! The binary started outside the repository, as after `cargo install --path .`, in tmux:
//! the workbench opens on scenario 1 from the scenarios built into the binary (written
//! into the data directory on first use) and reads an instruction with the example pool
//! found beside it.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::Path;

use support::cli::{KEY, KEY_VAR, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::tmux::{Tmux, isolated_env, quote};

#[test]
fn the_workbench_opens_on_scenario_1_in_a_directory_outside_the_repository() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("anywhere");
    let repo = fixtures::root().canonicalize().unwrap();
    assert!(!dir.canonicalize().unwrap().starts_with(&repo));
    assert!(!dir.join("scenarios").exists());
    // `betr tui` with no scenario, only the model's flags.
    let command = format!(
        "cd {dir} && {isolated} {KEY_VAR}={KEY} {bin} tui --backend openai --base-url {url} \
         --model fake-model --api-key-env {KEY_VAR} --tick-ms 50; \
         echo \"betr exited with status $?\"; sleep 60",
        dir = quote(&dir),
        isolated = isolated_env(&dir),
        bin = quote(Path::new(env!("CARGO_BIN_EXE_betr"))),
        url = server.base_url(),
    );
    let tmux = Tmux::start(&command);
    tmux.wait_for(
        &[
            "Behavior tree",
            "press i to type an instruction",
            "red_on_blue",
            "openai fake-model",
        ],
        20,
    );
    // The scenario is whole: its base file (skills, predicates) and its example pool were
    // found beside it, so the instruction is read and planned.
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("Put the blue cube on the green cube");
    tmux.keys(&["Enter"]);
    tmux.wait_for(
        &[
            "Goal: \"blue cube\" on \"green cube\"",
            "grasp \"blue cube\"!",
        ],
        20,
    );
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    let shipped = dir.join("data/betr/scenarios");
    for file in [
        "cell/red_on_blue.toml",
        "cell/cell.toml",
        "cell/examples.toml",
    ] {
        assert!(shipped.join(file).is_file(), "{file} not installed");
    }
    // The model was asked with examples of the cell's pool in its prompt.
    let pool = support::repo::scenario("scenarios/cell/red_on_blue.toml").examples;
    let prompts: Vec<String> = server.received().iter().map(|r| r.prompt()).collect();
    assert!(
        prompts
            .iter()
            .any(|p| pool.iter().any(|e| p.contains(&e.instruction))),
        "{prompts:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
