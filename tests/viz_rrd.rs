#![allow(clippy::unwrap_used)]
//! Scenario 1 recorded by `betr repair --rrd` and checked with the viewer's own CLI
//! (`rerun rrd verify`, `rerun rrd print`) from `rerun-sdk==0.36.3`, installed once into
//! a virtual environment under the target directory when it is missing.

mod support;

use std::path::{Path, PathBuf};
use std::process::Command;

const RERUN_SDK: &str = "rerun-sdk==0.36.3";

/// The `rerun` program of the pinned Python package, installed on first use.
fn rerun_cli() -> PathBuf {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rerun-venv");
    let rerun = venv.join("bin").join("rerun");
    let version_ok = |rerun: &Path| {
        Command::new(rerun)
            .arg("--version")
            .output()
            .is_ok_and(|o| {
                o.status.success() && String::from_utf8_lossy(&o.stdout).contains("0.36.3")
            })
    };
    if version_ok(&rerun) {
        return rerun;
    }
    if !venv.join("bin").join("pip").exists() {
        let status = Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .unwrap();
        assert!(
            status.success(),
            "python3 -m venv failed (install python3-venv)"
        );
    }
    let status = Command::new(venv.join("bin").join("pip"))
        .args(["install", "--quiet", RERUN_SDK])
        .status()
        .unwrap();
    assert!(status.success(), "pip install {RERUN_SDK} failed");
    assert!(
        version_ok(&rerun),
        "{} is not rerun 0.36.3",
        rerun.display()
    );
    // No usage data from test runs.
    let _ = Command::new(&rerun).args(["analytics", "disable"]).output();
    rerun
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

    let rerun = rerun_cli();
    let verify = Command::new(&rerun)
        .args(["rrd", "verify"])
        .arg(&rrd)
        .output()
        .unwrap();
    assert!(
        verify.status.success(),
        "rerun rrd verify: {}\n{}",
        String::from_utf8_lossy(&verify.stdout),
        String::from_utf8_lossy(&verify.stderr)
    );

    let print = Command::new(&rerun)
        .args(["rrd", "print"])
        .arg(&rrd)
        .output()
        .unwrap();
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
