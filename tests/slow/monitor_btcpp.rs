//! `betr monitor` watching the real BehaviorTree.CPP (through `behaviortreepy`, its Python
//! bindings) under Groot2's publisher: a tree with Fallback, ReactiveSequence, Inverter,
//! RetryUntilSuccessful and a SubTree ticked by scripts/btcpp_publisher.py, whose own
//! StdCoutLogger says what happened.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use crate::support;

use std::io::{BufRead, BufReader};
use std::process::{Child, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use support::btcpp::{Publisher, free_port_pair, python};
use support::cli::{command, tmp};
use support::tmux::{Tmux, isolated_env, quote};

/// `betr monitor --print` started on `port` for `secs` (with `more` arguments), its lines
/// arriving on a channel.
fn print_monitor(
    dir: &std::path::Path,
    port: u16,
    secs: u32,
    more: &[&str],
) -> (Child, mpsc::Receiver<String>) {
    let (secs, address) = (secs.to_string(), format!(":{port}"));
    let mut args = vec!["monitor", "--print", "--for", &secs, &address];
    args.extend_from_slice(more);
    let mut child = command(dir, &args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = BufReader::new(child.stdout.take().unwrap());
    let (lines, received) = mpsc::channel();
    std::thread::spawn(move || {
        for line in stdout.lines().map_while(Result::ok) {
            if lines.send(line).is_err() {
                return;
            }
        }
    });
    (child, received)
}

/// Lines until one starts with `prefix` (that one included); panics after 30 s.
fn lines_until(received: &mpsc::Receiver<String>, prefix: &str) -> Vec<String> {
    let mut out = Vec::new();
    loop {
        let line = received
            .recv_timeout(Duration::from_secs(30))
            .unwrap_or_else(|e| {
                panic!(
                    "no line starting {prefix:?} ({e}); so far:\n{}",
                    out.join("\n")
                )
            });
        let done = line.starts_with(prefix);
        out.push(line);
        if done {
            return out;
        }
    }
}

/// `betr monitor :PORT` on the screen of a tmux of its own; says how it exited.
fn monitor_in_tmux(dir: &std::path::Path, port: u16) -> Tmux {
    Tmux::start(&format!(
        "cd {} && {} {} monitor :{port}; echo monitor exited $?; sleep 30",
        quote(dir),
        isolated_env(dir),
        quote(std::path::Path::new(env!("CARGO_BIN_EXE_betr")))
    ))
}

/// The status changes in `--print` lines: (name, old, new).
fn changes(lines: &[String]) -> Vec<(String, String, String)> {
    lines
        .iter()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let fields: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(fields.len(), 6, "a change line has 6 fields: {l}");
            assert_eq!(fields[4], "→", "{l}");
            (fields[2].into(), fields[3].into(), fields[5].into())
        })
        .collect()
}

#[test]
fn print_reports_every_status_change_the_tree_made_in_order() {
    let python = python();
    let dir = tmp("monitor-print");
    let port = free_port_pair();
    let mut publisher = Publisher::start(&python, port, 6);
    let record = dir.join("watched.jsonl");
    let (mut monitor, received) = print_monitor(&dir, port, 8, &["--record", "watched.jsonl"]);
    let header = lines_until(&received, "# watching");
    assert_eq!(
        header.last().unwrap(),
        &format!("# watching 127.0.0.1:{port}: tree Main, 8 nodes")
    );
    let tree = lines_until(&received, "# 1 ");
    let shown: Vec<&str> = tree
        .iter()
        .map(|l| l.split_whitespace().nth(2).unwrap())
        .collect();
    assert_eq!(
        shown,
        [
            "Fallback",
            "ReactiveSequence",
            "Inverter",
            "IsBlocked",
            "SubTree",
            "RetryUntilSuccessful",
            "Grasp",
            "Recover"
        ],
        "the tree whole, the SubTree's tree under it:\n{}",
        tree.join("\n")
    );
    publisher.go();
    let seen = publisher.seen();
    let status = monitor.wait().unwrap();
    assert!(status.success(), "betr monitor: {status}");
    let printed: Vec<String> = received.try_iter().collect();
    let reported = changes(&printed);
    assert!(seen.len() > 60, "six ticks change many statuses: {seen:?}");
    assert_eq!(reported, seen, "betr's lines:\n{}", printed.join("\n"));
    // The main tree's blackboard, as the Python side set it.
    assert!(
        printed
            .iter()
            .any(|l| l.starts_with("# blackboard Main: grasps = ")
                && l.ends_with("target = \"red cube\"")),
        "{}",
        printed.join("\n")
    );
    let live: Vec<String> = [header, tree, printed.clone()].concat();
    replays_as_watched(&dir, &record, &live, seen.len());
    // Once the publisher is gone, that is said.
    assert!(
        printed
            .iter()
            .any(|l| l.starts_with("# the connection to") && l.contains("was lost")),
        "{}",
        printed.join("\n")
    );
}

