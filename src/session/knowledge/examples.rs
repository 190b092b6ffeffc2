//! Corrections kept as worked examples of a domain: when a person chooses a reading that
//! was not offered first, or types the goal an instruction meant, the instruction as said
//! and the goal that was run are kept in `examples.jsonl` beside the policies and the
//! learned rules, with where they came from. Every later request of the domain chooses
//! its prompt's examples from the written pool and these, so a request phrased like a
//! corrected one is shown its correction. Keeping one costs no model call.
//!
//! One JSON object a line: a line that does not read (hand-edited, cut) is reported with
//! its number and left as it is, and the other lines still load. A change is made under a
//! lock (`examples.jsonl.lock` beside it) to the file as it is then: a new example is
//! appended whole, a revoked or replaced one is taken out by writing the file anew
//! atomically, every other line (unreadable ones too) kept as it was. Two sessions
//! keeping corrections at once lose neither.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::goal::Formula;
use crate::planner::{Outcome, Planner};
use crate::scenario::{Example, ExampleSource, Scenario};

use super::KnowledgeError;

/// The file's name inside the policy directory.
pub const FILE_NAME: &str = "examples.jsonl";

/// A correction kept, with where it came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KeptExample {
    pub id: String,
    /// The domain's base file stem (`cafe`, `cell`): used for its requests alone.
    pub domain: String,
    /// The instruction as the person said it.
    pub instruction: String,
    /// The goal that was run for it.
    pub goal: String,
    /// The scenario file it was corrected in.
    pub scenario: String,
    pub kept_at: String,
    /// The reading it replaced (the goal offered first), when there was one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaced: Option<String>,
    /// Who corrected it, and how (a person choosing a reading, typing the goal).
    pub kept_by: String,
}

impl KeptExample {
    /// The worked example a prompt may show.
    pub fn example(&self) -> Example {
        Example {
            instruction: self.instruction.clone(),
            goal: self.goal.clone(),
            source: ExampleSource::Kept(self.id.clone()),
        }
    }

    /// Whether it is about the same instruction of the same domain as `other` (said
    /// alike but for case and spacing).
    fn same_instruction(&self, other: &KeptExample) -> bool {
        self.domain == other.domain && said(&self.instruction) == said(&other.instruction)
    }
}

fn said(instruction: &str) -> String {
    instruction
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_lowercase()
}

/// The kept examples, and the lines of the file that did not read.
#[derive(Debug, Clone, Default)]
pub struct KeptExamples {
    pub path: PathBuf,
    pub examples: Vec<KeptExample>,
    /// Each line that did not read: `FILE line N: why`.
    pub problems: Vec<String>,
}

/// A correction that is not kept, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotKept {
    #[error("the instruction is empty")]
    NoInstruction,
    #[error("the goal {goal} does not fit the scene: {why}")]
    NotInScene { goal: String, why: String },
    #[error("the goal {goal} cannot be planned from the scene's first state: {why}")]
    Unplannable { goal: String, why: String },
}

impl KeptExamples {
    /// The kept examples of a policy directory's file.
    pub fn path_in(policy_dir: &Path) -> PathBuf {
        policy_dir.join(FILE_NAME)
    }

