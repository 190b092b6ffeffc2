//! Every number from outside is checked against its range before it is used, and a
//! model's reply is read only up to its cap: the real binary with flags, `betr.toml`
//! settings and a fake OpenAI server that sends too much.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::Path;
use std::process::Output;

use support::cli::{betr, openai_flags, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

fn cafe() -> String {
    fixtures::root()
        .join("scenarios/cafe/no_coffee.toml")
        .to_string_lossy()
        .into_owned()
}

/// `betr interpret` of the cafe scenario against `base`, with `extra` flags.
fn interpret(dir: &Path, base: &str, extra: &[&str]) -> Output {
    let scenario = cafe();
    let mut args = vec!["interpret", &scenario, "Bring a coffee to the window table"];
    args.extend(openai_flags(base));
    args.extend_from_slice(extra);
    betr(dir, &args)
}

/// Refused with exit 2, no panic, and the error says `phrase`.
fn refused(out: &Output, phrase: &str) {
    let log = text(out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(!log.contains("panicked"), "{log}");
    assert!(log.contains(phrase), "expected {phrase:?} in:\n{log}");
}

#[test]
fn durations_and_counts_out_of_range_are_refused_with_the_range() {
    let server = FakeServer::start(
        vec![],
        Behavior::Reply("Goal: On_Coffee_WindowTable6".into()),
    );
    let base = server.base_url();
    let dir = tmp("bounds-flags");
    for t in ["1e20", "0", "-1", "NaN", "inf", "3601"] {
        refused(
            &interpret(&dir, &base, &[&format!("--timeout={t}")]),
            "timeout_secs = ",
        );
    }
    refused(
        &interpret(&dir, &base, &["--temperature", "1e30"]),
        "temperature = ",
    );
    refused(
        &interpret(&dir, &base, &["--max-retries", "4000000000"]),
        "max_retries = ",
    );
    // The lab's levers, on the command that takes them.
    for k in ["4294967296", "18446744073709551615", "101"] {
        refused(
            &betr(&dir, &["eval", "goals", "--examples-shown", k]),
            "is not in 0..=100",
        );
    }
    refused(
        &betr(&dir, &["eval", "goals", "--candidates", "0"]),
        "is not in 1..=64",
    );
    let scenario = cafe();
    refused(
        &betr(&dir, &["run", &scenario, "--max-ticks", "0"]),
        "is not in 1..=1000000000",
    );
    assert_eq!(server.received().len(), 0, "nothing was asked");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn settings_files_out_of_range_are_refused() {
    let server = FakeServer::start(
        vec![],
        Behavior::Reply("Goal: On_Coffee_WindowTable6".into()),
    );
    let base = server.base_url();
    let dir = tmp("bounds-config");
    for (setting, said) in [
        ("connect_timeout_secs = 1e20", "connect_timeout_secs = "),
        ("timeout_secs = 1e20", "timeout_secs = "),
        ("max_tokens = 0", "max_tokens = 0"),
        ("context = 4294967295", "context = 4294967295"),
        ("max_reply_bytes = 1099511627776", "max_reply_bytes = "),
        (
            "initial_backoff_ms = 18446744073709551615",
            "initial_backoff_ms = ",
        ),
    ] {
        std::fs::write(dir.join("betr.toml"), format!("[llm]\n{setting}\n")).unwrap();
        refused(&interpret(&dir, &base, &["--config", "betr.toml"]), said);
    }
    // Speech to text: the timeout of `[stt]`, checked before any audio is sent.
    std::fs::write(
        dir.join("betr.toml"),
        format!("[stt]\nbackend = \"openai\"\nbase_url = \"{base}\"\ntimeout_secs = 1e20\n"),
    )
    .unwrap();
    std::fs::write(dir.join("a.wav"), silence_wav()).unwrap();
    refused(
        &betr(&dir, &["transcribe", "a.wav", "--config", "betr.toml"]),
        "timeout_secs = ",
    );
    assert_eq!(server.received().len(), 0, "nothing was asked");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A tenth of a second of 16 kHz mono 16-bit silence.
fn silence_wav() -> Vec<u8> {
    let samples = 1600u32;
    let data = samples * 2;
    let mut w = Vec::new();
    w.extend_from_slice(b"RIFF");
    w.extend_from_slice(&(36 + data).to_le_bytes());
    w.extend_from_slice(b"WAVEfmt ");
    w.extend_from_slice(&16u32.to_le_bytes());
    w.extend_from_slice(&1u16.to_le_bytes()); // PCM
    w.extend_from_slice(&1u16.to_le_bytes()); // mono
    w.extend_from_slice(&16_000u32.to_le_bytes());
    w.extend_from_slice(&32_000u32.to_le_bytes());
    w.extend_from_slice(&2u16.to_le_bytes());
    w.extend_from_slice(&16u16.to_le_bytes());
    w.extend_from_slice(b"data");
    w.extend_from_slice(&data.to_le_bytes());
    w.resize(w.len() + data as usize, 0);
    w
}

#[test]
fn an_endless_reply_is_cut_off_at_the_cap() {
    let server = FakeServer::start(vec![], Behavior::Endless);
    let dir = tmp("bounds-endless");
    let out = interpret(&dir, &server.base_url(), &[]);
    refused(&out, "longer than 262144 bytes");
    assert_eq!(server.received().len(), 1, "not asked again");
    // The cap is a setting of `[llm]`.
    std::fs::write(dir.join("betr.toml"), "[llm]\nmax_reply_bytes = 4096\n").unwrap();
    let out = interpret(&dir, &server.base_url(), &["--config", "betr.toml"]);
    refused(&out, "longer than 4096 bytes");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn prompts_and_errors_never_grow_with_a_long_reply() {
    // 200 KB (under the cap) that is no goal: refused, and told to the model again.
    let junk = format!("Goal: {}", "On_Coffee ".repeat(20_000));
    let server = FakeServer::start(vec![], Behavior::Reply(junk));
    let dir = tmp("bounds-echo");
    let out = interpret(&dir, &server.base_url(), &[]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let received = server.received();
    assert!(received.len() >= 2, "{} calls", received.len());
    let first = received[0].prompt().len();
    for r in &received {
        let size = r.prompt().len();
        assert!(
            size < first + 10_000,
            "a prompt of {size} bytes after one of {first}"
        );
    }
    for line in String::from_utf8_lossy(&out.stderr).lines() {
        assert!(
            line.len() < 2_000,
            "a line of {} bytes on stderr",
            line.len()
        );
    }
    assert!(
        out.stdout.len() < 100_000,
        "{} bytes on stdout",
        out.stdout.len()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A tree file nested thousands of levels deep (6 MB of text) is refused when it is read,
/// naming the line, where `verify` and `repair` used to overflow the stack.
#[test]
fn a_tree_nested_too_deep_is_refused_not_a_stack_overflow() {
    let dir = tmp("bounds-deep-tree");
    let mut tree = String::new();
    let levels = 2_400;
    for depth in 0..levels {
        tree.push_str(&"  ".repeat(depth));
        tree.push_str("sequence\n");
    }
    tree.push_str(&"  ".repeat(levels));
    tree.push_str("\"red cube\" on \"blue cube\"?\n");
    std::fs::write(dir.join("deep.bt"), &tree).unwrap();
    let scenario = fixtures::root()
        .join("scenarios/cell/red_on_blue.toml")
        .to_string_lossy()
        .into_owned();
    for args in [
        vec!["verify", &scenario[..], "--tree", "deep.bt"],
        vec![
            "repair",
            &scenario,
            "--tree",
            "deep.bt",
            "--add",
            "~\"any object\" on \"blue cube\"",
        ],
    ] {
        let out = betr(&dir, &args);
        let log = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {log}");
        assert!(
            log.contains("deep.bt:") && log.contains("levels of nesting"),
            "{args:?}: {log}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A scenario that extends a device without end (`/dev/zero`) is read only up to the
/// limit for a scenario file, and refused naming it, not read until memory runs out.
#[test]
fn a_scenario_extending_a_file_without_end_is_refused_at_the_limit() {
    let dir = tmp("bounds-endless-base");
    std::fs::write(dir.join("s.toml"), "extends = \"/dev/zero\"\n").unwrap();
    let out = betr(&dir, &["plan", "s.toml"]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(
        log.contains("/dev/zero") && log.contains("larger than 4 MiB"),
        "{log}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A goal of twelve either/or choices (4,096 alternatives once multiplied out) is refused
/// when read, naming the limit, instead of planning for minutes; repeated choices absorb
/// and are planned.
#[test]
fn a_goal_with_too_many_alternatives_is_refused_when_read() {
    let dir = tmp("bounds-alternatives");
    let scenario = fixtures::root()
        .join("scenarios/cafe/cafe.toml")
        .to_string_lossy()
        .into_owned();
    let same = vec!["(On_Chips_Table1 | On_Milk_Table1)"; 16].join(" & ");
    let out = betr(&dir, &["plan", &scenario, "--goal", &same]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let places = [
        "Table1",
        "Table2",
        "Table3",
        "WindowTable4",
        "WindowTable5",
        "WindowTable6",
        "QuietTable7",
        "QuietTable8",
        "QuietTable9",
        "ReadingNook",
        "Bar",
        "Bar2",
    ];
    let different: Vec<String> = places
        .iter()
        .map(|p| format!("(On_Chips_{p} | On_Milk_{p})"))
        .collect();
    let out = betr(&dir, &["plan", &scenario, "--goal", &different.join(" & ")]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(log.contains("at most 1024 alternatives"), "{log}");
    std::fs::remove_dir_all(dir).unwrap();
}
