//! Fixes that carry over, measured: scenarios resolved one after the other, every
//! proposal approved, once with the fixes kept as rules between them (`--yes --learn`:
//! each kept fix lifted, checked and kept in `DIR/knowledge.toml`, the next scenario
//! planned with every rule so far) and once without, each step's model calls, failures
//! in the world and ticks side by side.
//!
//! Steps are journaled in `DIR/cases.jsonl` as they finish and the knowledge file lives in
//! `DIR`, so an interrupted sequence resumes where it stopped.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::llm::LanguageModel;
use crate::scenario::Scenario;
use crate::session::knowledge::{KeptRule, Knowledge, Provenance, kept_conditions, rule_for_fix};
use crate::session::{Event, Options};

use super::EvalError;
use super::run::{Journal, RunConfig, Tap, elapsed_ms};
use super::session_run::resolve_approving;

/// One scenario of the sequence, with or without the knowledge kept so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SequenceStep {
    pub scenario: String,
    pub name: String,
    /// Planned with the rules kept by the steps before.
    pub with_knowledge: bool,
    pub success: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ticks: Option<u64>,
    /// Model calls of the step (goal and failures).
    pub calls: usize,
    /// Actions that failed in the world (the simulated execution cell).
    pub world_failures: usize,
    /// Rules that were added to the scenario's skills before planning.
    pub rules_applied: Vec<String>,
    /// Rules this step kept (ids), and rules it offered that were refused (with why).
    pub rules_kept: Vec<String>,
    pub rules_refused: Vec<String>,
    pub wall_ms: f64,
}

/// `results.json` of `betr eval resolve --sequence`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SequenceResults {
    /// How many of the steps (from the first) are the failure scenarios; the rest are the
    /// new tasks.
    pub failure_steps: usize,
    pub steps: Vec<SequenceStep>,
    pub rules: Vec<KeptRule>,
}

/// Run `scenarios` in order, without knowledge and then with it.
pub async fn run_sequence(
    model: &Arc<dyn LanguageModel>,
    scenarios: &[(String, Scenario)],
    failure_steps: usize,
    options: &Options,
    cfg: &RunConfig<'_>,
    dir: &Path,
) -> Result<SequenceResults, EvalError> {
    let journal = Journal::new(dir);
    let mut done: Vec<SequenceStep> = journal.read()?;
    let mut knowledge = Knowledge::open(&Knowledge::path_in(dir))
        .map_err(|e| EvalError::io(dir, std::io::Error::other(e.to_string())))?;
    let total = scenarios.len() * 2;
    cfg.progress.begin(total, done.len());
    for with_knowledge in [false, true] {
        for (path, scenario) in scenarios {
            if done
                .iter()
                .any(|s| s.scenario == *path && s.with_knowledge == with_knowledge)
            {
                continue;
            }
            let step = run_step(
                model,
                (path, scenario),
                with_knowledge,
                &mut knowledge,
                options,
                cfg,
            )
            .await?;
            journal.append(&step)?;
            done.push(step);
            cfg.progress
                .finished(&format!("{path} ({})", mode(with_knowledge)));
        }
    }
    cfg.progress.end();
    let order = |s: &SequenceStep| {
        (
            s.with_knowledge,
            scenarios.iter().position(|(p, _)| *p == s.scenario),
        )
    };
    done.retain(|s| scenarios.iter().any(|(p, _)| *p == s.scenario));
    done.sort_by_key(order);
    Ok(SequenceResults {
        failure_steps,
        steps: done,
        rules: knowledge.rules.clone(),
    })
}

fn mode(with_knowledge: bool) -> &'static str {
    if with_knowledge {
        "with knowledge"
    } else {
        "without"
    }
}

