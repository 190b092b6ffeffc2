//! A `betr resolve` session recording with `--record`, killed (SIGKILL) while it waits for
//! the model: the recording up to the kill replays, the failure before it included.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use betr::record::{Replay, Step};
use betr::session::Event;
use support::cli::{KEY_VAR, betr, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

#[test]
fn a_session_killed_midway_leaves_a_recording_that_replays() {
    let dir = tmp("record-kill");
    let record = dir.join("killed.jsonl");
    let record_s = record.to_string_lossy().to_string();
    let scenario = fixtures::root().join("scenarios/cafe/no_coffee.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    // The model takes its time: the session is killed while it waits.
    let server = FakeServer::start(
        vec![],
        Behavior::Slow(
            std::time::Duration::from_secs(30),
            "Goal: On_Coffee_WindowTable6".into(),
        ),
    );
    let base = server.base_url();
    let mut child = support::cli::command(
        &dir,
        &[
            "resolve",
            &scenario_s,
            "--yes",
            "--stated-goal",
            "--base-url",
            &base,
            "--model",
            "fake-model",
            "--api-key-env",
            KEY_VAR,
            "--record",
            &record_s,
        ],
    )
    .stdout(std::process::Stdio::null())
    .stderr(std::process::Stdio::null())
    .spawn()
    .unwrap();
    let started = std::time::Instant::now();
    // Waiting for the model means the failure is recorded: the tree, its ticks, the question.
    while !std::fs::read_to_string(&record).is_ok_and(|r| r.contains("\"event\":\"asking\"")) {
        assert!(
            started.elapsed() < std::time::Duration::from_secs(60),
            "the session never asked the model"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let replay = Replay::load(&record, None).unwrap();
    assert!(
        replay
            .steps
            .iter()
            .any(|(_, s)| matches!(s, Step::Event(Event::ActionFailed { .. }))),
        "the failure before the kill is in the recording"
    );
    let out = betr(&dir, &["replay", &record_s, "--print"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(text(&out).contains("asking the model"), "{}", text(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}
