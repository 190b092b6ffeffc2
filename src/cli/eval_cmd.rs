//! `betr eval goals | resolve | params`: the paper's experiments. Each prints a table,
//! writes results.json, results.csv, table.md and a PNG chart into the output directory,
//! and records every finished case in `cases.jsonl` as it finishes, so an interrupted run
//! is resumed by running the same command with the same `--out`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::Subcommand;

use betr::dataset;
use betr::eval::run::RunConfig;
use betr::eval::{self, chart, chart_runs, goals, goals_run, params, resolve};
use betr::llm::LanguageModel;
use betr::scenario::Scenario;
use betr::store::write_atomic;

use super::eval_setup::{Bar, RunFlags, prepare};

#[derive(Subcommand)]
pub enum EvalExperiment {
    /// Goal interpretation on the 100 LLM-OBTEA cafe instructions: one model call each
    /// (or --answers FILE), scored by the dataset's rule.
    Goals {
        /// The dataset directory (easy.txt, medium.txt, hard.txt).
        #[arg(long, default_value = "../shared/datasets/llm-obtea")]
        dataset: PathBuf,
        /// Score these recorded answers (one line per case, easy then medium then hard)
        /// instead of asking a model.
        #[arg(long)]
        answers: Option<PathBuf>,
        /// The scenario whose vocabulary, scene and examples the prompt uses.
        #[arg(long, default_value = "scenarios/cafe/cafe.toml")]
        scenario: PathBuf,
        /// Repetitions; run k sends seed k.
        #[arg(long, default_value_t = 1)]
        runs: usize,
        /// Run every set of requests a suite file names (docs/eval-suite.toml: the cafe
        /// dataset, held-out cafe requests, the cell's scenarios, and the greenhouse's, the
        /// lab's, the warehouse's and the hospital's held-out requests), each into a folder
        /// of its own, and print them side by side; --dataset and --scenario are not used.
        #[arg(long, value_name = "FILE")]
        suite: Option<PathBuf>,
        /// Read every set twice: first as the product reads, then each request again with
        /// every other request's miss kept as a person's correction (its gold goal), as
        /// betr keeps corrections for later requests of the domain (never its own). The
        /// second pass goes to `second-pass/` and is reported beside the first.
        #[arg(long, conflicts_with = "answers")]
        learn: bool,
        /// The example pool requests are read with: the scenario's written one, only the
        /// pool betr makes from the domain when a scenario writes none, or none.
        #[arg(
            long,
            value_enum,
            default_value = "written",
            conflicts_with = "answers"
        )]
        example_pool: goals_run::ExamplePool,
        #[command(flatten)]
        run: RunFlags,
    },
    /// The ten failure scenarios, each resolved end to end N times in simulation.
    Resolve {
        /// Runs per scenario; run k sends seed k.
        #[arg(long, default_value_t = 10)]
        runs: usize,
        /// Questions about failures per run before giving up.
        #[arg(long, default_value_t = 5)]
        max_rounds: usize,
        /// Where each run's goal comes from: the model reading the instruction, or the
        /// scenario's stated goal (so the failure under study is always reached).
        #[arg(long, value_enum, default_value = "interpret")]
        goal: GoalSource,
        /// The directory holding cell/ and cafe/ scenarios.
        #[arg(long, default_value = "scenarios")]
        scenarios: PathBuf,
        /// Run the ten failure scenarios one after the other and then the new tasks of
        /// cell/tasks/ (the same kinds of failure with other objects), once keeping every
        /// approved fix as a rule for the next (as `betr resolve --yes --learn`) and once
        /// without: model calls, failures in the world and ticks side by side (--runs is
        /// not used).
        #[arg(long)]
        sequence: bool,
        /// Run the ten scenarios in three settings, each into a folder of its own under
        /// --out, and print them side by side: the model alone (nothing tried before it is
        /// proposed, the paper's setting), twin-screened (fixes tried in the scenario's
        /// model only: the cafe without its hidden rules), and executed (the cell
        /// scenarios' actions performed by --executor, MuJoCo unless it names another).
        #[arg(long, conflicts_with = "sequence")]
        three_settings: bool,
        #[command(flatten)]
        run: RunFlags,
    },
    /// The seven parameter scenarios: values proposed and whether the world accepts them.
    Params {
        /// Runs per scenario; run k sends seed k.
        #[arg(long, default_value_t = 10)]
        runs: usize,
        /// Questions per run before giving up (a rejected value is asked again).
        #[arg(long, default_value_t = 5)]
        max_rounds: usize,
        /// Where each run's goal comes from: the model reading the instruction, or the
        /// scenario's stated goal (so the failure under study is always reached).
        #[arg(long, value_enum, default_value = "interpret")]
        goal: GoalSource,
        /// The directory holding cell/params/: the seven scenarios of the paper, or any
        /// other parameter scenarios there (every `*.toml`).
        #[arg(long, default_value = "scenarios")]
        scenarios: PathBuf,
        #[command(flatten)]
        run: RunFlags,
    },
}

