//! Cassettes and the usage log grow by whole lines: a line cut by a process killed
//! midway through it (written here as a kill leaves it) is left out and reported when
//! the cassette is replayed, and taken off before the next line is appended, so one cut
//! entry never makes a whole file unreadable. The real binary against a fake server.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::io::Write;
use std::path::Path;
use std::process::Output;

use support::cli::{betr, openai_flags, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

fn interpret(dir: &Path, backend: &[&str], instruction: &str) -> Output {
    let scenario = fixtures::root()
        .join("scenarios/cafe/no_coffee.toml")
        .to_string_lossy()
        .into_owned();
    let mut args = vec![
        "interpret",
        &scenario,
        instruction,
        "--cassette",
        "c.jsonl",
        "--usage-log",
        "u.jsonl",
    ];
    args.extend_from_slice(backend);
    betr(dir, &args)
}

/// What a process killed in the middle of writing an entry leaves: half a line.
fn cut_a_line(path: &Path) {
    let text = std::fs::read_to_string(path).unwrap();
    let half = &text.lines().next().unwrap()[..40];
    std::fs::OpenOptions::new()
        .append(true)
        .open(path)
        .unwrap()
        .write_all(half.as_bytes())
        .unwrap();
}

fn every_line_is_json(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(
        text.ends_with('\n'),
        "{} ends with a whole line",
        path.display()
    );
    for line in text.lines() {
        serde_json::from_str::<serde_json::Value>(line)
            .unwrap_or_else(|e| panic!("{}: {e}: {line}", path.display()));
    }
    text.lines().count()
}

#[test]
fn a_cut_last_line_is_left_out_on_replay_and_taken_off_before_the_next_entry() {
    let server = FakeServer::start(
        vec![],
        Behavior::Reply("Goal: On_Coffee_WindowTable6".into()),
    );
    let base = server.base_url();
    let live = openai_flags(&base);
    let replay = ["--backend", "replay", "--model", "fake-model"];
    let dir = tmp("whole-lines");
    let first = "Bring a coffee to the window table";
    let out = interpret(&dir, &live, first);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let (cassette, usage) = (dir.join("c.jsonl"), dir.join("u.jsonl"));
    cut_a_line(&cassette);
    cut_a_line(&usage);

    // Replay leaves the cut line out, says so, and answers from the whole ones.
    let out = interpret(&dir, &replay, first);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(log.contains("last line was cut"), "{log}");

    // The next live run appends whole lines after taking the cut one off.
    let second = "The window table wants its coffee";
    let out = interpret(&dir, &live, second);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert_eq!(every_line_is_json(&cassette), 2);
    assert!(every_line_is_json(&usage) >= 2);
    for instruction in [first, second] {
        let out = interpret(&dir, &replay, instruction);
        let log = text(&out);
        assert_eq!(out.status.code(), Some(0), "{log}");
        assert!(!log.contains("was cut"), "{log}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
