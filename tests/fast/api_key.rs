//! A secret API key set in the environment during a run appears in no file the run wrote:
//! not the cassette, the usage log, the session recording, the rerun recordings, the saved
//! tree or the config file, and not in an error.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use support::cli::{KEY, KEY_VAR, betr, files_under, relative_to, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

#[test]
fn the_api_key_appears_in_no_file_the_run_wrote() {
    let dir = tmp("key");
    std::fs::write(
        dir.join("betr.toml"),
        format!(
            "[llm]\nbackend = \"openai\"\nmodel = \"fake-model\"\napi_key_env = \"{KEY_VAR}\"\n"
        ),
    )
    .unwrap();
    let scenario = fixtures::root().join("scenarios/cafe/no_coffee.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let base = server.base_url();
    // Default paths: ./betr.toml is read, the usage log goes to $XDG_STATE_HOME, the tree
    // to the policy directory in $XDG_DATA_HOME.
    let out = betr(
        &dir,
        &[
            "resolve",
            &scenario_s,
            "--yes",
            "--base-url",
            &base,
            "--cassette",
            "rec.jsonl",
            "--record",
            "session.jsonl",
            "--rrd",
            "session.rrd",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    // The recording converted for the 3D view too.
    let out = betr(
        &dir,
        &["replay", "session.jsonl", "--to-rrd", "replayed.rrd"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let out = betr(
        &dir,
        &[
            "interpret",
            &scenario_s,
            "--base-url",
            &base,
            "--show-replies",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(!text(&out).contains(KEY));
    // A server that rejects the key (and echoes it back): the error names the variable only,
    // and an existing tree file is left as it was.
    std::fs::write(dir.join("keep.bt"), "unchanged").unwrap();
    let bad = FakeServer::start(vec![], Behavior::Unauthorized);
    let bad_base = bad.base_url();
    let out = betr(
        &dir,
        &[
            "resolve",
            &scenario_s,
            "--yes",
            "--base-url",
            &bad_base,
            "--save",
            "keep.bt",
        ],
    );
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(log.contains(KEY_VAR) && !log.contains(KEY), "{log}");
    assert_eq!(
        std::fs::read_to_string(dir.join("keep.bt")).unwrap(),
        "unchanged"
    );
    // The key really was sent, so its absence from the files means something.
    let sent = server.received();
    assert!(
        sent.iter()
            .all(|r| r.header("authorization") == Some(format!("Bearer {KEY}").as_str()))
    );

    let written = files_under(&dir);
    let names: Vec<String> = written.iter().map(|p| relative_to(p, &dir)).collect();
    for expected in [
        "betr.toml",
        "rec.jsonl",
        "session.jsonl",
        "session.rrd",
        "replayed.rrd",
        "state/betr/usage.jsonl",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} not written; files: {names:?}"
        );
    }
    assert!(
        names
            .iter()
            .any(|n| n.starts_with("data/betr/policies/no_coffee-") && n.ends_with(".bt")),
        "no policy written; files: {names:?}"
    );
    for file in &written {
        let bytes = std::fs::read(file).unwrap();
        let hay = String::from_utf8_lossy(&bytes);
        assert!(!hay.contains(KEY), "the key is in {}", file.display());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_key_inside_the_base_url_or_repeated_by_a_reply_appears_in_nothing_written() {
    let dir = tmp("key-in-url");
    let scenario = fixtures::root()
        .join("scenarios/cafe/no_coffee.toml")
        .to_string_lossy()
        .into_owned();
    // A reply that repeats the key it was sent with.
    let server = FakeServer::start(
        vec![],
        Behavior::Reply(format!(
            "Reasoning: the key is {KEY}.\nGoal: On_Coffee_WindowTable6"
        )),
    );
    let base = format!("http://user:{KEY}@{}/v1", server.addr);
    let mut args = support::cli::resolve_yes(&scenario, &base);
    args.extend([
        "--cassette",
        "c.jsonl",
        "--record",
        "r.jsonl",
        "--show-replies",
    ]);
    // The variable the key is configured in is empty: only the URL holds the key.
    let out = support::cli::betr_with(&dir, &args, &[(KEY_VAR, ""), ("BETR_LOG", "betr=debug")]);
    let sent = server.received();
    assert!(!sent.is_empty(), "{}", text(&out));
    assert!(
        sent.iter()
            .all(|r| r.header("authorization") == Some(format!("Bearer {KEY}").as_str())),
        "the key from the URL is sent as the key"
    );
    assert!(
        !text(&out).contains(KEY),
        "the key on the terminal:\n{}",
        text(&out)
    );
    let written = files_under(&dir);
    assert!(written.iter().any(|p| p.ends_with("c.jsonl")));
    assert!(written.iter().any(|p| p.ends_with("r.jsonl")));
    for file in &written {
        let hay = String::from_utf8_lossy(&std::fs::read(file).unwrap()).into_owned();
        assert!(!hay.contains(KEY), "the key is in {}", file.display());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
