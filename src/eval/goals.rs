//! The goal-interpretation experiment: score answers against the 100 gold goals of the
//! LLM-OBTEA dataset by the published rule (minimal DNF compared as sets of sets of
//! literals). An answer that does not parse, or names an atom outside the vocabulary, is
//! wrong — never an error that stops a run.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::dataset::{Case, Difficulty};
use crate::domain::Vocabulary;
use crate::goal::{Formula, same_dnf};

use super::run::{CallRecord, UsageSummary};

/// One scored case, as written to `results.json` and `results.csv`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseResult {
    /// The run (1-based) the answer belongs to.
    #[serde(default = "first_run")]
    pub run: usize,
    pub difficulty: String,
    pub index: usize,
    pub instruction: String,
    pub gold: String,
    /// The answer as given (`None`: no answer).
    pub answer: Option<String>,
    pub correct: bool,
    /// Why a wrong answer is wrong when it is not merely a different goal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub problem: Option<String>,
    /// The reply's full text, when the answer came from a model in this run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reply: Option<String>,
    /// Every call's accounting, when the answer came from a model in this run.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub calls: Vec<CallRecord>,
    /// The first call's answer, before any check, vote or feedback (when the answer came
    /// from a model): what a single call would have scored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_answer: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_correct: Option<bool>,
    /// Feedback rounds the answer needed.
    #[serde(default)]
    pub feedback_rounds: usize,
    /// The readings offered (the answer first), when the answer came from a model.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub readings: Vec<String>,
    /// Whether the gold goal is among the readings offered.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gold_in_readings: Option<bool>,
    /// What was found for and against the answer, whose doubt level the calibration
    /// counts (the level is summed up again when results are read, by the rule in use).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evidence: Option<crate::session::interpret::doubt::Evidence>,
}

fn first_run() -> usize {
    1
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally {
    pub correct: usize,
    pub total: usize,
}

impl Tally {
    pub fn percent(&self) -> f64 {
        if self.total == 0 {
            0.0
        } else {
            100.0 * self.correct as f64 / self.total as f64
        }
    }
}

/// The `results.json` document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoalsResults {
    pub easy: Tally,
    pub medium: Tally,
    pub hard: Tally,
    /// Per run, when there were several (the tallies above add them up).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub runs: Vec<RunTally>,
    /// Calls, tokens, cost and latency, when the answers came from a model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub usage: Option<UsageSummary>,
    /// With `--learn`: the answers of the second pass, each request read with every other
    /// request's correction kept as an example of the domain.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub second_pass: Option<PassTallies>,
    /// How often the doubt level marked a wrong answer, and a right one, when the cases
    /// recorded their evidence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub doubt: Option<DoubtCalibration>,
    pub cases: Vec<CaseResult>,
}

/// The answers right per difficulty, of one pass over a set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PassTallies {
    pub easy: Tally,
    pub medium: Tally,
    pub hard: Tally,
}

impl PassTallies {
    pub fn overall(&self) -> Tally {
        Tally {
            correct: self.easy.correct + self.medium.correct + self.hard.correct,
            total: self.easy.total + self.medium.total + self.hard.total,
        }
    }
}

/// The doubt level against the answers: of the wrong answers, those marked doubtful; of
/// the right ones, those marked doubtful too.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DoubtCalibration {
    pub wrong_marked: Tally,
    pub right_marked: Tally,
}

impl DoubtCalibration {
    /// Counted over the cases that recorded their evidence, by the doubt rule in use.
    pub fn of<'a>(cases: impl IntoIterator<Item = &'a CaseResult>) -> Option<DoubtCalibration> {
        let mut out = DoubtCalibration::default();
        let mut any = false;
        for c in cases {
            let Some(evidence) = &c.evidence else {
                continue;
            };
            any = true;
            let marked = evidence.level() == crate::session::interpret::doubt::Level::Doubtful;
            let tally = if c.correct {
                &mut out.right_marked
            } else {
                &mut out.wrong_marked
            };
            tally.total += 1;
            tally.correct += usize::from(marked);
        }
        any.then_some(out)
    }

    /// The two counts added up with another set's.
    pub fn plus(self, other: DoubtCalibration) -> DoubtCalibration {
        let sum = |a: Tally, b: Tally| Tally {
            correct: a.correct + b.correct,
            total: a.total + b.total,
        };
        DoubtCalibration {
            wrong_marked: sum(self.wrong_marked, other.wrong_marked),
            right_marked: sum(self.right_marked, other.right_marked),
        }
    }
}

/// The tallies of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunTally {
    pub run: usize,
    pub easy: Tally,
    pub medium: Tally,
    pub hard: Tally,
}

#[derive(Debug, thiserror::Error)]
pub enum AnswersError {
    #[error("{path}: {source}")]
    Read {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error(
        "{path}: expected {expected} lines (one answer per case, in the order easy, medium, hard), found {found}"
    )]
    Count {
        path: String,
        expected: usize,
        found: usize,
    },
}

