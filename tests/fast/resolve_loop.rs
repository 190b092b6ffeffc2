//! End to end: every failure scenario (a scenario file with `expected_fix`) and every
//! parameter scenario resolves through `betr resolve --yes` against the fake OpenAI server
//! answering with hand-written fixture replies: prompt → reply → validation → repair →
//! success in simulation → saved tree. Also through the library and through record/replay.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::{Path, PathBuf};

use betr::llm::openai::{AuthHeader, OpenAiClient, OpenAiSettings, RetryPolicy};
use betr::scenario::Scenario;
use betr::session::{self, Ending, Event, Options, Proposal};
use support::cli::{KEY_VAR, betr, resolve_yes, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::spread;

fn scenario_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.filter_map(Result::ok) {
        let p = e.path();
        if p.is_dir() {
            scenario_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "toml") {
            out.push(p);
        }
    }
}

/// Failure scenarios (with `expected_fix`) and parameter scenarios (under `params/`).
fn resolvable_scenarios() -> Vec<PathBuf> {
    let mut all = Vec::new();
    scenario_files(&fixtures::root().join("scenarios"), &mut all);
    all.sort();
    all.into_iter()
        .filter(|p| is_param(p) || Scenario::load(p).is_ok_and(|s| !s.expected_fix.is_empty()))
        // A failure only the real arms produce needs the robot's description, which the
        // isolated home these commands run in does not have (tests/slow/cell_arms.rs covers
        // those scenarios in the engine).
        .filter(|p| is_param(p) || !fails_only_with_the_arms(p))
        .collect()
}

/// The planning world (reach spheres and gripper sweep) plans the goal to success, yet
/// the scenario expects fixes.
fn fails_only_with_the_arms(path: &Path) -> bool {
    let Ok(s) = Scenario::load(path) else {
        return false;
    };
    let (Some(goal), Ok(world)) = (s.goal.clone(), betr::world::load(&s)) else {
        return false;
    };
    betr::planner::Planner::new(&s.domain)
        .plan(&goal.to_dnf(), world.as_ref())
        .is_ok_and(|plan| plan.outcome == betr::planner::Outcome::Success)
}

fn is_param(p: &Path) -> bool {
    p.components().any(|c| c.as_os_str() == "params")
}

