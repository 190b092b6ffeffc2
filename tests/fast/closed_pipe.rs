//! Every printing command with a reader that has gone before the first line
//! (`betr plan S | head -0`): it must end as it would have ended with its output read
//! (never a panic, exit 101), and keep everything it saves — trees, policies, learned
//! rules and recordings.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::Path;
use std::process::{Output, Stdio};

use support::cli::{Scratch, command, openai_flags, resolve_yes, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

fn scenario() -> String {
    fixtures::root()
        .join("scenarios/cell/red_on_blue.toml")
        .to_string_lossy()
        .into_owned()
}

/// The command with its standard output read to the end.
fn read_whole(dir: &Path, args: &[&str]) -> Output {
    command(dir, args).output().unwrap()
}

/// The command writing into a pipe whose reader has already gone: its first write fails
/// with a broken pipe. Standard error is kept.
fn closed_early(dir: &Path, args: &[&str]) -> Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    command(dir, args)
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

/// Two scratch directories, one for each way of running.
fn twins(name: &str) -> (Scratch, Scratch) {
    (tmp(&format!("{name}-read")), tmp(&format!("{name}-closed")))
}

/// Run `args` both ways in their own directory and check that they end alike; the
/// directories are returned for what they saved.
fn both_ways(name: &str, args: &[&str]) -> (Scratch, Scratch) {
    let (read, closed) = twins(name);
    let whole = read_whole(&read, args);
    let cut = closed_early(&closed, args);
    let stderr = String::from_utf8_lossy(&cut.stderr);
    assert_ne!(cut.status.code(), Some(101), "{args:?} panicked:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}:\n{stderr}");
    assert_eq!(
        cut.status.code(),
        whole.status.code(),
        "{args:?} ends otherwise when nobody reads it:\n{stderr}\n--- read whole:\n{}",
        text(&whole)
    );
    (read, closed)
}

/// The same tree saved both ways (a policy's header lines carry the time it was saved).
fn same_file(read: &Path, closed: &Path, name: &str) {
    let tree = |dir: &Path, how: &str| {
        let text = std::fs::read_to_string(dir.join(name))
            .unwrap_or_else(|e| panic!("{name} with the output {how}: {e}"));
        text.lines()
            .filter(|l| !l.starts_with('#'))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let whole = tree(read, "read");
    assert!(!whole.is_empty(), "{name} holds a tree");
    assert_eq!(whole, tree(closed, "closed"), "{name}");
}

#[test]
fn commands_without_a_model_end_as_they_would_and_keep_their_saves() {
    let s = scenario();
    let add = "~\"any object\" on \"blue cube\"";
    let commands: Vec<Vec<&str>> = vec![
        vec!["plan", &s],
        vec!["plan", &s, "--goal", "\"red cube\" on \"green cube\""],
        vec!["run", &s],
        vec!["run", &s, "--trace"],
        vec!["run", &s, "--variant", "clear"],
        vec!["repair", &s, "--add", add],
        vec!["verify", &s],
        vec!["export", &s, "--format", "dot"],
        vec!["export", &s, "--format", "btcpp"],
        vec!["knowledge", "list"],
        vec!["model", "list"],
        vec!["--help"],
        vec!["--version"],
        vec!["plan", "--help"],
    ];
    for (i, args) in commands.iter().enumerate() {
        let (a, b) = both_ways(&format!("pipe-{i}"), args);
        for d in [a, b] {
            std::fs::remove_dir_all(d).unwrap();
        }
    }
}

#[test]
fn a_repaired_tree_is_saved_when_nobody_reads_the_output() {
    let s = scenario();
    let args = [
        "repair",
        &s,
        "--add",
        "~\"any object\" on \"blue cube\"",
        "--save",
        "s.bt",
    ];
    let (read, closed) = both_ways("pipe-repair-save", &args);
    same_file(&read, &closed, "s.bt");
    for d in [read, closed] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn a_recording_is_whole_and_replays_when_nobody_reads_the_output() {
    let s = scenario();
    let (read, closed) = both_ways("pipe-record", &["run", &s, "--record", "r.jsonl"]);
    for dir in [&read, &closed] {
        let recording = betr::record::read(&dir.join("r.jsonl")).unwrap();
        assert_eq!(recording.cut_at, None);
        assert!(!recording.entries.is_empty());
        // Printing the recording, to a reader that has gone too.
        let out = closed_early(dir, &["replay", "r.jsonl", "--print"]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    }
    for d in [read, closed] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn resolve_and_learn_keep_the_policy_and_the_rule_when_nobody_reads_the_output() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let base = server.base_url();
    let s = scenario();
    let mut args = resolve_yes(&s, &base);
    args.extend(["--learn", "--policy-dir", "pd", "--save", "resolved.bt"]);
    let (read, closed) = both_ways("pipe-resolve", &args);
    same_file(&read, &closed, "resolved.bt");
    for dir in [&read, &closed] {
        let knowledge =
            betr::session::knowledge::Knowledge::open(&dir.join("pd/knowledge.toml")).unwrap();
        assert_eq!(knowledge.rules.len(), 1, "{}", dir.display());
    }
    // The rule listed and shown, and the instruction read, to readers that have gone.
    for extra in [
        vec!["knowledge", "list", "--policy-dir", "pd"],
        vec!["knowledge", "show", "r1", "--policy-dir", "pd"],
        [&["interpret", &s][..], &openai_flags(&base)].concat(),
    ] {
        let whole = read_whole(&read, &extra);
        let cut = closed_early(&closed, &extra);
        assert_eq!(
            cut.status.code(),
            whole.status.code(),
            "{extra:?}: {}",
            text(&cut)
        );
        assert_ne!(cut.status.code(), Some(101));
    }
    for d in [read, closed] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn a_save_path_that_cannot_be_written_is_refused_before_any_work() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let base = server.base_url();
    let s = scenario();
    let dir = tmp("pipe-unwritable");
    // A path under a regular file can never be created.
    std::fs::write(dir.join("a-file"), "").unwrap();
    let save = "a-file/tree.bt";
    let mut resolve = resolve_yes(&s, &base);
    resolve.extend(["--save", save]);
    let mut learn = resolve_yes(&s, &base);
    learn.extend(["--learn", "--policy-dir", "a-file/pd"]);
    let repair = [
        "repair",
        &s,
        "--add",
        "~\"any object\" on \"blue cube\"",
        "--save",
        save,
    ];
    for args in [&resolve[..], &learn[..], &repair[..]] {
        let out = read_whole(&dir, args);
        let log = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {log}");
        assert!(
            log.contains("a-file/"),
            "the path is named: {args:?}: {log}"
        );
        assert!(!log.contains("Goal:"), "refused before the work:\n{log}");
    }
    assert_eq!(server.received().len(), 0, "no model call");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Standard output on a full disk (`/dev/full` fails every write with "no space"): the
/// command fails, naming standard output, instead of exiting 0 with an empty file.
#[test]
fn output_that_cannot_be_written_fails_the_command() {
    let s = scenario();
    let dir = tmp("pipe-full-disk");
    for args in [
        vec!["plan", &s[..]],
        vec!["export", &s, "--format", "btcpp"],
    ] {
        let full = std::fs::File::options()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = command(&dir, &args)
            .stdout(Stdio::from(full))
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}:\n{stderr}");
        assert!(
            stderr.contains("standard output could not be written"),
            "{args:?}:\n{stderr}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// `export --out` to a FIFO someone reads: the reader gets the whole tree and the FIFO is
/// still a FIFO (it was never replaced by a regular file).
#[test]
fn an_export_to_a_fifo_is_written_through() {
    use std::os::unix::fs::FileTypeExt;
    let s = scenario();
    let dir = tmp("pipe-fifo");
    let fifo = dir.join("tree.xml");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let out = read_whole(
        &dir,
        &["export", &s, "--format", "btcpp", "--out", "tree.xml"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let xml = reader.join().unwrap();
    assert!(
        xml.contains("<root") && xml.trim_end().ends_with("</root>"),
        "{xml}"
    );
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// Text from outside (here a scenario's name) reaches the terminal with its escape
/// sequences and reordering marks written out, never raw.
#[test]
fn escape_sequences_and_reordering_marks_from_a_scenario_are_written_out() {
    let dir = tmp("pipe-controls");
    let base = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    std::fs::write(
        dir.join("evil.toml"),
        format!(
            "extends = {:?}\n[scenario]\nname = \"Evil \\u001b[2J \\u202e eman\"\n\
             goal = '\"red cube\" on \"blue cube\"'\n",
            base.to_string_lossy()
        ),
    )
    .unwrap();
    let out = read_whole(&dir, &["plan", "evil.toml"]);
    let all = text(&out);
    assert_eq!(out.status.code(), Some(0), "{all}");
    assert!(all.contains("Evil \\u{1b}[2J \\u{202e} eman"), "{all}");
    assert!(
        !all.contains('\u{1b}') && !all.contains('\u{202e}'),
        "{all}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}
