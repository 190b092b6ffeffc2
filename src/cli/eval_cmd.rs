//! `betr eval goals | resolve | params`: the paper's experiments. Each prints a table,
//! writes results.json, results.csv, table.md and a PNG chart into the output directory,
//! and records every finished case in `cases.jsonl` as it finishes, so an interrupted run
//! is resumed by running the same command with the same `--out`.

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use betr::dataset;
use betr::domain::Scenario;
use betr::eval::run::{Progress, RunConfig};
use betr::eval::{self, chart, chart_runs, goals, goals_run, params, resolve};
use betr::llm::LanguageModel;
use betr::llm::config::Backend;
use betr::store::write_atomic;

use super::llm_cmds::{self, LlmFlags};

/// The prompt ablations of the paper's Table III.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PromptVariant {
    Full,
    NoDescriptions,
    NoObjectRule,
    OriginalExamples,
    Cot,
}

impl PromptVariant {
    fn name(self) -> &'static str {
        match self {
            PromptVariant::Full => "full",
            PromptVariant::NoDescriptions => "no-descriptions",
            PromptVariant::NoObjectRule => "no-object-rule",
            PromptVariant::OriginalExamples => "original-examples",
            PromptVariant::Cot => "cot",
        }
    }
}

/// Flags every experiment that asks a model shares.
#[derive(Args, Debug, Clone)]
pub struct RunFlags {
    /// Prompt variant (ablations of the paper's Table III); original-examples needs --examples FILE.
    #[arg(long, value_enum, default_value = "full")]
    pub prompt: PromptVariant,
    /// Requests in flight at once (default: 4 for HTTP backends, 1 for the local model).
    #[arg(long, value_name = "K")]
    pub concurrency: Option<usize>,
    /// Where to write the results (default: a new directory under eval-results/). Pointing
    /// a run at an existing directory resumes it: cases already recorded are not asked again.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Stop after this many newly finished cases (for testing interruption).
    #[arg(long, hide = true)]
    pub limit: Option<usize>,
    #[command(flatten)]
    pub llm: LlmFlags,
}

/// Draws a progress bar on stderr when it is a terminal; otherwise draws nothing.
struct Bar(ProgressBar);

impl Bar {
    fn new() -> Bar {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(None, target);
        if let Ok(style) = ProgressStyle::with_template(
            "{bar:40} {pos}/{len} [{elapsed_precise}, eta {eta}] {msg}",
        ) {
            bar.set_style(style);
        }
        Bar(bar)
    }
}

impl Progress for Bar {
    fn begin(&self, total: usize, done: usize) {
        self.0.set_length(total as u64);
        self.0.set_position(done as u64);
        if done > 0 {
            self.0.println(format!(
                "resuming: {done} of {total} case(s) already recorded"
            ));
        }
    }
    fn finished(&self, label: &str) {
        self.0.inc(1);
        self.0.set_message(label.to_string());
    }
    fn end(&self) {
        self.0.finish_and_clear();
    }
}

/// The model, its options with the prompt variant applied, and the run settings.
struct Prepared {
    llm: llm_cmds::Llm,
    label: String,
    settings: BTreeMap<String, String>,
    concurrency: usize,
}

