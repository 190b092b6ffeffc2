//! The failure-resolution experiment: each of the ten failure scenarios resolved N times
//! end to end in simulation (interpret, plan, fail, ask, validate, repair, re-run), every
//! proposal approved. A proposal counts as correct only if it was kept (it removed the
//! failure it was asked about) and the final tree, which contains it, succeeds in the
//! simulated world.

use std::collections::HashSet;
use std::path::Path;
use std::time::Instant;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::domain::Condition;
use crate::scenario::Scenario;
use std::sync::Arc;

use crate::llm::LanguageModel;
use crate::session::{Event, Options, Proposal};

use super::EvalError;
use super::run::{
    CallRecord, Journal, RunConfig, Tap, UsageSummary, drive, elapsed_ms, mean_sd, percentile,
};
use super::session_run::{Trace, resolve_approving};

/// The ten failure scenarios of SCENARIOS.md, in its order (paths under `scenarios/`).
pub const FAILURE_SCENARIOS: [&str; 10] = [
    "cell/red_on_blue.toml",
    "cell/blocked_both.toml",
    "cell/flip_cup.toml",
    "cell/centrifuge.toml",
    "cell/cupboard.toml",
    "cell/banana_unknown.toml",
    "cell/banana_far.toml",
    "cafe/no_coffee.toml",
    "cafe/find_fries.toml",
    "cafe/sweep.toml",
];

/// One proposal of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProposalRecord {
    pub proposal: String,
    /// The change removed the failure it was asked about (else it was undone).
    pub kept: bool,
    /// Kept, and the final tree succeeded in simulation.
    pub correct: bool,
    /// Why it was undone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// One run of one scenario (a line of `cases.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResolveCase {
    pub scenario: String,
    pub name: String,
    pub run: usize,
    pub success: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ticks: Option<u64>,
    /// Why the run did not succeed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goal: Option<String>,
    /// The interpreted goal equals the scenario's (as formulas).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goal_as_expected: Option<bool>,
    pub rounds: usize,
    /// An action failed in simulation (the failure under study was reached).
    #[serde(default)]
    pub failure_reached: bool,
    /// Resolved: the goal is the scenario's, a failure was reached, the kept changes hold
    /// every condition the scenario names as its fix, and the final tree succeeded.
    #[serde(default)]
    pub resolved: bool,
    /// The model's first candidate (before any check in simulation) holds a condition
    /// the scenario names as its fix.
    #[serde(default)]
    pub first_candidate_right: bool,
    pub proposals: Vec<ProposalRecord>,
    /// Candidates the model wrote that were tried in simulation and set aside.
    #[serde(default)]
    pub screened_out: usize,
    /// Replies that could not be used (no valid answer in them).
    pub unusable_replies: usize,
    pub calls: Vec<CallRecord>,
    pub wall_ms: f64,
}

/// Per scenario, over its runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioSummary {
    pub scenario: String,
    pub name: String,
    pub runs: usize,
    pub successes: usize,
    pub success_rate: f64,
    /// Runs whose goal was not the scenario's (never counted as resolved).
    #[serde(default)]
    pub misread_goals: usize,
    #[serde(default)]
    pub resolved: usize,
    #[serde(default)]
    pub first_candidate_right: usize,
    pub proposals: usize,
    pub wrong_proposals: usize,
    pub unusable_replies: usize,
    pub calls_mean: f64,
    /// Mean ticks of the successful runs.
    pub ticks_mean: Option<f64>,
    pub time_median_ms: f64,
}

/// `results.json` of `betr eval resolve`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResolveResults {
    pub scenarios: Vec<ScenarioSummary>,
    pub usage: UsageSummary,
    pub cases: Vec<ResolveCase>,
}

/// One setting of `betr eval resolve --three-settings`: its name, its results, and whether
/// it performs only the cell scenarios' actions elsewhere (its other rows are left out).
pub struct Setting {
    pub name: String,
    pub results: ResolveResults,
    pub cell_only: bool,
}

