//! The goal-interpretation experiment with a model: one call per instruction, no
//! feedback; the reply's goal is scored by the dataset rule exactly as a recorded answer
//! would be (no name is corrected, so an atom outside the vocabulary stays wrong).

use std::path::Path;

use crate::dataset::{Case, Difficulty};
use crate::domain::{Condition, Scenario};
use crate::goal::Formula;
use crate::llm::prompt::{self, Context, Templates, Variant};
use crate::llm::reply::{self, extract};
use std::sync::Arc;

use crate::llm::{LanguageModel, OutputConstraint, grammar, schema};

use super::EvalError;
use super::goals::{CaseResult, GoalsResults, Tally, score};
use super::run::{Journal, RunConfig, Tap, UsageSummary, drive};

/// How the goal prompt is written and sent.
#[derive(Debug, Clone)]
pub struct PromptSettings {
    pub templates: Templates,
    pub variant: Variant,
    pub temperature: f32,
    pub max_tokens: u32,
    /// Constrain replies with the vocabulary's JSON schema when the model supports it.
    pub structured: bool,
    /// Constrain replies with a grammar from the vocabulary when the model supports it.
    pub grammar: bool,
}

/// The answer a reply gives: the text after its last `Goal:` label that parses (else the
/// last one), a JSON reply's goal, or a reply that is a single line. `None`: no answer.
pub fn answer_of(text: &str, scenario: &Scenario) -> Option<String> {
    let lines = extract::lines(text);
    let labelled = extract::labelled(&lines, &["goal", "final goal"]);
    if let Some((_, last)) = labelled.last() {
        let parsing = labelled
            .iter()
            .rev()
            .map(|(_, a)| extract::strip_ticks(a).trim())
            .find(|a| Formula::parse(a).is_ok());
        return Some(
            parsing
                .unwrap_or(extract::strip_ticks(last).trim())
                .to_string(),
        );
    }
    if text.trim_start().starts_with('{') {
        // A structured reply: read its goal without correcting any name.
        return Some(
            match reply::goal(text, &scenario.domain.vocabulary, f64::INFINITY) {
                Ok(a) => a.goal.to_string(),
                Err(_) => text.trim().to_string(),
            },
        );
    }
    let t = text.trim();
    (!t.is_empty()).then(|| t.to_string())
}

/// Ask for every case of every run that `dir`'s journal does not hold yet, score each as
/// it comes back, and return the results over all recorded cases of runs 1..=runs.
pub async fn run_goals(
    model: &Arc<dyn LanguageModel>,
    scenario: &Scenario,
    facts: &[Condition],
    cases: &[Case],
    settings: &PromptSettings,
    cfg: &RunConfig<'_>,
    dir: &Path,
) -> Result<GoalsResults, EvalError> {
    let journal = Journal::new(dir);
    let recorded: Vec<CaseResult> = journal.read()?;
    let key = |run: usize, difficulty: &str, index: usize| format!("{run}/{difficulty}/{index}");
    let have: std::collections::HashSet<String> = recorded
        .iter()
        .map(|c| key(c.run, &c.difficulty, c.index))
        .collect();
    let jobs: Vec<(usize, &Case)> = (1..=cfg.runs)
        .flat_map(|run| cases.iter().map(move |c| (run, c)))
        .filter(|(run, c)| !have.contains(&key(*run, c.difficulty.as_str(), c.index)))
        .collect();
    let done = cfg.runs * cases.len() - jobs.len();
    drive(
        jobs,
        done,
        cfg,
        &journal,
        |c: &CaseResult| format!("run {} {} #{}", c.run, c.difficulty, c.index + 1),
        |(run, case)| ask_one(model, scenario, facts, case, run, settings, cfg),
    )
    .await?;
    Ok(collect(journal.read()?, cases, cfg.runs))
}

