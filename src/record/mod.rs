//! Session recordings: every session (workbench or command line) can write one file that
//! holds the scenario it ran and every event the session reported (the tree after each
//! change, every tick's node statuses, every model call with its reply, every approval,
//! rejection, edit, undo and repair) and every command a front end sent, with times, so
//! that it can be replayed without the model.
//!
//! A BehaviorTree.CPP process watched over Groot2's protocol (`betr monitor --record`)
//! is recorded in the same file format: its header names the publisher instead of a
//! scenario, and its entries are the watch's events (`watched.rs`).
//!
//! The file is JSON Lines, append-only: a header line, then one entry per line, each
//! written whole and flushed as it happens, so a recording cut by a crash is readable up
//! to its last whole line (`file.rs`). An event entry is the session's `Event` as serde
//! writes it, so a new event or field is recorded without code here. The header says the
//! format's version; `v1.rs` reads the first version's entries into events. See
//! docs/RECORDING.md.

pub mod describe;
pub mod file;
pub mod replay;
pub mod session;
pub mod v1;
pub mod watched;

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::monitor::{Address, WatchEvent};
use crate::session::Event;

pub use describe::{brief, describe, describe_step, trace};
pub use file::{Recorder, Recording, read};
pub use replay::{Replay, ReplayError, Resimulation, Step};
pub use session::SessionRecorder;
pub use watched::WatchedRun;

/// What the first line says the file is.
pub const FORMAT: &str = "betr-recording";
/// The version of the entries this build writes (it reads [`v1::VERSION`] too).
pub const VERSION: u32 = 2;

/// The first line: what was recorded, where, with which build.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    pub format: String,
    pub version: u32,
    #[serde(flatten)]
    pub source: Source,
    /// The betr version that wrote it.
    pub betr: String,
    /// When the session started (RFC 3339, UTC).
    pub started: String,
}

impl Header {
    /// The name of the scenario a session ran on (none for a watched process).
    pub fn scenario_name(&self) -> Option<&str> {
        match &self.source {
            Source::Session { name, .. } => Some(name),
            Source::Watched { .. } => None,
        }
    }
}

/// What was recorded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Source {
    /// A session of betr's own on a scenario.
    Session {
        /// The scenario file as the session named it.
        scenario: PathBuf,
        /// The scenario's name, to tell a wrong file apart when it is replayed.
        name: String,
        variant: Option<String>,
    },
    /// A BehaviorTree.CPP process watched at this publisher's address.
    Watched { watched: Address },
}

/// One line after the header.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Entry {
    /// What a front end asked of the engine, in words (`approve`, `edit …`, `undo`).
    Command { ms: u64, command: String },
    /// What the engine reported.
    Event { ms: u64, event: Event },
    /// What the watch of a BehaviorTree.CPP process reported.
    Watched { ms: u64, watched: WatchEvent },
}

impl Entry {
    /// Milliseconds since the session started.
    pub fn ms(&self) -> u64 {
        match self {
            Entry::Command { ms, .. } | Entry::Event { ms, .. } | Entry::Watched { ms, .. } => *ms,
        }
    }
}

/// Why a recording could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: empty: not a betr recording")]
    Empty { path: PathBuf },
    #[error("{path}, line 1: not a betr recording ({reason})")]
    NotARecording { path: PathBuf, reason: String },
    #[error(
        "{path}: a recording of format version {found}; this betr reads versions {} and {VERSION}",
        v1::VERSION
    )]
    Version { path: PathBuf, found: u32 },
    #[error("{path}, line {line}: {reason}")]
    Line {
        path: PathBuf,
        line: usize,
        reason: String,
    },
}