/// The formula in an answer line as a model may have written it: an optional `Goal:`
/// label, code ticks and surrounding spaces are not part of it.
pub fn answer_formula(line: &str) -> &str {
    let t = line.trim().trim_matches('`').trim();
    match t.find("Goal:") {
        Some(i) => t[i + "Goal:".len()..].trim().trim_matches('`').trim(),
        None => t,
    }
}

/// Score one answer against its gold goal.
pub fn score(vocabulary: &Vocabulary, case: &Case, answer: Option<&str>) -> CaseResult {
    let (correct, problem) = judge(vocabulary, &case.gold, answer);
    CaseResult {
        run: 1,
        difficulty: case.difficulty.as_str().to_string(),
        index: case.index,
        instruction: case.instruction.clone(),
        gold: case.gold.clone(),
        answer: answer.map(str::to_string),
        correct,
        problem,
        reply: None,
        calls: Vec::new(),
        first_answer: None,
        first_correct: None,
        readings: Vec::new(),
        gold_in_readings: None,
        evidence: None,
        feedback_rounds: 0,
    }
}

/// Whether `answer` is the gold goal of `case` by the dataset's rule.
pub fn is_correct(vocabulary: &Vocabulary, case: &Case, answer: Option<&str>) -> bool {
    judge(vocabulary, &case.gold, answer).0
}

fn judge(vocabulary: &Vocabulary, gold: &str, answer: Option<&str>) -> (bool, Option<String>) {
    let Some(text) = answer.map(answer_formula).filter(|t| !t.is_empty()) else {
        return (false, Some("no answer".into()));
    };
    let formula = match Formula::parse(text) {
        Ok(f) => f,
        Err(e) => return (false, Some(format!("does not parse: {e}"))),
    };
    if let Some(e) = formula
        .atoms()
        .iter()
        .find_map(|a| vocabulary.check_atom(a).err())
    {
        return (false, Some(format!("outside the vocabulary: {e}")));
    }
    match Formula::parse(gold) {
        Ok(g) => (same_dnf(&formula, &g), None),
        Err(e) => (false, Some(format!("the gold goal does not parse: {e}"))),
    }
}

/// Read an answers file: exactly one line per case (an empty line = no answer).
pub fn read_answers(path: &Path, expected: usize) -> Result<Vec<Option<String>>, AnswersError> {
    let text = std::fs::read_to_string(path).map_err(|source| AnswersError::Read {
        path: path.display().to_string(),
        source,
    })?;
    let mut lines: Vec<&str> = text
        .split('\n')
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .collect();
    // A final newline ends the last line; it does not start an extra one.
    if text.ends_with('\n') {
        lines.pop();
    }
    if lines.len() != expected {
        return Err(AnswersError::Count {
            path: path.display().to_string(),
            expected,
            found: lines.len(),
        });
    }
    Ok(lines
        .into_iter()
        .map(|l| (!l.trim().is_empty()).then(|| l.to_string()))
        .collect())
}

impl GoalsResults {
    /// Tallies of `cases` (of every run); per-run tallies when there are several runs,
    /// and the usage of the calls when the answers came from a model.
    pub fn from_cases(cases: Vec<CaseResult>) -> Self {
        let tally = |run: Option<usize>, d: Difficulty| {
            let of = |c: &&CaseResult| c.difficulty == d.as_str() && run.is_none_or(|r| c.run == r);
            Tally {
                correct: cases.iter().filter(of).filter(|c| c.correct).count(),
                total: cases.iter().filter(of).count(),
            }
        };
        let mut run_ids: Vec<usize> = cases.iter().map(|c| c.run).collect();
        run_ids.sort_unstable();
        run_ids.dedup();
        let runs = if run_ids.len() > 1 {
            run_ids
                .iter()
                .map(|&r| RunTally {
                    run: r,
                    easy: tally(Some(r), Difficulty::Easy),
                    medium: tally(Some(r), Difficulty::Medium),
                    hard: tally(Some(r), Difficulty::Hard),
                })
                .collect()
        } else {
            Vec::new()
        };
        let calls: Vec<&CallRecord> = cases.iter().flat_map(|c| &c.calls).collect();
        GoalsResults {
            easy: tally(None, Difficulty::Easy),
            medium: tally(None, Difficulty::Medium),
            hard: tally(None, Difficulty::Hard),
            runs,
            usage: (!calls.is_empty()).then(|| UsageSummary::of(calls)),
            second_pass: None,
            doubt: DoubtCalibration::of(&cases),
            cases,
        }
    }

    /// The answers right per difficulty.
    pub fn tallies(&self) -> PassTallies {
        PassTallies {
            easy: self.easy,
            medium: self.medium,
            hard: self.hard,
        }
    }

    /// The first calls' tallies (easy, medium, hard), when the cases recorded them.
    pub fn first_call(&self) -> Option<[Tally; 3]> {
        self.tally_by(|c| c.first_correct)
    }

    /// Per difficulty, the cases whose gold goal is among the readings offered; `None`
    /// when no case recorded its readings.
    pub fn gold_in_readings(&self) -> Option<[Tally; 3]> {
        self.tally_by(|c| c.gold_in_readings)
    }