async fn ask_one(
    model: &Arc<dyn LanguageModel>,
    scenario: &Scenario,
    facts: &[Condition],
    case: &Case,
    run: usize,
    settings: &PromptSettings,
    cfg: &RunConfig<'_>,
) -> Result<CaseResult, EvalError> {
    let ctx = Context {
        scenario,
        facts,
        instruction: &case.instruction,
        variant: &settings.variant,
    };
    let mut request = prompt::request(
        ctx.goal(&settings.templates)?,
        settings.temperature,
        settings.max_tokens,
    );
    // The same constraint the session would use: a grammar for the local model, a JSON
    // schema for servers that take one.
    if settings.grammar && model.supports_grammar() {
        request.constraint = Some(OutputConstraint::Grammar {
            name: "goal".into(),
            gbnf: grammar::goal_grammar(
                &scenario.domain.vocabulary,
                true,
                settings.variant.chain_of_thought,
            ),
        });
    } else if settings.structured && model.supports_constraint() {
        request.constraint = Some(schema::goal(&scenario.domain.vocabulary));
    }
    let tap = Tap::new(model.clone(), Some(run as u64), &cfg.prices);
    let reply = tap.chat(&request).await.map_err(|source| EvalError::Llm {
        case: format!(
            "run {run}, {} case {}",
            case.difficulty.as_str(),
            case.index + 1
        ),
        source,
    })?;
    let answer = answer_of(&reply.text, scenario);
    let mut result = score(&scenario.domain.vocabulary, case, answer.as_deref());
    result.run = run;
    result.reply = Some(reply.text);
    result.call = tap.calls().pop();
    Ok(result)
}

/// The recorded cases of runs 1..=runs, in dataset order within each run.
fn collect(recorded: Vec<CaseResult>, cases: &[Case], runs: usize) -> GoalsResults {
    let order = |c: &CaseResult| {
        let d = Difficulty::ALL
            .iter()
            .position(|d| d.as_str() == c.difficulty)
            .unwrap_or(usize::MAX);
        (c.run, d, c.index)
    };
    let mut kept: Vec<CaseResult> = Vec::new();
    for c in recorded {
        let known = cases
            .iter()
            .any(|k| k.difficulty.as_str() == c.difficulty && k.index == c.index);
        if c.run >= 1 && c.run <= runs && known && !kept.iter().any(|k| order(k) == order(&c)) {
            kept.push(c);
        }
    }
    kept.sort_by_key(order);
    GoalsResults::from_cases(kept)
}

/// The table with model columns: accuracy per difficulty and overall, then calls,
/// tokens, cost and latency; one row per run when there are several, then all runs.
pub fn table(results: &GoalsResults, system: &str, temperature: f32, expected: usize) -> String {
    let cell = |t: &Tally| format!("{:.1}% ({}/{})", t.percent(), t.correct, t.total);
    let usage = |u: &UsageSummary| {
        format!(
            "{} | {} | {} | ${:.4} | {:.2} s | {:.2} s",
            u.calls,
            u.prompt_tokens,
            u.completion_tokens,
            u.price_usd,
            u.latency_median_ms / 1000.0,
            u.latency_p95_ms / 1000.0
        )
    };
    let mut out = String::from(
        "| system | easy | medium | hard | overall | calls | prompt tokens | completion tokens | cost | latency median | latency p95 |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &results.runs {
        let cases: Vec<&super::run::CallRecord> = results
            .cases
            .iter()
            .filter(|c| c.run == r.run)
            .filter_map(|c| c.call.as_ref())
            .collect();
        let overall = Tally {
            correct: r.easy.correct + r.medium.correct + r.hard.correct,
            total: r.easy.total + r.medium.total + r.hard.total,
        };
        out.push_str(&format!(
            "| {system}, run {} | {} | {} | {} | {} | {} |\n",
            r.run,
            cell(&r.easy),
            cell(&r.medium),
            cell(&r.hard),
            cell(&overall),
            usage(&UsageSummary::of(cases))
        ));
    }
    let label = if results.runs.is_empty() {
        system.to_string()
    } else {
        format!("{system}, all {} runs", results.runs.len())
    };
    out.push_str(&format!(
        "| {label} | {} | {} | {} | {} | {} |\n",
        cell(&results.easy),
        cell(&results.medium),
        cell(&results.hard),
        cell(&results.overall()),
        usage(&results.usage.clone().unwrap_or_default())
    ));
    let mut notes = Vec::new();
    let finished = results.cases.len();
    if finished < expected {
        notes.push(format!(
            "Partial: {finished} of {expected} cases finished; run the same command again to finish."
        ));
    }
    notes.push(if temperature == 0.0 {
        "Temperature 0: repeated runs send the same prompt (seed = run number) and are expected to give the same answers.".to_string()
    } else {
        format!("Temperature {temperature}; run k sends seed k.")
    });
    if let Some(u) = &results.usage {
        notes.extend(u.notes());
    }
    out.push('\n');
    for n in notes {
        out.push_str(&format!("- {n}\n"));
    }
    out
}
