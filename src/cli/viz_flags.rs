//! `--viewer connect[=URL]|spawn|web`, `--rrd FILE` and `--record FILE`: where a session
//! streams besides the screen: the 3D view, and the session's recording.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};

use betr::record::SessionRecorder;
use betr::scenario::Scenario;
use betr::session::{Command, Event};
use betr::viz::{RobotMeshes, Sinks, Viewer, ViewerLife, Viz};

#[derive(clap::Args, Debug, Clone, Default)]
pub struct VizFlags {
    /// Stream the cell, the tree and the events to the rerun viewer: `connect` (a running
    /// viewer at rerun+http://127.0.0.1:9876/proxy), `connect=URL`, `spawn` (start the
    /// `rerun` program's native viewer; needs a display), or `web` (start `rerun
    /// --serve-web`, listening on this machine only, and print the address to open in a
    /// browser; `web=0.0.0.0`: on every interface, reachable from other machines). `rerun` comes with
    /// `pip install rerun-sdk==0.36.*`.
    #[arg(long, value_name = "connect[=URL]|spawn|web[=0.0.0.0]")]
    pub viewer: Option<Viewer>,
    /// Save a rerun recording of the session to FILE (.rrd).
    #[arg(long, value_name = "FILE")]
    pub rrd: Option<PathBuf>,
    /// Which of the robot's meshes the 3D view draws: `coarse` (each link's collision
    /// mesh, in its colour; 2.7 MB for the YuMi) or `detailed` (each link's visual mesh;
    /// 29 MB for the YuMi, in every recording and sent to every viewer).
    #[arg(long, value_name = "coarse|detailed", default_value = "coarse")]
    pub robot_meshes: RobotMeshes,
    /// Record the session to FILE: the tree after each change, every tick, every model
    /// reply and every approval, written as it happens (`betr replay FILE` shows it again,
    /// without the model).
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
}

impl VizFlags {
    /// The viz the flags ask for, laid out for `scenario`'s world; a viewer that is not there is said once on stderr
    /// (`quiet`: not said, the caller shows `Viz::notice` itself). A web viewer's address
    /// is always printed, before any workbench takes the screen, with the ports it moved
    /// to when the usual ones were taken; one that outlives the command is left running
    /// and its process said.
    pub fn open(
        &self,
        quiet: bool,
        web_viewer: ViewerLife,
        scenario: &Scenario,
    ) -> Result<Option<Viz>> {
        let mut viz = Viz::open(&Sinks {
            viewer: self.viewer.clone(),
            rrd: self.rrd.clone(),
            web_viewer,
            meshes: self.robot_meshes,
            no_scene: scenario.world_kind != "cell",
        })?;
        if let Some(moved) = viz.as_ref().and_then(Viz::web_moved) {
            errln!("3D view: {moved}");
        }
        if let Some(exposed) = viz.as_ref().and_then(Viz::web_exposed) {
            errln!("warning: 3D view: {exposed}");
        }
        // The address on a line of its own, to copy whole.
        if let Some(url) = viz.as_ref().and_then(Viz::web_url) {
            errln!("3D view: open this address in a browser:\n{url}");
        }
        if web_viewer == ViewerLife::OutlivesCommand
            && let Some(server) = viz.as_mut().and_then(Viz::take_web_server)
        {
            let pid = server.leave_running();
            errln!(
                "3D view: the web viewer keeps running after this command; `kill -- -{pid}` stops it"
            );
        }
        if !quiet && let Some(note) = viz.as_ref().and_then(Viz::notice) {
            errln!("{note}");
        }
        Ok(viz)
    }
}

impl VizFlags {
    /// The recording `--record` asks for, started on `scenario` (its file: `path`).
    pub fn recorder(
        &self,
        scenario: &Scenario,
        path: &Path,
        variant: Option<&str>,
    ) -> Result<Option<SessionRecorder>> {
        let Some(file) = &self.record else {
            return Ok(None);
        };
        let recorder = SessionRecorder::create(file, path, &scenario.name, variant)
            .with_context(|| "--record")?;
        Ok(Some(recorder))
    }
}

/// What follows a session besides the screen: the 3D view (the session's events and
/// submitted instructions) and the recording (events and commands).
#[derive(Default)]
pub struct SessionTap {
    pub viz: Option<Viz>,
    pub record: Option<SessionRecorder>,
}

impl SessionTap {
    pub fn is_empty(&self) -> bool {
        self.viz.is_none() && self.record.is_none()
    }
}

impl betr::tui::Tap for SessionTap {
    fn event(&mut self, event: &Event) {
        if let Some(v) = self.viz.as_mut() {
            v.on_event(event);
        }
        if let Some(r) = self.record.as_mut() {
            r.event(event);
        }
    }

    fn command(&mut self, command: &Command) {
        if let (Some(v), Command::Submit(text)) = (self.viz.as_mut(), command) {
            v.instruction(text);
        }
        if let Some(r) = self.record.as_mut() {
            r.command(command);
        }
    }

    fn viewer_page(&self) -> Option<String> {
        self.viz.as_ref().and_then(Viz::web_url).map(str::to_string)
    }

    fn notice(&self) -> Option<String> {
        let recording = self.record.as_ref().and_then(SessionRecorder::stopped);
        let viewer = self.viz.as_ref().and_then(Viz::notice);
        recording.or(viewer).map(str::to_string)
    }
}
