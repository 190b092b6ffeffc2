//! Starting a viewer: rerun's native viewer (`rerun::spawn`, which needs a display) or its
//! web viewer (`rerun --serve-web`, opened in any browser).
//!
//! The native viewer outlives the session, as `rerun::spawn` makes it. A web viewer betr
//! starts is a [`WebServer`] whose life the caller chooses ([`ViewerLife`]): the
//! workbench's stops when the workbench closes — quitting stops it and every process it
//! started (the `rerun` on PATH may be a launcher running the viewer's binary as its
//! child), and it stays in the workbench's process group, so a terminal that closes hangs
//! it up with the workbench; a one-shot command's gets a process group of its own and
//! stays, so its recording is there to look at, and the group is said so it can be
//! stopped. It serves
//! on the usual ports (9876 for the stream, 9090 for the page) when they are free and on
//! ports the system gives otherwise, so two workbenches on one machine each have their
//! own. A one-shot command uses a web viewer already listening on the usual ports.

use std::ffi::OsStr;
use std::io::ErrorKind;
use std::net::{IpAddr, TcpListener};
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use super::{DEFAULT_URL, listening};

/// Where the web viewer serves its page unless the port is taken.
pub const WEB_PORT: u16 = 9090;
/// The gRPC port sessions stream to unless it is taken (the one of [`DEFAULT_URL`]).
pub const GRPC_PORT: u16 = 9876;
/// How long a started `rerun` may take to listen.
const START_TIMEOUT: Duration = Duration::from_secs(20);
/// How long a stopped viewer may take to go before it is killed.
const STOP_TIMEOUT: Duration = Duration::from_secs(3);
/// How long a viewer that listens must keep running to be taken as the one listening.
const SETTLE: Duration = Duration::from_millis(300);
/// Starts tried when the viewer stops at once: ports free when chosen can be taken by
/// another program before the viewer binds them.
const START_ATTEMPTS: usize = 3;

/// How long a web viewer betr starts lives.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ViewerLife {
    /// It keeps running after the command, so what it received can still be looked at;
    /// one already listening on the usual ports is used instead of starting one.
    #[default]
    OutlivesCommand,
    /// It is started for this session alone and stopped when the session's `Viz` goes
    /// (the workbench quitting).
    StopsWithSession,
}

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
    #[error("no free port for the web viewer: {reason}")]
    NoPort { reason: String },
    #[error(
        "`rerun --serve-web` stopped ({status}) before listening on ports {grpc} (stream) and {web} (page), {attempts} time(s); `--viewer connect=URL` streams to a viewer started by hand"
    )]
    Stopped {
        status: ExitStatus,
        grpc: u16,
        web: u16,
        attempts: usize,
    },
    #[error(
        "`rerun --serve-web` did not listen on ports {grpc} (stream) and {web} (page) within {seconds} s"
    )]
    NotListening { grpc: u16, web: u16, seconds: u64 },
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

/// A web viewer to stream to: the gRPC URL, the page to open, and the process when betr
/// started it.
pub struct WebViewer {
    pub grpc: String,
    pub open: String,
    /// Why it is not on the usual ports, when it is not.
    pub moved: Option<String>,
    /// That other machines can reach it, when it listens beyond this one.
    pub exposed: Option<String>,
    pub server: Option<WebServer>,
}

/// A `rerun --serve-web` betr started. Stopped when dropped unless left running: the
/// process and everything it started (the `rerun` on PATH may be a launcher that runs the
/// viewer's binary as its child).
#[derive(Debug)]
pub struct WebServer {
    child: Child,
    /// In a process group of its own (to outlive the command), or in betr's.
    own_group: bool,
    left_running: bool,
}

impl WebServer {
    /// The process id (and, when it has a group of its own, the group's).
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Keep it running after this process ends; its process id, to stop it by (`kill --
    /// -PID` stops its group when it has one of its own).
    pub fn leave_running(mut self) -> u32 {
        self.left_running = true;
        self.pid()
    }

