//! Starting a viewer: rerun's native viewer (`rerun::spawn`, which needs a display) or its
//! web viewer (`rerun --serve-web`, opened in any browser). Both outlive the session that
//! started them, as `rerun::spawn`'s viewer does, so a short command's recording stays
//! there to look at; a viewer already listening is used as it is.

use std::io::ErrorKind;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::{DEFAULT_URL, listening};

/// Where the web viewer serves its page.
pub const WEB_PORT: u16 = 9090;
/// The gRPC port sessions stream to (the one of [`DEFAULT_URL`]).
const GRPC_PORT: u16 = 9876;
/// How long a started `rerun` may take to listen.
const START_TIMEOUT: Duration = Duration::from_secs(20);

/// Why a viewer could not be started.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    #[error(
        "no display for the native viewer (DISPLAY and WAYLAND_DISPLAY are unset); `--viewer web` serves it to a browser, `--rrd FILE` saves the recording for `rerun FILE`"
    )]
    NoDisplay,
    #[error(
        "the `rerun` program is not installed (`pip install rerun-sdk==0.36.*` puts it on PATH)"
    )]
    NotInstalled,
    #[error("cannot start `{program}`: {reason}")]
    CannotStart { program: String, reason: String },
    #[error("`rerun --serve-web` stopped ({status}); is port {GRPC_PORT} or {WEB_PORT} taken?")]
    Stopped { status: std::process::ExitStatus },
    #[error(
        "`rerun --serve-web` did not listen on ports {GRPC_PORT} and {WEB_PORT} within {seconds} s"
    )]
    NotListening { seconds: u64 },
}

/// The native viewer started, streaming to it at the returned URL; why not otherwise.
pub(super) fn spawn_native() -> Result<String, ViewerError> {
    let display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()));
    if cfg!(target_os = "linux") && !display {
        return Err(ViewerError::NoDisplay);
    }
    let opts = rerun::SpawnOptions::default();
    match rerun::spawn(&opts) {
        Ok(_) => Ok(format!("rerun+http://{}/proxy", opts.connect_addr())),
        Err(rerun::SpawnError::ExecutableNotFoundInPath { .. }) => Err(ViewerError::NotInstalled),
        Err(e) => {
            let e = e.to_string();
            Err(ViewerError::CannotStart {
                program: "rerun".into(),
                reason: e.lines().next().unwrap_or_default().trim().to_string(),
            })
        }
    }
}

/// A web viewer to stream to: the gRPC URL and the page to open.
pub(super) struct WebViewer {
    pub grpc: String,
    pub open: String,
}

/// The page of the web viewer showing what is streamed to `grpc`.
pub fn web_page(grpc: &str) -> String {
    let encoded: String = grpc
        .chars()
        .map(|c| match c {
            ':' => "%3A".to_string(),
            '/' => "%2F".to_string(),
            '+' => "%2B".to_string(),
            c => c.to_string(),
        })
        .collect();
    format!("http://127.0.0.1:{WEB_PORT}/?url={encoded}")
}

/// `rerun --serve-web` started (or found listening already) and listening.
pub(super) fn start_web() -> Result<WebViewer, ViewerError> {
    let grpc = DEFAULT_URL.to_string();
    let page = format!("http://127.0.0.1:{WEB_PORT}/");
    let viewer = WebViewer {
        open: web_page(&grpc),
        grpc,
    };
    if listening(&viewer.grpc) && listening(&page) {
        return Ok(viewer);
    }
    let mut child = Command::new("rerun")
        .args(["--serve-web", "--port"])
        .arg(GRPC_PORT.to_string())
        .arg("--web-viewer-port")
        .arg(WEB_PORT.to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| match e.kind() {
            ErrorKind::NotFound => ViewerError::NotInstalled,
            _ => ViewerError::CannotStart {
                program: "rerun --serve-web".into(),
                reason: e.to_string(),
            },
        })?;
    let started = Instant::now();
    while !(listening(&viewer.grpc) && listening(&page)) {
        if let Ok(Some(status)) = child.try_wait() {
            return Err(ViewerError::Stopped { status });
        }
        if started.elapsed() > START_TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(ViewerError::NotListening {
                seconds: START_TIMEOUT.as_secs(),
            });
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok(viewer)
}
