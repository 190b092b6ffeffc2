//! Goal interpretation on several domains side by side: a suite file names sets of
//! requests, each either a dataset folder read in one scene, or a folder of scenario files
//! each with its own request and goal in its own scene. Each set runs as `eval goals`
//! does, into a folder of its own; the suite's table puts the sets side by side.
//!
//! ```toml
//! [[set]]
//! name = "greenhouse"
//! scenario = "scenarios/greenhouse/greenhouse.toml"
//! dataset = "docs/heldout-greenhouse"
//! tuned = false
//!
//! [[set]]
//! name = "cell"
//! scenarios = "scenarios/cell"
//! tuned = true
//! ```
//!
//! Paths are read from the directory the command runs in. `tuned` says whether how
//! requests are read was written with the set's requests in view; the table says so.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::dataset::{self, Case, Difficulty};
use crate::scenario::Scenario;

use super::goals::{GoalsResults, Tally};

/// Why a suite could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    #[error("cannot read {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: {source}", path.display())]
    Toml {
        path: PathBuf,
        #[source]
        source: toml::de::Error,
    },
    #[error("{}: set {name:?} {problem}", path.display())]
    Set {
        path: PathBuf,
        name: String,
        problem: String,
    },
    #[error(transparent)]
    Dataset(#[from] dataset::DatasetError),
    #[error(transparent)]
    Scenario(#[from] crate::scenario::ScenarioError),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SuiteFile {
    set: Vec<SetFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SetFile {
    name: String,
    scenario: Option<PathBuf>,
    dataset: Option<PathBuf>,
    scenarios: Option<PathBuf>,
    #[serde(default)]
    tuned: bool,
}

/// One set of a suite, read: its scenes and its cases, each with the index of its scene.
pub struct Set {
    pub name: String,
    pub tuned: bool,
    pub scenes: Vec<Scenario>,
    pub cases: Vec<(usize, Case)>,
}

/// Read the suite at `path` and every set it names.
pub fn load(path: &Path) -> Result<Vec<Set>, SuiteError> {
    let text = std::fs::read_to_string(path).map_err(|source| SuiteError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let file: SuiteFile = toml::from_str(&text).map_err(|source| SuiteError::Toml {
        path: path.to_path_buf(),
        source,
    })?;
    let mut sets: Vec<Set> = Vec::new();
    for s in file.set {
        let problem = |problem: &str| SuiteError::Set {
            path: path.to_path_buf(),
            name: s.name.clone(),
            problem: problem.to_string(),
        };
        if s.name.is_empty()
            || !s
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(problem(
                "needs a name of letters, digits, - and _ (it names the set's folder)",
            ));
        }
        if sets.iter().any(|t| t.name == s.name) {
            return Err(problem("is named twice"));
        }
        let set = match (&s.scenario, &s.dataset, &s.scenarios) {
            (Some(scenario), Some(dataset), None) => Set {
                name: s.name.clone(),
                tuned: s.tuned,
                scenes: vec![Scenario::load(scenario)?],
                cases: dataset::load(dataset)?
                    .into_iter()
                    .map(|c| (0, c))
                    .collect(),
            },
            (None, None, Some(dir)) => from_scenarios(&s.name, s.tuned, dir, path)?,
            _ => {
                return Err(problem(
                    "needs either scenario and dataset, or scenarios (a folder of scenario files)",
                ));
            }
        };
        if set.cases.is_empty() {
            return Err(problem("has no request"));
        }
        sets.push(set);
    }
    Ok(sets)
}

/// Every scenario file under `dir` that states a request and its goal, as a case in its
/// own scene; the difficulty is the goal's size (one condition easy, two medium, more
/// hard), numbered in path order.
fn from_scenarios(name: &str, tuned: bool, dir: &Path, suite: &Path) -> Result<Set, SuiteError> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let entries = std::fs::read_dir(&d).map_err(|source| SuiteError::Io {
            path: d.clone(),
            source,
        })?;
        for entry in entries {
            let path = entry
                .map_err(|source| SuiteError::Io {
                    path: d.clone(),
                    source,
                })?
                .path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "toml") {
                files.push(path);
            }
        }
    }
    files.sort();
    let mut set = Set {
        name: name.to_string(),
        tuned,
        scenes: Vec::new(),
        cases: Vec::new(),
    };
    for file in files {
        // A domain's base file and its example pool are no scenario of their own.
        let text = std::fs::read_to_string(&file).map_err(|source| SuiteError::Io {
            path: file.clone(),
            source,
        })?;
        let is_scenario = toml::from_str::<toml::Table>(&text)
            .map_err(|source| SuiteError::Toml {
                path: file.clone(),
                source,
            })?
            .contains_key("scenario");
        if !is_scenario {
            continue;
        }
        let scenario = Scenario::load(&file)?;
        let (Some(instruction), Some(goal)) = (scenario.instruction.clone(), &scenario.goal) else {
            continue;
        };
        let difficulty = match goal.atoms().len() {
            1 => Difficulty::Easy,
            2 => Difficulty::Medium,
            _ => Difficulty::Hard,
        };
        let index = set
            .cases
            .iter()
            .filter(|(_, c)| c.difficulty == difficulty)
            .count();
        let case = Case {
            difficulty,
            index,
            instruction,
            gold: goal.to_string(),
        };
        set.cases.push((set.scenes.len(), case));
        set.scenes.push(scenario);
    }
    if set.cases.is_empty() {
        return Err(SuiteError::Set {
            path: suite.to_path_buf(),
            name: name.to_string(),
            problem: format!(
                "finds no scenario file with a request and a goal under {}",
                dir.display()
            ),
        });
    }
    Ok(set)
}