/// Where a resolve or params run's goal comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum GoalSource {
    /// The model reads the scenario's instruction (a misread goal is its own column).
    Interpret,
    /// The scenario's stated goal; the instruction still reaches the failure questions.
    Scenario,
}

impl GoalSource {
    /// As run.json records it.
    fn name(self) -> &'static str {
        match self {
            GoalSource::Interpret => "interpret",
            GoalSource::Scenario => "scenario",
        }
    }
}

/// Run the chosen experiment.
pub fn run(experiment: EvalExperiment) -> Result<ExitCode> {
    use SessionExperiment as S;
    match experiment {
        EvalExperiment::Goals {
            dataset,
            answers: Some(answers),
            scenario,
            run,
            ..
        } => goals_from_answers(&dataset, &answers, &scenario, run.out.as_deref()),
        EvalExperiment::Goals {
            answers: None,
            suite: Some(suite),
            runs,
            learn,
            example_pool,
            run,
            ..
        } => goals_suite(&suite, (runs, learn, example_pool), &run),
        EvalExperiment::Goals {
            dataset,
            answers: None,
            scenario,
            runs,
            learn,
            example_pool,
            run,
            suite: None,
        } => goals_with_model(&dataset, &scenario, (runs, learn, example_pool), &run),
        EvalExperiment::Resolve {
            runs,
            max_rounds,
            goal,
            scenarios,
            sequence: false,
            three_settings: false,
            run,
        } => session_experiment(S::Resolve, &scenarios, runs, (max_rounds, goal), &run),
        EvalExperiment::Resolve {
            runs,
            max_rounds,
            goal,
            scenarios,
            three_settings: true,
            run,
            ..
        } => three_settings(&scenarios, runs, (max_rounds, goal), &run),
        EvalExperiment::Resolve {
            max_rounds,
            goal,
            scenarios,
            sequence: true,
            run,
            ..
        } => sequence_experiment(&scenarios, (max_rounds, goal), &run),
        EvalExperiment::Params {
            runs,
            max_rounds,
            goal,
            scenarios,
            run,
        } => session_experiment(S::Params, &scenarios, runs, (max_rounds, goal), &run),
    }
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
        errln!("warning: chart not drawn: {e}");
    }
    out!("{table}");
    outln!("\nresults: {}", dir.display());
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
    let cases = load_dataset(dataset_dir)?;
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
    (runs, learn, pool): (usize, bool, goals_run::ExamplePool),
    flags: &RunFlags,
) -> Result<ExitCode> {
    let cases = load_dataset(dataset_dir)?;
    let scenario = Scenario::load(scenario_path)?;
    let mut settings = vec![("dataset", dataset_dir.display().to_string())];
    settings.extend(pool_setting(pool));
    let p = prepare(flags, &settings)?;
    let dir =
        eval::output_dir(flags.out.as_deref(), "goals").context("creating the output directory")?;
    p.llm.model.set_purpose("eval goals");
    let mut in_scene: Vec<goals_run::SceneCase> = cases
        .iter()
        .map(|case| goals_run::SceneCase {
            scenario: &scenario,
            case: case.clone(),
            examples: None,
        })
        .collect();
    pool.apply(&mut in_scene);
    goal_set(&p, &in_scene, (runs, learn), flags, &dir)?;
    Ok(ExitCode::SUCCESS)
}