fn prepare(flags: &RunFlags, extra: &[(&str, String)]) -> Result<Prepared> {
    let mut llm_flags = flags.llm.clone();
    match flags.prompt {
        PromptVariant::Full => {}
        PromptVariant::NoDescriptions => llm_flags.no_descriptions = true,
        PromptVariant::NoObjectRule => llm_flags.no_object_rule = true,
        PromptVariant::Cot => llm_flags.cot = true,
        PromptVariant::OriginalExamples => {
            if llm_flags.examples.is_none() {
                bail!(
                    "--prompt original-examples: the examples of the original LLM-OBTEA prompt are not shipped with betr; give them with --examples FILE (TOML: [[examples]] with instruction and goal)"
                );
            }
        }
    }
    let llm = llm_cmds::setup(&llm_flags)?;
    let backend = format!("{:?}", llm.settings.backend).to_lowercase();
    let model = llm.model.model().to_string();
    let mut settings: BTreeMap<String, String> = BTreeMap::new();
    settings.insert("backend".into(), backend.clone());
    settings.insert("model".into(), model.clone());
    settings.insert("prompt".into(), flags.prompt.name().into());
    settings.insert("temperature".into(), llm.settings.temperature.to_string());
    settings.insert("structured".into(), llm.settings.structured.to_string());
    let optional = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
    for (k, v) in [
        ("examples", optional(&llm_flags.examples)),
        ("prompts", optional(&llm_flags.prompts)),
    ] {
        if let Some(v) = v {
            settings.insert(k.into(), v);
        }
    }
    for (k, v) in extra {
        settings.insert((*k).into(), v.clone());
    }
    let concurrency = flags
        .concurrency
        .unwrap_or(if llm.settings.backend == Backend::Local {
            1
        } else {
            4
        })
        .max(1);
    Ok(Prepared {
        label: format!("{model} ({backend}), prompt {}", flags.prompt.name()),
        llm,
        settings,
        concurrency,
    })
}

fn runtime() -> Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the async runtime")
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    write_atomic(&dir.join(name), bytes).with_context(|| format!("writing {name}"))
}

/// Write results.json, results.csv and table.md; draw the chart (a missing font only
/// costs the picture).
fn write_all<T: serde::Serialize>(
    dir: &Path,
    results: &T,
    csv: &str,
    table: &str,
    chart: impl FnOnce() -> Result<(), chart::ChartError>,
) -> Result<()> {
    write(
        dir,
        "results.json",
        serde_json::to_string_pretty(results)?.as_bytes(),
    )?;
    write(dir, "results.csv", csv.as_bytes())?;
    write(dir, "table.md", table.as_bytes())?;
    if let Err(e) = chart() {
        eprintln!("warning: chart not drawn: {e}");
    }
    print!("{table}");
    println!("\nresults: {}", dir.display());
    Ok(())
}

fn stopped(dir: &Path) -> String {
    format!(
        "the run stopped; finished cases are kept in {} — run the same command again to resume",
        dir.join("cases.jsonl").display()
    )
}

/// Score a file of recorded answers (one line per case) and write the results.
pub fn goals_from_answers(
    dataset_dir: &Path,
    answers: &Path,
    scenario: &Path,
    out: Option<&Path>,
) -> Result<ExitCode> {
    let cases = dataset::load(dataset_dir)?;
    let scenario = Scenario::load(scenario)?;
    let lines = goals::read_answers(answers, cases.len())?;
    let scored: Vec<goals::CaseResult> = cases
        .iter()
        .zip(&lines)
        .map(|(case, answer)| goals::score(&scenario.domain.vocabulary, case, answer.as_deref()))
        .collect();
    let results = goals::GoalsResults::from_cases(scored);
    let label = format!("answers from {}", answers.display());
    let dir = eval::output_dir(out, "goals").context("creating the output directory")?;
    let table = results.table(&label);
    write_all(&dir, &results, &results.csv(), &table, || {
        goals_chart(&dir, &label, &results)
    })?;
    Ok(ExitCode::SUCCESS)
}

fn goals_chart(
    dir: &Path,
    label: &str,
    results: &goals::GoalsResults,
) -> Result<(), chart::ChartError> {
    chart::accuracy_chart(
        &dir.join("accuracy.png"),
        "Goal interpretation accuracy (LLM-OBTEA cafe set)",
        &eval::goals_series(label, results),
    )
}