    /// Ask the viewer and what it started to end, and kill them when they do not in time.
    pub fn stop(&mut self) {
        use nix::sys::signal::{Signal, kill};
        use nix::unistd::Pid;
        let Ok(raw) = i32::try_from(self.child.id()) else {
            return;
        };
        if self.own_group {
            return stop_group(&mut self.child, Pid::from_raw(raw));
        }
        // The launcher's descendants are found before it goes: orphaned, they are no
        // longer known as its.
        let mut pids = descendants(raw);
        pids.push(raw);
        for pid in &pids {
            let _ = kill(Pid::from_raw(*pid), Signal::SIGTERM);
        }
        let asked = Instant::now();
        loop {
            let _ = self.child.try_wait();
            let left: Vec<i32> = pids.iter().copied().filter(|p| alive(*p)).collect();
            if left.is_empty() {
                return;
            }
            if asked.elapsed() > STOP_TIMEOUT {
                tracing::warn!(?left, "the web viewer did not stop when asked: killed");
                for pid in left {
                    let _ = kill(Pid::from_raw(pid), Signal::SIGKILL);
                }
                let _ = self.child.wait();
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

/// Ask a process group to end, and kill it when it does not in time.
fn stop_group(child: &mut Child, group: nix::unistd::Pid) {
    use nix::sys::signal::{Signal, killpg};
    // Already gone (the group is empty): nothing to stop.
    if killpg(group, Signal::SIGTERM).is_err() {
        let _ = child.wait();
        return;
    }
    let asked = Instant::now();
    while asked.elapsed() < STOP_TIMEOUT {
        if matches!(child.try_wait(), Ok(Some(_))) && killpg(group, None).is_err() {
            return;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    tracing::warn!(
        group = group.as_raw(),
        "the web viewer did not stop when asked: killed"
    );
    let _ = killpg(group, Signal::SIGKILL);
    let _ = child.wait();
}

/// The parent and the state of a process, from `/proc/PID/stat` (after its name, which
/// may hold spaces and brackets).
fn parent_and_state(pid: i32) -> Option<(i32, char)> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let mut fields = stat.rsplit_once(')')?.1.split_whitespace();
    let state = fields.next()?.chars().next()?;
    let parent = fields.next()?.parse().ok()?;
    Some((parent, state))
}

/// Whether `pid` runs (a zombie has ended).
fn alive(pid: i32) -> bool {
    parent_and_state(pid).is_some_and(|(_, state)| state != 'Z')
}

/// Every process descending from `root`, read from `/proc` (none where there is none).
fn descendants(root: i32) -> Vec<i32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    let parents: Vec<(i32, i32)> = entries
        .flatten()
        .filter_map(|e| e.file_name().to_str()?.parse::<i32>().ok())
        .filter_map(|pid| Some((pid, parent_and_state(pid)?.0)))
        .collect();
    let mut found = vec![root];
    let mut at = 0;
    while at < found.len() {
        let parent = found[at];
        found.extend(
            parents
                .iter()
                .filter(|(_, p)| *p == parent)
                .map(|(c, _)| *c),
        );
        at += 1;
    }
    found.remove(0);
    found
}

impl Drop for WebServer {
    fn drop(&mut self) {
        if !self.left_running {
            self.stop();
        }
    }
}

/// The page of the web viewer serving on `web_port` showing what is streamed to `grpc`.
pub fn web_page(grpc: &str, web_port: u16) -> String {
    let encoded: String = grpc
        .chars()
        .map(|c| match c {
            ':' => "%3A".to_string(),
            '/' => "%2F".to_string(),
            '+' => "%2B".to_string(),
            c => c.to_string(),
        })
        .collect();
    format!("http://127.0.0.1:{web_port}/?url={encoded}")
}

/// A web viewer to stream to: for a one-shot command one listening on the usual ports
/// when there is one; otherwise `program --serve-web` started and listening.
pub(super) fn start_web(
    program: &OsStr,
    life: ViewerLife,
    address: IpAddr,
) -> Result<WebViewer, ViewerError> {
    let usual_page = format!("http://127.0.0.1:{WEB_PORT}/");
    if life == ViewerLife::OutlivesCommand && listening(DEFAULT_URL) && listening(&usual_page) {
        return Ok(WebViewer {
            grpc: DEFAULT_URL.to_string(),
            open: web_page(DEFAULT_URL, WEB_PORT),
            moved: None,
            exposed: None,
            server: None,
        });
    }
    let mut attempt = 0;
    loop {
        attempt += 1;
        let (grpc, web) = free_ports()?;
        match serve(
            program,
            (address, grpc, web),
            life == ViewerLife::OutlivesCommand,
        ) {
            Err(ViewerError::Stopped { status, .. }) if attempt < START_ATTEMPTS => {
                tracing::info!(%status, grpc, web, "the web viewer stopped at once: new ports");
            }
            Err(ViewerError::Stopped { status, .. }) => {
                return Err(ViewerError::Stopped {
                    status,
                    grpc,
                    web,
                    attempts: attempt,
                });
            }
            Err(e) => return Err(e),
            Ok(server) => {
                let url = format!("rerun+http://127.0.0.1:{grpc}/proxy");
                let taken: Vec<String> = [(GRPC_PORT, grpc), (WEB_PORT, web)]
                    .iter()
                    .filter(|(usual, got)| usual != got)
                    .map(|(usual, _)| usual.to_string())
                    .collect();
                let moved = (!taken.is_empty()).then(|| {
                    format!(
                        "port {} taken: this web viewer serves on ports {grpc} (stream) and {web} (page)",
                        taken.join(" and ")
                    )
                });
                let exposed = (!address.is_loopback()).then(|| {
                    format!(
                        "the web viewer listens on {address}: anyone who reaches this machine on \
                         ports {grpc} and {web} can watch the session (`--viewer web` keeps it \
                         to this machine)"
                    )
                });
                return Ok(WebViewer {
                    open: web_page(&url, web),
                    grpc: url,
                    moved,
                    exposed,
                    server: Some(server),
                });
            }
        }
    }
}

/// `program --serve-web` on this address and these ports (`own_group`: in a process
/// group of its own), once it listens on both.
fn serve(
    program: &OsStr,
    (address, grpc, web): (IpAddr, u16, u16),
    own_group: bool,
) -> Result<WebServer, ViewerError> {
    let mut command = Command::new(program);
    command
        .arg("--bind")
        .arg(address.to_string())
        .args(["--serve-web", "--port"])
        .arg(grpc.to_string())
        .arg("--web-viewer-port")
        .arg(web.to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    if own_group {
        command.process_group(0);
    }
    let child = command.spawn().map_err(|e| match e.kind() {
        ErrorKind::NotFound => ViewerError::NotInstalled,
        _ => ViewerError::CannotStart {
            program: format!("{} --serve-web", program.to_string_lossy()),
            reason: e.to_string(),
        },
    })?;
    // Owned from here: any way out of this function that does not return it stops it.
    let mut server = WebServer {
        child,
        own_group,
        left_running: false,
    };
    let url = format!("rerun+http://127.0.0.1:{grpc}/proxy");
    let page = format!("http://127.0.0.1:{web}/");
    let started = Instant::now();
    while !(listening(&url) && listening(&page)) {
        if let Some(e) = exited(&mut server, grpc, web) {
            return Err(e);
        }
        if started.elapsed() > START_TIMEOUT {
            return Err(ViewerError::NotListening {
                grpc,
                web,
                seconds: START_TIMEOUT.as_secs(),
            });
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    // Another program may have taken one of the ports between their choice and the
    // viewer's start, answering in its place while the viewer stops: it must still run.
    std::thread::sleep(SETTLE);
    match exited(&mut server, grpc, web) {
        Some(e) => Err(e),
        None => Ok(server),
    }
}

/// When the viewer's launcher has exited: it stopped with whatever it left behind (the
/// viewer's binary may outlive the launcher), said with its ports.
fn exited(server: &mut WebServer, grpc: u16, web: u16) -> Option<ViewerError> {
    let status = server.child.try_wait().ok().flatten()?;
    server.stop();
    Some(ViewerError::Stopped {
        status,
        grpc,
        web,
        attempts: 1,
    })
}

/// A port for the stream and one for the page: the usual ones when nothing holds them,
/// else ones the system gives. Both are held until both are chosen, so they differ.
pub(super) fn free_ports() -> Result<(u16, u16), ViewerError> {
    let grpc = bind(GRPC_PORT)?;
    let web = bind(WEB_PORT)?;
    let port = |l: &TcpListener| {
        l.local_addr()
            .map(|a| a.port())
            .map_err(|e| ViewerError::NoPort {
                reason: e.to_string(),
            })
    };
    Ok((port(&grpc)?, port(&web)?))
}

/// A listener on `usual` on every interface (as the viewer binds), else on a port the
/// system gives.
fn bind(usual: u16) -> Result<TcpListener, ViewerError> {
    TcpListener::bind(("0.0.0.0", usual))
        .or_else(|_| TcpListener::bind(("0.0.0.0", 0)))
        .map_err(|e| ViewerError::NoPort {
            reason: e.to_string(),
        })
}
