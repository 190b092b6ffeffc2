//! `--viewer connect[=URL]|spawn` and `--rrd FILE`: where the 3D view streams.

use std::path::PathBuf;

use anyhow::Result;

use betr::session::{Command, Event};
use betr::viz::{Sinks, Viewer, Viz};

#[derive(clap::Args, Debug, Clone, Default)]
pub struct VizFlags {
    /// Stream the cell, the tree and the events to the rerun viewer: `connect` (a running
    /// viewer at rerun+http://127.0.0.1:9876/proxy), `connect=URL`, or `spawn` (start the
    /// `rerun` program if it is installed).
    #[arg(long, value_name = "connect[=URL]|spawn")]
    pub viewer: Option<Viewer>,
    /// Save a rerun recording of the session to FILE (.rrd).
    #[arg(long, value_name = "FILE")]
    pub rrd: Option<PathBuf>,
}

impl VizFlags {
    /// The viz the flags ask for; a viewer that is not there is said once on stderr
    /// (`quiet`: not said, the caller shows `Viz::notice` itself).
    pub fn open(&self, quiet: bool) -> Result<Option<Viz>> {
        let viz = Viz::open(&Sinks {
            viewer: self.viewer.clone(),
            rrd: self.rrd.clone(),
        })?;
        if !quiet && let Some(note) = viz.as_ref().and_then(Viz::notice) {
            eprintln!("{note}");
        }
        Ok(viz)
    }
}

/// The workbench's tap: the viz follows the session's events and submitted instructions.
pub struct VizTap(pub Viz);

impl betr::tui::Tap for VizTap {
    fn event(&mut self, event: &Event) {
        self.0.on_event(event);
    }

    fn command(&mut self, command: &Command) {
        if let Command::Submit(text) = command {
            self.0.instruction(text);
        }
    }

    fn notice(&self) -> Option<String> {
        self.0.notice().map(str::to_string)
    }
}
