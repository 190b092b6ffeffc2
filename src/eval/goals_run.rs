//! The goal-interpretation experiment with a model: each instruction is read exactly as a
//! session reads it (examples chosen for the request, candidates checked, a vote, and
//! feedback when none passes; or one call with the checks off), and scored by the
//! dataset rule. No name is corrected, so an atom outside the vocabulary stays wrong.
//! Each case also records the first call's answer, so one run shows both the single-call
//! accuracy and what checking and feedback added.

use std::path::Path;
use std::sync::Arc;

use crate::dataset::{Case, Difficulty};
use crate::llm::LanguageModel;
use crate::scenario::{Example, ExampleSource, Scenario};
use crate::session::{self, Event, Options};
use crate::world::World;

use super::EvalError;
use super::goals::{CaseResult, GoalsResults, Tally, is_correct, score};
use super::run::{Journal, RunConfig, Tap, UsageSummary, drive, percentile};

/// Ask for every case of every run that `dir`'s journal does not hold yet, score each as
/// it comes back, and return the results over all recorded cases of runs 1..=runs.
/// `scenario`: the scene every instruction is given in (candidates are planned in copies).
pub async fn run_goals(
    model: &Arc<dyn LanguageModel>,
    scenario: &Scenario,
    cases: &[Case],
    options: &Options,
    cfg: &RunConfig<'_>,
    dir: &Path,
) -> Result<GoalsResults, EvalError> {
    let in_scene: Vec<SceneCase> = cases
        .iter()
        .map(|case| SceneCase {
            scenario,
            case: case.clone(),
            examples: None,
        })
        .collect();
    run_goals_in_scenes(model, &in_scene, options, cfg, dir).await
}

/// Which example pool the cases of a run read with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExamplePool {
    /// The scenario's own (the product's reading).
    Written,
    /// Only the pool betr makes from the domain for a scenario that writes none.
    Made,
    /// No pool at all (the examples made for each request from its own words stay).
    None,
}

impl ExamplePool {
    pub fn name(self) -> &'static str {
        match self {
            ExamplePool::Written => "written",
            ExamplePool::Made => "made",
            ExamplePool::None => "none",
        }
    }

    /// `cases` with this pool in place of their scene's (unchanged for `Written`).
    pub fn apply(self, cases: &mut [SceneCase<'_>]) {
        let mut made: Vec<(*const Scenario, Vec<Example>)> = Vec::new();
        for c in cases {
            c.examples = match self {
                ExamplePool::Written => continue,
                ExamplePool::None => Some(Vec::new()),
                ExamplePool::Made => {
                    let key: *const Scenario = c.scenario;
                    let pool = match made.iter().find(|(k, _)| *k == key) {
                        Some((_, pool)) => pool.clone(),
                        None => {
                            let pool = crate::session::interpret::made_pool::made_pool(
                                c.scenario,
                                crate::session::interpret::made_pool::MADE_POOL,
                            );
                            made.push((key, pool.clone()));
                            pool
                        }
                    };
                    Some(pool)
                }
            };
        }
    }
}

/// A case and the scene its instruction is given in.
pub struct SceneCase<'a> {
    pub scenario: &'a Scenario,
    pub case: Case,
    /// The example pool its prompt chooses from, when not the options' or the scene's.
    pub examples: Option<Vec<Example>>,
}

