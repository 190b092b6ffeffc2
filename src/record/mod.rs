//! Session recordings: every session (workbench or command line) can write one file that
//! holds the scenario it ran, the tree after each change, every tick's node statuses,
//! every model call with its reply, and every approval, rejection, edit, undo and repair,
//! with times, so that it can be replayed without the model.
//!
//! The file is JSON Lines, append-only: a header line, then one entry per line, each
//! written whole and flushed as it happens, so a recording cut by a crash is readable up
//! to its last whole line (`file.rs`). Entries name nodes by their position in the tree's
//! pre-order, which the tree's text keeps, so a replayed tree (read back from its text)
//! gets the statuses of the recorded one (`convert.rs`). The format is versioned; see
//! docs/RECORDING.md.

pub mod convert;
pub mod describe;
pub mod file;
pub mod replay;
pub mod session;

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::llm::usage::UsageTotals;

pub use convert::{Decoder, Encoder};
pub use describe::{brief, describe};
pub use file::{Recorder, Recording, read};
pub use replay::{Replay, ReplayError, Resimulation, Step};
pub use session::SessionRecorder;

/// What the first line says the file is.
pub const FORMAT: &str = "betr-recording";
/// The version of the entries this build writes and reads.
pub const VERSION: u32 = 1;

/// The first line: what was recorded, where, with which build.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    pub format: String,
    pub version: u32,
    /// The scenario file as the session named it.
    pub scenario: PathBuf,
    /// The scenario's name, to tell a wrong file apart when it is replayed.
    pub name: String,
    pub variant: Option<String>,
    /// The betr version that wrote it.
    pub betr: String,
    /// When the session started (RFC 3339, UTC).
    pub started: String,
}

/// One line after the header.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Entry {
    /// What a front end asked of the engine, in words (`approve`, `edit …`, `undo`).
    Command { ms: u64, command: String },
    /// What the engine reported.
    Event { ms: u64, event: Recorded },
}

impl Entry {
    /// Milliseconds since the session started.
    pub fn ms(&self) -> u64 {
        match self {
            Entry::Command { ms, .. } | Entry::Event { ms, .. } => *ms,
        }
    }
}

/// A session event as recorded: plain text and numbers, nodes by pre-order position.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Recorded {
    /// The tree changed: all of it, in betr's tree text.
    Tree {
        text: String,
        new_nodes: Vec<usize>,
        why: String,
    },
    /// One tick: every node's status as one letter per node in pre-order (`-` idle,
    /// `R` running, `S` success, `F` failure, `H` halted).
    Tick {
        tick: u64,
        root: char,
        statuses: String,
        visited: Vec<usize>,
        failures: Vec<(usize, String)>,
        completed: Vec<usize>,
        halted: Vec<usize>,
        /// Nodes that returned a status a person forced.
        #[serde(default)]
        forced: Vec<usize>,
    },
    Asking {
        what: String,
    },
    Replied {
        attribution: String,
        prompt_tokens: u64,
        completion_tokens: u64,
        latency_ms: u64,
        text: String,
    },
    InvalidReply {
        error: String,
    },
    CandidateRejected {
        candidate: String,
        reason: String,
        author: Option<String>,
    },
    Goal {
        goal: String,
        reasoning: Option<String>,
        matches_expected: Option<bool>,
        /// Where the goal came from (absent in older recordings: the model).
        #[serde(default = "model_author")]
        author: String,
    },
    ActionFailed {
        action: String,
        node: usize,
        node_path: String,
        error: String,
    },
    Proposal {
        proposal: RecordedProposal,
        reasoning: Option<String>,
        author: String,
        /// What betr found about the failure and the change (absent in older recordings).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        evidence: Option<crate::session::Evidence>,
    },
    Approved,
    Rejected,
    Repaired {
        added_nodes: usize,
        valued_nodes: usize,
    },
    DidNotHelp {
        reason: String,
    },
    Success {
        ticks: u64,
    },
    GaveUp {
        reason: String,
    },
    RunState {
        running: bool,
    },
    WorldChanged {
        facts: Vec<String>,
        reset: bool,
    },
    Usage {
        totals: UsageTotals,
    },
    /// A verification's verdict in words (the full report is not kept).
    Checked {
        holds: bool,
        summary: String,
    },
    PolicySaved {
        path: PathBuf,
        fixes: usize,
    },
    PolicyLoaded {
        path: PathBuf,
        fixes: usize,
    },
    Error {
        message: String,
    },
    /// The nodes whose status a person forced, each with the status (`S`, `F`, `R`).
    Forced {
        forced: Vec<(usize, char)>,
    },
    /// The nodes with a breakpoint, and whether running stops after a node fails.
    Breakpoints {
        nodes: Vec<usize>,
        on_failure: bool,
    },
    /// Running stopped at a breakpoint (`on_failure`: after a node failed).
    BreakpointHit {
        node: usize,
        node_path: String,
        tick: u64,
        on_failure: bool,
    },
    /// Anything else worth a line of the log (plans, rules, notices, exports).
    Note {
        message: String,
    },
}

/// A proposal as recorded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum RecordedProposal {
    Conditions {
        action: String,
        node: usize,
        conditions: Vec<String>,
    },
    Value {
        skill: String,
        object: String,
        param: String,
        value: String,
    },
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
    #[error("{path}: a recording of format version {found}; this betr reads version {VERSION}")]
    Version { path: PathBuf, found: u32 },
    #[error("{path}, line {line}: {reason}")]
    Line {
        path: PathBuf,
        line: usize,
        reason: String,
    },
    #[error("line {line}: {reason}")]
    Decode { line: usize, reason: String },
}

/// Who wrote a goal of a recording older than goals' authors: the model.
fn model_author() -> String {
    "model".into()
}
