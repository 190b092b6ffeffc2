//! The MuJoCo cell: betr's own executor for a world betr does not own. It is a Python
//! process (`mujoco_executor.py`, carried inside the binary) on MuJoCo's official
//! bindings, spoken to through the executor protocol like a user's own simulator.
//!
//! Why a process and not the `mujoco-rs` crate: the Python wheel carries its own
//! `libmujoco`, so nothing is compiled and a betr that never asks for MuJoCo neither
//! builds nor fetches it; and it goes through the same protocol a user's simulator or a
//! robot bridge does, so the seam is exercised by a real second world.
//!
//! On first use the packages are installed by pip into a virtual environment in the
//! cache, every wheel checked against the SHA-256 in `mujoco-requirements.txt`, pip's
//! progress shown. The environment is built beside its final place and moved there when
//! complete, so an interrupted install leaves nothing half-made.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use sha2::Digest as _;

use super::{ExecutorError, ProcessExecutor};

/// The MuJoCo release the requirements pin.
pub const MUJOCO_VERSION: &str = "3.3.7";
const SCRIPT: &str = include_str!("mujoco_executor.py");
const REQUIREMENTS: &str = include_str!("mujoco-requirements.txt");

/// What `--executor` names to run the MuJoCo cell.
pub const NAME: &str = "mujoco";

/// Where the environment and the script live: the models' cache.
pub fn home() -> PathBuf {
    crate::model::cache_dir().join(format!("mujoco-{MUJOCO_VERSION}"))
}

fn failed(detail: String) -> ExecutorError {
    ExecutorError::Stopped {
        executor: NAME.into(),
        detail,
    }
}

/// The MuJoCo executor, its environment made first when it is not there (unless
/// `offline`); `args` go to the script. `say` hears what is being done (pip's own
/// progress goes to standard error).
pub fn spawn(
    args: &[String],
    offline: bool,
    say: &dyn Fn(&str),
) -> Result<ProcessExecutor, ExecutorError> {
    let (python, script) = installed(offline, say)?;
    let mut argv = vec![script.display().to_string()];
    argv.extend(args.iter().cloned());
    ProcessExecutor::spawn_named(Some(NAME), &python.display().to_string(), &argv)
}

/// The environment's Python and the executor's script, both in place (the environment
/// made first when it is not there, unless `offline`).
pub fn installed(offline: bool, say: &dyn Fn(&str)) -> Result<(PathBuf, PathBuf), ExecutorError> {
    let home = home();
    let python = environment(&home, offline, say)?;
    // Named by its content: two betr builds sharing the cache each run their own.
    let digest = sha2::Sha256::digest(SCRIPT.as_bytes());
    let short: String = digest.iter().take(6).map(|b| format!("{b:02x}")).collect();
    let script = home.join(format!("mujoco_executor-{short}.py"));
    write_if_changed(&script, SCRIPT)?;
    Ok((python, script))
}

/// The environment's Python, after making the environment if it is not complete.
fn environment(home: &Path, offline: bool, say: &dyn Fn(&str)) -> Result<PathBuf, ExecutorError> {
    let venv = home.join("venv");
    let python = venv.join("bin").join("python");
    if venv.join(COMPLETE).is_file() {
        return Ok(python);
    }
    if offline {
        return Err(failed(format!(
            "MuJoCo {MUJOCO_VERSION} is not installed in {} and this command fetches nothing \
             (offline): run it once online to install it",
            venv.display()
        )));
    }
    std::fs::create_dir_all(home)
        .map_err(|e| failed(format!("cannot make {}: {e}", home.display())))?;
    let building = home.join(format!("venv.building-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&building);
    say(&format!(
        "Installing MuJoCo {MUJOCO_VERSION} for the MuJoCo executor into {} (once; about 160 MB)",
        venv.display()
    ));
    let made = make_environment(&building);
    if let Err(e) = made {
        let _ = std::fs::remove_dir_all(&building);
        return Err(e);
    }
    match std::fs::rename(&building, &venv) {
        Ok(()) => {}
        // Another betr finished first: its environment is as good.
        Err(_) if venv.join(COMPLETE).is_file() => {
            let _ = std::fs::remove_dir_all(&building);
        }
        Err(e) => {
            let _ = std::fs::remove_dir_all(&building);
            return Err(failed(format!(
                "cannot move the environment into place: {e}"
            )));
        }
    }
    say("MuJoCo installed");
    Ok(python)
}

/// Written last into a complete environment.
const COMPLETE: &str = ".betr-complete";

fn make_environment(dir: &Path) -> Result<(), ExecutorError> {
    let python3 = std::env::var("BETR_PYTHON").unwrap_or_else(|_| "python3".into());
    run(
        Command::new(&python3).args(["-m", "venv"]).arg(dir),
        &format!("{python3} -m venv (Debian: apt install python3-venv)"),
    )?;
    let requirements = dir.join("requirements.txt");
    write_if_changed(&requirements, REQUIREMENTS)?;
    run(
        Command::new(dir.join("bin").join("python"))
            .args([
                "-m",
                "pip",
                "install",
                "--require-hashes",
                "--progress-bar",
                "on",
                "-r",
            ])
            .arg(&requirements),
        "pip install (MuJoCo's pinned packages)",
    )?;
    run(
        Command::new(dir.join("bin").join("python")).args(["-c", "import mujoco"]),
        "import mujoco",
    )?;
    std::fs::write(dir.join(COMPLETE), MUJOCO_VERSION)
        .map_err(|e| failed(format!("cannot mark the environment complete: {e}")))
}

/// Run a step of the install with its output on the terminal's standard error.
fn run(command: &mut Command, what: &str) -> Result<(), ExecutorError> {
    let status = command
        .stdin(Stdio::null())
        .stdout(Stdio::from(std::io::stderr()))
        .status()
        .map_err(|e| failed(format!("installing MuJoCo: {what} did not start: {e}")))?;
    if status.success() {
        Ok(())
    } else {
        Err(failed(format!(
            "installing MuJoCo: {what} failed ({status})"
        )))
    }
}

fn write_if_changed(path: &Path, text: &str) -> Result<(), ExecutorError> {
    if std::fs::read_to_string(path).is_ok_and(|t| t == text) {
        return Ok(());
    }
    crate::store::write_atomic(path, text.as_bytes())
        .map_err(|e| failed(format!("cannot write {}: {e}", path.display())))
}
