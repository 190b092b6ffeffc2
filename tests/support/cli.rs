//! Running the `betr` binary in a scratch directory that holds everything it writes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The variable the tests put the API key in, and the key.
pub const KEY_VAR: &str = "BETR_TEST_SECRET_KEY";
pub const KEY: &str = "sk-betr-e2e-SECRET-5f3c9a1e7d";

/// A scratch directory of one test, removed when the test is done with it; a failing
/// test leaves it, for looking into.
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A new, empty scratch directory named after the test's `name` and the process.
pub fn tmp(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("betr-e2e-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

/// Run the binary in `dir` with HOME and XDG dirs inside it, so every file it writes lands
/// there.
pub fn betr(dir: &Path, args: &[&str]) -> Output {
    betr_with(dir, args, &[])
}

/// [`betr`] with extra environment variables.
pub fn betr_with(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    command(dir, args)
        .envs(env.iter().copied())
        .output()
        .unwrap()
}

/// The command [`betr`] runs, for a test that starts it and stops it midway.
pub fn command(dir: &Path, args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_betr"));
    command
        .args(args)
        .current_dir(dir)
        .env("HOME", dir)
        .env("XDG_STATE_HOME", dir.join("state"))
        .env("XDG_DATA_HOME", dir.join("data"))
        .env("XDG_CONFIG_HOME", dir.join("config"))
        // The cache too, and no model directory from the caller's environment: with the
        // caller's cache, a robot description fetched there would give the cell its real
        // arms, and every command would plan their motions.
        .env("XDG_CACHE_HOME", dir.join("cache"))
        .env_remove("BETR_MODEL_DIR")
        // The home is empty: a one-shot command fetches nothing into it (a cell whose
        // robot description is not in the cache runs its abstraction). A test of the
        // fetch sets BETR_OFFLINE=0.
        .env("BETR_OFFLINE", "1")
        .env(KEY_VAR, KEY)
        .env_remove("BETR_CONFIG")
        .env_remove("BETR_BACKEND")
        .env_remove("BETR_MODEL")
        .env_remove("BETR_BASE_URL")
        .env_remove("BETR_API_KEY_ENV")
        .env_remove("BETR_CASSETTE")
        .env_remove("BETR_STT")
        .env_remove("BETR_STT_MODEL")
        .env_remove("BETR_STT_BASE_URL")
        .env_remove("BETR_STT_API_KEY_ENV")
        .env_remove("BETR_STT_LANGUAGE");
    command
}

pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Every file under `dir`.
pub fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    walk(dir, &mut out);
    out
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().filter_map(Result::ok) {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else {
            out.push(p);
        }
    }
}

pub fn relative_to(p: &Path, base: &Path) -> String {
    p.strip_prefix(base)
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

/// The flags that ask the model `fake-model` of an OpenAI-compatible server at `base`
/// (the fake server of the tests), with the key in [`KEY_VAR`].
pub fn openai_flags(base: &str) -> [&str; 8] {
    [
        "--backend",
        "openai",
        "--base-url",
        base,
        "--model",
        "fake-model",
        "--api-key-env",
        KEY_VAR,
    ]
}

/// `betr resolve SCENARIO --yes` against the server at `base` ([`openai_flags`]).
pub fn resolve_yes<'a>(scenario: &'a str, base: &'a str) -> Vec<&'a str> {
    let mut args = vec!["resolve", scenario, "--yes"];
    args.extend(openai_flags(base));
    args
}
