//! `betr eval goals` on the cafe's 100 requests: the dataset, the fixture replies made from
//! its gold goals (with deliberate mistakes), the command against the fake server, and
//! the results read back. Shared by the fast tier's `eval_cmds` and the slow tier's (a run
//! killed midway).

use std::path::{Path, PathBuf};

use betr::dataset::{self, Case};
use betr::goal::{Formula, same_dnf};
use serde_json::Value as Json;

use super::cli::{KEY_VAR, betr};
use super::fake_openai::FakeServer;
use super::fixtures::{self, FixtureReply};

pub fn dataset_dir() -> PathBuf {
    fixtures::root().join("../shared/datasets/llm-obtea")
}

pub fn cafe() -> String {
    fixtures::root()
        .join("scenarios/cafe/cafe.toml")
        .display()
        .to_string()
}

pub fn cases() -> Vec<Case> {
    dataset::load(&dataset_dir()).unwrap()
}

pub fn read_json(path: &Path) -> Json {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

pub fn tally(results: &Json, difficulty: &str) -> (u64, u64) {
    let t = &results[difficulty];
    (t["correct"].as_u64().unwrap(), t["total"].as_u64().unwrap())
}

/// A goal that is valid in the vocabulary but not the gold one.
pub fn different_goal(gold: &str) -> String {
    let g = Formula::parse(gold).unwrap();
    ["Active_AC", "~Active_AC", "Active_TubeLight"]
        .into_iter()
        .find(|a| !same_dnf(&Formula::parse(a).unwrap(), &g))
        .unwrap()
        .to_string()
}

/// Fixture replies for all 100 instructions: the gold goal, except a deliberately wrong
/// goal for every case whose index ends in 3 (3 easy, 3 medium, 4 hard).
pub fn goal_fixtures() -> Vec<FixtureReply> {
    cases()
        .iter()
        .map(|c| FixtureReply {
            seed: None,
            when: vec![
                "# Task: goal interpretation".into(),
                format!("## Request\n{}\n", c.instruction),
            ],
            text: if c.index % 10 == 3 {
                format!("Goal: {}", different_goal(&c.gold))
            } else {
                format!("Goal: {}", c.gold)
            },
            note: format!(
                "{}: generated from the gold goals in tests/support/eval_goals.rs",
                fixtures::SOURCE
            ),
        })
        .collect()
}

pub fn model_goals(dir: &Path, server: &FakeServer, extra: &[&str]) -> std::process::Output {
    let d = dataset_dir().display().to_string();
    let url = server.base_url();
    let scenario = cafe();
    let mut args = vec![
        "eval",
        "goals",
        "--dataset",
        &d,
        "--scenario",
        &scenario,
        "--out",
        "out",
        "--backend",
        "openai",
        "--base-url",
        &url,
        "--model",
        "fake-model",
        "--api-key-env",
        KEY_VAR,
        // The fixtures answer whole requests; reading by parts is tested elsewhere.
        "--whole-request",
    ];
    args.extend_from_slice(extra);
    betr(dir, &args)
}