async fn run_step(
    model: &Arc<dyn LanguageModel>,
    (path, scenario): (&str, &Scenario),
    with_knowledge: bool,
    knowledge: &mut Knowledge,
    options: &Options,
    cfg: &RunConfig<'_>,
) -> Result<SequenceStep, EvalError> {
    let mut planned = scenario.clone();
    let rules_applied = if with_knowledge {
        knowledge.apply(&mut planned).0
    } else {
        Vec::new()
    };
    let tap = Arc::new(Tap::new(model.clone(), Some(1), &cfg.prices));
    let start = Instant::now();
    let trace = resolve_approving(&planned, tap.clone(), options, None)
        .await
        .map_err(|source| EvalError::Session {
            case: format!("{path} ({})", mode(with_knowledge)),
            source,
        })?;
    let world_failures = trace
        .events
        .iter()
        .filter(|e| matches!(e, Event::ActionFailed { .. }))
        .count();
    let mut rules_kept = Vec::new();
    let mut rules_refused = Vec::new();
    if with_knowledge && trace.ending.is_ok() {
        for (action, condition, author) in kept_conditions(&trace.kept) {
            let (rule, refused) = rule_for_fix(action, condition, scenario, knowledge);
            for (rule, why) in refused {
                rules_refused.push(format!("{}: {why}", rule.describe(&scenario.domain)));
            }
            let Some(rule) = rule else {
                continue;
            };
            let (kept, _) = knowledge
                .keep(KeptRule::new(
                    &rule,
                    scenario,
                    Provenance {
                        scenario_file: path.to_string(),
                        action,
                        condition,
                        proposed_by: author.to_string(),
                        kept_by: "betr eval resolve --sequence (every fix kept)".into(),
                    },
                ))
                .map_err(|e| {
                    EvalError::io(&knowledge.path, std::io::Error::other(e.to_string()))
                })?;
            rules_kept.push(format!("{} {}", kept.id, rule.describe(&scenario.domain)));
        }
    }
    Ok(SequenceStep {
        scenario: path.to_string(),
        name: scenario.name.clone(),
        with_knowledge,
        success: trace.ending.is_ok(),
        ticks: trace.ending.as_ref().ok().copied(),
        calls: tap.calls().len(),
        world_failures,
        rules_applied,
        rules_kept,
        rules_refused,
        wall_ms: elapsed_ms(start),
    })
}

impl SequenceResults {
    fn step(&self, scenario: &str, with_knowledge: bool) -> Option<&SequenceStep> {
        self.steps
            .iter()
            .find(|s| s.scenario == scenario && s.with_knowledge == with_knowledge)
    }

    /// The side-by-side table (Markdown), one row per scenario, totals per part.
    pub fn table(&self, label: &str) -> String {
        let mut out = format!(
            "# Fixes that carry over: scenarios in sequence ({label})\n\n\
             | # | scenario | calls without | calls with | world failures without | world failures with | ticks without | ticks with | rules used | rules kept |\n\
             |---|---|---|---|---|---|---|---|---|---|\n"
        );
        let order: Vec<&str> = {
            let mut v: Vec<&str> = Vec::new();
            for s in &self.steps {
                if !v.contains(&s.scenario.as_str()) {
                    v.push(&s.scenario);
                }
            }
            v
        };
        let mut totals = [[0usize; 4]; 2];
        for (i, scenario) in order.iter().enumerate() {
            let part = usize::from(i >= self.failure_steps);
            let without = self.step(scenario, false);
            let with = self.step(scenario, true);
            let name = with.or(without).map_or("", |s| s.name.as_str());
            let cell = |s: Option<&SequenceStep>, f: &dyn Fn(&SequenceStep) -> String| {
                s.map_or_else(|| "–".into(), f)
            };
            let ticks = |s: &SequenceStep| {
                if s.success {
                    s.ticks.map_or_else(|| "–".into(), |t| t.to_string())
                } else {
                    "failed".into()
                }
            };
            for (k, s) in [without, with].into_iter().enumerate() {
                if let Some(s) = s {
                    totals[part][k] += s.calls;
                    totals[part][2 + k] += s.world_failures;
                }
            }
            out.push_str(&format!(
                "| {} | {name} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                i + 1,
                cell(without, &|s| s.calls.to_string()),
                cell(with, &|s| s.calls.to_string()),
                cell(without, &|s| s.world_failures.to_string()),
                cell(with, &|s| s.world_failures.to_string()),
                cell(without, &ticks),
                cell(with, &ticks),
                cell(with, &|s| if s.rules_applied.is_empty() {
                    "–".into()
                } else {
                    s.rules_applied.join(", ")
                }),
                cell(with, &|s| if s.rules_kept.is_empty() {
                    "–".into()
                } else {
                    s.rules_kept
                        .iter()
                        .filter_map(|r| r.split(' ').next())
                        .collect::<Vec<_>>()
                        .join(", ")
                }),
            ));
        }
        let names = ["the failure scenarios", "the new tasks"];
        out.push('\n');
        for (part, name) in names.iter().enumerate() {
            let [cw, ck, fw, fk] = totals[part];
            out.push_str(&format!(
                "- {name}: {cw} calls and {fw} failures in the world without kept knowledge, {ck} calls and {fk} failures with it\n"
            ));
        }
        if !self.rules.is_empty() {
            out.push_str("\nRules kept along the way:\n");
            for r in &self.rules {
                let words = match &r.only {
                    Some(only) => format!("{} (only for {})", r.requires, only.join(", ")),
                    None => r.requires.clone(),
                };
                out.push_str(&format!(
                    "- {}: {} needs {words} (from {})\n",
                    r.id, r.skill, r.scenario
                ));
            }
        }
        let refused: Vec<&String> = self.steps.iter().flat_map(|s| &s.rules_refused).collect();
        if !refused.is_empty() {
            out.push_str("\nOffered and refused:\n");
            for r in refused {
                out.push_str(&format!("- {r}\n"));
            }
        }
        out
    }
}