/// One set's row of the suite's table.
pub struct SetRow<'a> {
    pub name: &'a str,
    pub tuned: bool,
    pub results: &'a GoalsResults,
}

/// The sets side by side: per set the requests, the first answer right, the answer
/// after the checks right, the gold among the readings offered, calls and time per
/// request.
pub fn table(rows: &[SetRow]) -> String {
    let overall = |t: Option<[Tally; 3]>| {
        t.map(|[e, m, h]| Tally {
            correct: e.correct + m.correct + h.correct,
            total: e.total + m.total + h.total,
        })
    };
    let cell = |t: Option<Tally>| {
        t.map_or("–".to_string(), |t| {
            format!("{:.1}% ({}/{})", t.percent(), t.correct, t.total)
        })
    };
    let mut out = String::from(
        "| set | read tuned on it | requests | first answer | after checks (easy / medium / hard) | after checks | gold among readings | calls per request | time per request (median) |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for row in rows {
        let r = row.results;
        let after = Some([r.easy, r.medium, r.hard]);
        let share = |t: &Tally| {
            if t.total == 0 {
                "–".to_string()
            } else {
                format!("{:.0}", t.percent())
            }
        };
        let by_difficulty = format!(
            "{} / {} / {} %",
            share(&r.easy),
            share(&r.medium),
            share(&r.hard)
        );
        let n = r.cases.len().max(1);
        let calls: usize = r.cases.iter().map(|c| c.calls.len()).sum();
        let mut times: Vec<f64> = r
            .cases
            .iter()
            .map(|c| c.calls.iter().map(|k| k.latency_ms).sum::<f64>())
            .collect();
        times.sort_by(f64::total_cmp);
        let median = times.get(times.len() / 2).copied().unwrap_or(0.0) / 1000.0;
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.2} s |\n",
            row.name,
            if row.tuned { "yes" } else { "no" },
            r.cases.len(),
            cell(overall(r.first_call())),
            by_difficulty,
            cell(overall(after)),
            cell(overall(r.gold_in_readings())),
            calls as f64 / n as f64,
            median,
        ));
    }
    out.push_str(&learned_table(rows));
    out
}

