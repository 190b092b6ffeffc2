//! A tmux server of a test's own, to run the `betr` binary in a terminal as a person
//! would: start a command, send keys and text, and read the screen (polling
//! `capture-pane` until what is wanted shows, with a timeout).

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// tmux servers started by this process (each test has its own).
static SERVERS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// A tmux server of our own (its own socket), killed when dropped.
pub struct Tmux {
    socket: String,
    session: String,
}

impl Tmux {
    pub fn run(&self, args: &[&str]) -> Output {
        Command::new("tmux")
            .arg("-L")
            .arg(&self.socket)
            .args(args)
            .output()
            .expect("tmux is required for this test (scripts/test.sh installs it)")
    }

    pub fn start(command: &str) -> Tmux {
        let t = Tmux {
            socket: format!(
                "betr-test-{}-{}",
                std::process::id(),
                SERVERS.fetch_add(1, std::sync::atomic::Ordering::SeqCst)
            ),
            session: "betr".into(),
        };
        let out = t.run(&[
            "new-session",
            "-d",
            "-s",
            &t.session,
            "-x",
            "120",
            "-y",
            "40",
            command,
        ]);
        assert!(
            out.status.success(),
            "tmux: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        t
    }

    pub fn screen(&self) -> String {
        String::from_utf8_lossy(
            &self
                .run(&["capture-pane", "-p", "-t", &self.session])
                .stdout,
        )
        .into_owned()
    }

    pub fn keys(&self, keys: &[&str]) {
        let mut args = vec!["send-keys", "-t", &self.session];
        args.extend_from_slice(keys);
        assert!(self.run(&args).status.success());
    }

    pub fn text(&self, text: &str) {
        assert!(
            self.run(&["send-keys", "-t", &self.session, "-l", text])
                .status
                .success()
        );
    }

    /// Poll the screen until it contains every one of `wanted`; panic with the screen
    /// after `secs` seconds.
    pub fn wait_for(&self, wanted: &[&str], secs: u64) -> String {
        self.wait_until(wanted, secs, |screen| {
            wanted.iter().all(|w| screen.contains(w))
        })
    }

    /// Poll the screen until it contains one of `wanted`.
    pub fn wait_for_any(&self, wanted: &[&str], secs: u64) -> String {
        self.wait_until(wanted, secs, |screen| {
            wanted.iter().any(|w| screen.contains(w))
        })
    }

    pub fn wait_until(&self, wanted: &[&str], secs: u64, done: impl Fn(&str) -> bool) -> String {
        let deadline = Instant::now() + Duration::from_secs(secs);
        loop {
            let screen = self.screen();
            if done(&screen) {
                return screen;
            }
            assert!(
                Instant::now() < deadline,
                "timed out waiting for {wanted:?}; the screen:\n{screen}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = self.run(&["kill-server"]);
    }
}

pub fn quote(p: &Path) -> String {
    format!("'{}'", p.display())
}

/// `env` with the home, state, config, data and cache directories inside `dir`, no model
/// directory from the caller's environment and nothing fetched: the shell's form of
/// [`super::cli::command`]'s isolated home, for a command line tmux runs.
pub fn isolated_env(dir: &Path) -> String {
    format!(
        "env -u BETR_MODEL_DIR HOME={dir} XDG_CACHE_HOME={dir}/cache BETR_OFFLINE=1 \
         XDG_STATE_HOME={dir}/state XDG_CONFIG_HOME={dir}/config XDG_DATA_HOME={dir}/data",
        dir = quote(dir)
    )
}

/// The shell command that opens the workbench on `scenario` (relative to the crate root)
/// in `dir`, with the model answered by `server`, then says how it exited. It fetches
/// nothing (`BETR_OFFLINE`): the cache under `dir` has no robot description, so the cell
/// keeps its reach spheres and gripper sweep, the same in every run.
pub fn workbench_command_on(
    scenario: &str,
    dir: &Path,
    server: &super::fake_openai::FakeServer,
    (env, extra): (&str, &str),
) -> String {
    let scenario = super::fixtures::root().join(scenario);
    format!(
        "cd {dir} && {isolated} {key_var}={key} BETR_USAGE_LOG=usage.jsonl {env} {bin} tui \
         {scenario} --backend openai --base-url {url} --model fake-model --api-key-env {key_var} \
         --policy-dir {policies} --tick-ms 50 {extra}; echo \"betr exited with status $?\"; \
         sleep 60",
        dir = quote(dir),
        isolated = isolated_env(dir),
        bin = quote(Path::new(env!("CARGO_BIN_EXE_betr"))),
        scenario = quote(&scenario),
        url = server.base_url(),
        policies = quote(&dir.join("policies")),
        key_var = super::cli::KEY_VAR,
        key = super::cli::KEY,
    )
}
