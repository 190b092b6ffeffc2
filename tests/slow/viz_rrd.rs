#![allow(clippy::unwrap_used)]
//! Scenario 1 recorded by `betr repair --rrd` and checked with the viewer's own CLI
//! (`rerun rrd verify`, `rerun rrd print`) from `rerun-sdk==0.36.3`, installed once into
//! a virtual environment under the target directory when it is missing.

use crate::support;

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

/// `betr repair` of scenario 1 with its fix, recorded to `file` in the test folder `dir`
/// (made afresh): the recording's path and what betr said on stderr, once it succeeded.
fn repaired_scenario1(dir: &str, file: &str) -> (std::path::PathBuf, String) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(dir);
    std::fs::create_dir_all(&dir).unwrap();
    let rrd = dir.join(file);
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
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("SUCCESS"), "{stdout}");
    (rrd, stderr)
}

#[test]
fn scenario1_recording_verifies_and_lists_the_entities() {
    let (rrd, _) = repaired_scenario1("viz_rrd", "scenario1.rrd");
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
    // The robot is its meshes when its description is in the cache (the arms test below
    // fetches it), else boxes and segments.
    let robot: &[&str] = if listing.contains("/world/robot/yumi/") {
        &["/world/robot/yumi/visual_geometries/yumi_body"]
    } else {
        &["/world/robot/torso", "/world/robot/arms"]
    };
    for entity in [
        "/world/solids/table",
        "/world/solids/blue_cube",
        "/world/solids/green_cube",
        "/world/solids/red_cube",
        "/world/approach",
        "/tree/graph",
        "/tree/text",
        "/events",
    ]
    .iter()
    .chain(robot)
    {
        assert!(
            listing.contains(entity),
            "{entity} not in `rerun rrd print`:\n{listing}"
        );
    }
}

/// The views of a recording's layout (its blueprint's distinct `/view/…` entities).
fn views(rrd: &Path) -> usize {
    let print = rerun_rrd(&["print".as_ref(), "-v".as_ref(), rrd.as_os_str()]);
    assert!(
        print.status.success(),
        "{}",
        String::from_utf8_lossy(&print.stderr)
    );
    let listing = String::from_utf8_lossy(&print.stdout);
    let mut views: Vec<&str> = listing
        .match_indices("/view/")
        .filter_map(|(at, _)| listing.get(at..at + "/view/".len() + 36))
        .collect();
    views.sort_unstable();
    views.dedup();
    views.len()
}

