//! The `rerun` program of the pinned Python package (`rerun-sdk==0.36.3`), installed into
//! a virtual environment under the target directory when it is missing. Test binaries
//! that run at once take turns through a lock file: two installing into one venv see each
//! other's half-done install.

use std::path::{Path, PathBuf};
use std::process::Command;

const RERUN_SDK: &str = "rerun-sdk==0.36.3";

/// The `rerun` program of the pinned Python package, installed on first use (once per
/// test binary: two tests installing into one venv at once see each other's half-done
/// install).
pub fn rerun_cli() -> PathBuf {
    static RERUN: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    RERUN.get_or_init(install_rerun_cli).clone()
}

fn install_rerun_cli() -> PathBuf {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rerun-venv");
    let lock = std::fs::File::create(venv.with_extension("lock")).unwrap();
    let _turn = nix::fcntl::Flock::lock(lock, nix::fcntl::FlockArg::LockExclusive)
        .map_err(|(_, e)| e)
        .unwrap();
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

/// The venv's `bin` directory, to put first on a command's PATH.
pub fn bin_dir() -> PathBuf {
    rerun_cli().parent().unwrap().to_path_buf()
}