/// With `--learn` or recorded evidence: per set the answers right in the first pass and
/// in the second (every other request's miss kept as a correction), and how the doubt
/// level marked wrong and right answers; the doubt over every set last.
fn learned_table(rows: &[SetRow]) -> String {
    let learned = rows.iter().any(|r| r.results.second_pass.is_some());
    let doubts = rows.iter().any(|r| r.results.doubt.is_some());
    if !learned && !doubts {
        return String::new();
    }
    let cell = |t: Tally| format!("{:.1}% ({}/{})", t.percent(), t.correct, t.total);
    let share = |t: Tally| {
        if t.total == 0 {
            "–".to_string()
        } else {
            format!("{:.0}", t.percent())
        }
    };
    let by_difficulty = |p: &super::goals::PassTallies| {
        format!(
            "{} / {} / {} %",
            share(p.easy),
            share(p.medium),
            share(p.hard)
        )
    };
    let mut out = String::from(
        "\n| set | first pass (easy / medium / hard) | first pass | corrections kept | second pass (easy / medium / hard) | second pass | wrong answers marked doubtful | right answers marked doubtful |\n|---|---|---|---|---|---|---|---|\n",
    );
    let mut all = super::goals::DoubtCalibration::default();
    for row in rows {
        let r = row.results;
        let first = r.tallies();
        let (second_by, second) = r.second_pass.as_ref().map_or_else(
            || ("–".to_string(), "–".to_string()),
            |p| (by_difficulty(p), cell(p.overall())),
        );
        let (wrong, right) = r.doubt.map_or_else(
            || ("–".to_string(), "–".to_string()),
            |d| (cell(d.wrong_marked), cell(d.right_marked)),
        );
        if let Some(d) = r.doubt {
            all = all.plus(d);
        }
        out.push_str(&format!(
            "| {} | {} | {} | {} | {second_by} | {second} | {wrong} | {right} |\n",
            row.name,
            by_difficulty(&first),
            cell(first.overall()),
            if r.second_pass.is_some() {
                r.cases.iter().filter(|c| !c.correct).count().to_string()
            } else {
                "–".to_string()
            },
        ));
    }
    if doubts {
        out.push_str(&format!(
            "| every set | | | | | | {} | {} |\n",
            cell(all.wrong_marked),
            cell(all.right_marked)
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("write");
        path
    }

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("betr-suite-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        dir
    }

    #[test]
    fn a_set_needs_either_a_dataset_or_scenario_files() {
        let dir = temp("either");
        let suite = write(
            &dir,
            "suite.toml",
            "[[set]]\nname = \"x\"\nscenario = \"a.toml\"\n",
        );
        let err = load(&suite).err().expect("refused").to_string();
        assert!(err.contains("set \"x\" needs either"), "{err}");
        let suite = write(
            &dir,
            "suite.toml",
            "[[set]]\nname = \"a b\"\nscenarios = \".\"\n",
        );
        let err = load(&suite).err().expect("refused").to_string();
        assert!(err.contains("needs a name"), "{err}");
    }

    #[test]
    fn scenario_files_give_one_case_each_in_their_own_scene() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let dir = temp("cell");
        let suite = write(
            &dir,
            "suite.toml",
            &format!(
                "[[set]]\nname = \"cell\"\nscenarios = {:?}\ntuned = true\n",
                root.join("scenarios/cell").display().to_string()
            ),
        );
        let sets = load(&suite).expect("loads");
        let cell = &sets[0];
        assert!(cell.tuned);
        assert!(cell.cases.len() >= 10, "{}", cell.cases.len());
        assert_eq!(cell.scenes.len(), cell.cases.len());
        for (scene, case) in &cell.cases {
            assert_eq!(
                cell.scenes[*scene].instruction.as_deref(),
                Some(case.instruction.as_str())
            );
        }
    }
}
