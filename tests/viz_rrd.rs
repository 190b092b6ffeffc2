#![allow(clippy::unwrap_used)]
//! Scenario 1 recorded by `betr repair --rrd` and checked with the viewer's own CLI
//! (`rerun rrd verify`, `rerun rrd print`) from `rerun-sdk==0.36.3`, installed once into
//! a virtual environment under the target directory when it is missing.

mod support;

use std::path::Path;
use std::process::Command;

use support::rerun::rerun_cli;

/// `rerun rrd ARGS…` with the pinned CLI.
fn rerun_rrd(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(rerun_cli())
        .arg("rrd")
        .args(args)
        .output()
        .unwrap()
}

/// Whether `rerun rrd verify` accepts `file`, with what it said.
fn verified(file: &Path) -> (bool, String) {
    let out = rerun_rrd(&["verify".as_ref(), file.as_os_str()]);
    let said = format!(
        "rerun rrd verify: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), said)
}

#[test]
fn scenario1_recording_verifies_and_lists_the_entities() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viz_rrd");
    std::fs::create_dir_all(&dir).unwrap();
    let rrd = dir.join("scenario1.rrd");
    let _ = std::fs::remove_file(&rrd);
    let rrd_arg = rrd.to_string_lossy();
    let out = support::repo::betr(&[
        "repair",
        "scenarios/cell/red_on_blue.toml",
        "--add",
        "~\"any object\" on \"blue cube\"",
        "--rrd",
        &rrd_arg,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("SUCCESS"), "{stdout}");
    assert!(rrd.metadata().unwrap().len() > 0);

    let (ok, said) = verified(&rrd);
    assert!(ok, "{said}");

    let print = rerun_rrd(&["print".as_ref(), rrd.as_os_str()]);
    assert!(
        print.status.success(),
        "{}",
        String::from_utf8_lossy(&print.stderr)
    );
    let listing = String::from_utf8_lossy(&print.stdout);
    for entity in [
        "/world/solids/table",
        "/world/solids/blue_cube",
        "/world/solids/green_cube",
        "/world/solids/red_cube",
        "/world/robot/torso",
        "/world/robot/arms",
        "/world/approach",
        "/tree/graph",
        "/tree/text",
        "/events",
    ] {
        assert!(
            listing.contains(entity),
            "{entity} not in `rerun rrd print`:\n{listing}"
        );
    }
}

/// A session writing an `.rrd` is killed with SIGKILL while it waits for the model: the
/// file holds the plan, the failing run and the question up to there (flushed whenever the
/// session comes to rest), the viewer's own reader reads it, and `rerun rrd optimize`
/// makes a complete file of it (the footer a finished recording ends with).
#[test]
fn a_session_killed_while_waiting_leaves_an_rrd_the_viewer_reads() {
    use std::time::{Duration, Instant};
    use support::fake_openai::{Behavior, FakeServer};

    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viz_rrd_kill");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let rrd = dir.join("killed.rrd");
    let rrd_arg = rrd.to_string_lossy().to_string();
    let scenario = support::repo::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_arg = scenario.to_string_lossy().to_string();
    let server = FakeServer::start(
        vec![],
        Behavior::Slow(Duration::from_secs(60), "Goal: x".into()),
    );
    let base = server.base_url();
    let mut child = support::cli::command(
        &dir,
        &[
            "resolve",
            &scenario_arg,
            "--yes",
            "--stated-goal",
            "--base-url",
            &base,
            "--model",
            "fake-model",
            "--api-key-env",
            support::cli::KEY_VAR,
            "--rrd",
            &rrd_arg,
        ],
    )
    .stdout(std::process::Stdio::null())
    .stderr(std::process::Stdio::null())
    .spawn()
    .unwrap();
    let started = Instant::now();
    while server.received().is_empty() {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "the session never asked the model"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // The question is on its way; the flush at rest happens as it is asked.
    std::thread::sleep(Duration::from_millis(500));
    child.kill().unwrap();
    child.wait().unwrap();

    let print = rerun_rrd(&["print".as_ref(), rrd.as_os_str()]);
    let listing = String::from_utf8_lossy(&print.stdout);
    for entity in ["/world/solids/blue_cube", "/tree/graph", "/events"] {
        assert!(
            listing.contains(entity),
            "{entity} not in `rerun rrd print` of the killed session's file:\n{listing}\n{}",
            String::from_utf8_lossy(&print.stderr)
        );
    }
    let whole = dir.join("optimized.rrd");
    let optimize = rerun_rrd(&[
        "optimize".as_ref(),
        rrd.as_os_str(),
        "-o".as_ref(),
        whole.as_os_str(),
    ]);
    assert!(
        optimize.status.success(),
        "rerun rrd optimize: {}",
        String::from_utf8_lossy(&optimize.stderr)
    );
    let (ok, said) = verified(&whole);
    assert!(ok, "{said}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The recording carries the viewer's layout (the blueprint: the cell, the tree graph
/// with its forces off, the tree's text and the log, the time panel on the session's
/// steps), the graph's node positions, and both timelines, as the viewer's CLI reads them.
#[test]
fn the_recording_holds_the_blueprint_the_tree_positions_and_the_step_timeline() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viz_rrd_blueprint");
    std::fs::create_dir_all(&dir).unwrap();
    let rrd = dir.join("scenario1.rrd");
    let _ = std::fs::remove_file(&rrd);
    let rrd_arg = rrd.to_string_lossy();
    let out = support::repo::betr(&[
        "repair",
        "scenarios/cell/red_on_blue.toml",
        "--add",
        "~\"any object\" on \"blue cube\"",
        "--rrd",
        &rrd_arg,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let print = rerun_rrd(&["print".as_ref(), rrd.as_os_str()]);
    let listing = String::from_utf8_lossy(&print.stdout);
    for what in [
        "Blueprint,",
        "/viewport - data columns: [ViewportBlueprint:auto_views ViewportBlueprint:root_container]",
        "ContainerBlueprint:col_shares",
        "ContainerBlueprint:row_shares",
        "TimePanelBlueprint:timeline",
        "ForceLink:enabled",
        "ForceManyBody:enabled",
        "ForceCenter:enabled",
        "/tree/graph - data columns: [GraphNodes:colors GraphNodes:labels GraphNodes:node_ids GraphNodes:positions]",
    ] {
        assert!(
            listing.contains(what),
            "{what} not in `rerun rrd print`:\n{listing}"
        );
    }
    assert_eq!(
        listing.matches("ViewBlueprint:class_identifier").count(),
        4,
        "four views: the cell, the tree graph, the tree's text and the log\n{listing}"
    );

    let headers = rerun_rrd(&["print".as_ref(), "-vv".as_ref(), rrd.as_os_str()]);
    let headers = String::from_utf8_lossy(&headers.stdout);
    assert!(headers.contains("index_name: step"), "{headers}");
    assert!(headers.contains("index_name: tick"), "{headers}");
    // The time panel opens on the step timeline.
    let data = rerun_rrd(&["print".as_ref(), "-vvv".as_ref(), rrd.as_os_str()]);
    let data = String::from_utf8_lossy(&data.stdout);
    let time_panel = data
        .split("Chunk(")
        .find(|c| c.contains("/time_panel"))
        .unwrap_or_default();
    assert!(time_panel.contains("step"), "{time_panel}");
}

/// Whether something listens on `port` of this machine.
fn port_open(port: u16) -> bool {
    std::net::TcpStream::connect(("127.0.0.1", port)).is_ok()
}

/// `--viewer spawn` without a display and `--viewer web` without `rerun` say why and
/// where to go; `--viewer web` with a web viewer listening streams to it and prints the
/// page to open, which the viewer serves.
#[test]
fn the_viewer_flags_say_what_they_started_or_why_not() {
    use std::io::{Read, Write};
    let scenario = "scenarios/cell/red_on_blue.toml";
    let run = |viewer: &str, path: &std::ffi::OsStr| {
        Command::new(env!("CARGO_BIN_EXE_betr"))
            .args(["run", scenario, "--viewer", viewer])
            .current_dir(support::repo::root())
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .env("PATH", path)
            .output()
            .unwrap()
    };
    let system_path = std::env::var_os("PATH").unwrap_or_default();
    let spawn = run("spawn", &system_path);
    let said = String::from_utf8_lossy(&spawn.stderr);
    assert!(
        said.contains("no display for the native viewer") && said.contains("--viewer web"),
        "{said}"
    );

    // Ports 9876 and 9090 are the web viewer's; another program on them is not ours
    // to stop.
    if port_open(9876) || port_open(9090) {
        eprintln!("ports 9876/9090 are taken: the web viewer part is not run");
        return;
    }
    let without_rerun = run("web", std::ffi::OsStr::new("/usr/bin:/bin"));
    let said = String::from_utf8_lossy(&without_rerun.stderr);
    assert!(
        said.contains("the `rerun` program is not installed"),
        "{said}"
    );

    // The viewer's binary itself (the venv's `rerun` is a Python launcher of it), so the
    // test can stop what it started.
    let venv = rerun_cli()
        .parent()
        .unwrap()
        .parent()
        .unwrap()
        .to_path_buf();
    let binary = std::fs::read_dir(venv.join("lib"))
        .unwrap()
        .map(|d| {
            d.unwrap()
                .path()
                .join("site-packages/rerun_sdk/rerun_cli/rerun")
        })
        .find(|p| p.exists())
        .unwrap();
    let mut viewer = Command::new(binary)
        .args(["--serve-web", "--port", "9876", "--web-viewer-port", "9090"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !(port_open(9876) && port_open(9090)) {
        assert!(
            started.elapsed().as_secs() < 30,
            "rerun --serve-web did not listen"
        );
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let web = run("web", &system_path);
    let said = String::from_utf8_lossy(&web.stderr).to_string();
    let mut page = String::new();
    if let Ok(mut http) = std::net::TcpStream::connect(("127.0.0.1", 9090)) {
        let _ = http.write_all(b"GET / HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n");
        let _ = http.read_to_string(&mut page);
    }
    let _ = viewer.kill();
    let _ = viewer.wait();
    assert!(
        said.contains(
            "3D view: open http://127.0.0.1:9090/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A9876%2Fproxy"
        ),
        "{said}"
    );
    assert!(!said.contains("not connected"), "{said}");
    assert!(
        page.starts_with("HTTP/1.") && page.contains("200"),
        "{page}"
    );
}
