//! Evaluation runners that reproduce the paper's experiments and write their results:
//! a table in the paper's layout, JSON and CSV with every case, and a PNG chart.

pub mod chart;
pub mod chart_runs;
pub mod goals;
pub mod goals_run;
pub mod levers;
pub mod params;
pub mod resolve;
pub mod run;
pub mod sequence;
mod session_run;
pub mod suite;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use chart::Series;

/// Published accuracies on the LLM-OBTEA goal set (easy, medium, hard), from the dataset's
/// README, drawn beside a run for comparison.
pub const PUBLISHED_GOALS: [(&str, [f64; 3]); 4] = [
    ("LLM-OBTEA, GPT-3.5, no feedback", [84.7, 76.7, 59.0]),
    ("LLM-OBTEA, GPT-3.5, 5 feedback rounds", [90.7, 82.0, 65.0]),
    ("LLM-OBTEA, GPT-4, no feedback", [90.0, 86.7, 85.5]),
    ("BETR-XP-LLM, GPT-4-1106, one call", [100.0, 100.0, 97.0]),
];

/// The published series plus this run's.
pub fn goals_series(label: &str, results: &goals::GoalsResults) -> Vec<Series> {
    let mut out: Vec<Series> = PUBLISHED_GOALS
        .iter()
        .map(|(l, v)| Series {
            label: (*l).to_string(),
            values: *v,
        })
        .collect();
    out.push(Series {
        label: label.to_string(),
        values: [
            results.easy.percent(),
            results.medium.percent(),
            results.hard.percent(),
        ],
    });
    out
}

/// `--out DIR`, or a new directory under `eval-results/` named by the experiment and time.
pub fn output_dir(out: Option<&Path>, experiment: &str) -> std::io::Result<PathBuf> {
    let dir = match out {
        Some(d) => d.to_path_buf(),
        None => {
            let stamp = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs());
            PathBuf::from("eval-results").join(format!("{experiment}-{stamp}"))
        }
    };
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// Why an experiment could not run (a wrong answer is a result, never an error).
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error(
        "{dir} holds results made with {what} = {old:?}, not {new:?}; resume with the same settings or choose another --out"
    )]
    Mismatch {
        dir: String,
        what: String,
        old: String,
        new: String,
    },
    #[error("{case}: {source}")]
    Llm {
        case: String,
        #[source]
        source: crate::llm::LlmError,
    },
    #[error("{case}: {source}")]
    Session {
        case: String,
        #[source]
        source: crate::session::SessionError,
    },
    #[error(transparent)]
    Prompt(#[from] crate::llm::prompt::PromptError),
    #[error(transparent)]
    Scenario(#[from] crate::scenario::ScenarioError),
}

impl EvalError {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        EvalError::Io {
            path: path.display().to_string(),
            source,
        }
    }
}
