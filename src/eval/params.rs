//! The missing-parameter experiment: each of the seven parameter scenarios resolved N
//! times; every value the model proposes is recorded with the world's verdict. A value is
//! accepted when, after it was set, the action that needed it no longer fails (the
//! simulator judges it: an egg squeezed too hard breaks, a brush cannot scoop sand). A
//! rejected value followed by a corrected one counts both, the first marked rejected.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::domain::Value;
use crate::scenario::Scenario;
use std::sync::Arc;

use crate::llm::LanguageModel;
use crate::session::repair::ask::{MIDWAY, NOT_TRIED};
use crate::session::{Event, Options, Proposal};

use super::EvalError;
use super::resolve::run_sessions;
use super::run::{CallRecord, RunConfig, UsageSummary, mean_sd};
use super::session_run::Trace;

/// The seven parameter scenarios of SCENARIOS.md (paths under `scenarios/`) with the
/// value the paper's GPT-4 proposed (mean of 10 runs), for comparison.
pub const PARAM_SCENARIOS: [(&str, &str); 7] = [
    ("cell/params/egg.toml", "5.3 N"),
    ("cell/params/hammer.toml", "37.2 N"),
    ("cell/params/pillow.toml", "0.6 m/s"),
    ("cell/params/first_aid.toml", "1.5 m/s"),
    ("cell/params/baby.toml", "0.1 m/s"),
    ("cell/params/sand.toml", "shovel"),
    ("cell/params/plate.toml", "sponge or brush"),
];

/// The parameter scenarios under `dir` (paths relative to it): those of
/// [`PARAM_SCENARIOS`] that `dir/cell/params/` holds, in that order, then every other
/// `*.toml` there by name, so a directory of other parameter scenarios (such as those
/// held out from choosing a method) runs the same way. Empty when there are none.
pub fn param_scenarios(dir: &Path) -> std::io::Result<Vec<String>> {
    let folder = dir.join("cell/params");
    let mut others: Vec<String> = std::fs::read_dir(&folder)?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".toml"))
        .map(|name| format!("cell/params/{name}"))
        .filter(|p| !PARAM_SCENARIOS.iter().any(|(known, _)| known == p))
        .collect();
    others.sort();
    let mut paths: Vec<String> = PARAM_SCENARIOS
        .iter()
        .map(|(p, _)| (*p).to_string())
        .filter(|p| dir.join(p).is_file())
        .collect();
    paths.extend(others);
    Ok(paths)
}

/// One proposed value and the world's verdict.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValueRecord {
    /// As written (`5.3 N`, `shovel`).
    pub value: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub number: Option<f64>,
    pub accepted: bool,
    /// Tried in simulation before it was offered, and set aside there.
    #[serde(default)]
    pub screened: bool,
    /// What the world reported when it rejected the value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Who proposed the value when it was not the model (betr's midway value).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub by: Option<String>,
    /// Turned away without a try: beyond what the world had refused, or refused before.
    #[serde(default)]
    pub not_tried: bool,
}

/// One run of one parameter scenario (a line of `cases.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamsCase {
    pub scenario: String,
    pub name: String,
    pub run: usize,
    pub success: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The goal the run worked on was the scenario's.
    #[serde(default)]
    pub goal_as_expected: bool,
    /// The goal was the scenario's, a value was accepted by the world, and the tree
    /// succeeded.
    #[serde(default)]
    pub resolved: bool,
    pub values: Vec<ValueRecord>,
    /// Proposals of conditions instead of a value.
    pub other_proposals: usize,
    pub unusable_replies: usize,
    pub calls: Vec<CallRecord>,
    pub wall_ms: f64,
}

/// What the world accepts for the scenario's parameter (from `[[world.values]]`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    pub skill: String,
    pub parameter: String,
    pub unit: Option<String>,
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// Categories the world accepts (categorical parameters).
    pub allowed: Option<Vec<String>>,
    /// Categories a proposal may name.
    pub categories: Vec<String>,
}