fn relative(p: &Path) -> String {
    p.strip_prefix(fixtures::root())
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

#[test]
fn every_failure_and_parameter_scenario_resolves_through_the_cli() {
    let scenarios = resolvable_scenarios();
    assert!(scenarios.len() >= 3, "found {scenarios:?}");
    let files = fixtures::all();
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("cli");
    let mut calls = 0;
    for path in &scenarios {
        let rel = relative(path);
        assert!(
            files.iter().any(|(_, f)| f.scenario == rel),
            "no fixture replies for {rel} in tests/fixtures/replies/"
        );
        let scenario = Scenario::load(path).unwrap();
        let save = dir.join(format!(
            "{}.bt",
            path.file_stem().unwrap().to_string_lossy()
        ));
        let path_s = path.to_string_lossy().to_string();
        let save_s = save.to_string_lossy().to_string();
        let base = server.base_url();
        let mut args = resolve_yes(&path_s, &base);
        args.extend([
            "--save",
            &save_s,
            "--cassette",
            "cassette.jsonl",
            "--usage-log",
            "usage.jsonl",
        ]);
        let out = betr(&dir, &args);
        let log = text(&out);
        calls += log.matches("\n→ asking the model for ").count();
        // Shown with `cargo test --test resolve_loop -- --nocapture`.
        println!("$ betr resolve {rel} --yes ...\n{log}");
        assert_eq!(out.status.code(), Some(0), "{rel}:\n{log}");
        assert!(log.contains("SUCCESS in simulation"), "{rel}:\n{log}");
        assert!(
            log.contains("hand-written fixture, not a model's answer"),
            "{rel}:\n{log}"
        );
        assert!(
            !log.contains("reply from model"),
            "a fixture shown as a model's answer:\n{log}"
        );
        if is_param(path) {
            assert!(
                log.contains("Proposal: set "),
                "{rel}: expected a value:\n{log}"
            );
        }
        for fix in &scenario.expected_fix {
            assert!(
                log.contains(&format!("Proposal: insert {fix}")),
                "{rel}: expected the fix {fix}:\n{log}"
            );
        }
        // The saved tree runs to success on its own, without any model.
        let run = betr(&dir, &["run", &path_s, "--tree", &save_s]);
        assert_eq!(
            run.status.code(),
            Some(0),
            "{rel}: saved tree:\n{}",
            text(&run)
        );
    }
    // Every call was accounted.
    let usage = std::fs::read_to_string(dir.join("usage.jsonl")).unwrap();
    assert!(calls >= 2 * scenarios.len());
    assert_eq!(usage.lines().count(), calls, "{usage}");
    assert!(usage.contains("\"source\":\"hand-written\""));
    std::fs::remove_dir_all(&dir).unwrap();
}

// The library's loop in two tests, so the harness runs the halves side by side.
#[test]
fn the_library_loop_applies_the_expected_fixes_of_the_failure_scenarios() {
    library_loop_applies_the_expected_fixes(|p| !is_param(p));
}

#[test]
fn the_library_loop_applies_the_expected_values_of_the_parameter_scenarios() {
    library_loop_applies_the_expected_fixes(is_param);
}

/// Every resolvable scenario `which` selects resolves through `session::resolve` with the
/// fixture replies, reading the scenario's goal and inserting its expected fix.
fn library_loop_applies_the_expected_fixes(which: fn(&Path) -> bool) {
    let scenarios: Vec<PathBuf> = resolvable_scenarios()
        .into_iter()
        .filter(|p| which(p))
        .collect();
    assert!(!scenarios.is_empty(), "no scenario selected");
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let client = OpenAiClient::new(OpenAiSettings {
        base_url: server.base_url(),
        model: "fake-model".into(),
        api_key_env: None,
        api_key: None,
        auth_header: AuthHeader::Bearer,
        timeout: std::time::Duration::from_secs(5),
        connect_timeout: std::time::Duration::from_secs(1),
        retry: RetryPolicy::default(),
        structured: false,
        max_tokens_field: "max_tokens".into(),
        max_reply_bytes: 256 * 1024,
    })
    .unwrap();
    let client: std::sync::Arc<dyn betr::llm::LanguageModel> = std::sync::Arc::new(client);
    // Each scenario resolves in a world of its own, so they run on every core.
    spread::each(
        &scenarios,
        |p| relative(p),
        |path| {
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .unwrap();
            let scenario = Scenario::load(path).unwrap();
            let mut approved: Vec<Proposal> = Vec::new();
            let mut events = Vec::new();
            let r = rt
                .block_on(session::resolve(
                    &scenario,
                    None,
                    client.clone(),
                    &Options::default(),
                    &mut |p| {
                        approved.push(p.clone());
                        true
                    },
                    &mut |e| events.push(e.clone()),
                ))
                .unwrap();
            assert!(
                matches!(r.ending, Ending::Success { .. }),
                "{}: {:?}",
                scenario.name,
                r.ending
            );
            let goal_ok = events.iter().any(|e| {
                matches!(
                    e,
                    Event::Goal {
                        matches_expected: Some(true),
                        ..
                    }
                )
            });
            assert!(
                goal_ok,
                "{}: the interpreted goal differs from the scenario's",
                scenario.name
            );
            let inserted: Vec<String> = approved
                .iter()
                .flat_map(|p| match p {
                    Proposal::Conditions { conditions, .. } => {
                        conditions.iter().map(ToString::to_string).collect()
                    }
                    Proposal::Value { .. } => vec![],
                })
                .collect();
            assert_eq!(inserted, scenario.expected_fix, "{}", scenario.name);
            let values = approved
                .iter()
                .filter(|p| matches!(p, Proposal::Value { .. }))
                .count();
            assert_eq!(
                values > 0,
                is_param(path),
                "{}: {approved:?}",
                scenario.name
            );
        },
    );
}

#[test]
fn a_recorded_cassette_replays_without_a_server_and_misses_loudly() {
    let dir = tmp("replay");
    let scenario = fixtures::root().join("scenarios/cafe/sweep.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    {
        let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
        let base = server.base_url();
        let out = betr(
            &dir,
            &[
                "resolve",
                &scenario_s,
                "--yes",
                "--base-url",
                &base,
                "--model",
                "fake-model",
                "--api-key-env",
                KEY_VAR,
                "--cassette",
                "c.jsonl",
                "--save",
                "a.bt",
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    }
    let out = betr(
        &dir,
        &[
            "resolve",
            &scenario_s,
            "--yes",
            "--backend",
            "replay",
            "--cassette",
            "c.jsonl",
            "--save",
            "b.bt",
        ],
    );
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        log.contains("hand-written fixture"),
        "replay keeps the origin:\n{log}"
    );
    assert_eq!(
        std::fs::read(dir.join("a.bt")).unwrap(),
        std::fs::read(dir.join("b.bt")).unwrap()
    );
    // A different prompt (another request) is not in the cassette: replay refuses, exit 2.
    let out = betr(
        &dir,
        &[
            "interpret",
            &scenario_s,
            "Sweep the floor by the window twice",
            "--backend",
            "replay",
            "--cassette",
            "c.jsonl",
        ],
    );
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        text(&out).contains("has no reply for model \"fake-model\""),
        "{}",
        text(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn resolve_yes_never_keeps_a_change_that_fails_verification() {
    // Scenario 1 with the red cube fragile: the fix the model proposes grasps it.
    let path = fixtures::root().join("tests/fixtures/scenarios/fragile_red.toml");
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("cli-violation");
    let base = server.base_url();
    let out = betr(&dir, &resolve_yes(path.to_str().unwrap(), &base));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    assert!(
        stdout.contains("fails verification in the model"),
        "{stdout}"
    );
    assert!(
        stdout.contains("Nothing saved: no change was kept."),
        "{stdout}"
    );
    // Each refused change is told to the next question.
    assert!(
        stdout.contains("The change did not help and was undone: it fixes the failure in simulation, but the changed tree fails verification"),
        "{stdout}"
    );
    assert!(!stdout.contains("SUCCESS in simulation"), "{stdout}");
    // The counterexample is on stderr: the red cube grasped.
    assert!(stderr.contains("✕ never \"red cube\" grasped"), "{stderr}");
    assert!(stderr.contains("counterexample:"), "{stderr}");
    assert!(stderr.contains("grasp \"red cube\"!"), "{stderr}");
    assert!(
        !dir.join("data/betr/policies").exists() && !dir.join("policies").exists(),
        "nothing may be saved"
    );
}

#[test]
fn spread_cases_come_back_in_order() {
    let items: Vec<u32> = (0..20).collect();
    assert_eq!(
        spread::each(&items, |i| i.to_string(), |i| i * 2),
        (0..20).map(|i| i * 2).collect::<Vec<u32>>()
    );
}

#[test]
fn every_spread_case_that_fails_is_named() {
    let items = [1, 2, 3, 4];
    let told = std::panic::catch_unwind(|| {
        spread::each(
            &items,
            |i| format!("case {i}"),
            |i| assert!(i % 2 == 1, "{i} is even"),
        )
    })
    .unwrap_err();
    let told = spread::message(told.as_ref());
    assert!(told.starts_with("2 of 4 cases failed"), "{told}");
    assert!(told.contains("case 2: 2 is even"), "{told}");
    assert!(told.contains("case 4: 4 is even"), "{told}");
}

/// A cassette that cannot be written is refused before the model is asked: no call is
/// paid for whose reply could not be kept.
#[test]
fn a_cassette_that_cannot_be_written_is_refused_before_any_call() {
    let dir = tmp("cassette-unwritable");
    std::fs::write(dir.join("a-file"), "").unwrap();
    let scenario = fixtures::root().join("scenarios/cafe/sweep.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let base = server.base_url();
    let mut args = resolve_yes(&scenario_s, &base);
    args.extend(["--cassette", "a-file/c.jsonl"]);
    let out = betr(&dir, &args);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(log.contains("a-file/c.jsonl"), "{log}");
    assert!(
        server.received().is_empty(),
        "{} calls were sent",
        server.received().len()
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A person who answers "no" to the proposal ends the loop: the model is not asked again
/// (the one question about the failure is the last call the server sees).
#[test]
fn a_rejected_proposal_ends_the_loop_without_another_call() {
    use std::io::Write;
    let dir = tmp("reject-no-call");
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let base = server.base_url();
    let mut args = vec!["resolve", &scenario_s[..], "--stated-goal"];
    args.extend(support::cli::openai_flags(&base));
    let mut child = support::cli::command(&dir, &args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(b"n\n").unwrap();
    let out = child.wait_with_output().unwrap();
    let log = text(&out);
    assert!(log.contains("Not approved; stopping."), "{log}");
    assert_eq!(out.status.code(), Some(1), "{log}");
    // The stated goal needs no reading: the only call is the question about the failure.
    assert_eq!(server.received().len(), 1, "{log}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A cassette on a full disk (`/dev/full` refuses every write with "no space") loses
/// nothing else: the loop goes on, the tree that succeeded is saved, and the command then
/// fails naming the cassette.
#[test]
fn a_cassette_on_a_full_disk_keeps_the_tree_and_fails_the_command_at_its_end() {
    let dir = tmp("cassette-full");
    let scenario = fixtures::root().join("scenarios/cafe/sweep.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let base = server.base_url();
    let mut args = resolve_yes(&scenario_s, &base);
    args.extend(["--cassette", "/dev/full", "--save", "kept.bt"]);
    let out = betr(&dir, &args);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(log.contains("could not write /dev/full"), "{log}");
    assert!(
        std::fs::read_to_string(dir.join("kept.bt")).is_ok_and(|t| !t.is_empty()),
        "{log}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}