/// One set of requests read and scored into `dir` (resumed from its journal), with its
/// table, CSV, JSON and chart written there.
fn goal_set(
    p: &super::eval_setup::Prepared,
    cases: &[goals_run::SceneCase],
    (runs, learn): (usize, bool),
    flags: &RunFlags,
    dir: &Path,
) -> Result<goals::GoalsResults> {
    let mut results = read_set(p, cases, runs, flags, dir)?;
    if learn {
        let pool = p.llm.options.steps.prompt.examples.as_deref();
        let second = goals_run::with_corrections(cases, &results, pool);
        let second_dir = dir.join("second-pass");
        eprintln!(
            "second pass: {} request(s), {} correction(s) kept",
            second.len(),
            results.cases.iter().filter(|c| !c.correct).count()
        );
        let second_results = read_set(p, &second, runs, flags, &second_dir)?;
        write(
            &second_dir,
            "results.json",
            serde_json::to_string_pretty(&second_results)?.as_bytes(),
        )?;
        results.second_pass = Some(second_results.tallies());
    }
    let table = goals_run::table(
        &results,
        &p.label,
        p.llm.options.temperature,
        runs.max(1) * cases.len(),
    );
    write_all(dir, &results, &results.csv(), &table, || {
        goals_chart(dir, &p.label, &results)
    })?;
    Ok(results)
}

/// The cases read into `dir`'s journal (resumed), its results written there too.
fn read_set(
    p: &super::eval_setup::Prepared,
    cases: &[goals_run::SceneCase],
    runs: usize,
    flags: &RunFlags,
    dir: &Path,
) -> Result<goals::GoalsResults> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    eval::run::check_settings(dir, "goals", &p.settings)?;
    let model: Arc<dyn LanguageModel> = p.llm.model.clone();
    let bar = Bar::new();
    let cfg = RunConfig {
        runs: runs.max(1),
        concurrency: p.concurrency,
        limit: flags.limit,
        prices: p.model_settings.prices.clone(),
        progress: &bar,
        executor: None,
    };
    let results = super::runtime()?
        .block_on(goals_run::run_goals_in_scenes(
            &model,
            cases,
            &p.llm.options,
            &cfg,
            dir,
        ))
        .with_context(|| stopped(dir))?;
    Ok(results)
}

/// The example pool as run.json records it: only when it is not the scenario's own, so
/// a run of the product's reading reads as before.
fn pool_setting(pool: goals_run::ExamplePool) -> Option<(&'static str, String)> {
    (pool != goals_run::ExamplePool::Written).then(|| ("example_pool", pool.name().to_string()))
}