    fn tally_by(&self, verdict: impl Fn(&CaseResult) -> Option<bool>) -> Option<[Tally; 3]> {
        if self.cases.iter().all(|c| verdict(c).is_none()) {
            return None;
        }
        Some(Difficulty::ALL.map(|d| {
            let of: Vec<&CaseResult> = self
                .cases
                .iter()
                .filter(|c| c.difficulty == d.as_str())
                .collect();
            Tally {
                correct: of.iter().filter(|c| verdict(c) == Some(true)).count(),
                total: of.len(),
            }
        }))
    }

    pub fn overall(&self) -> Tally {
        Tally {
            correct: self.easy.correct + self.medium.correct + self.hard.correct,
            total: self.easy.total + self.medium.total + self.hard.total,
        }
    }

    /// The table in the paper's layout (accuracy per difficulty), one row per system.
    pub fn table(&self, system: &str) -> String {
        let cell = |t: &Tally| format!("{:.1}% ({}/{})", t.percent(), t.correct, t.total);
        let mut out = String::new();
        out.push_str("| system | easy | medium | hard | overall |\n|---|---|---|---|---|\n");
        out.push_str(&format!(
            "| {system} | {} | {} | {} | {} |\n",
            cell(&self.easy),
            cell(&self.medium),
            cell(&self.hard),
            cell(&self.overall())
        ));
        out
    }

    /// Every case as CSV (RFC 4180 quoting).
    pub fn csv(&self) -> String {
        let q = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
        let mut out = String::from(
            "run,difficulty,index,instruction,gold,answer,correct,problem,first_answer,first_correct,calls,prompt_tokens,completion_tokens,latency_ms\n",
        );
        for c in &self.cases {
            let (p, k, l) = if c.calls.is_empty() {
                (String::new(), String::new(), String::new())
            } else {
                (
                    c.calls
                        .iter()
                        .map(|x| x.prompt_tokens)
                        .sum::<u64>()
                        .to_string(),
                    c.calls
                        .iter()
                        .map(|x| x.completion_tokens)
                        .sum::<u64>()
                        .to_string(),
                    format!("{:.0}", c.calls.iter().map(|x| x.latency_ms).sum::<f64>()),
                )
            };
            out.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{},{p},{k},{l}\n",
                c.run,
                c.difficulty,
                c.index,
                q(&c.instruction),
                q(&c.gold),
                q(c.answer.as_deref().unwrap_or("")),
                c.correct,
                q(c.problem.as_deref().unwrap_or("")),
                q(c.first_answer.as_deref().unwrap_or("")),
                c.first_correct.map_or(String::new(), |b| b.to_string()),
                c.calls.len(),
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(gold: &str) -> Case {
        Case {
            difficulty: Difficulty::Easy,
            index: 0,
            instruction: "x".into(),
            gold: gold.into(),
        }
    }

    fn vocab() -> Vocabulary {
        use crate::domain::{Object, Predicate};
        Vocabulary {
            objects: vec![
                Object {
                    name: "AC".into(),
                    types: vec!["appliance".into()],
                    called: Vec::new(),
                },
                Object {
                    name: "TubeLight".into(),
                    types: vec!["appliance".into()],
                    called: Vec::new(),
                },
            ],
            predicates: vec![Predicate {
                name: "Active".into(),
                arg_types: vec![vec!["appliance".into()]],
                description: String::new(),
                words: Default::default(),
            }],
        }
    }

    #[test]
    fn equal_dnfs_are_correct_whatever_the_spelling() {
        let v = vocab();
        let c = case("Active_AC & ~Active_TubeLight");
        assert!(score(&v, &c, Some("~Active_TubeLight&Active_AC")).correct);
        assert!(score(&v, &c, Some("Goal: (Active_AC) & ~(Active_TubeLight)")).correct);
        assert!(score(&v, &c, Some("`Goal: Active_AC & ~Active_TubeLight`")).correct);
        assert!(!score(&v, &c, Some("Active_AC")).correct);
    }

    #[test]
    fn bad_answers_are_wrong_with_a_reason() {
        let v = vocab();
        let c = case("Active_AC");
        let r = score(&v, &c, Some("Active_AC &"));
        assert!(
            !r.correct
                && r.problem
                    .as_deref()
                    .is_some_and(|p| p.starts_with("does not parse"))
        );
        let r = score(&v, &c, Some("Active_Fan"));
        assert!(
            !r.correct
                && r.problem
                    .as_deref()
                    .is_some_and(|p| p.contains("outside the vocabulary"))
        );
        let r = score(&v, &c, None);
        assert_eq!(r.problem.as_deref(), Some("no answer"));
    }

    #[test]
    fn csv_quotes_fields() {
        let v = vocab();
        let mut c = case("Active_AC");
        c.instruction = "say \"hi\", please".into();
        let results = GoalsResults::from_cases(vec![score(&v, &c, Some("Active_AC"))]);
        assert!(results.csv().contains("\"say \"\"hi\"\", please\""));
        assert_eq!(
            results.easy,
            Tally {
                correct: 1,
                total: 1
            }
        );
    }
}
