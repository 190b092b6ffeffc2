//! Hand-written replies under `tests/fixtures/replies/`, used to test the plumbing. Each
//! file says so in its `source`, names its scenario, and lists replies with the strings a
//! prompt must contain for the reply to be given.

use std::path::{Path, PathBuf};

use serde::Deserialize;

pub const SOURCE: &str = "hand-written for plumbing tests";

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixtureFile {
    pub source: String,
    /// The scenario file (relative to the crate root) the replies are for.
    pub scenario: String,
    pub reply: Vec<RawReply>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawReply {
    pub when: Vec<String>,
    /// Given only to a request with this seed (a sampled candidate); none: to any.
    #[serde(default)]
    pub seed: Option<u64>,
    pub text: String,
}

impl FixtureReply {
    /// Whether this reply answers `prompt` asked with `seed`.
    pub fn answers(&self, prompt: &str, seed: Option<u64>) -> bool {
        self.when.iter().all(|w| prompt.contains(w.as_str()))
            && self.seed.is_none_or(|s| seed == Some(s))
    }
}

/// A reply ready for the fake server.
#[derive(Debug, Clone)]
pub struct FixtureReply {
    pub when: Vec<String>,
    /// Given only to a request with this seed; none: to any.
    pub seed: Option<u64>,
    pub text: String,
    /// What the `x-betr-fixture` header says.
    pub note: String,
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every fixture file, by path.
pub fn all() -> Vec<(PathBuf, FixtureFile)> {
    let dir = root().join("tests/fixtures/replies");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixture dir")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("fixture");
            let f: FixtureFile =
                toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            assert_eq!(
                f.source,
                SOURCE,
                "{} must say it is hand-written",
                p.display()
            );
            (p, f)
        })
        .collect()
}

/// The replies of one file, labelled with their origin.
pub fn replies(path: &Path, file: &FixtureFile) -> Vec<FixtureReply> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    file.reply
        .iter()
        .map(|r| FixtureReply {
            when: r.when.clone(),
            seed: r.seed,
            text: r.text.clone(),
            note: format!("{SOURCE}: tests/fixtures/replies/{name}"),
        })
        .collect()
}

/// Every reply of every file (prompts of different scenarios differ in their instruction).
pub fn every_reply() -> Vec<FixtureReply> {
    let mut all: Vec<FixtureReply> = all().iter().flat_map(|(p, f)| replies(p, f)).collect();
    // The first reply that answers a prompt is given: the most specific first.
    all.sort_by_key(|r| std::cmp::Reverse(r.when.len()));
    all
}

/// The replies of the fixture file `name` alone (`red_on_blue.toml`): for a session whose
/// replies must come from that file when another file's would match the prompt too.
pub fn replies_of(name: &str) -> Vec<FixtureReply> {
    all()
        .iter()
        .filter(|(p, _)| p.file_name().is_some_and(|n| n == name))
        .flat_map(|(p, f)| replies(p, f))
        .collect()
}

/// Scenario 1's failure answered with the expected fix and a reasoning whose first claim
/// the world contradicts: the red cube lies on the blue cube, not on the table.
pub fn false_claim_reply() -> FixtureReply {
    FixtureReply {
        when: vec![
            "# Task: failure resolution".into(),
            "`grasp \"blue cube\"`".into(),
        ],
        seed: None,
        text: "Reasoning: The red cube is on the table, so the blue cube must be clear.\n\
               Conditions:\n~\"any object\" on \"blue cube\"\n"
            .into(),
        note: "hand-written: a reasoning with a false claim".into(),
    }
}