impl Limits {
    pub fn text(&self) -> String {
        let unit = self.unit.as_deref().unwrap_or("");
        match (&self.allowed, self.min, self.max) {
            (Some(a), _, _) => a.join(", "),
            (None, Some(lo), Some(hi)) => format!("{lo}–{hi} {unit}"),
            (None, Some(lo), None) => format!("≥ {lo} {unit}"),
            (None, None, Some(hi)) => format!("≤ {hi} {unit}"),
            (None, None, None) => "any".into(),
        }
    }
}

/// Per scenario, over its runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamSummary {
    pub scenario: String,
    pub name: String,
    pub limits: Limits,
    pub runs: usize,
    /// Each run's first proposal.
    pub first_values: Vec<String>,
    /// Mean and sample standard deviation of the first numeric proposals.
    pub mean: Option<f64>,
    pub sd: Option<f64>,
    pub first_accepted: usize,
    /// Runs in which one of the first three values tried (in simulation or in the world)
    /// was accepted.
    #[serde(default)]
    pub accepted_within_three: usize,
    pub values_proposed: usize,
    pub values_accepted: usize,
    pub successes: usize,
    #[serde(default)]
    pub resolved: usize,
    #[serde(default)]
    pub misread_goals: usize,
    /// The paper's GPT-4 (mean of 10 runs).
    pub paper: String,
}

/// `results.json` of `betr eval params`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamsResults {
    pub scenarios: Vec<ParamSummary>,
    pub usage: UsageSummary,
    pub cases: Vec<ParamsCase>,
}

/// The scenario's value parameter and the world's limits on it.
pub fn limits(scenario: &Scenario) -> Result<Limits, EvalError> {
    let Some((skill, param)) = scenario
        .domain
        .skills
        .iter()
        .find_map(|s| s.values.first().map(|v| (s, v)))
    else {
        return Ok(Limits::default());
    };
    let mut l = Limits {
        skill: skill.name.clone(),
        parameter: param.name.clone(),
        unit: param.unit.clone(),
        categories: param.categories.clone(),
        ..Limits::default()
    };
    if scenario.world_kind == "cell" {
        let scene = crate::world::cell::scene::read(scenario, None)?;
        if let Some(j) = scene
            .judges
            .iter()
            .find(|j| j.skill == skill.name && j.value == param.name)
        {
            l.min = j.min.as_ref().map(|m| m.0);
            l.max = j.max.as_ref().map(|m| m.0);
            l.allowed = j.allowed.as_ref().map(|a| a.0.clone());
        }
    }
    Ok(l)
}

pub async fn run_params(
    model: &Arc<dyn LanguageModel>,
    scenarios: &[(String, Scenario)],
    options: &Options,
    cfg: &RunConfig<'_>,
    dir: &Path,
) -> Result<ParamsResults, EvalError> {
    let key = |c: &ParamsCase| (c.scenario.clone(), c.run);
    let cases = run_sessions(model, scenarios, options, cfg, dir, key, record).await?;
    let mut summaries = Vec::new();
    for (path, scenario) in scenarios {
        let runs: Vec<&ParamsCase> = cases.iter().filter(|c| c.scenario == *path).collect();
        summaries.push(summarize(path, scenario, &runs)?);
    }
    Ok(ParamsResults {
        scenarios: summaries,
        usage: UsageSummary::of(cases.iter().flat_map(|c| &c.calls)),
        cases,
    })
}

