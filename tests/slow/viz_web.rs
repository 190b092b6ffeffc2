//! `betr tui --viewer web` with the real `rerun --serve-web` (rerun-sdk 0.36.3 in a venv
//! under the target directory): two workbenches on one machine each start a web viewer
//! of their own, on other ports when the usual ones are taken, and each shows its page in
//! the log; quitting one stops its viewer — the `rerun` launcher and the viewer's binary it
//! runs — and leaves the other's serving; closing the other's terminal takes its viewer
//! down with it.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::collections::BTreeSet;
use std::io::{Read, Write};
use std::time::{Duration, Instant};

use support::cli::{Scratch, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::tmux::Tmux;

/// One test at a time: two starting viewers at once may choose the same free ports (each
/// start is tried again then, but the test would measure the race, not the workbench).
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// A running `--serve-web` process: its id, process group and page port.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Served {
    pid: u32,
    group: u32,
    web_port: u16,
}

/// Every process on this machine serving rerun's web viewer.
fn web_viewers() -> BTreeSet<Served> {
    let mut out = BTreeSet::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(cmdline) = std::fs::read(entry.path().join("cmdline")) else {
            continue;
        };
        let args: Vec<String> = cmdline
            .split(|b| *b == 0)
            .map(|a| String::from_utf8_lossy(a).into_owned())
            .collect();
        if !args.iter().any(|a| a == "--serve-web") {
            continue;
        }
        let web_port = args
            .iter()
            .position(|a| a == "--web-viewer-port")
            .and_then(|i| args.get(i + 1))
            .and_then(|p| p.parse().ok())
            .unwrap_or(0);
        let Some(group) = group_of(pid) else {
            continue;
        };
        out.insert(Served {
            pid,
            group,
            web_port,
        });
    }
    out
}

/// A field of `pid`'s stat after its name in brackets (0: state, 1: parent, 2: group).
fn stat_field(pid: u32, field: usize) -> Option<u32> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let after_name = stat.rsplit_once(')')?.1;
    after_name.split_whitespace().nth(field)?.parse().ok()
}

fn group_of(pid: u32) -> Option<u32> {
    stat_field(pid, 2)
}

/// Whether `pid` descends from `ancestor`.
fn descends_from(pid: u32, ancestor: u32) -> bool {
    let mut at = pid;
    for _ in 0..64 {
        match stat_field(at, 1) {
            Some(parent) if parent == ancestor => return true,
            Some(parent) if parent > 1 => at = parent,
            _ => return false,
        }
    }
    false
}

/// The web viewers a workbench in `tmux` started (other tests may run viewers of their
/// own meanwhile), once they stop changing: the launcher starts the viewer's binary a
/// moment later.
fn viewers_of(tmux: &Tmux) -> BTreeSet<Served> {
    let out = tmux.run(&["list-panes", "-F", "#{pane_pid}"]);
    let pane: u32 = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
    let started = Instant::now();
    let mut last = BTreeSet::new();
    loop {
        let now: BTreeSet<Served> = web_viewers()
            .into_iter()
            .filter(|s| descends_from(s.pid, pane))
            .collect();
        if !now.is_empty() && now == last {
            return now;
        }
        assert!(started.elapsed() < Duration::from_secs(30), "no web viewer");
        last = now;
        std::thread::sleep(Duration::from_millis(500));
    }
}