/// The cases of a second pass that learns from the first (`--learn`): each case's pool is
/// its own, else `pool` (when the run replaces the scene's), else its scene's, with every other case's
/// miss of `first` kept as a person would correct it, the instruction with its gold goal,
/// never the case's own. A correction is kept for the cases of the same domain whose scene
/// has every object its goal names.
pub fn with_corrections<'a>(
    cases: &[SceneCase<'a>],
    first: &GoalsResults,
    pool: Option<&[Example]>,
) -> Vec<SceneCase<'a>> {
    let misses: Vec<(&SceneCase, String)> = cases
        .iter()
        .filter(|c| {
            first.cases.iter().any(|r| {
                !r.correct && r.difficulty == c.case.difficulty.as_str() && r.index == c.case.index
            })
        })
        .map(|c| {
            let id = format!("{}#{}", c.case.difficulty.as_str(), c.case.index + 1);
            (c, id)
        })
        .collect();
    cases
        .iter()
        .map(|c| {
            let domain = crate::session::knowledge::domain_of(c.scenario);
            let base = c.examples.as_deref().or(pool);
            let mut examples: Vec<Example> = base.unwrap_or(&c.scenario.examples).to_vec();
            for (miss, id) in &misses {
                let own =
                    miss.case.difficulty == c.case.difficulty && miss.case.index == c.case.index;
                if own
                    || crate::session::knowledge::domain_of(miss.scenario) != domain
                    || c.scenario.parse_goal(&miss.case.gold).is_err()
                {
                    continue;
                }
                examples.push(Example {
                    instruction: miss.case.instruction.clone(),
                    goal: miss.case.gold.clone(),
                    source: ExampleSource::Kept(id.clone()),
                });
            }
            SceneCase {
                scenario: c.scenario,
                case: c.case.clone(),
                examples: Some(examples),
            }
        })
        .collect()
}

