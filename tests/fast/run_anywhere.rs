//! The binary started outside the repository, as after `cargo install --path .`: the
//! workbench opens on scenario 1 from the scenarios built into the binary (written into
//! the data directory on first use), and a scenario that does not exist is refused with
//! the places looked in, each once, and the scenarios known.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

mod support;

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

#[test]
fn a_missing_scenario_names_each_place_looked_in_once_and_lists_the_known_ones() {
    let dir = tmp("anywhere-missing");
    let out = support::cli::betr(&dir, &["plan", "scenarios/cell/red_on_green.toml"]);
    let text = support::cli::text(&out);
    assert_eq!(out.status.code(), Some(2), "{text}");
    let data = dir.join("data/betr/scenarios");
    let expected = format!(
        "scenario scenarios/cell/red_on_green.toml not found; looked for \
         scenarios/cell/red_on_green.toml, {}. Scenarios known: ",
        data.join("cell/red_on_green.toml").display()
    );
    assert!(text.contains(&expected), "{text}");
    for known in [
        "cafe/no_coffee",
        "cell/red_on_blue",
        "greenhouse/greenhouse",
    ] {
        assert!(text.contains(known), "{known} not listed: {text}");
    }
    assert!(!text.contains("cell/examples"), "{text}");
    // A name of the list works from here: the tree is planned, and the scenario's
    // hidden rule (no coffee) fails it in simulation.
    let out = support::cli::betr(&dir, &["plan", "cafe/no_coffee"]);
    let text = support::cli::text(&out);
    assert!(
        text.contains("failed in simulation: Coffee not found"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_goal_dataset_beside_the_repository_is_asked_for_clearly_elsewhere() {
    let dir = tmp("anywhere-dataset");
    let out = support::cli::betr(
        &dir,
        &[
            "eval",
            "goals",
            "--backend",
            "replay",
            "--cassette",
            "x.jsonl",
        ],
    );
    let text = support::cli::text(&out);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(
        text.contains("the goal dataset ../shared/datasets/llm-obtea is not there")
            && text.contains("--dataset DIR"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