    /// Read the file; a missing file is none kept yet.
    pub fn open(path: &Path) -> Result<KeptExamples, KnowledgeError> {
        let text = super::read_or_empty(path)?;
        let mut kept = KeptExamples {
            path: path.to_path_buf(),
            ..KeptExamples::default()
        };
        for (number, line) in text.lines().enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            match serde_json::from_str::<KeptExample>(line) {
                Ok(example) => kept.examples.push(example),
                Err(e) => kept.problems.push(format!(
                    "{} line {}: {e}; left out",
                    path.display(),
                    number + 1
                )),
            }
        }
        Ok(kept)
    }

    /// The examples of `domain`.
    pub fn of_domain<'a>(&'a self, domain: &'a str) -> impl Iterator<Item = &'a KeptExample> {
        self.examples.iter().filter(move |e| e.domain == domain)
    }

    /// Keep `example` (its id is given here): appended to the file as it is now, unless it
    /// holds the same instruction of the domain with the same goal already (that one is
    /// returned, not new); one with another goal is replaced by it.
    pub fn keep(
        &mut self,
        mut example: KeptExample,
    ) -> Result<(KeptExample, bool), KnowledgeError> {
        let _lock = self.lock()?;
        self.reread()?;
        let same: Vec<&KeptExample> = self
            .examples
            .iter()
            .filter(|e| e.same_instruction(&example))
            .collect();
        if let Some(e) = same.iter().find(|e| e.goal == example.goal) {
            return Ok(((*e).clone(), false));
        }
        example.id = super::next_id('e', self.examples.iter().map(|e| e.id.as_str()));
        let line = serde_json::to_string(&example).map_err(|e| KnowledgeError::Parse {
            path: self.path.clone(),
            message: e.to_string(),
        })?;
        if same.is_empty() {
            crate::store::append_line(&self.path, &line)
                .map_err(|source| self.write_error(source))?;
        } else {
            let replaced: Vec<String> = same.iter().map(|e| e.id.clone()).collect();
            self.rewrite(
                |kept| kept.is_none_or(|k| !replaced.contains(&k.id)),
                Some(&line),
            )?;
        }
        self.reread()?;
        Ok((example, true))
    }

    /// Keep a correction of `instruction` in `scenario` (`goal` run instead of
    /// `replaced`) once [`check_correction`] passes; with whether it is new.
    pub fn keep_correction(
        &mut self,
        (scenario, scenario_file): (&Scenario, &Path),
        (instruction, goal): (&str, &Formula),
        replaced: Option<&Formula>,
        kept_by: &str,
    ) -> Result<(KeptExample, bool), KnowledgeError> {
        check_correction(scenario, instruction, goal)?;
        self.keep(correction(
            scenario,
            scenario_file,
            (instruction, goal),
            replaced,
            kept_by,
        ))
    }

    /// Take an example out: later requests no longer see it.
    pub fn revoke(&mut self, id: &str) -> Result<KeptExample, KnowledgeError> {
        let _lock = self.lock()?;
        self.reread()?;
        let Some(removed) = self.examples.iter().find(|e| e.id == id).cloned() else {
            return Err(KnowledgeError::NoSuchExample {
                id: id.to_string(),
                path: self.path.clone(),
                known: super::known_ids(self.examples.iter().map(|e| e.id.as_str())),
            });
        };
        self.rewrite(|kept| kept.is_none_or(|k| k.id != id), None)?;
        self.reread()?;
        Ok(removed)
    }

    /// Write the file anew with the lines `keep` keeps (it is given each line's example,
    /// `None` for one that does not read: such lines are kept unless it says otherwise),
    /// then `add`.
    fn rewrite(
        &self,
        keep: impl Fn(Option<&KeptExample>) -> bool,
        add: Option<&str>,
    ) -> Result<(), KnowledgeError> {
        let text = super::read_or_empty(&self.path)?;
        let mut out = String::new();
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            let read = serde_json::from_str::<KeptExample>(line).ok();
            if keep(read.as_ref()) {
                out.push_str(line);
                out.push('\n');
            }
        }
        if let Some(line) = add {
            out.push_str(line);
            out.push('\n');
        }
        crate::store::write_atomic(&self.path, out.as_bytes()).map_err(|e| self.write_error(e))
    }

    fn write_error(&self, source: std::io::Error) -> KnowledgeError {
        KnowledgeError::Write {
            path: self.path.clone(),
            source,
        }
    }

    /// An exclusive lock of the file, on `examples.jsonl.lock` beside it (the file itself
    /// is replaced when an example is taken out).
    fn lock(&self) -> Result<std::fs::File, KnowledgeError> {
        super::lock_beside(&self.path)
    }

    fn reread(&mut self) -> Result<(), KnowledgeError> {
        let again = KeptExamples::open(&self.path)?;
        self.examples = again.examples;
        self.problems = again.problems;
        Ok(())
    }

    /// The kept examples of `scenario`'s domain that fit its scene, as worked examples,
    /// and a note for each left out (its goal names what this scene does not have).
    pub fn for_scenario(&self, scenario: &Scenario) -> (Vec<Example>, Vec<String>) {
        let domain = super::domain_of(scenario);
        let mut fit = Vec::new();
        let mut notes = Vec::new();
        for kept in self.of_domain(&domain) {
            match scenario.parse_goal(&kept.goal) {
                Ok(_) => fit.push(kept.example()),
                Err(e) => notes.push(format!(
                    "kept example {} does not fit this scene ({e}); left out",
                    kept.id
                )),
            }
        }
        (fit, notes)
    }
}

/// Check a correction before it is kept: an instruction, a goal of the scene's own objects
/// that the planner can reach from the scene's first state (an action failing in
/// simulation is what failure resolution is for: the goal itself is reachable).
pub fn check_correction(
    scenario: &Scenario,
    instruction: &str,
    goal: &Formula,
) -> Result<(), NotKept> {
    if instruction.trim().is_empty() {
        return Err(NotKept::NoInstruction);
    }
    let text = goal.to_string();
    scenario
        .parse_goal(&text)
        .map_err(|e| NotKept::NotInScene {
            goal: text.clone(),
            why: e.to_string(),
        })?;
    let world = crate::world::load(scenario).map_err(|e| NotKept::NotInScene {
        goal: text.clone(),
        why: e.to_string(),
    })?;
    let plan = Planner::new(&scenario.domain)
        .plan(&goal.to_dnf(), world.as_ref())
        .map_err(|e| NotKept::Unplannable {
            goal: text.clone(),
            why: e.to_string(),
        })?;
    match plan.outcome {
        Outcome::Success | Outcome::ActionFailed { .. } => Ok(()),
        other => Err(NotKept::Unplannable {
            goal: text,
            why: format!("{other:?}"),
        }),
    }
}