/// The processes of `viewers` still running after waiting up to 10 s for them to go.
fn still_running(viewers: &BTreeSet<Served>) -> Vec<u32> {
    let started = Instant::now();
    loop {
        let running: Vec<u32> = viewers
            .iter()
            .map(|s| s.pid)
            .filter(|pid| {
                std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
                    !stat
                        .rsplit_once(')')
                        .is_some_and(|(_, r)| r.trim_start().starts_with('Z'))
                })
            })
            .collect();
        if running.is_empty() || started.elapsed() > Duration::from_secs(10) {
            return running;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The local addresses of the sockets listening on `port`, as /proc/net/tcp and tcp6 list
/// them (hex: `0100007F` is 127.0.0.1, `00000000` every interface).
fn listening_addresses(port: u16) -> Vec<String> {
    let mut out = Vec::new();
    for table in ["/proc/net/tcp", "/proc/net/tcp6"] {
        let Ok(text) = std::fs::read_to_string(table) else {
            continue;
        };
        for line in text.lines().skip(1) {
            let fields: Vec<&str> = line.split_whitespace().collect();
            // local address, then remote address, then the state (0A: listening).
            if let [_, local, _, state, ..] = fields.as_slice()
                && *state == "0A"
                && let Some((address, hex_port)) = local.rsplit_once(':')
                && u16::from_str_radix(hex_port, 16) == Ok(port)
            {
                out.push(address.to_string());
            }
        }
    }
    out
}

/// The status line of the page the web viewer serves on `port`.
fn page_status(port: u16) -> String {
    let mut page = String::new();
    if let Ok(mut http) = std::net::TcpStream::connect(("127.0.0.1", port)) {
        let _ = http.write_all(b"GET / HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n");
        let _ = http.read_to_string(&mut page);
    }
    page.lines().next().unwrap_or_default().to_string()
}

/// The scratch directory the workbench runs in (removed when dropped, after the
/// workbench, which is declared after it) and the workbench on scenario 1 with `--viewer
/// web`, the pinned `rerun` first on PATH.
fn workbench(name: &str, server: &FakeServer) -> (Scratch, Tmux) {
    let dir = tmp(name);
    let path = format!(
        "PATH={}:{}",
        support::rerun::bin_dir().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let command = support::tmux::workbench_command_on(
        "scenarios/cell/red_on_blue.toml",
        &dir,
        server,
        (&path, "--viewer web"),
    );
    (dir, Tmux::start(&command))
}

/// Its group's page port, which the workbench's log names.
fn port_of(viewers: &BTreeSet<Served>) -> (u32, u16) {
    let groups: BTreeSet<u32> = viewers.iter().map(|s| s.group).collect();
    assert_eq!(groups.len(), 1, "one viewer's processes: {viewers:?}");
    let port = viewers.iter().map(|s| s.web_port).max().unwrap();
    (*groups.first().unwrap(), port)
}

#[test]
fn two_workbenches_each_have_a_web_viewer_and_quitting_stops_its_own() {
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    support::rerun::rerun_cli();
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));

    let (_first_dir, first) = workbench("viz-web-first", &server);
    first.wait_for(&["Behavior tree", "3D view: open", "http://127.0.0.1:"], 60);
    let first_viewers = viewers_of(&first);
    let (first_group, first_port) = port_of(&first_viewers);
    // The launcher and the viewer's binary it runs.
    assert!(first_viewers.len() >= 2, "{first_viewers:?}");
    first.wait_for(&[&format!("http://127.0.0.1:{first_port}/?url=")], 10);
    // Reachable from this machine only.
    let addresses = listening_addresses(first_port);
    assert!(
        !addresses.is_empty() && addresses.iter().all(|a| a == "0100007F"),
        "the page listens on {addresses:?}"
    );

    let (_second_dir, second) = workbench("viz-web-second", &server);
    second.wait_for(&["Behavior tree", "3D view: open", "http://127.0.0.1:"], 60);
    let second_viewers = viewers_of(&second);
    let (second_group, second_port) = port_of(&second_viewers);
    assert_ne!(second_group, first_group);
    // The first holds its page's port: the second serves on another and says which.
    assert_ne!(second_port, first_port);
    second.wait_for(&[&format!("http://127.0.0.1:{second_port}/?url=")], 10);
    assert!(page_status(first_port).contains("200"), "{first_port}");
    assert!(page_status(second_port).contains("200"), "{second_port}");

    // Nothing to lose: q quits at once, and the first workbench's viewer goes with it.
    first.keys(&["q"]);
    let after = first.wait_for(&["betr exited with status 0"], 30);
    assert!(after.contains("the web viewer was stopped"), "{after}");
    assert_eq!(still_running(&first_viewers), Vec::<u32>::new());
    assert!(
        page_status(first_port).is_empty(),
        "{first_port} still serves"
    );
    assert!(page_status(second_port).contains("200"), "{second_port}");

    // The second's terminal closes: the hangup reaches its viewer with it.
    drop(second);
    assert_eq!(still_running(&second_viewers), Vec::<u32>::new());
}

/// A one-shot command's web viewer stays after the command, so what it was sent can be
/// looked at, and the command says how to stop it (the test then does so).
#[test]
fn a_one_shot_commands_web_viewer_stays_and_says_how_to_stop_it() {
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let path = format!(
        "{}:{}",
        support::rerun::bin_dir().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let listening = |port: u16| std::net::TcpStream::connect(("127.0.0.1", port)).is_ok();
    let usual_listening = listening(9876) && listening(9090);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_betr"))
        .args(["run", "scenarios/cell/red_on_blue.toml", "--viewer", "web"])
        .current_dir(support::repo::root())
        .env("PATH", path)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stderr).to_string();
    let Some(stop) = said
        .lines()
        .find_map(|l| l.split_once("`kill -- -").map(|(_, rest)| rest))
        .and_then(|rest| rest.split('`').next())
    else {
        // Only a viewer already on the usual ports (another session's) is used without
        // starting one: then nothing is left to stop.
        assert!(
            usual_listening,
            "no viewer started and none was there: {said}"
        );
        assert!(
            said.contains("3D view: open this address in a browser:\nhttp://127.0.0.1:9090/"),
            "{said}"
        );
        return;
    };
    let group: i32 = stop.parse().unwrap();
    // The address is on the line after the one that announces it.
    let url = said
        .lines()
        .skip_while(|l| *l != "3D view: open this address in a browser:")
        .nth(1)
        .unwrap();
    let port: u16 = url
        .trim_start_matches("http://127.0.0.1:")
        .split('/')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let served = page_status(port);
    let viewers: BTreeSet<Served> = web_viewers()
        .into_iter()
        .filter(|s| s.group == u32::try_from(group).unwrap())
        .collect();
    let _ = nix::sys::signal::killpg(
        nix::unistd::Pid::from_raw(group),
        nix::sys::signal::Signal::SIGTERM,
    );
    assert!(served.contains("200"), "{served}: {said}");
    assert!(viewers.len() >= 2, "{viewers:?}");
    assert_eq!(still_running(&viewers), Vec::<u32>::new());
}
