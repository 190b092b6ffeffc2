//! The seed corpus, read from the repository when a run starts: the scenario files (their
//! text, the scenarios they load, their goals and example goals, and the tree planned for
//! each goal), the goals of the LLM-OBTEA dataset beside the repository, the hand-written
//! model replies of the test fixtures, the BehaviorTree.CPP fixtures and the journals of
//! the recorded evaluations (with a line of each experiment's journal kept under
//! `fuzz/seeds/journal/`, since `eval-results/` is not part of a checkout). The dataset is
//! read where it lies, never copied into the project.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::FuzzError;
use crate::bt::Tree;
use crate::planner::Planner;
use crate::scenario::Scenario;

/// Journal lines taken from each `cases.jsonl`.
const JOURNAL_LINES_PER_FILE: usize = 40;

/// A scenario file that loads, with the tree planned for its goal.
pub struct ScenarioSeed {
    /// The path relative to the repository (`scenarios/cell/red_on_blue.toml`).
    pub rel: String,
    pub path: PathBuf,
    pub scenario: Arc<Scenario>,
    pub planned: Option<Tree>,
}

/// A model reply of the fixtures, with the scenario it answers in.
pub struct ReplySeed {
    pub text: String,
    /// Index into [`Corpus::scenarios`].
    pub scenario: Option<usize>,
}

pub struct Corpus {
    pub root: PathBuf,
    /// Every TOML file under `scenarios/` and `tests/fixtures/scenarios/`, as text.
    pub toml_files: Vec<(PathBuf, String)>,
    pub scenarios: Vec<ScenarioSeed>,
    /// Goals of the scenarios, of their examples and of the dataset.
    pub goals: Vec<String>,
    pub replies: Vec<ReplySeed>,
    pub journal_lines: Vec<String>,
    pub xml: Vec<String>,
}

impl Corpus {
    /// Read the seeds of the repository at `root`.
    pub fn load(root: &Path) -> Result<Corpus, FuzzError> {
        let mut toml_files = Vec::new();
        for dir in ["scenarios", "tests/fixtures/scenarios"] {
            for path in files_under(&root.join(dir), "toml") {
                let text = read(&path)?;
                toml_files.push((path, text));
            }
        }
        let mut scenarios = Vec::new();
        let mut goals = Vec::new();
        for (path, _) in &toml_files {
            // Base files and example pools are not scenarios of their own.
            let Ok(scenario) = Scenario::load(path) else {
                continue;
            };
            if let Some(goal) = &scenario.goal {
                goals.push(goal.to_string());
            }
            goals.extend(scenario.expected_fix.iter().cloned());
            goals.extend(scenario.examples.iter().map(|e| e.goal.clone()));
            let planned = plan(&scenario);
            let rel = path
                .strip_prefix(root)
                .unwrap_or(path)
                .to_string_lossy()
                .into_owned();
            scenarios.push(ScenarioSeed {
                rel,
                path: path.clone(),
                scenario: Arc::new(scenario),
                planned,
            });
        }
        let dataset = root.join("../shared/datasets/llm-obtea");
        if let Ok(cases) = crate::dataset::load(&dataset) {
            goals.extend(cases.into_iter().map(|c| c.gold));
        }
        goals.sort();
        goals.dedup();
        let replies = replies(root, &scenarios)?;
        let mut journal_lines = Vec::new();
        // Journals of past runs when there are any, and what every checkout has: a line
        // of each experiment's journal (`fuzz/seeds/journal/`) and the journal regressions.
        let journals = files_under(&root.join("eval-results"), "jsonl")
            .into_iter()
            .chain(files_under(&root.join("fuzz/seeds/journal"), "jsonl"))
            .chain(files_under(&root.join("fuzz/regressions/journal"), "jsonl"));
        for path in journals {
            let text = read(&path)?;
            journal_lines.extend(
                text.lines()
                    .take(JOURNAL_LINES_PER_FILE)
                    .map(str::to_string),
            );
        }
        let mut xml = Vec::new();
        for path in files_under(&root.join("tests/fixtures/btcpp"), "xml") {
            xml.push(read(&path)?);
        }
        Ok(Corpus {
            root: root.to_path_buf(),
            toml_files,
            scenarios,
            goals,
            replies,
            journal_lines,
            xml,
        })
    }
}

/// The tree planned for the scenario's goal in its world, finished or not.
fn plan(scenario: &Scenario) -> Option<Tree> {
    let goal = scenario.goal.as_ref()?;
    let world = crate::world::load(scenario).ok()?;
    let plan = Planner::new(&scenario.domain)
        .plan(&goal.to_dnf(), world.as_ref())
        .ok()?;
    Some(plan.tree)
}

/// The `[[reply]]` texts of `tests/fixtures/replies/*.toml`.
fn replies(root: &Path, scenarios: &[ScenarioSeed]) -> Result<Vec<ReplySeed>, FuzzError> {
    let mut out = Vec::new();
    for path in files_under(&root.join("tests/fixtures/replies"), "toml") {
        let text = read(&path)?;
        let value: toml::Value = toml::from_str(&text).map_err(|e| FuzzError::Seed {
            path: path.clone(),
            detail: e.to_string(),
        })?;
        let scenario = value
            .get("scenario")
            .and_then(toml::Value::as_str)
            .and_then(|name| scenarios.iter().position(|s| s.rel == name));
        let texts = value
            .get("reply")
            .and_then(toml::Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(|r| r.get("text")?.as_str());
        out.extend(texts.map(|t| ReplySeed {
            text: t.to_string(),
            scenario,
        }));
    }
    Ok(out)
}

fn read(path: &Path) -> Result<String, FuzzError> {
    std::fs::read_to_string(path).map_err(|source| FuzzError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The files under `dir` (recursively) whose extension is `ext`, in a stable order.
fn files_under(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == ext) {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}