/// `betr eval goals --suite FILE`: every set of the suite, each into `OUT/<set>/` (resumed
/// like a single run), then the sets side by side in `OUT/suite.md`.
fn goals_suite(
    suite: &Path,
    (runs, learn, pool): (usize, bool, goals_run::ExamplePool),
    flags: &RunFlags,
) -> Result<ExitCode> {
    let sets = eval::suite::load(suite)?;
    let mut settings = vec![("suite", suite.display().to_string())];
    settings.extend(pool_setting(pool));
    let p = prepare(flags, &settings)?;
    let dir = eval::output_dir(flags.out.as_deref(), "goals-suite")
        .context("creating the output directory")?;
    p.llm.model.set_purpose("eval goals");
    let mut done: Vec<(String, bool, goals::GoalsResults)> = Vec::new();
    for set in &sets {
        let set_dir = dir.join(&set.name);
        std::fs::create_dir_all(&set_dir)
            .with_context(|| format!("creating {}", set_dir.display()))?;
        eprintln!("{}: {} request(s)", set.name, set.cases.len());
        let mut cases: Vec<goals_run::SceneCase> = set
            .cases
            .iter()
            .map(|(scene, case)| goals_run::SceneCase {
                scenario: &set.scenes[*scene],
                case: case.clone(),
                examples: None,
            })
            .collect();
        pool.apply(&mut cases);
        let results = goal_set(&p, &cases, (runs, learn), flags, &set_dir)?;
        done.push((set.name.clone(), set.tuned, results));
    }
    let rows: Vec<eval::suite::SetRow> = done
        .iter()
        .map(|(name, tuned, results)| eval::suite::SetRow {
            name,
            tuned: *tuned,
            results,
        })
        .collect();
    let table = format!(
        "Goal interpretation, {}\n\n{}",
        p.label,
        eval::suite::table(&rows)
    );
    write_atomic(&dir.join("suite.md"), table.as_bytes())
        .with_context(|| format!("writing {}", dir.join("suite.md").display()))?;
    println!("{table}");
    println!("results in {}", dir.display());
    Ok(ExitCode::SUCCESS)
}

/// `betr eval resolve --sequence`: the failure scenarios, then the new tasks, without and
/// with the fixes kept as rules between them.
fn sequence_experiment(
    scenarios_dir: &Path,
    (max_rounds, goal): (usize, GoalSource),
    flags: &RunFlags,
) -> Result<ExitCode> {
    let mut paths: Vec<String> = resolve::FAILURE_SCENARIOS
        .iter()
        .map(|p| (*p).to_string())
        .collect();
    let failure_steps = paths.len();
    let tasks_dir = scenarios_dir.join("cell/tasks");
    let mut tasks: Vec<String> = std::fs::read_dir(&tasks_dir)
        .with_context(|| format!("reading {}", tasks_dir.display()))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter_map(|p| {
            p.file_name()
                .map(|n| format!("cell/tasks/{}", n.to_string_lossy()))
        })
        .collect();
    tasks.sort();
    paths.extend(tasks);
    let scenarios = load_scenarios(scenarios_dir, &paths)?;
    let goal_source = goal.name();
    let mut p = prepare(
        flags,
        &[
            ("max_rounds", max_rounds.to_string()),
            ("goal", goal_source.to_string()),
            ("sequence", paths.join(" ")),
        ],
    )?;
    p.llm.options.max_rounds = max_rounds;
    p.llm.options.use_scenario_goal = goal == GoalSource::Scenario;
    p.label = format!("{}, goal: {goal_source}", p.label);
    let dir = eval::output_dir(flags.out.as_deref(), "resolve-sequence")
        .context("creating the output directory")?;
    eval::run::check_settings(&dir, "resolve-sequence", &p.settings)?;
    p.llm.model.set_purpose("eval resolve --sequence");
    let model: Arc<dyn LanguageModel> = p.llm.model.clone();
    let bar = Bar::new();
    let cfg = RunConfig {
        runs: 1,
        concurrency: 1,
        limit: flags.limit,
        prices: p.model_settings.prices.clone(),
        progress: &bar,
        executor: None,
    };
    let results = super::runtime()?
        .block_on(eval::sequence::run_sequence(
            &model,
            &scenarios,
            failure_steps,
            &p.llm.options,
            &cfg,
            &dir,
        ))
        .with_context(|| stopped(&dir))?;
    let table = results.table(&p.label);
    write(
        &dir,
        "results.json",
        serde_json::to_string_pretty(&results)?.as_bytes(),
    )?;
    write(&dir, "table.md", table.as_bytes())?;
    out!("{table}");
    outln!("\nresults: {}", dir.display());
    Ok(ExitCode::SUCCESS)
}

