//! The 3D view: streams the simulated cell, the behavior tree and the session's events to
//! the rerun viewer (gRPC to a running viewer, a native or web viewer it starts, an `.rrd`
//! file, or several at once), with a default layout (`blueprint.rs`).
//!
//! A front-end module: it reads `bt` trees and tick records, the cell's
//! [`SceneSnapshot`](crate::world::cell::snapshot::SceneSnapshot) and session
//! [`Event`]s; nothing below the front ends knows it exists. Two timelines: `step` orders
//! the whole session, one step per tick and one for each moment of the resolve loop (the
//! failure, the question to the model, the proposal, the approval and repair, a new
//! tree), so each has its own frame; `tick` is the tick number the workbench shows (a run
//! after a repair starts again at 1); `motion` counts the steps and, between two, the
//! configurations an arm of the robot went through, so scrubbing it shows the arm moving
//! along its planned path. Each tick logs the tree's statuses and the scene after that
//! tick; with real arms the robot is drawn from its description (`robot.rs`). Logging never stops a session: a failed log call is traced and
//! ignored, and a viewer that is not listening is reported once in [`Viz::notice`].

pub mod blueprint;
pub mod robot;
pub mod scene;
#[cfg(test)]
mod tests;
pub mod tree;
mod viewer;
pub mod watched;

pub use robot::RobotMeshes;
pub use viewer::{GRPC_PORT, ViewerLife, WEB_PORT, WebServer};

use std::ffi::OsStr;
use std::net::{TcpStream, ToSocketAddrs};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use rerun::sink::{FileSink, GrpcSink, LogSink};
use rerun::{RecordingStream, RecordingStreamBuilder, TextLog};

use crate::bt::{TickRecord, Tree};
use crate::session::Event;
use crate::world::cell::snapshot::SceneSnapshot;
use crate::world::{CellWorld, World};

/// The application id recordings are made under.
pub const APP_ID: &str = "betr";
/// The timeline of the workbench's tick numbers.
pub const TIMELINE: &str = "tick";
/// The timeline of the session's steps: every tick and every moment of the resolve loop.
pub const STEPS: &str = "step";
/// The timeline of the steps and, between two, the configurations a moving arm goes
/// through.
pub const MOTION: &str = "motion";
/// Entity path of the event log.
pub const EVENTS: &str = "events";
/// What the session says when no viewer listens.
pub const NOT_CONNECTED: &str = "viewer not connected";
/// Where a viewer listens by default.
pub const DEFAULT_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

/// A viewer to stream to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Viewer {
    /// A running viewer at this URL (none: the default).
    Connect(Option<String>),
    /// Start the `rerun` program's native viewer, then stream to it.
    Spawn,
    /// Start the `rerun` program as a web viewer (`rerun --serve-web`) listening on this
    /// address (`web`: 127.0.0.1, this machine only; `web=0.0.0.0`: every interface),
    /// stream to it, and say the address to open in a browser.
    Web(std::net::IpAddr),
}

impl std::str::FromStr for Viewer {
    type Err = VizError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.split_once('=') {
            None if s == "spawn" => Ok(Viewer::Spawn),
            None if s == "web" => Ok(Viewer::Web(std::net::Ipv4Addr::LOCALHOST.into())),
            // This machine, or every interface: the viewer is then still reached here at
            // 127.0.0.1, which is where betr streams to.
            Some(("web", address)) => match address.parse::<std::net::IpAddr>() {
                Ok(ip) if ip.is_loopback() || ip.is_unspecified() => Ok(Viewer::Web(ip)),
                _ => Err(VizError::BadViewer(s.to_string())),
            },
            None if s == "connect" => Ok(Viewer::Connect(None)),
            Some(("connect", url)) if !url.is_empty() => Ok(Viewer::Connect(Some(url.into()))),
            _ => Err(VizError::BadViewer(s.to_string())),
        }
    }
}