/// The recording of a watched run: `betr replay --print` tells what `betr monitor
/// --print` told, `--to-rrd` writes a recording the viewer's own CLI accepts, and the
/// replay screen steps through it.
fn replays_as_watched(
    dir: &std::path::Path,
    record: &std::path::Path,
    live: &[String],
    seen: usize,
) {
    let file = record.to_str().unwrap();
    let out = command(dir, &["replay", file, "--print"]).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let told = String::from_utf8(out.stdout).unwrap();
    let mut told: Vec<&str> = told.lines().collect();
    assert!(told.remove(0).starts_with("# replay of "), "{told:?}");
    assert_eq!(told, live, "the replay tells what the watch printed");

    let rrd = dir.join("watched.rrd");
    let out = command(dir, &["replay", file, "--to-rrd", rrd.to_str().unwrap()])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{said}");
    assert!(said.contains(&format!("({seen} status changes")), "{said}");
    let verify = std::process::Command::new(support::rerun::rerun_cli())
        .args(["rrd", "verify"])
        .arg(&rrd)
        .output()
        .unwrap();
    assert!(
        verify.status.success(),
        "rerun rrd verify: {}",
        String::from_utf8_lossy(&verify.stderr)
    );

    let tmux = Tmux::start(&format!(
        "cd {} && {} {} replay {}; echo replay exited $?; sleep 30",
        quote(dir),
        isolated_env(dir),
        quote(std::path::Path::new(env!("CARGO_BIN_EXE_betr"))),
        quote(record)
    ));
    tmux.wait_for(
        &[
            "replay watched.jsonl",
            &format!("change 0/{seen}"),
            "paused",
        ],
        30,
    );
    tmux.keys(&[".", ".", "."]);
    tmux.wait_for(&[&format!("change 3/{seen}"), "IDLE → RUNNING"], 10);
    tmux.keys(&["G"]);
    tmux.wait_for(&[&format!("change {seen}/{seen}"), "at the end"], 10);
    tmux.keys(&["q"]);
    tmux.wait_for(&["replay exited 0"], 10);
}

#[test]
fn print_follows_a_robot_that_restarts() {
    let python = python();
    let dir = tmp("monitor-restart");
    let port = free_port_pair();
    let mut first = Publisher::start(&python, port, 2);
    let (mut monitor, received) = print_monitor(&dir, port, 20, &[]);
    lines_until(&received, "# watching");
    first.go();
    let first_seen = first.seen();
    lines_until(&received, "# the connection to");
    let mut second = Publisher::start(&python, port, 3);
    let between = lines_until(&received, "# watching");
    second.go();
    let second_seen = second.seen();
    monitor.kill().unwrap();
    monitor.wait().unwrap();
    let after: Vec<String> = received.try_iter().collect();
    assert_eq!(changes(&after), second_seen, "{}", after.join("\n"));
    assert!(changes(&between).len() <= first_seen.len());
}

#[test]
fn the_screen_shows_the_running_tree_and_a_lost_robot() {
    let python = python();
    let dir = tmp("monitor-screen");
    let port = free_port_pair();
    let mut publisher = Publisher::start(&python, port, 0);
    let tmux = monitor_in_tmux(&dir, port);
    tmux.wait_for(
        &[
            &format!("watching 127.0.0.1:{port}"),
            "8 nodes",
            "following",
        ],
        30,
    );
    publisher.go();
    // The tree ticks: statuses and the changes pane move.
    let wanted = [
        "Grasp \"grasp\" (Action)",
        "SubTree \"Work\"",
        "IDLE → RUNNING",
    ];
    tmux.wait_until(&wanted, 30, |screen| {
        wanted.iter().all(|w| screen.contains(w))
            && screen.contains("status changes (")
            && !screen.contains("status changes (0)")
    });
    publisher.stop();
    drop(publisher);
    tmux.wait_for(&["was lost", "trying again"], 30);
    // The root's pane shows the main tree's blackboard as last read.
    tmux.keys(&["Home"]);
    tmux.wait_for(&["blackboard Main", "target = \"red cube\""], 10);
    tmux.keys(&["q"]);
    tmux.wait_for(&["monitor exited 0"], 10);
}

/// The number in the changes pane's title.
fn changes_shown(screen: &str) -> u64 {
    let at = screen.find("status changes (").expect("the changes pane") + "status changes (".len();
    screen[at..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect::<String>()
        .parse()
        .unwrap()
}

#[test]
fn a_breakpoint_stops_the_real_tree_until_the_person_lets_it_go() {
    let python = python();
    let dir = tmp("monitor-breakpoint");
    let port = free_port_pair();
    let mut publisher = Publisher::start(&python, port, 0);
    let tmux = monitor_in_tmux(&dir, port);
    tmux.wait_for(&[&format!("watching 127.0.0.1:{port}")], 30);
    // Home, then down to the grasp (the seventh row), and a breakpoint before it.
    tmux.keys(&["Home"]);
    for _ in 0..6 {
        tmux.keys(&["Down"]);
    }
    tmux.wait_for(&["Action · path 0.1.0.0"], 10);
    tmux.keys(&["b"]);
    tmux.wait_for(&["● [ ] Grasp"], 10);
    publisher.go();
    // The breakpoint's notice and the changes that led to it come over separate requests:
    // the stop counts once the changes pane has them too.
    let stopped = tmux.wait_until(&["stopped with the changes before it"], 30, |screen| {
        screen.contains("stopped before Grasp \"grasp\" (Action)")
            && screen.contains("▶ [ ] Grasp")
            && changes_shown(screen) > 0
    });
    // The tree waits: no change while stopped.
    std::thread::sleep(Duration::from_millis(500));
    let still = tmux.screen();
    assert_eq!(changes_shown(&still), changes_shown(&stopped), "{still}");
    assert!(still.contains("stopped before Grasp"), "{still}");
    // Failed without being ticked: the tree goes on and stops at the next grasp.
    tmux.keys(&["x"]);
    tmux.wait_until(&["stopped again"], 30, |screen| {
        screen.contains("stopped before Grasp") && changes_shown(screen) > changes_shown(&still)
    });
    // Taking the breakpoint away lets the tree run on.
    tmux.keys(&["b"]);
    let running = tmux.wait_until(&["running on"], 30, |screen| {
        !screen.contains("stopped before") && changes_shown(screen) > changes_shown(&still) + 100
    });
    assert!(!running.contains("refused"), "{running}");
    tmux.keys(&["q"]);
    tmux.wait_for(&["monitor exited 0"], 10);
    publisher.stop();
}