fn record(
    path: &str,
    scenario: &Scenario,
    run: usize,
    trace: Trace,
    calls: Vec<CallRecord>,
    wall_ms: f64,
) -> ParamsCase {
    let mut values: Vec<ValueRecord> = Vec::new();
    let mut other = 0;
    let mut unusable = 0;
    // The (skill, object) of the value being judged, until the next outcome shows.
    let mut pending: Option<(String, String)> = None;
    let mut goal_as_expected = false;
    let number = |value: &Value| match value {
        Value::Number { value, .. } => Some(*value),
        Value::Category(_) => None,
    };
    let written = |value: &Value| match value {
        Value::Category(c) => c.clone(),
        v => v.to_string(),
    };
    for e in &trace.events {
        match e {
            Event::Goal {
                matches_expected, ..
            } => goal_as_expected = *matches_expected == Some(true),
            Event::InvalidReply { .. } => unusable += 1,
            // A value the model wrote that failed in simulation before it was offered.
            Event::CandidateRejected {
                proposal: Some(Proposal::Value { value, .. }),
                reason,
                author,
                ..
            } => values.push(ValueRecord {
                value: written(value),
                number: number(value),
                accepted: false,
                screened: true,
                error: Some(reason.clone()),
                by: author.clone(),
                not_tried: reason.starts_with(NOT_TRIED),
            }),
            Event::Proposal {
                proposal:
                    Proposal::Value {
                        skill,
                        object,
                        value,
                        ..
                    },
                author,
                ..
            } => {
                values.push(ValueRecord {
                    value: written(value),
                    number: number(value),
                    accepted: false,
                    screened: false,
                    error: None,
                    by: (author == MIDWAY).then(|| author.clone()),
                    not_tried: false,
                });
                pending = Some((skill.clone(), object.clone()));
            }
            Event::Proposal { .. } => other += 1,
            Event::DidNotHelp { reason } => {
                if pending.take().is_some()
                    && let Some(v) = values.last_mut()
                {
                    v.error = Some(reason.clone());
                }
            }
            Event::ActionFailed { action, error, .. } => {
                if let Some((skill, object)) = pending.take()
                    && let Some(v) = values.last_mut()
                {
                    let same = action.skill == skill && action.args.first() == Some(&object);
                    v.accepted = !same;
                    v.error = same.then(|| error.clone());
                }
            }
            Event::Success { .. } | Event::GaveUp { .. } => {
                if pending.take().is_some()
                    && let Some(v) = values.last_mut()
                {
                    v.accepted = true;
                }
            }
            _ => {}
        }
    }
    let success = trace.ending.is_ok();
    ParamsCase {
        scenario: path.to_string(),
        name: scenario.name.clone(),
        run,
        success,
        reason: trace.ending.err().map(|e| e.to_string()),
        goal_as_expected,
        resolved: success && goal_as_expected && values.iter().any(|v| v.accepted),
        values,
        other_proposals: other,
        unusable_replies: unusable,
        calls,
        wall_ms,
    }
}

fn summarize(
    path: &str,
    scenario: &Scenario,
    runs: &[&ParamsCase],
) -> Result<ParamSummary, EvalError> {
    let firsts: Vec<&ValueRecord> = runs.iter().filter_map(|c| c.values.first()).collect();
    let numbers: Vec<f64> = firsts.iter().filter_map(|v| v.number).collect();
    let stats = mean_sd(&numbers);
    let all = runs.iter().flat_map(|c| &c.values);
    Ok(ParamSummary {
        scenario: path.to_string(),
        name: scenario.name.clone(),
        limits: limits(scenario)?,
        runs: runs.len(),
        first_values: firsts.iter().map(|v| v.value.clone()).collect(),
        mean: stats.map(|s| s.0),
        sd: stats.map(|s| s.1),
        first_accepted: firsts.iter().filter(|v| v.accepted).count(),
        accepted_within_three: runs
            .iter()
            .filter(|c| {
                c.values
                    .iter()
                    .filter(|v| !v.not_tried)
                    .take(3)
                    .any(|v| v.accepted)
            })
            .count(),
        values_proposed: all.clone().count(),
        values_accepted: all.filter(|v| v.accepted).count(),
        successes: runs.iter().filter(|c| c.success).count(),
        resolved: runs.iter().filter(|c| c.resolved).count(),
        misread_goals: runs.iter().filter(|c| !c.goal_as_expected).count(),
        paper: PARAM_SCENARIOS
            .iter()
            .find(|(p, _)| *p == path)
            .map_or_else(String::new, |(_, v)| (*v).to_string()),
    })
}