/// The scenarios at `paths` under `dir`, each with its path as given.
fn load_scenarios(dir: &Path, paths: &[impl AsRef<str>]) -> Result<Vec<(String, Scenario)>> {
    paths
        .iter()
        .map(|p| {
            let path = dir.join(p.as_ref());
            Scenario::load(&path)
                .map(|s| (p.as_ref().to_string(), s))
                .with_context(|| format!("loading {}", path.display()))
        })
        .collect()
}

/// Which experiment `session_experiment` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionExperiment {
    Resolve,
    Params,
}

/// What makes one of the three settings out of the command's lab flags.
type PullLevers = fn(&mut super::lab_flags::LabFlags);

/// `betr eval resolve --three-settings`: the experiment in each setting, then the table
/// of the three (`settings.md` in the output directory).
fn three_settings(
    scenarios_dir: &Path,
    runs: usize,
    rounds_and_goal: (usize, GoalSource),
    flags: &RunFlags,
) -> Result<ExitCode> {
    let dir = eval::output_dir(flags.out.as_deref(), "resolve-settings")
        .context("creating the output directory")?;
    let executor = flags
        .lab
        .executor
        .clone()
        .unwrap_or_else(|| "mujoco".into());
    let pulled: [(&str, &str, PullLevers); 3] = [
        ("model alone", "model-alone", |lab| {
            lab.no_shortlist = true;
            lab.no_screening = true;
            lab.executor = None;
        }),
        ("twin-screened", "twin-screened", |lab| {
            lab.twin_screening = true;
            lab.executor = None;
        }),
        ("executed", "executed", |_| {}),
    ];
    let mut settings = Vec::new();
    for (name, folder, pull) in pulled {
        let mut setting = flags.clone();
        setting.out = Some(dir.join(folder));
        pull(&mut setting.lab);
        if folder == "executed" {
            setting.lab.executor = Some(executor.clone());
        }
        errln!("eval resolve: {name}");
        session_experiment(
            SessionExperiment::Resolve,
            scenarios_dir,
            runs,
            rounds_and_goal,
            &setting,
        )?;
        let file = dir.join(folder).join("results.json");
        let text = std::fs::read_to_string(&file)
            .with_context(|| format!("reading {}", file.display()))?;
        let results =
            serde_json::from_str(&text).with_context(|| format!("reading {}", file.display()))?;
        settings.push(resolve::Setting {
            name: if folder == "executed" {
                format!("executed by {executor}")
            } else {
                name.to_string()
            },
            results,
            cell_only: folder == "executed",
        });
    }
    let table = resolve::settings_table(&settings);
    betr::store::write_atomic(&dir.join("settings.md"), table.as_bytes())
        .with_context(|| format!("writing {}", dir.join("settings.md").display()))?;
    outln!("\n{table}\nresults: {}", dir.display());
    Ok(ExitCode::SUCCESS)
}