/// Where a session's recording goes.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Sinks {
    pub viewer: Option<Viewer>,
    pub rrd: Option<PathBuf>,
    /// How long a web viewer started for the session lives.
    pub web_viewer: ViewerLife,
    /// Which of the robot's meshes are drawn.
    pub meshes: RobotMeshes,
    /// The session has no cell to draw (a symbolic world): the layout leaves the 3D view
    /// out rather than show it empty.
    pub no_scene: bool,
}

impl Sinks {
    pub fn is_empty(&self) -> bool {
        self.viewer.is_none() && self.rrd.is_none()
    }
}

#[derive(Debug, thiserror::Error)]
pub enum VizError {
    #[error(
        "--viewer {0:?}: expected `connect`, `connect=URL`, `spawn`, `web` (this machine only) or `web=0.0.0.0` (every interface)"
    )]
    BadViewer(String),
    #[error("cannot write the recording {path}: {message}")]
    Rrd { path: PathBuf, message: String },
    #[error("cannot start a recording: {0}")]
    Stream(#[from] rerun::RecordingStreamError),
}

/// The host and port of a viewer URL (`rerun+http://HOST:PORT/proxy`).
fn address(url: &str) -> Option<String> {
    let rest = url.split_once("://").map_or(url, |(_, r)| r);
    let host = rest.split('/').next()?;
    (!host.is_empty()).then(|| host.to_string())
}

/// Whether something listens at the viewer URL (a short TCP probe).
fn listening(url: &str) -> bool {
    let Some(addrs) = address(url).and_then(|a| a.to_socket_addrs().ok()) else {
        return false;
    };
    addrs
        .into_iter()
        .any(|a| TcpStream::connect_timeout(&a, Duration::from_millis(500)).is_ok())
}

/// How long a flush at a resting point may wait for the sinks.
const FLUSH_TIMEOUT: Duration = Duration::from_secs(2);

/// Streams one session.
pub struct Viz {
    rec: RecordingStream,
    tree: Option<Arc<Tree>>,
    /// The nodes the last change added to the tree, marked in the graph.
    new_nodes: Vec<crate::bt::NodeId>,
    /// The session's step (the `step` timeline).
    step: i64,
    /// Ticks logged so far.
    ticks: i64,
    /// The `motion` timeline's last value.
    motion: i64,
    /// The robot's description is in the recording.
    robot_drawn: bool,
    /// Which of the robot's meshes are drawn.
    meshes: RobotMeshes,
    /// The arms' joint values last drawn, per arm.
    arms_drawn: Vec<Vec<f64>>,
    /// The solids last drawn (what a motion since picked up or let go is found in them).
    solids_drawn: Vec<crate::world::cell::snapshot::SolidView>,
    /// An approval opened the current step: the repair and its new tree join it.
    repairing: bool,
    notice: Option<String>,
    /// What to open in a browser, when a web viewer was asked for.
    web_url: Option<String>,
    /// Why the web viewer is not on the usual ports, when it is not.
    web_moved: Option<String>,
    /// That the web viewer can be reached from other machines, when it listens beyond
    /// this one.
    web_exposed: Option<String>,
    /// An `.rrd` file is written: flushed whenever the session comes to rest, so a
    /// session killed while it waits (for the model, for a person) leaves a file that
    /// holds everything up to there.
    file: bool,
    /// The web viewer started for this session alone; last, so the stream is closed
    /// before the viewer stops.
    web_server: Option<WebServer>,
}

impl Viz {
    /// A run begins: the tree it ticks and the world before its first tick.
    pub fn run_start(&mut self, tree: &Tree, world: &dyn World) {
        self.set_tree(Arc::new(tree.clone()), Vec::new());
        if let Some(scene) = CellWorld::scene_of(world) {
            self.scene(&scene);
        }
    }

    /// A tick of the run, and the world after it.
    pub fn run_tick(&mut self, record: &TickRecord, world: &dyn World) {
        self.tick(record, CellWorld::scene_of(world).as_ref());
    }

