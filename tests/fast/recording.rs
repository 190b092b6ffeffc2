//! Session recordings end to end: a `betr resolve` session against the fake OpenAI server
//! recorded with `--record`, replayed with no server running (the model's replies, the
//! failure and the proposal come from the file; printed with `--print`, the workbench
//! refused without a terminal), converted to a rerun recording; a
//! `betr repair` session likewise; a recording cut mid-entry (as a crash leaves it) replays
//! up to its last whole entry; the events read back carry the statuses of the recorded
//! ticks node for node; and the recordings of format version 1 in
//! tests/fixtures/recordings still load, replay, and write again as the current version.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::io::Write;

use betr::bt::{self, Status};
use betr::record::{Replay, SessionRecorder, Step};
use betr::session::Event;
use support::cli::{KEY_VAR, betr, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

#[test]
fn a_resolve_session_is_recorded_and_replayed_without_the_model() {
    let dir = tmp("record-resolve");
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let record = dir.join("session.jsonl");
    let record_s = record.to_string_lossy().to_string();
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
                "--record",
                &record_s,
                "--save",
                "a.bt",
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    }
    // No server from here on.
    let replay = Replay::load(&record, None).unwrap();
    assert_eq!(replay.scenario.name, "Red cube on the blue cube");
    assert_eq!(replay.cut_at, None);
    let events: Vec<&Event> = replay
        .steps
        .iter()
        .filter_map(|(_, s)| match s {
            Step::Event(e) => Some(e),
            Step::Command(_) => None,
        })
        .collect();
    let failure = events
        .iter()
        .position(|e| matches!(e, Event::ActionFailed { .. }))
        .expect("the failure is recorded");
    let proposal = events
        .iter()
        .position(|e| matches!(e, Event::Proposal { .. }))
        .expect("the proposal is recorded");
    assert!(failure < proposal);
    assert!(
        events
            .iter()
            .any(|e| matches!(e, Event::Replied { text, .. } if !text.is_empty())),
        "the model's replies are in the recording"
    );
    assert!(events.iter().any(|e| matches!(e, Event::Success { .. })));
    let ticks = events
        .iter()
        .filter(|e| matches!(e, Event::Ticked { .. }))
        .count();
    assert!(ticks > 5, "{ticks} ticks");

    let out = betr(&dir, &["replay", &record_s, "--print"]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        log.contains("failed in simulation: No collision free path found"),
        "{log}"
    );
    assert!(log.contains("Proposal: "), "{log}");
    assert!(log.contains("✓ SUCCESS"), "{log}");
    // Without --print the replay is the workbench, which needs a terminal.
    let out = betr(&dir, &["replay", &record_s]);
    assert_ne!(out.status.code(), Some(0), "{}", text(&out));
    assert!(text(&out).contains("--print"), "{}", text(&out));

    let rrd = dir.join("session.rrd");
    let rrd_s = rrd.to_string_lossy().to_string();
    let out = betr(&dir, &["replay", &record_s, "--to-rrd", &rrd_s]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(
        !text(&out).contains("re-simulating the cell gave other statuses"),
        "{}",
        text(&out)
    );
    assert!(std::fs::metadata(&rrd).unwrap().len() > 1000);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_repair_session_replays_its_ticks_node_for_node() {
    let dir = tmp("record-repair");
    let record = dir.join("repair.jsonl");
    let record_s = record.to_string_lossy().to_string();
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let out = betr(
        &dir,
        &[
            "repair",
            &scenario_s,
            "--add",
            "~\"any object\" on \"blue cube\"",
            "--record",
            &record_s,
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let replay = Replay::load(&record, None).unwrap();
    let mut tree = None;
    let mut last = None;
    for (_, step) in &replay.steps {
        match step {
            Step::Event(Event::TreeChanged { tree: t, .. }) => tree = Some(t.clone()),
            Step::Event(Event::Ticked { record }) => last = Some(record.clone()),
            _ => {}
        }
    }
    let (tree, last) = (tree.unwrap(), last.unwrap());
    // The final tick: the goal condition holds, so the root succeeds through it.
    let root = tree.root();
    assert_eq!(last.status(root), Status::Success);
    let goal = tree.children(root).unwrap()[0];
    assert_eq!(
        tree.kind(goal).unwrap().as_condition().unwrap().to_string(),
        "\"blue cube\" on \"green cube\""
    );
    assert_eq!(last.status(goal), Status::Success);
    // The replayed tree is the repaired one.
    assert!(bt::to_text(&tree).contains("~\"any object\" on \"blue cube\"?"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_recording_cut_mid_entry_replays_up_to_its_last_whole_entry() {
    let dir = tmp("record-cut");
    let record = dir.join("cut.jsonl");
    let record_s = record.to_string_lossy().to_string();
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let out = betr(&dir, &["run", &scenario_s, "--record", &record_s]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    let whole = std::fs::read(&record).unwrap();
    // As a crash mid-write leaves it: half of one more entry, no newline.
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .open(&record)
        .unwrap();
    f.write_all(br#"{"kind":"event","ms":99,"event":{"event":"tick","tick":7,"#)
        .unwrap();
    drop(f);
    let replay = Replay::load(&record, None).unwrap();
    assert!(replay.cut_at.is_some());
    let out = betr(&dir, &["replay", &record_s, "--print"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(text(&out).contains("partial entry"), "{}", text(&out));
    assert!(text(&out).contains("failed in simulation: No collision free path found"));
    // A line broken in the middle of the file is an error naming it (exit 2).
    let mut broken = b"".to_vec();
    let first_newline = whole.iter().position(|b| *b == b'\n').unwrap();
    broken.extend_from_slice(&whole[..=first_newline]);
    broken.extend_from_slice(b"{oops\n");
    broken.extend_from_slice(&whole[first_newline + 1..]);
    std::fs::write(&record, broken).unwrap();
    let out = betr(&dir, &["replay", &record_s, "--print"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("line 2"), "{}", text(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}
/// A reasoning whose claim the world contradicts ("the red cube is on the table", while it
/// lies on the blue cube) is recorded as doubtful with the claim quoted: the replay says so
/// where it tells the proposal.
#[test]
fn a_false_claim_in_the_reasoning_is_recorded_as_doubtful() {
    let dir = tmp("record-false-claim");
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let record = dir.join("session.jsonl");
    let record_s = record.to_string_lossy().to_string();
    {
        let mut replies = vec![fixtures::false_claim_reply()];
        replies.extend(fixtures::replies_of("red_on_blue.toml"));
        let server = FakeServer::start(vec![], Behavior::Fixtures(replies));
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
                "--record",
                &record_s,
            ],
        );
        assert!(out.status.code().is_some(), "{}", text(&out));
    }
    let out = betr(&dir, &["replay", &record_s, "--print"]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        log.contains(
            "doubtful (it says \"The red cube is on the table\", but \"red cube\" on \"table\" is false at the failure)"
        ),
        "{log}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The steps of `replay` in words, as `betr replay --print` tells them.
fn told(replay: &Replay) -> Vec<String> {
    replay
        .steps
        .iter()
        .flat_map(|(_, s)| betr::record::describe_step(s))
        .collect()
}

#[test]
fn a_version_1_recording_still_loads_replays_and_writes_again() {
    let dir = tmp("record-v1");
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    for name in ["v1-resolve.jsonl", "v1-repair.jsonl"] {
        let old = fixtures::root()
            .join("tests/fixtures/recordings")
            .join(name);
        let replay = Replay::load(&old, Some(&scenario)).unwrap();
        assert_eq!(replay.header.version, 1);
        assert_eq!(replay.cut_at, None);
        // The failure names its node by id and by path in the tree it failed in.
        let mut tree = None;
        let mut failed = false;
        for (_, step) in &replay.steps {
            match step {
                Step::Event(Event::TreeChanged { tree: t, .. }) => tree = Some(t.clone()),
                Step::Event(Event::ActionFailed {
                    node, node_path, ..
                }) => {
                    let tree = tree.as_ref().expect("a tree before the failure");
                    assert_eq!(&tree.path(*node).unwrap(), node_path);
                    failed = true;
                }
                _ => {}
            }
        }
        assert!(failed, "{name}: the failure is read back");
        let words = told(&replay);
        assert!(
            words
                .iter()
                .any(|w| w.contains("failed in simulation: No collision free path found")),
            "{name}: {words:#?}"
        );
        assert!(words.iter().any(|w| w.starts_with("✓ SUCCESS")), "{name}");

        // Written again, it is a recording of the current version that tells the same.
        let new = dir.join(name);
        let mut recorder =
            SessionRecorder::create(&new, &scenario, &replay.scenario.name, None).unwrap();
        for (_, step) in &replay.steps {
            if let Step::Event(e) = step {
                recorder.event(e);
            }
        }
        drop(recorder);
        let again = Replay::load(&new, None).unwrap();
        assert_eq!(again.header.version, betr::record::VERSION);
        let events = |r: &Replay| -> Vec<String> {
            r.steps
                .iter()
                .filter(|(_, s)| matches!(s, Step::Event(_)))
                .flat_map(|(_, s)| betr::record::describe_step(s))
                .collect()
        };
        assert_eq!(events(&again), events(&replay), "{name}");
        let ticks = |r: &Replay| -> Vec<Vec<Status>> {
            r.steps
                .iter()
                .filter_map(|(_, s)| match s {
                    Step::Event(Event::Ticked { record }) => Some(record.statuses.clone()),
                    _ => None,
                })
                .collect()
        };
        assert!(!ticks(&replay).is_empty());
        assert_eq!(
            ticks(&again),
            ticks(&replay),
            "{name}: the ticks node for node"
        );

        let out = betr(
            &dir,
            &[
                "replay",
                &old.to_string_lossy(),
                "--scenario",
                &scenario_s,
                "--print",
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", text(&out));
        assert!(text(&out).contains("✓ SUCCESS"), "{}", text(&out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