/// `betr eval resolve` and `betr eval params`: each scenario resolved `runs` times.
pub fn session_experiment(
    which: SessionExperiment,
    scenarios_dir: &Path,
    runs: usize,
    (max_rounds, goal): (usize, GoalSource),
    flags: &RunFlags,
) -> Result<ExitCode> {
    let (name, paths): (&str, Vec<String>) = match which {
        SessionExperiment::Resolve => (
            "resolve",
            resolve::FAILURE_SCENARIOS
                .iter()
                .map(|p| (*p).to_string())
                .collect(),
        ),
        SessionExperiment::Params => {
            let paths = params::param_scenarios(scenarios_dir).with_context(|| {
                format!("listing {}", scenarios_dir.join("cell/params").display())
            })?;
            if paths.is_empty() {
                bail!(
                    "no parameter scenarios (*.toml) in {}",
                    scenarios_dir.join("cell/params").display()
                );
            }
            ("params", paths)
        }
    };
    let scenarios = load_scenarios(scenarios_dir, &paths)?;
    let goal_source = goal.name();
    let mut p = prepare(
        flags,
        &[
            ("max_rounds", max_rounds.to_string()),
            ("goal", goal_source.to_string()),
        ],
    )?;
    p.llm.options.max_rounds = max_rounds;
    p.llm.options.use_scenario_goal = goal == GoalSource::Scenario;
    p.label = format!("{}, goal: {goal_source}", p.label);
    let dir =
        eval::output_dir(flags.out.as_deref(), name).context("creating the output directory")?;
    eval::run::check_settings(&dir, name, &p.settings)?;
    p.llm.model.set_purpose(&format!("eval {name}"));
    let model: Arc<dyn LanguageModel> = p.llm.model.clone();
    let bar = Bar::new();
    let executor = flags
        .lab
        .executor
        .as_deref()
        .map(super::executor_factory)
        .transpose()?;
    let cfg = RunConfig {
        runs: runs.max(1),
        concurrency: p.concurrency,
        limit: flags.limit,
        prices: p.model_settings.prices.clone(),
        progress: &bar,
        executor: executor
            .as_ref()
            .map(|f| f as &betr::eval::run::ExecutorFactory),
    };
    let rt = super::runtime()?;
    match which {
        SessionExperiment::Resolve => {
            let results = rt
                .block_on(resolve::run_resolve(
                    &model,
                    &scenarios,
                    &p.llm.options,
                    &cfg,
                    &dir,
                ))
                .with_context(|| stopped(&dir))?;
            write_resolve(&dir, &results, &p.label, cfg.runs)?;
        }
        SessionExperiment::Params => {
            let results = rt
                .block_on(params::run_params(
                    &model,
                    &scenarios,
                    &p.llm.options,
                    &cfg,
                    &dir,
                ))
                .with_context(|| stopped(&dir))?;
            write_params(&dir, &results, &p.label, cfg.runs)?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `betr eval resolve`'s results into `dir`: JSON, CSV, the table and the chart.
fn write_resolve(
    dir: &Path,
    results: &resolve::ResolveResults,
    label: &str,
    runs: usize,
) -> Result<()> {
    let bars: Vec<(String, f64)> = results
        .scenarios
        .iter()
        .enumerate()
        .map(|(i, s)| (format!("{} {}", i + 1, s.name), s.success_rate))
        .collect();
    let table = results.table(label, runs);
    write_all(dir, results, &results.csv(), &table, || {
        chart_runs::success_chart(
            &dir.join("resolve.png"),
            &format!("Failure resolution: success rate ({label})"),
            &bars,
        )
    })
}

/// `betr eval params`' results into `dir`: JSON, CSV, the table and the chart.
fn write_params(
    dir: &Path,
    results: &params::ParamsResults,
    label: &str,
    runs: usize,
) -> Result<()> {
    let table = results.table(label, runs);
    write_all(dir, results, &results.csv(), &table, || {
        chart_runs::params_chart(
            &dir.join("params.png"),
            &format!("Proposed parameter values, accepted range shaded ({label})"),
            &chart_runs::params_panels(results),
        )
    })
}

/// The goal dataset's cases; a dataset directory that is not there is said with where it
/// was looked for (it is not shipped with betr: the default is beside the repository).
fn load_dataset(dir: &Path) -> Result<Vec<dataset::Case>> {
    if !dir.is_dir() {
        bail!(
            "the goal dataset {} is not there (it is not shipped with betr; the default is \
             ../shared/datasets/llm-obtea beside the repository, so run from the repository's \
             root or pass --dataset DIR)",
            dir.display()
        );
    }
    Ok(dataset::load(dir)?)
}