/// A session with a cell opens on the 3D view beside the tree and the log; one with no
/// cell to draw (the cafe's symbolic world) leaves the empty 3D view out.
#[test]
fn a_world_with_no_cell_has_no_3d_view() {
    let (cell, _) = repaired_scenario1("viz_rrd_views", "scenario1.rrd");
    assert_eq!(
        views(&cell),
        4,
        "the cell, the tree graph, its text, the log"
    );
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viz_rrd_views");
    let cafe = dir.join("cafe.rrd");
    // The run fails in the world (no coffee), as the scenario is written to.
    let out = support::repo::betr(&[
        "run",
        "scenarios/cafe/no_coffee.toml",
        "--rrd",
        &cafe.to_string_lossy(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (ok, said) = verified(&cafe);
    assert!(ok, "{said}");
    assert_eq!(views(&cafe), 3, "the tree graph, its text, the log");
}

/// The YuMi's description in the cache, fetched on first use like the robot's own tests.
fn description() {
    use betr::model::{Pip, Progress, YUMI_DESCRIPTION, cache_dir, ensure_description};
    struct Quiet;
    impl Progress for Quiet {
        fn stage(&mut self, _: &str) {}
        fn bytes(&mut self, _: u64, _: u64) {}
    }
    ensure_description(&YUMI_DESCRIPTION, &cache_dir(), Pip::DEFAULT, &mut Quiet)
        .unwrap_or_else(|e| panic!("fetching the YuMi's description: {e}"));
}

/// One entity's rows in `rerun rrd print -vvv`: each row's cells by column name.
fn rows_of(data: &str, entity: &str) -> Vec<std::collections::BTreeMap<String, String>> {
    let cells = |line: &str| -> Vec<String> {
        line.trim_start_matches(['│', ' '])
            .split('┆')
            .map(|c| c.trim().trim_end_matches(['│', ' ']).trim().to_string())
            .collect()
    };
    let mut rows = Vec::new();
    for chunk in data.split("Chunk(").skip(1) {
        let Some(head) = chunk.lines().next() else {
            continue;
        };
        if !head.contains(&format!(" - {entity} - ")) {
            continue;
        }
        let Some(names) = chunk.lines().find(|l| l.contains("RowId")).map(cells) else {
            continue;
        };
        for line in chunk.lines().filter(|l| l.contains("row_")) {
            rows.push(names.iter().cloned().zip(cells(line)).collect());
        }
    }
    rows
}

/// Scenario 1 run with the YuMi's real arms, recorded and read back with the viewer's
/// CLI: what rerun's URDF importer makes of the robot's description (the links' meshes in
/// frames named after the links, every joint's transform at value 0 in `tf_static`), the
/// URDF's text, the root hung from
/// the view's `world`, every arm joint's transform (from its parent link's frame to its
/// child's) at each tick and, between the ticks an arm moved in, along its way on the
/// `motion` timeline, the gripper's path, and the solid that blocked the failing grasp
/// drawn as such.
#[test]
fn scenario1_with_real_arms_records_the_robot_and_its_joints_per_tick() {
    description();
    let (rrd, stderr) = repaired_scenario1("viz_rrd_arms", "scenario1-arms.rrd");
    assert!(
        !stderr.contains("reach spheres and gripper sweep instead"),
        "the arms move: {stderr}"
    );
    let (ok, said) = verified(&rrd);
    assert!(ok, "{said}");

    let print = rerun_rrd(&["print".as_ref(), rrd.as_os_str()]);
    let listing = String::from_utf8_lossy(&print.stdout);
    let robot = "/world/robot/yumi";
    let mut links = vec!["yumi_body".to_string()];
    for side in ["l", "r"] {
        links.extend((1..=7).map(|n| format!("yumi_link_{n}_{side}")));
        links.push(format!("gripper_{side}_base"));
        links.push(format!("gripper_{side}_finger_r"));
        links.push(format!("gripper_{side}_finger_l"));
    }
    for link in &links {
        let mesh = format!(
            "{robot}/visual_geometries/{link}/visual_0 - data columns: [Asset3D:albedo_factor Asset3D:blob Asset3D:media_type]"
        );
        assert!(listing.contains(&mesh), "{mesh} not in:\n{listing}");
    }
    // The URDF itself, as text (the CLI prints only its first lines).
    let data = rerun_rrd(&["print".as_ref(), "-vvv".as_ref(), rrd.as_os_str()]);
    let data = String::from_utf8_lossy(&data.stdout);
    let urdf = data
        .split("Chunk(")
        .find(|c| {
            c.lines()
                .next()
                .is_some_and(|h| h.contains(" - /robot_description - "))
        })
        .unwrap_or_default();
    assert!(
        urdf.contains("component: TextDocument:text") && urdf.contains("<?xml version=\"1.0\""),
        "no URDF text: {urdf}"
    );
    assert!(
        !listing.contains("/world/robot/torso"),
        "no boxes for a robot drawn from its meshes"
    );

    let data = rerun_rrd(&["print".as_ref(), "-vvv".as_ref(), rrd.as_os_str()]);
    let data = String::from_utf8_lossy(&data.stdout);
    // Each link's meshes sit in the link's frame.
    let frames = rows_of(
        &data,
        &format!("{robot}/visual_geometries/yumi_link_4_l/visual_0"),
    );
    assert!(
        frames.iter().any(|r| r
            .get("CoordinateFrame:frame")
            .is_some_and(|f| f.contains("yumi_link_4_l"))),
        "{frames:?}"
    );
    // The robot's root link (the URDF's `world`) hangs from the view's origin, once a tick.
    let base = rows_of(&data, &format!("{robot}/base"));
    assert!(
        base.iter().all(|r| {
            r.get("Transform3D:parent_frame").map(String::as_str) == Some("[tf#/world]")
                && r.get("Transform3D:child_frame").map(String::as_str) == Some("[world]")
        }) && !base.is_empty(),
        "{:?}",
        base.first()
    );
    let base_motions: std::collections::BTreeSet<&str> = base
        .iter()
        .filter_map(|r| r.get("motion"))
        .map(String::as_str)
        .collect();
    let base_steps: std::collections::BTreeSet<&str> = base
        .iter()
        .filter_map(|r| r.get("step"))
        .map(String::as_str)
        .collect();
    assert_eq!(
        base_motions.len(),
        base_steps.len(),
        "the base does not move between steps"
    );
    // The importer's static joint transforms, one per joint, between the links' frames.
    let tf_static = rows_of(&data, "/tf_static");
    let static_pairs: std::collections::BTreeSet<(String, String)> = tf_static
        .iter()
        .filter_map(|r| {
            Some((
                r.get("Transform3D:parent_frame")?.clone(),
                r.get("Transform3D:child_frame")?.clone(),
            ))
        })
        .collect();
    assert!(
        static_pairs.len() >= 2 * 7 + 6,
        "tf_static: {} pairs: {static_pairs:?}",
        static_pairs.len()
    );
    assert!(
        tf_static
            .iter()
            .all(|r| r.get("step").is_none() && r.get("tick").is_none()),
        "tf_static is static: {:?}",
        tf_static.first()
    );
    // The left arm makes scenario 1's motions: each of its joints at several ticks, its
    // parent and child links named as the importer names them, and more values of
    // `motion` than ticks (the way between).
    for n in 1..=7 {
        let joint = format!("yumi_joint_{n}_l");
        let rows = rows_of(&data, &format!("{robot}/joints/{joint}"));
        let ticks: std::collections::BTreeSet<&str> = rows
            .iter()
            .filter_map(|r| r.get("tick"))
            .map(String::as_str)
            .collect();
        let motions: std::collections::BTreeSet<&str> = rows
            .iter()
            .filter_map(|r| r.get("motion"))
            .map(String::as_str)
            .collect();
        assert!(ticks.len() >= 5, "{joint}: ticks {ticks:?}");
        assert!(
            motions.len() > 3 * ticks.len(),
            "{joint}: sub-steps on the motion timeline: {} values for {} ticks",
            motions.len(),
            ticks.len()
        );
        assert!(
            rows.iter().all(|r| r
                .get("Transform3D:child_frame")
                .is_some_and(|f| f.starts_with("[yumi_link_"))
                && r.get("Transform3D:parent_frame")
                    .is_some_and(|f| f.starts_with("[yumi_"))),
            "{joint}: {:?}",
            rows.first()
        );
        let pair = rows.first().and_then(|r| {
            Some((
                r.get("Transform3D:parent_frame")?.clone(),
                r.get("Transform3D:child_frame")?.clone(),
            ))
        });
        assert!(
            pair.as_ref().is_some_and(|p| static_pairs.contains(p)),
            "{joint}: {pair:?} is not a joint the importer logged"
        );
    }
    assert!(
        listing.contains("/world/robot/gripper_path - data columns: [LineStrips3D:colors LineStrips3D:radii LineStrips3D:strips]"),
        "{listing}"
    );
    // The failing grasp before the repair: the red cube is in the arm's way.
    assert!(data.contains("red cube blocks the arm"), "no blocker drawn");
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
        support::check::cannot_check(
            "the web viewer part of the viewer flags' test",
            "ports 9876/9090 (the web viewer's) are taken by another program, which is not \
             this test's to stop",
        );
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
            "3D view: open this address in a browser:\nhttp://127.0.0.1:9090/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A9876%2Fproxy\n"
        ),
        "{said}"
    );
    assert!(!said.contains("not connected"), "{said}");
    assert!(
        page.starts_with("HTTP/1.") && page.contains("200"),
        "{page}"
    );
}