impl ParamsResults {
    /// One row per scenario: the values of each run (rejected ones marked ✗, corrections
    /// after →), mean ± sd, the accepted range, how often the world accepted, success.
    pub fn table(&self, system: &str, expected_runs: usize) -> String {
        let mut out = format!(
            "Missing parameters, {system}\n\n| scenario | parameter | proposed (each run) | mean ± sd | world accepts | first value accepted | accepted within 3 values tried | all values accepted | resolved | misread goal | tree succeeded | paper (GPT-4) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n"
        );
        for s in &self.scenarios {
            let each: Vec<String> = self
                .cases
                .iter()
                .filter(|c| c.scenario == s.scenario)
                .map(|c| {
                    let v: Vec<String> = c
                        .values
                        .iter()
                        .map(|v| {
                            format!(
                                "{}{}{}",
                                v.value,
                                if v.by.is_some() { " (midway)" } else { "" },
                                match (v.accepted, v.not_tried) {
                                    (true, _) => "",
                                    (false, false) => " ✗",
                                    (false, true) => " ⊘",
                                }
                            )
                        })
                        .collect();
                    if v.is_empty() {
                        "—".into()
                    } else {
                        v.join(" → ")
                    }
                })
                .collect();
            let stat = match (s.mean, s.sd) {
                (Some(m), Some(sd)) => format!(
                    "{m:.2} ± {sd:.2} {}",
                    s.limits.unit.as_deref().unwrap_or("")
                ),
                _ => category_counts(&s.first_values),
            };
            out.push_str(&format!(
                "| {} | {} | {} | {} | {} | {}/{} | {}/{} | {}/{} | {}/{} | {} | {}/{} | {} |\n",
                s.name,
                s.limits.parameter,
                each.join(", "),
                stat.trim(),
                s.limits.text().trim(),
                s.first_accepted,
                s.runs,
                s.accepted_within_three,
                s.runs,
                s.values_accepted,
                s.values_proposed,
                s.resolved,
                s.runs,
                s.misread_goals,
                s.successes,
                s.runs,
                s.paper
            ));
        }
        let finished: usize = self.scenarios.iter().map(|s| s.runs).sum();
        out.push_str(&super::run::table_footer(
            &self.usage,
            "- mean ± sd over each run's first value (the model's first answer, before any check in simulation); ✗: the world rejected the value, in the check before it was offered or after it was set; ⊘: not tried, as it lay beyond what the world had already refused or the robot can do, or was refused before (it still counts among the values proposed); (midway): betr's value halfway between values refused on either side, after none of the model's helped. Accepted within 3 values tried: one of a run's first three values tried in simulation or the world was accepted. Resolved: the goal was the scenario's, a value was accepted and the tree succeeded; a misread goal is never resolved.\n",
            finished,
            expected_runs * self.scenarios.len(),
        ));
        out
    }

    /// Every proposed value as CSV (a run without proposals has one row with no value).
    pub fn csv(&self) -> String {
        let q = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
        let mut out = String::from(
            "scenario,run,proposal,value,number,accepted,error,success,calls,wall_ms\n",
        );
        for c in &self.cases {
            let row = |i: String, v: Option<&ValueRecord>| {
                format!(
                    "{},{},{i},{},{},{},{},{},{},{:.0}\n",
                    q(&c.scenario),
                    c.run,
                    q(v.map_or("", |v| v.value.as_str())),
                    v.and_then(|v| v.number)
                        .map(|n| n.to_string())
                        .unwrap_or_default(),
                    v.is_some_and(|v| v.accepted),
                    q(v.and_then(|v| v.error.as_deref()).unwrap_or("")),
                    c.success,
                    c.calls.len(),
                    c.wall_ms
                )
            };
            if c.values.is_empty() {
                out.push_str(&row(String::new(), None));
            }
            for (i, v) in c.values.iter().enumerate() {
                out.push_str(&row((i + 1).to_string(), Some(v)));
            }
        }
        out
    }
}

/// `shovel ×7, spoon ×3`, most frequent first.
fn category_counts(values: &[String]) -> String {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for v in values {
        match counts.iter_mut().find(|(c, _)| c == v) {
            Some((_, n)) => *n += 1,
            None => counts.push((v.clone(), 1)),
        }
    }
    counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let parts: Vec<String> = counts.iter().map(|(c, n)| format!("{c} ×{n}")).collect();
    if parts.is_empty() {
        "—".into()
    } else {
        parts.join(", ")
    }
}