/// A correction of `instruction` in `scenario`: `goal` run instead of `replaced`.
fn correction(
    scenario: &Scenario,
    scenario_file: &Path,
    (instruction, goal): (&str, &Formula),
    replaced: Option<&Formula>,
    kept_by: &str,
) -> KeptExample {
    KeptExample {
        id: String::new(),
        domain: super::domain_of(scenario),
        instruction: instruction.trim().to_string(),
        goal: goal.to_string(),
        scenario: scenario_file.display().to_string(),
        kept_at: crate::session::policy::now_rfc3339(),
        replaced: replaced.map(ToString::to_string),
        kept_by: kept_by.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("betr-examples-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn kept(instruction: &str, goal: &str) -> KeptExample {
        KeptExample {
            id: String::new(),
            domain: "cafe".into(),
            instruction: instruction.into(),
            goal: goal.into(),
            scenario: "scenarios/cafe/cafe.toml".into(),
            kept_at: "2026-11-29T00:00:00Z".into(),
            replaced: Some("Closed_Curtain".into()),
            kept_by: "a person".into(),
        }
    }

    #[test]
    fn kept_listed_replaced_and_revoked() {
        let d = dir("keep");
        let path = KeptExamples::path_in(&d);
        let mut examples = KeptExamples::open(&path).unwrap();
        assert!(examples.examples.is_empty());
        let (first, new) = examples
            .keep(kept("Draw the blinds", "~Closed_Curtain"))
            .unwrap();
        assert!(new);
        assert_eq!(first.id, "e1");
        // The same instruction with the same goal is not kept twice.
        let (again, new) = examples
            .keep(kept("draw  the blinds", "~Closed_Curtain"))
            .unwrap();
        assert!(!new);
        assert_eq!(again.id, "e1");
        examples
            .keep(kept("Coffee for table 2", "On_Coffee_Table2"))
            .unwrap();
        // Another goal for the same instruction replaces the first.
        let (third, _) = examples
            .keep(kept("Draw the blinds", "Closed_Curtain"))
            .unwrap();
        assert_eq!(third.id, "e3");
        let read = KeptExamples::open(&path).unwrap();
        let ids: Vec<&str> = read.examples.iter().map(|e| e.id.as_str()).collect();
        assert_eq!(ids, ["e2", "e3"]);
        examples.revoke("e2").unwrap();
        let read = KeptExamples::open(&path).unwrap();
        assert_eq!(read.examples.len(), 1);
        assert!(
            examples
                .revoke("e9")
                .unwrap_err()
                .to_string()
                .contains("e3")
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_bad_line_is_named_the_others_load_and_it_stays_in_the_file() {
        let d = dir("bad");
        let path = KeptExamples::path_in(&d);
        let mut examples = KeptExamples::open(&path).unwrap();
        examples
            .keep(kept("Draw the blinds", "~Closed_Curtain"))
            .unwrap();
        let mut text = std::fs::read_to_string(&path).unwrap();
        text.push_str("{\"id\": \"e7\", hand-edited\n");
        std::fs::write(&path, &text).unwrap();
        examples
            .keep(kept("Coffee for table 2", "On_Coffee_Table2"))
            .unwrap();
        let read = KeptExamples::open(&path).unwrap();
        assert_eq!(read.examples.len(), 2);
        assert_eq!(read.problems.len(), 1);
        assert!(read.problems[0].contains("line 2"), "{:?}", read.problems);
        // Taking an example out rewrites the file: the bad line is kept as it was.
        let mut examples = read;
        examples.revoke("e1").unwrap();
        let after = std::fs::read_to_string(&path).unwrap();
        assert!(after.contains("hand-edited"));
        assert!(!after.contains("Draw the blinds"));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn two_sessions_keeping_at_once_lose_neither() {
        let d = dir("two");
        let path = KeptExamples::path_in(&d);
        let threads: Vec<_> = (0..2)
            .map(|t| {
                let path = path.clone();
                std::thread::spawn(move || {
                    let mut mine = KeptExamples::open(&path).unwrap();
                    for i in 0..10 {
                        mine.keep(kept(&format!("request {t}-{i}"), "Closed_Curtain"))
                            .unwrap();
                    }
                })
            })
            .collect();
        for t in threads {
            t.join().unwrap();
        }
        let read = KeptExamples::open(&path).unwrap();
        assert_eq!(read.examples.len(), 20);
        let mut ids: Vec<&str> = read.examples.iter().map(|e| e.id.as_str()).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), 20, "every id given once");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_correction_must_fit_the_scene_and_be_plannable() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml");
        let cafe = Scenario::load(&path).unwrap();
        let goal = |t: &str| Formula::parse(t).unwrap();
        assert_eq!(
            check_correction(&cafe, "Coffee for table 2", &goal("On_Coffee_Table2")),
            Ok(())
        );
        assert!(matches!(
            check_correction(&cafe, "Tea for the moon", &goal("On_Coffee_Moon")),
            Err(NotKept::NotInScene { .. })
        ));
        assert_eq!(
            check_correction(&cafe, "  ", &goal("On_Coffee_Table2")),
            Err(NotKept::NoInstruction)
        );
        // The robot holds one thing at a time: both at once cannot be reached.
        assert!(matches!(
            check_correction(
                &cafe,
                "Hold the coffee and the chips",
                &goal("Holding_Coffee & Holding_Chips")
            ),
            Err(NotKept::Unplannable { .. })
        ));
    }
}