/// The settings side by side, a row per scenario: resolved of the runs, and how many
/// runs' first candidate was right; a total row.
pub fn settings_table(settings: &[Setting]) -> String {
    let mut out = String::from("| # | scenario |");
    for s in settings {
        out.push_str(&format!(" {} |", s.name));
    }
    out.push_str("\n|---|---|");
    out.push_str(&"---|".repeat(settings.len()));
    out.push('\n');
    let rows = settings.first().map_or(0, |s| s.results.scenarios.len());
    let mut totals = vec![(0, 0); settings.len()];
    for i in 0..rows {
        let first = &settings[0].results.scenarios[i];
        out.push_str(&format!("| {} | {} |", i + 1, first.name));
        for (s, total) in settings.iter().zip(totals.iter_mut()) {
            let row = s
                .results
                .scenarios
                .iter()
                .find(|r| r.scenario == first.scenario);
            match row {
                Some(r) if !s.cell_only || r.scenario.starts_with("cell/") => {
                    out.push_str(&format!(
                        " {}/{} (first right {}) |",
                        r.resolved, r.runs, r.first_candidate_right
                    ));
                    total.0 += r.resolved;
                    total.1 += r.runs;
                }
                _ => out.push_str(" — |"),
            }
        }
        out.push('\n');
    }
    out.push_str("| | all |");
    for (resolved, runs) in totals {
        out.push_str(&format!(" {resolved}/{runs} |"));
    }
    out.push('\n');
    out
}

/// Run every (scenario, run) pair the journal in `dir` does not hold yet through the
/// session with `make`, and return every recorded case of runs 1..=runs, by scenario then run.
pub(crate) async fn run_sessions<T>(
    model: &Arc<dyn LanguageModel>,
    scenarios: &[(String, Scenario)],
    options: &Options,
    cfg: &RunConfig<'_>,
    dir: &Path,
    key: impl Fn(&T) -> (String, usize),
    make: impl Fn(&str, &Scenario, usize, Trace, Vec<CallRecord>, f64) -> T,
) -> Result<Vec<T>, EvalError>
where
    T: Serialize + DeserializeOwned,
{
    let journal = Journal::new(dir);
    let have: HashSet<(String, usize)> = journal.read::<T>()?.iter().map(&key).collect();
    let jobs: Vec<(usize, &(String, Scenario))> = (1..=cfg.runs)
        .flat_map(|run| scenarios.iter().map(move |s| (run, s)))
        .filter(|(run, (path, _))| !have.contains(&(path.clone(), *run)))
        .collect();
    let done = cfg.runs * scenarios.len() - jobs.len();
    let label = |t: &T| {
        let (s, r) = key(t);
        format!("{s} run {r}")
    };
    let make = &make;
    drive(
        jobs,
        done,
        cfg,
        &journal,
        label,
        |(run, (path, scenario))| async move {
            let tap = Arc::new(Tap::new(model.clone(), Some(run as u64), &cfg.prices));
            let start = Instant::now();
            let executor = match cfg.executor {
                Some(start) if scenario.world_kind == "cell" => {
                    Some(start().map_err(|e| EvalError::Session {
                        case: format!("{path}, run {run}"),
                        source: e.into(),
                    })?)
                }
                _ => None,
            };
            let trace = resolve_approving(scenario, tap.clone(), options, executor)
                .await
                .map_err(|source| EvalError::Session {
                    case: format!("{path}, run {run}"),
                    source,
                })?;
            Ok(make(
                path,
                scenario,
                run,
                trace,
                tap.calls(),
                elapsed_ms(start),
            ))
        },
    )
    .await?;
    let mut all: Vec<T> = Vec::new();
    let mut seen = HashSet::new();
    for t in journal.read::<T>()? {
        let (s, r) = key(&t);
        if r >= 1 && r <= cfg.runs && scenarios.iter().any(|(p, _)| *p == s) && seen.insert((s, r))
        {
            all.push(t);
        }
    }
    let order = |t: &T| {
        let (s, r) = key(t);
        (scenarios.iter().position(|(p, _)| *p == s), r)
    };
    all.sort_by_key(order);
    Ok(all)
}

pub async fn run_resolve(
    model: &Arc<dyn LanguageModel>,
    scenarios: &[(String, Scenario)],
    options: &Options,
    cfg: &RunConfig<'_>,
    dir: &Path,
) -> Result<ResolveResults, EvalError> {
    let key = |c: &ResolveCase| (c.scenario.clone(), c.run);
    let cases = run_sessions(model, scenarios, options, cfg, dir, key, record).await?;
    Ok(summarize(scenarios, cases))
}

