//! The repository the tests run in: its scenario files, the `betr` binary run from its
//! root (where `scenarios/` and `../shared` are), and an async runtime.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use betr::scenario::Scenario;

pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A file of the repository by its relative path.
pub fn path(rel: &str) -> PathBuf {
    root().join(rel)
}

/// A rule learned for every object of `skill`: it needs `requires`.
pub fn rule(skill: &str, requires: &str) -> betr::domain::LearnedRule {
    betr::domain::LearnedRule {
        id: String::new(),
        skill: skill.into(),
        requires: requires.into(),
        only: None,
    }
}

/// A scenario by its path relative to the repository (a failure names the file).
pub fn scenario(rel: &str) -> Scenario {
    Scenario::load(&path(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The goal-interpretation dataset beside the repository (`../shared`).
pub fn dataset_dir() -> PathBuf {
    root().join("../shared/datasets/llm-obtea")
}

/// The binary run from the repository's root, its data directory (where it would write
/// the shipped scenarios and policies) a scratch one under the target directory rather
/// than the home directory of whoever runs the tests.
pub fn betr(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_betr"))
        .args(args)
        .current_dir(root())
        .env(
            "XDG_DATA_HOME",
            Path::new(env!("CARGO_TARGET_TMPDIR")).join("repo-data"),
        )
        .output()
        .expect("the betr binary runs")
}

/// The exit code (`None` when killed) and stdout followed by stderr.
pub fn code_and_text(out: &Output) -> (Option<i32>, String) {
    (
        out.status.code(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// A runtime for tests that drive the engine or the workbench by hand.
pub fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("a tokio runtime")
}