/// [`run_goals`] with each case in its own scene (a domain's scenario files, each with
/// its instruction and goal).
pub async fn run_goals_in_scenes(
    model: &Arc<dyn LanguageModel>,
    cases: &[SceneCase<'_>],
    options: &Options,
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
    let jobs: Vec<(usize, &SceneCase)> = (1..=cfg.runs)
        .flat_map(|run| cases.iter().map(move |c| (run, c)))
        .filter(|(run, c)| !have.contains(&key(*run, c.case.difficulty.as_str(), c.case.index)))
        .collect();
    let done = cfg.runs * cases.len() - jobs.len();
    // Names are never corrected: the dataset rule scores what the model wrote.
    let options = Options {
        min_similarity: f64::INFINITY,
        ..options.clone()
    };
    drive(
        jobs,
        done,
        cfg,
        &journal,
        |c: &CaseResult| format!("run {} {} #{}", c.run, c.difficulty, c.index + 1),
        |(run, c)| {
            let mut options = options.clone();
            if let Some(pool) = &c.examples {
                options.steps.prompt.examples = Some(pool.clone());
            }
            async move {
                // Each instruction is read against its scenario's first state.
                let world = crate::world::load(c.scenario)?;
                ask_one(model, c.scenario, world, &c.case, run, &options, cfg).await
            }
        },
    )
    .await?;
    let plain: Vec<Case> = cases.iter().map(|c| c.case.clone()).collect();
    Ok(collect(journal.read()?, &plain, cfg.runs))
}

async fn ask_one(
    model: &Arc<dyn LanguageModel>,
    scenario: &Scenario,
    world: Box<dyn World>,
    case: &Case,
    run: usize,
    options: &Options,
    cfg: &RunConfig<'_>,
) -> Result<CaseResult, EvalError> {
    let tap = Tap::new(model.clone(), Some(run as u64), &cfg.prices);
    let mut replies: Vec<String> = Vec::new();
    let mut emit = |e: &Event| {
        if let Event::Replied { text, .. } = e {
            replies.push(text.clone());
        }
    };
    let reading =
        session::interpret(scenario, world, &case.instruction, &tap, options, &mut emit).await;
    let vocabulary = &scenario.domain.vocabulary;
    let mut result = match reading {
        Ok(r) => {
            let mut result = score(vocabulary, case, Some(&r.answer.goal.to_string()));
            let first = r.first.as_ref().map(|f| f.to_string());
            result.first_correct = Some(is_correct(vocabulary, case, first.as_deref()));
            result.first_answer = first;
            result.feedback_rounds = r.feedback_rounds;
            result.readings = r.readings.iter().map(ToString::to_string).collect();
            result.gold_in_readings = Some(
                result
                    .readings
                    .iter()
                    .any(|g| is_correct(vocabulary, case, Some(g))),
            );
            if let Some(why) = r.doubt() {
                result.problem = Some(format!("kept with a doubt: {why}"));
            }
            result.evidence = Some(r.evidence);
            result
        }
        // No usable reply at all is a wrong answer, not an error that stops the run.
        Err(session::SessionError::NoGoal { attempts, last }) => {
            let mut result = score(vocabulary, case, None);
            result.problem = Some(format!("no usable reply in {attempts} call(s): {last}"));
            result.first_correct = Some(false);
            result
        }
        // A question too long for the model fails its case alone (feedback rounds make a
        // prompt longer); the next case is asked as usual.
        Err(session::SessionError::Llm(e @ crate::llm::LlmError::TooLong { .. })) => {
            let mut result = score(vocabulary, case, None);
            result.problem = Some(e.to_string());
            result.first_correct = Some(false);
            result
        }
        Err(e) => {
            return Err(EvalError::Session {
                case: format!(
                    "run {run}, {} case {}",
                    case.difficulty.as_str(),
                    case.index + 1
                ),
                source: e,
            });
        }
    };
    result.run = run;
    result.reply = Some(replies.join("\n---\n"));
    result.calls = tap.calls();
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
    for (what, tallies) in [
        ("first call only", results.first_call()),
        (
            "gold among the readings offered",
            results.gold_in_readings(),
        ),
        (
            "second pass, every other request's miss kept as a correction",
            results.second_pass.map(|p| [p.easy, p.medium, p.hard]),
        ),
    ] {
        let Some([easy, medium, hard]) = tallies else {
            continue;
        };
        let overall = Tally {
            correct: easy.correct + medium.correct + hard.correct,
            total: easy.total + medium.total + hard.total,
        };
        out.push_str(&format!(
            "| {system}, {what} | {} | {} | {} | {} | {} | | | | | |\n",
            cell(&easy),
            cell(&medium),
            cell(&hard),
            cell(&overall),
            results.cases.len(),
        ));
    }
    for r in &results.runs {
        let cases: Vec<&super::run::CallRecord> = results
            .cases
            .iter()
            .filter(|c| c.run == r.run)
            .flat_map(|c| &c.calls)
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
    let notes = table_notes(results, temperature, expected);
    out.push('\n');
    for n in notes {
        out.push_str(&format!("- {n}\n"));
    }
    out
}

/// The notes under the table: a partial run, the temperature, calls and time per
/// instruction, the doubt's calibration, what the usage leaves out.
fn table_notes(results: &GoalsResults, temperature: f32, expected: usize) -> Vec<String> {
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
    if results.first_call().is_some() {
        let cases = results.cases.len().max(1) as f64;
        let calls: usize = results.cases.iter().map(|c| c.calls.len()).sum();
        let fed_back = results
            .cases
            .iter()
            .filter(|c| c.feedback_rounds > 0)
            .count();
        // The latency columns are per call; a person waits for all of an instruction's.
        let per_instruction: Vec<f64> = results
            .cases
            .iter()
            .map(|c| c.calls.iter().map(|call| call.latency_ms).sum::<f64>() / 1000.0)
            .collect();
        notes.push(format!(
            "\"First call only\" scores each instruction's first answer as it came; the row below it is the answer after the checks (parses, not contradictory, plannable, no more alternatives than the request offers, not true already, nothing pasted from an example or asked by no word), the vote among candidates and feedback. Calls per instruction: {:.2}; {fed_back} instruction(s) needed feedback. Time per instruction, all its calls: median {:.2} s, p95 {:.2} s.",
            calls as f64 / cases,
            percentile(&per_instruction, 50.0),
            percentile(&per_instruction, 95.0),
        ));
    }
    if let Some(d) = &results.doubt {
        notes.push(format!(
            "Doubt: {} of {} wrong answers marked doubtful, {} of {} right ones.",
            d.wrong_marked.correct,
            d.wrong_marked.total,
            d.right_marked.correct,
            d.right_marked.total
        ));
    }
    if let Some(u) = &results.usage {
        notes.extend(u.notes());
    }
    notes
}