fn record(
    path: &str,
    scenario: &Scenario,
    run: usize,
    trace: Trace,
    calls: Vec<CallRecord>,
    wall_ms: f64,
) -> ResolveCase {
    let success = trace.ending.is_ok();
    let fixes: Vec<Condition> = scenario
        .expected_fix
        .iter()
        .filter_map(|f| scenario.parse_goal(f).ok())
        .flat_map(|f| f.to_dnf().0.into_iter().flatten())
        .collect();
    let holds_fix = |p: &Proposal| match p {
        Proposal::Conditions { conditions, .. } => conditions.iter().any(|c| fixes.contains(c)),
        Proposal::Value { .. } => false,
    };
    let mut seen = Seen::default();
    for e in &trace.events {
        seen.take(e, success);
    }
    let resolved = success
        && seen.goal_as_expected == Some(true)
        && seen.failure_reached
        && !fixes.is_empty()
        && fixes.iter().all(|f| seen.kept_conditions.contains(f));
    ResolveCase {
        scenario: path.to_string(),
        name: scenario.name.clone(),
        run,
        success,
        ticks: trace.ending.as_ref().ok().copied(),
        reason: trace.ending.err().map(|e| e.to_string()),
        goal: seen.goal,
        goal_as_expected: seen.goal_as_expected,
        rounds: trace.rounds,
        failure_reached: seen.failure_reached,
        resolved,
        first_candidate_right: seen.first_candidate.as_ref().is_some_and(holds_fix),
        proposals: seen.proposals,
        screened_out: seen.screened_out,
        unusable_replies: seen.unusable,
        calls,
        wall_ms,
    }
}

/// What a run's events say about its goal and the proposals it was offered.
#[derive(Default)]
struct Seen {
    proposals: Vec<ProposalRecord>,
    goal: Option<String>,
    goal_as_expected: Option<bool>,
    unusable: usize,
    failure_reached: bool,
    screened_out: usize,
    first_candidate: Option<Proposal>,
    kept_conditions: Vec<Condition>,
    /// How many kept conditions there were before the last kept change, so a change that
    /// fails verification afterwards (and is rejected) is taken out again.
    kept_before_last: usize,
    pending: Option<Proposal>,
}

impl Seen {
    /// Take in one event of a run that ended in `success` or not.
    fn take(&mut self, e: &Event, success: bool) {
        match e {
            Event::ActionFailed { .. } => self.failure_reached = true,
            Event::CandidateRejected {
                proposal: Some(p), ..
            } => {
                self.screened_out += 1;
                self.first_candidate.get_or_insert_with(|| p.clone());
            }
            Event::Goal {
                goal,
                matches_expected,
                ..
            } => {
                self.goal = Some(goal.to_string());
                self.goal_as_expected = *matches_expected;
            }
            Event::InvalidReply { .. } => self.unusable += 1,
            Event::Proposal { proposal, .. } => {
                self.first_candidate.get_or_insert_with(|| proposal.clone());
                self.pending = Some(proposal.clone());
                self.proposals.push(ProposalRecord {
                    proposal: proposal.to_string(),
                    kept: false,
                    correct: false,
                    note: None,
                });
            }
            Event::Repaired { .. } => {
                if let Some(p) = self.proposals.last_mut() {
                    p.kept = true;
                    p.correct = success;
                }
                self.kept_before_last = self.kept_conditions.len();
                if let Some(Proposal::Conditions { conditions, .. }) = self.pending.take() {
                    self.kept_conditions.extend(conditions);
                }
            }
            Event::ChangeViolates { .. } => {
                if let Some(p) = self.proposals.last_mut() {
                    p.kept = false;
                    p.correct = false;
                }
                self.kept_conditions.truncate(self.kept_before_last);
            }
            Event::DidNotHelp { reason } => {
                if let Some(p) = self.proposals.last_mut() {
                    p.note = Some(reason.clone());
                }
            }
            _ => {}
        }
    }
}