/// Ask the model for the goal of each of the 100 instructions, `runs` times.
pub fn goals_with_model(
    dataset_dir: &Path,
    scenario_path: &Path,
    runs: usize,
    flags: &RunFlags,
) -> Result<ExitCode> {
    let cases = dataset::load(dataset_dir)?;
    let scenario = Scenario::load(scenario_path)?;
    let p = prepare(flags, &[("dataset", dataset_dir.display().to_string())])?;
    let dir =
        eval::output_dir(flags.out.as_deref(), "goals").context("creating the output directory")?;
    eval::run::check_settings(&dir, "goals", &p.settings)?;
    let world = betr::world::load(&scenario)?;
    let settings = goals_run::PromptSettings {
        templates: p.llm.options.templates.clone(),
        variant: p.llm.options.variant.clone(),
        temperature: p.llm.options.temperature,
        max_tokens: p.llm.options.max_tokens,
        structured: p.llm.options.structured,
    };
    p.llm.model.set_purpose("eval goals");
    let bar = Bar::new();
    let cfg = RunConfig {
        runs: runs.max(1),
        concurrency: p.concurrency,
        limit: flags.limit,
        prices: p.llm.settings.prices.clone(),
        progress: &bar,
    };
    let results = runtime()?
        .block_on(goals_run::run_goals(
            &p.llm.model,
            &scenario,
            &world.facts(),
            &cases,
            &settings,
            &cfg,
            &dir,
        ))
        .with_context(|| stopped(&dir))?;
    let table = goals_run::table(
        &results,
        &p.label,
        p.llm.options.temperature,
        cfg.runs * cases.len(),
    );
    write_all(&dir, &results, &results.csv(), &table, || {
        goals_chart(&dir, &p.label, &results)
    })?;
    Ok(ExitCode::SUCCESS)
}

/// Which experiment `session_experiment` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionExperiment {
    Resolve,
    Params,
}

/// `betr eval resolve` and `betr eval params`: each scenario resolved `runs` times.
pub fn session_experiment(
    which: SessionExperiment,
    scenarios_dir: &Path,
    runs: usize,
    max_rounds: usize,
    flags: &RunFlags,
) -> Result<ExitCode> {
    let (name, paths): (&str, Vec<&str>) = match which {
        SessionExperiment::Resolve => ("resolve", resolve::FAILURE_SCENARIOS.to_vec()),
        SessionExperiment::Params => (
            "params",
            params::PARAM_SCENARIOS.iter().map(|(p, _)| *p).collect(),
        ),
    };
    let scenarios = paths
        .iter()
        .map(|p| {
            let path = scenarios_dir.join(p);
            Scenario::load(&path)
                .map(|s| ((*p).to_string(), s))
                .with_context(|| format!("loading {}", path.display()))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut p = prepare(flags, &[("max_rounds", max_rounds.to_string())])?;
    p.llm.options.max_rounds = max_rounds;
    let dir =
        eval::output_dir(flags.out.as_deref(), name).context("creating the output directory")?;
    eval::run::check_settings(&dir, name, &p.settings)?;
    p.llm.model.set_purpose(&format!("eval {name}"));
    let bar = Bar::new();
    let cfg = RunConfig {
        runs: runs.max(1),
        concurrency: p.concurrency,
        limit: flags.limit,
        prices: p.llm.settings.prices.clone(),
        progress: &bar,
    };
    let rt = runtime()?;
    match which {
        SessionExperiment::Resolve => {
            let results = rt
                .block_on(resolve::run_resolve(
                    &p.llm.model,
                    &scenarios,
                    &p.llm.options,
                    &cfg,
                    &dir,
                ))
                .with_context(|| stopped(&dir))?;
            let bars: Vec<(String, f64)> = results
                .scenarios
                .iter()
                .enumerate()
                .map(|(i, s)| (format!("{} {}", i + 1, s.name), s.success_rate))
                .collect();
            let table = results.table(&p.label, cfg.runs);
            write_all(&dir, &results, &results.csv(), &table, || {
                chart_runs::success_chart(
                    &dir.join("resolve.png"),
                    &format!("Failure resolution: success rate ({})", p.label),
                    &bars,
                )
            })?;
        }
        SessionExperiment::Params => {
            let results = rt
                .block_on(params::run_params(
                    &p.llm.model,
                    &scenarios,
                    &p.llm.options,
                    &cfg,
                    &dir,
                ))
                .with_context(|| stopped(&dir))?;
            let table = results.table(&p.label, cfg.runs);
            write_all(&dir, &results, &results.csv(), &table, || {
                chart_runs::params_chart(
                    &dir.join("params.png"),
                    &format!(
                        "Proposed parameter values, accepted range shaded ({})",
                        p.label
                    ),
                    &chart_runs::params_panels(&results),
                )
            })?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
