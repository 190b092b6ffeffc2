//! Fuzzing every reader of outside input, on stable Rust: structured generation plus
//! mutation of a seed corpus read from the repository, deterministic by seed (input `i`
//! of seed `s` is the same on every machine, without the inputs before it).
//!
//! Each target reads one format and checks properties, not only the absence of panics:
//! what a reader accepts prints back to text that reads the same, a position an error
//! names lies inside the input on a character boundary, a reader with a writer reads its
//! own output back unchanged, and a lying WAV header allocates nothing it claims. Every
//! input runs under `catch_unwind`; a panic is a failure like a broken property, and a
//! failing input is saved so it can be replayed (`fuzz/regressions/TARGET/` keeps the
//! ones that were fixed).
//!
//! The targets: `goal` (goal formulas, conditions, a scenario's goals), `reply` (the
//! goal, conditions and value replies of a language model), `tree` (betr's tree text and
//! actions), `btcpp` (BehaviorTree.CPP XML over a scenario's domain), `scenario`
//! (scenario TOML and the world it describes), `policy` (saved policies), `cassette`
//! (LLM cassettes), `journal` (lines of an evaluation journal), `wav` (WAV files),
//! `recording` (session recordings and their decoding into events) and `groot2` (what a
//! BehaviorTree.CPP publisher sends `betr monitor`: its tree, statuses, changes and
//! blackboards).

mod corpus;
mod mutate;
mod rng;
mod runner;
mod targets;

use std::path::PathBuf;

pub use corpus::Corpus;
pub use rng::Rng;
pub use runner::{
    Failure, Progress, Report, RunOptions, check_caught, make_input, panic_message, run,
};

/// The targets, in the order `all` runs them.
pub const TARGETS: &[&str] = &[
    "goal",
    "reply",
    "tree",
    "btcpp",
    "scenario",
    "policy",
    "cassette",
    "journal",
    "wav",
    "recording",
    "groot2",
];

/// An input the target got wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Violation {
    /// The reader panicked.
    #[error("panic at {location}: {message}")]
    Panic { location: String, message: String },
    /// The reader returned, but what it returned breaks `rule`.
    #[error("{rule}: {detail}")]
    Property { rule: &'static str, detail: String },
}

impl Violation {
    /// What tells this failure apart from others of the same target: the panic's place or
    /// the broken rule.
    pub fn key(&self) -> &str {
        match self {
            Violation::Panic { location, .. } => location,
            Violation::Property { rule, .. } => rule,
        }
    }
}

/// A broken `rule`, with what was seen (cut to a readable length).
pub(crate) fn broken(rule: &'static str, detail: impl std::fmt::Display) -> Violation {
    Violation::Property {
        rule,
        detail: crate::excerpt::shortened(&detail.to_string(), 600),
    }
}

/// `Err(broken(rule, detail))` unless `holds`.
pub(crate) fn ensure(
    holds: bool,
    rule: &'static str,
    detail: impl FnOnce() -> String,
) -> Result<(), Violation> {
    if holds {
        Ok(())
    } else {
        Err(broken(rule, detail()))
    }
}

/// Why fuzzing could not start.
#[derive(Debug, thiserror::Error)]
pub enum FuzzError {
    #[error("unknown fuzz target {name:?} (known: {})", TARGETS.join(", "))]
    UnknownTarget { name: String },
    #[error("seed {path}: {detail}")]
    Seed { path: PathBuf, detail: String },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// What a target's inputs are made from.
pub struct Material {
    /// Inputs taken from the repository or written by hand.
    pub seeds: Vec<Vec<u8>>,
    /// Tokens of the format, inserted by mutations.
    pub tokens: Vec<String>,
    /// One level of nesting (opening, closing), repeated by mutations.
    pub brackets: Vec<(String, String)>,
}

/// What the runner needs of a target.
pub trait Target: Sync {
    fn name(&self) -> &'static str;
    /// The seeds and the format's pieces that mutations work from.
    fn material(&self) -> &Material;
    /// Whether the format is text (mutations keep to character boundaries).
    fn is_text(&self) -> bool {
        true
    }
    /// A new input made from the format's structure.
    fn generate(&self, rng: &mut Rng) -> Vec<u8>;
    /// Read `input` and check the properties of what was read.
    fn check(&self, input: &[u8]) -> Result<(), Violation>;
}

/// The target named `name` over `corpus`.
pub fn target(name: &str, corpus: &Corpus) -> Result<Box<dyn Target>, FuzzError> {
    targets::build(name, corpus)
}