fn summarize(scenarios: &[(String, Scenario)], cases: Vec<ResolveCase>) -> ResolveResults {
    let summaries = scenarios
        .iter()
        .map(|(path, scenario)| {
            let runs: Vec<&ResolveCase> = cases.iter().filter(|c| c.scenario == *path).collect();
            let successes = runs.iter().filter(|c| c.success).count();
            let proposals: usize = runs.iter().map(|c| c.proposals.len()).sum();
            let correct: usize = runs
                .iter()
                .map(|c| c.proposals.iter().filter(|p| p.correct).count())
                .sum();
            let ticks: Vec<f64> = runs
                .iter()
                .filter_map(|c| c.ticks)
                .map(|t| t as f64)
                .collect();
            let calls: Vec<f64> = runs.iter().map(|c| c.calls.len() as f64).collect();
            let times: Vec<f64> = runs.iter().map(|c| c.wall_ms).collect();
            ScenarioSummary {
                scenario: path.clone(),
                name: scenario.name.clone(),
                runs: runs.len(),
                successes,
                misread_goals: runs
                    .iter()
                    .filter(|c| c.goal_as_expected != Some(true))
                    .count(),
                resolved: runs.iter().filter(|c| c.resolved).count(),
                first_candidate_right: runs.iter().filter(|c| c.first_candidate_right).count(),
                success_rate: if runs.is_empty() {
                    0.0
                } else {
                    100.0 * successes as f64 / runs.len() as f64
                },
                proposals,
                wrong_proposals: proposals - correct,
                unusable_replies: runs.iter().map(|c| c.unusable_replies).sum(),
                calls_mean: mean_sd(&calls).map_or(0.0, |m| m.0),
                ticks_mean: mean_sd(&ticks).map(|m| m.0),
                time_median_ms: percentile(&times, 50.0),
            }
        })
        .collect();
    let usage = UsageSummary::of(cases.iter().flat_map(|c| &c.calls));
    ResolveResults {
        scenarios: summaries,
        usage,
        cases,
    }
}

impl ResolveResults {
    /// One row per scenario: success rate, proposals and the wrong ones, unusable
    /// replies, LLM calls, ticks and time.
    pub fn table(&self, system: &str, expected_runs: usize) -> String {
        let mut out = format!(
            "Failure resolution, {system}\n\n| # | scenario | resolved | first candidate right | misread goal | tree succeeded | proposals | wrong proposals | unusable replies | LLM calls per run | ticks | time per run |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n"
        );
        for (i, s) in self.scenarios.iter().enumerate() {
            out.push_str(&format!(
                "| {} | {} | {}/{} | {}/{} | {} | {:.0}% ({}/{}) | {} | {} | {} | {:.1} | {} | {:.2} s |\n",
                i + 1,
                s.name,
                s.resolved,
                s.runs,
                s.first_candidate_right,
                s.runs,
                s.misread_goals,
                s.success_rate,
                s.successes,
                s.runs,
                s.proposals,
                s.wrong_proposals,
                s.unusable_replies,
                s.calls_mean,
                s.ticks_mean.map_or("—".into(), |t| format!("{t:.0}")),
                s.time_median_ms / 1000.0
            ));
        }
        let finished: usize = self.scenarios.iter().map(|s| s.runs).sum();
        out.push_str(&super::run::table_footer(
            &self.usage,
            "- Resolved: the goal was the scenario's, the failure was reached, the kept changes hold the condition(s) the scenario names as its fix, and the final tree succeeded. A misread goal is never resolved, even when its tree succeeds (\"tree succeeded\"). First candidate right: the model's first answer, before any check in simulation, holds the fix. A proposal is correct only if it was kept and the final tree succeeded; ticks are of successful runs; time is the median wall time per run.\n",
            finished,
            expected_runs * self.scenarios.len(),
        ));
        out
    }

    /// Every run as CSV.
    pub fn csv(&self) -> String {
        let q = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
        let mut out = String::from(
            "scenario,run,success,rounds,proposals,wrong_proposals,unusable_replies,calls,prompt_tokens,completion_tokens,ticks,wall_ms,goal,proposal_list,reason\n",
        );
        for c in &self.cases {
            let u = UsageSummary::of(&c.calls);
            let list: Vec<String> = c
                .proposals
                .iter()
                .map(|p| format!("{}{}", p.proposal, if p.correct { "" } else { " [wrong]" }))
                .collect();
            out.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{},{:.0},{},{},{}\n",
                q(&c.scenario),
                c.run,
                c.success,
                c.rounds,
                c.proposals.len(),
                c.proposals.iter().filter(|p| !p.correct).count(),
                c.unusable_replies,
                u.calls,
                u.prompt_tokens,
                u.completion_tokens,
                c.ticks.map(|t| t.to_string()).unwrap_or_default(),
                c.wall_ms,
                q(c.goal.as_deref().unwrap_or("")),
                q(&list.join("; ")),
                q(c.reason.as_deref().unwrap_or(""))
            ));
        }
        out
    }
}