    /// Open the sinks; `None` when there are none. A viewer that cannot be reached is
    /// left out (see [`Viz::notice`]); a file that cannot be created is an error.
    pub fn open(sinks: &Sinks) -> Result<Option<Viz>, VizError> {
        if sinks.is_empty() {
            return Ok(None);
        }
        let mut out: Vec<Box<dyn LogSink>> = Vec::new();
        let mut notice = None;
        if let Some(path) = &sinks.rrd {
            let sink = FileSink::new(path).map_err(|e| VizError::Rrd {
                path: path.clone(),
                message: e.to_string(),
            })?;
            out.push(Box::new(sink));
        }
        let mut web_url = None;
        let mut web_moved = None;
        let mut web_exposed = None;
        let mut web_server = None;
        let url = match &sinks.viewer {
            Some(Viewer::Connect(url)) => Some(url.clone().unwrap_or_else(|| DEFAULT_URL.into())),
            Some(Viewer::Spawn) => match viewer::spawn_native() {
                Ok(url) => Some(url),
                Err(why) => {
                    notice = Some(format!("{NOT_CONNECTED}: {why}"));
                    None
                }
            },
            Some(Viewer::Web(address)) => {
                match viewer::start_web(OsStr::new("rerun"), sinks.web_viewer, *address) {
                    Ok(web) => {
                        web_url = Some(web.open);
                        web_moved = web.moved;
                        web_exposed = web.exposed;
                        web_server = web.server;
                        Some(web.grpc)
                    }
                    Err(why) => {
                        notice = Some(format!("{NOT_CONNECTED}: {why}"));
                        None
                    }
                }
            }
            None => None,
        };
        if let Some(url) = url {
            match url.parse() {
                Ok(uri) if listening(&url) => out.push(Box::new(GrpcSink::new(uri))),
                Ok(_) => notice = Some(format!("{NOT_CONNECTED} ({url})")),
                Err(e) => notice = Some(format!("{NOT_CONNECTED} ({url}: {e})")),
            }
        }
        let layout = if sinks.no_scene {
            blueprint::tree_and_log(STEPS)
        } else {
            blueprint::default_blueprint()
        };
        let builder = RecordingStreamBuilder::new(APP_ID).with_blueprint(layout);
        let rec = if out.is_empty() {
            RecordingStream::disabled()
        } else {
            builder.set_sinks(out)?
        };
        let mut viz = Viz::with_stream(rec);
        viz.notice = notice;
        viz.web_url = web_url;
        viz.web_moved = web_moved;
        viz.web_exposed = web_exposed;
        viz.web_server = web_server;
        viz.file = sinks.rrd.is_some();
        viz.meshes = sinks.meshes;
        Ok(Some(viz))
    }

    /// A viz over a stream made elsewhere (tests use an in-memory one).
    pub fn with_stream(rec: RecordingStream) -> Viz {
        if rec.is_enabled() {
            rec.set_time_sequence(STEPS, 0);
            rec.set_time_sequence(TIMELINE, 0);
            rec.set_time_sequence(MOTION, 0);
        }
        Viz {
            rec,
            tree: None,
            new_nodes: Vec::new(),
            step: 0,
            ticks: 0,
            motion: 0,
            robot_drawn: false,
            meshes: RobotMeshes::default(),
            arms_drawn: Vec::new(),
            solids_drawn: Vec::new(),
            repairing: false,
            notice: None,
            web_url: None,
            web_moved: None,
            web_exposed: None,
            file: false,
            web_server: None,
        }
    }

    /// The address to open in a browser, when a web viewer was asked for and is there.
    pub fn web_url(&self) -> Option<&str> {
        self.web_url.as_deref()
    }

    /// Why the web viewer is not on the usual ports, when it is not.
    pub fn web_moved(&self) -> Option<&str> {
        self.web_moved.as_deref()
    }

    /// That the web viewer can be reached from other machines, when it can.
    pub fn web_exposed(&self) -> Option<&str> {
        self.web_exposed.as_deref()
    }

    /// The web viewer started for this session, to leave running or to stop; none when
    /// none was started (or it was taken already).
    pub fn take_web_server(&mut self) -> Option<WebServer> {
        self.web_server.take()
    }

    /// Steps on the `step` timeline so far.
    pub fn steps(&self) -> i64 {
        self.step
    }

