//! The binary started outside the repository, as after `cargo install --path .`: a
//! scenario that does not exist is refused with the places looked in, each once, and the
//! scenarios known. (The workbench opening there on the built-in scenario 1, in tmux: the
//! slow tier's `run_anywhere`.)

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use support::cli::tmp;

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

/// Offline (`BETR_OFFLINE=1` or `--offline`), a command that needs the embedded model it
/// does not have fails saying so, and starts no download.
#[test]
fn offline_the_commands_that_read_with_the_embedded_model_fetch_nothing() {
    let dir = tmp("anywhere-offline");
    let scenario = support::fixtures::root()
        .join("scenarios/cell/red_on_blue.toml")
        .to_string_lossy()
        .into_owned();
    for (args, offline) in [
        (vec!["interpret", &scenario[..]], "1"),
        (vec!["resolve", &scenario, "--yes"], "1"),
        (vec!["--offline", "interpret", &scenario], "0"),
        (vec!["--offline", "model", "fetch"], "0"),
    ] {
        let out = support::cli::betr_with(&dir, &args, &[("BETR_OFFLINE", offline)]);
        let text = support::cli::text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {text}");
        assert!(
            text.contains("--offline (or BETR_OFFLINE) fetches nothing"),
            "{args:?}: {text}"
        );
        assert!(!text.contains("Fetching"), "{args:?}: {text}");
        assert!(
            !dir.join("cache/betr/models").exists()
                || support::cli::files_under(&dir.join("cache/betr/models")).is_empty(),
            "{args:?} left files in the cache"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}