    /// The next step of the session.
    fn next_step(&mut self) {
        self.step += 1;
        if self.rec.is_enabled() {
            self.rec.set_time_sequence(STEPS, self.step);
        }
        self.next_motion();
    }

    /// The next value of the `motion` timeline.
    fn next_motion(&mut self) {
        self.motion += 1;
        if self.rec.is_enabled() {
            self.rec.set_time_sequence(MOTION, self.motion);
        }
    }

    /// The one line to show when a viewer was asked for and is not there.
    pub fn notice(&self) -> Option<&str> {
        self.notice.as_deref()
    }

    /// Ticks logged so far.
    pub fn ticks(&self) -> i64 {
        self.ticks
    }

    pub fn stream(&self) -> &RecordingStream {
        &self.rec
    }

    fn warn<E: std::fmt::Display>(result: Result<(), E>) {
        if let Err(e) = result {
            tracing::warn!(error = %e, "cannot log to the viewer");
        }
    }

    /// A new tree (shown with no statuses until it is ticked), with the nodes the change
    /// that made it added.
    pub fn set_tree(&mut self, tree: Arc<Tree>, new_nodes: Vec<crate::bt::NodeId>) {
        if !self.rec.is_enabled() {
            return;
        }
        Self::warn(tree::log_tree(&self.rec, &tree, None, true, &new_nodes));
        self.tree = Some(tree);
        self.new_nodes = new_nodes;
    }

    /// One tick: the next step, at the tick's own number, with the tree's statuses and
    /// the scene after it (when the world is a cell).
    pub fn tick(&mut self, record: &TickRecord, scene: Option<&SceneSnapshot>) {
        self.ticks += 1;
        self.next_step();
        if !self.rec.is_enabled() {
            return;
        }
        self.rec
            .set_time_sequence(TIMELINE, i64::try_from(record.tick).unwrap_or(i64::MAX));
        if let Some(tree) = &self.tree {
            Self::warn(tree::log_tree(
                &self.rec,
                tree,
                Some(record),
                false,
                &self.new_nodes,
            ));
        }
        if let Some(scene) = scene {
            self.scene(scene);
        }
        for (_, error) in &record.failures {
            self.log(rerun::TextLogLevel::ERROR, format!("failed: {error}"));
        }
    }

    /// The scene at the current step. With real arms: the robot's description the first
    /// time, then the way an arm went since the last scene (each configuration a value of
    /// the `motion` timeline) and the joints now.
    pub fn scene(&mut self, scene: &SceneSnapshot) {
        if !self.rec.is_enabled() {
            return;
        }
        if let Some(arms) = &scene.arms {
            if !self.robot_drawn {
                Self::warn(robot::log_description(&self.rec, arms, self.meshes));
                self.robot_drawn = true;
            }
            let between = robot::sub_steps(arms, &self.arms_drawn);
            let moved = !between.is_empty();
            let carried = scene::Carried::between(&self.solids_drawn, &scene.solids);
            for (index, values) in between {
                self.next_motion();
                Self::warn(robot::log_joints(&self.rec, arms, &values));
                if let (Some(c), Some(path)) = (&carried, &arms.path) {
                    Self::warn(scene::log_carried(&self.rec, c, path, index));
                }
            }
            if moved {
                self.next_motion();
            }
            self.arms_drawn = robot::values_now(arms);
            Self::warn(robot::log_base(&self.rec, arms));
            Self::warn(robot::log_joints(&self.rec, arms, &self.arms_drawn));
            Self::warn(robot::log_gripper_path(&self.rec, arms));
            let blocker = scene.motion.as_ref().and_then(|m| m.blocker.as_deref());
            Self::warn(robot::log_blocking_link(&self.rec, arms, blocker));
        }
        Self::warn(scene::log_scene(&self.rec, scene));
        if scene.arms.is_some() {
            self.solids_drawn.clone_from(&scene.solids);
        }
    }

    /// A line in the event log.
    pub fn log(&mut self, level: &str, text: impl Into<String>) {
        if !self.rec.is_enabled() {
            return;
        }
        Self::warn(
            self.rec
                .log(EVENTS, &TextLog::new(text.into()).with_level(level)),
        );
    }

    pub fn instruction(&mut self, text: &str) {
        self.log(rerun::TextLogLevel::INFO, format!("instruction: {text}"));
    }

    /// Whether `event` opens a step of its own: the failure, the question, the proposal,
    /// the approval (or rejection) with the repair it makes, and a tree that comes from
    /// anything else (a plan, an undo, a load).
    fn opens_step(&mut self, event: &Event) -> bool {
        let opens = match event {
            Event::ActionFailed { .. }
            | Event::Asking { .. }
            | Event::Proposal { .. }
            | Event::Approved
            | Event::Rejected => true,
            Event::TreeChanged { .. } => !self.repairing,
            _ => false,
        };
        self.repairing = match event {
            Event::Approved => true,
            Event::TreeChanged { .. } | Event::Ticked { .. } | Event::Rejected => false,
            _ => self.repairing,
        };
        opens
    }

    /// Follow a session: its tree, ticks, scenes and the steps of the resolve loop, each
    /// step in the log in the words `record::describe` has for it.
    pub fn on_event(&mut self, event: &Event) {
        if self.opens_step(event) {
            self.next_step();
        }
        match event {
            Event::TreeChanged {
                tree, new_nodes, ..
            } => self.set_tree(tree.clone(), new_nodes.clone()),
            Event::Ticked { record } => self.tick(record, None),
            Event::Scene { scene } => self.scene(scene),
            Event::Diverged {
                predicted: Some(predicted),
                ..
            } if self.rec.is_enabled() => {
                Self::warn(scene::log_prediction(&self.rec, predicted));
            }
            Event::WorldChanged { reset: true, .. } if self.rec.is_enabled() => {
                Self::warn(self.rec.log(scene::TWIN, &rerun::Clear::recursive()));
            }
            _ => {}
        }
        let level = log_level(event);
        for line in crate::record::describe(event) {
            self.log(level, line);
        }
        let at_rest = matches!(
            event,
            Event::Asking { .. }
                | Event::Proposal { .. }
                | Event::ActionFailed { .. }
                | Event::Success { .. }
                | Event::GaveUp { .. }
                | Event::PersonDecides { .. }
                | Event::Error { .. }
                | Event::Failed { .. }
                | Event::BreakpointHit { .. }
                | Event::Planned { .. }
        );
        if at_rest && self.file {
            Self::warn(self.rec.flush_with_timeout(FLUSH_TIMEOUT));
        }
    }

    /// Send what is buffered (before the program exits).
    pub fn flush(&self) {
        if !self.rec.is_enabled() {
            return;
        }
        Self::warn(self.rec.flush_blocking());
    }
}

impl Drop for Viz {
    fn drop(&mut self) {
        self.flush();
    }
}

/// How loud the 3D view's log says `event`: warnings for what went wrong and waits for a
/// person, errors for what ended the session or a command, details at debug.
fn log_level(event: &Event) -> &'static str {
    use rerun::TextLogLevel as L;
    match event {
        Event::InvalidReply { .. }
        | Event::ActionFailed { .. }
        | Event::Rejected
        | Event::DidNotHelp { .. }
        | Event::ChangeViolates { .. }
        | Event::RuleRefused { .. }
        | Event::BreakpointHit { .. }
        | Event::PersonDecides { .. }
        | Event::Diverged { .. } => L::WARN,
        // A reasoning the evidence contradicts is marked in the log as on the screen.
        Event::Proposal {
            evidence: Some(e), ..
        } if e.doubt.is_some() => L::WARN,
        Event::ArmMotion { motion } if motion.length.is_none() => L::WARN,
        Event::GaveUp { .. } | Event::Error { .. } | Event::Failed { .. } => L::ERROR,
        Event::Asking { .. }
        | Event::Replied { .. }
        | Event::WorldChanged { .. }
        | Event::Notice { .. } => L::DEBUG,
        _ => L::INFO,
    }
}
