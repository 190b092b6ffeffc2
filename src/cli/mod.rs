//! Command-line front end: parses arguments, drives the library, prints results.

#[macro_use]
pub mod out;
mod background_fetch;
mod engine_driver;
mod export_cmd;
mod knowledge_cmd;
mod llm_cmds;
mod model_cmd;
mod monitor_cmd;
mod policy_cmd;
mod replay_cmd;
mod resolve_cmd;
mod tree_cmds;
pub mod tui_cmd;
mod values;
mod verify_cmd;
mod viz_flags;
mod voice_cmd;

// The lab: experiments, benchmarks and fuzzing, which the product never uses (the `lab`
// feature, on by default).
#[cfg(feature = "lab")]
mod bench_cmd;
#[cfg(feature = "lab")]
mod eval_cmd;
#[cfg(feature = "lab")]
mod eval_setup;
#[cfg(feature = "lab")]
mod fuzz_cmd;
#[cfg(feature = "lab")]
mod lab_flags;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

use betr::domain::Condition;
use betr::excerpt::excerpt;
use betr::goal::Formula;
use betr::scenario::Scenario;

#[derive(Parser)]
#[command(
    name = "betr",
    version,
    about = "Instruction → goal → behavior tree, repaired when the world disagrees",
    override_usage = "betr [SCENARIO] [WORKBENCH OPTIONS]\n       betr <COMMAND> [ARGS]",
    subcommand_precedence_over_arg = true
)]
pub struct Cli {
    /// What to do (none: the workbench, as `betr tui` with the same arguments).
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Without a command: the workbench's scenario and options (`betr cafe/no_coffee
    /// --viewer web` is `betr tui cafe/no_coffee --viewer web`).
    #[command(flatten)]
    pub workbench: tui_cmd::TuiArgs,
    /// Print trees with ASCII symbols instead of Unicode.
    #[arg(long, global = true)]
    pub ascii: bool,
    /// Fetch nothing: a robot description or embedded model not in the cache is said, and
    /// the command goes on without it (the cell with its reach spheres and gripper sweep,
    /// no embedded model answering) [env: BETR_OFFLINE].
    #[arg(long, global = true)]
    pub offline: bool,
}

#[derive(Subcommand)]
pub enum Command {
    /// betr against the tools it replaces, measured back to back on this machine: ticks
    /// against py_trees, planning and repair at scale, the embedded model against
    /// llama-bench, and the first answer of a one-shot command; one table, also as JSON.
    #[cfg(feature = "lab")]
    Bench(bench_cmd::BenchArgs),
    /// The workbench: type an instruction, plan, step or run the tree, approve the fixes a
    /// model proposes when an action fails, verify, save the policy.
    Tui(tui_cmd::TuiArgs),
    #[command(hide = true)]
    PolicySaveTest(PolicySaveTest),
    /// Hidden: fuzz a reader of outside input (or all of them); see docs/FUZZ.md.
    #[cfg(feature = "lab")]
    #[command(hide = true)]
    Fuzz(fuzz_cmd::FuzzArgs),
    /// Check the planned (or a saved) tree before it runs: structural rules, then every
    /// reachable state of the abstraction; exit 1 with a counterexample when violated.
    Verify(verify_cmd::VerifyArgs),
    /// Write a tree as BehaviorTree.CPP v4 XML (for BT.CPP and Groot2) or Graphviz DOT
    /// (statuses of the last tick of a run as colours, the last fix's nodes marked).
    Export {
        /// A scenario, as a file or a name like the other commands take (its planned
        /// tree), or a tree file (betr text, a saved policy, or BT.CPP XML).
        source: PathBuf,
        #[arg(long, value_enum)]
        format: export_cmd::Format,
        /// The scenario of a tree file that does not name one in a policy header.
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Write here (atomically) instead of to standard output.
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        knowledge: knowledge_cmd::KnowledgeFlags,
    },
    /// Watch a BehaviorTree.CPP process live over Groot2's protocol: its tree with every
    /// node's status (or --print: one line per status change).
    Monitor(monitor_cmd::MonitorArgs),
    /// Open a recorded session (--record FILE) in the workbench, read-only, to step through
    /// forward and back without the model; print it as text (--print), or convert it into a
    /// rerun recording (--to-rrd).
    Replay(replay_cmd::ReplayArgs),
    /// Reproduce the paper's experiments.
    #[cfg(feature = "lab")]
    Eval {
        #[command(subcommand)]
        experiment: eval_cmd::EvalExperiment,
    },
    /// What betr learned: rules from approved fixes (kept with `betr resolve --learn` or in
    /// the workbench) and readings a person corrected, kept as the domain's examples; list
    /// them, show one with where it came from, revoke one.
    Knowledge {
        #[command(subcommand)]
        action: knowledge_cmd::KnowledgeAction,
    },
    /// Embedded model files: fetch them into the cache, list them.
    Model {
        #[command(subcommand)]
        action: model_cmd::ModelAction,
    },
    /// Plan a tree for the scenario's goal (or --goal) and print it with its statuses.
    Plan {
        /// Scenario file, e.g. scenarios/cafe/no_coffee.toml (or cafe/no_coffee).
        scenario: PathBuf,
        /// A goal formula instead of the scenario's goal, e.g. 'On_Coffee_Table1 & Active_AC'.
        #[arg(long)]
        goal: Option<String>,
        #[command(flatten)]
        knowledge: knowledge_cmd::KnowledgeFlags,
    },
    /// Tick the planned tree (or a saved one) in a fresh world until success or failure.
    Run(tree_cmds::RunArgs),
    /// Plan, run until an action fails, insert conditions as that action's first
    /// preconditions, re-plan and run to success; print and optionally save the tree.
    Repair(tree_cmds::RepairArgs),
    /// Ask a language model for the goal an instruction means in the scenario.
    Interpret(resolve_cmd::InterpretArgs),
    /// Transcribe a WAV file (any rate, channels and bit depth) with the configured
    /// speech-to-text backend; print the transcript, and timings on stderr.
    Transcribe {
        file: PathBuf,
        /// Settings file (default: $BETR_CONFIG, ./betr.toml, ~/.config/betr/betr.toml).
        #[arg(long, value_name = "FILE")]
        config: Option<PathBuf>,
        #[command(flatten)]
        stt: voice_cmd::SttFlags,
    },
    /// Interpret the scenario's instruction, plan, simulate; on each failure ask the model
    /// for the missing preconditions (or parameter value), ask for approval, repair, re-run;
    /// save the tree that succeeds.
    Resolve(resolve_cmd::ResolveFlags),
}

/// Hidden: save a policy of `nodes` nodes to `path` `times` times (tests kill it mid-save).
#[derive(clap::Args)]
pub struct PolicySaveTest {
    pub path: PathBuf,
    #[arg(long, default_value_t = 20_000)]
    pub nodes: usize,
    #[arg(long, default_value_t = 1_000)]
    pub times: usize,
}

pub fn run(cli: Cli) -> Result<ExitCode> {
    let glyphs = if cli.ascii {
        &betr::bt::ASCII
    } else {
        &betr::bt::UNICODE
    };
    let var = |k: &str| std::env::var(k).ok();
    let offline = cli.offline || offline_from_env(&var)?;
    let Some(command) = cli.command else {
        let args = tui_cmd::TuiArgs {
            offline,
            ..cli.workbench
        };
        if let Some(scenario) = &args.scenario {
            scenario_or_command(scenario)?;
        }
        return tui_cmd::tui(&args, cli.ascii);
    };
    // Every engine a one-shot command starts reads it (`engine_driver::Driver::start`).
    let _ = OFFLINE.set(offline);
    match command {
        Command::Tui(mut args) => {
            args.offline = offline;
            tui_cmd::tui(&args, cli.ascii)
        }
        #[cfg(feature = "lab")]
        Command::Bench(args) => bench_cmd::run(&args),
        Command::PolicySaveTest(args) => policy_cmd::save_test(&args),
        #[cfg(feature = "lab")]
        Command::Fuzz(args) => fuzz_cmd::run(&args),
        #[cfg(feature = "lab")]
        Command::Eval { experiment } => eval_cmd::run(experiment),
        Command::Model { action } => model_cmd::run(action),
        Command::Knowledge { action } => knowledge_cmd::run(action),
        Command::Transcribe { file, config, stt } => {
            voice_cmd::transcribe(&file, config.as_deref(), &stt)
        }
        Command::Interpret(args) => resolve_cmd::interpret_command(&args),
        Command::Resolve(args) => resolve_cmd::resolve_command(&args, glyphs),
        Command::Export {
            source,
            format,
            scenario,
            out,
            knowledge,
        } => export_cmd::export(
            &source,
            scenario.as_deref(),
            format,
            out.as_deref(),
            &knowledge,
        ),
        Command::Plan {
            scenario,
            goal,
            knowledge,
        } => tree_cmds::plan(&load_with(&scenario, &knowledge)?, goal.as_deref(), glyphs),
        Command::Run(args) => tree_cmds::run_command(&args, glyphs),
        Command::Replay(args) => replay_cmd::replay(&args, cli.ascii),
        Command::Monitor(args) => monitor_cmd::monitor(&args, cli.ascii),
        Command::Repair(args) => tree_cmds::repair_command(&args, glyphs),
        Command::Verify(args) => verify_cmd::command(&args, cli.ascii),
    }
}

/// Whether this command fetches nothing (`--offline` or `BETR_OFFLINE`); set once, before
/// the command runs.
static OFFLINE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

fn offline() -> bool {
    OFFLINE.get().copied().unwrap_or(false)
}

/// `BETR_OFFLINE` set to true (1, true, yes) or false (unset, empty, 0, false, no).
pub fn offline_from_env(var: &dyn Fn(&str) -> Option<String>) -> Result<bool> {
    let Some(value) = var("BETR_OFFLINE") else {
        return Ok(false);
    };
    if value.trim().is_empty() {
        return Ok(false);
    }
    match betr::bounds::switch_value(&value) {
        Some(on) => Ok(on),
        None => bail!("BETR_OFFLINE={value:?} is not true or false"),
    }
}

impl Cli {
    /// The command line, parsed; workbench options given before a command are refused
    /// rather than ignored (`betr --viewer web plan S`: the option belongs after
    /// `betr tui`, or to a command that takes it, after the command).
    pub fn parse_checked() -> Cli {
        use clap::{CommandFactory, FromArgMatches, parser::ValueSource};
        let mut command = Cli::command();
        let matches = command.get_matches_mut();
        if let Some((name, _)) = matches.subcommand() {
            let given: Vec<String> = command
                .get_arguments()
                .filter(|a| !a.is_global_set())
                .filter(|a| {
                    matches.value_source(a.get_id().as_str()) == Some(ValueSource::CommandLine)
                })
                .map(|a| match a.get_long() {
                    Some(long) => format!("--{long}"),
                    None => a.get_id().to_string().to_uppercase(),
                })
                .collect();
            if !given.is_empty() {
                command
                    .error(
                        clap::error::ErrorKind::ArgumentConflict,
                        format!(
                            "{} before the command `{name}`: options before a command are the \
                             workbench's (`betr [SCENARIO] [OPTIONS]`); a command's own options \
                             go after it",
                            given.join(", ")
                        ),
                    )
                    .exit();
            }
        }
        Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
    }
}

/// The first word of a bare `betr WORD` is a scenario; one that names no scenario but is
/// close to a command's name was most likely that command mistyped (`betr tiu`).
fn scenario_or_command(word: &Path) -> Result<()> {
    let Err(not_found) = find_scenario(word) else {
        return Ok(());
    };
    let typed = word.to_string_lossy();
    let commands = <Cli as clap::CommandFactory>::command();
    let names = commands
        .get_subcommands()
        .filter(|c| !c.is_hide_set())
        .map(|c| c.get_name());
    match betr::domain::names::nearest(&typed, names, 0.6).first() {
        Some(command) => bail!(
            "{not_found}\n  no scenario or command is called {typed:?}; did you mean the command `betr {command}`?"
        ),
        None => Err(not_found),
    }
}

/// Resolve a scenario argument: a path, or a name under `scenarios/` with or without `.toml`.
fn load(arg: &Path) -> Result<Scenario> {
    Ok(Scenario::load(&find_scenario(arg)?)?)
}

/// A scenario with the learned rules the knowledge flags ask for.
fn load_with(arg: &Path, knowledge: &knowledge_cmd::KnowledgeFlags) -> Result<Scenario> {
    let mut scenario = load(arg)?;
    knowledge.apply(&mut scenario)?;
    with_made_examples(&mut scenario);
    Ok(scenario)
}

/// A scenario whose files write no worked examples reads with a pool made from its domain
/// (said on stderr).
fn with_made_examples(scenario: &mut Scenario) {
    let made = betr::session::interpret::made_pool::fill(scenario);
    if made > 0 {
        errln!(
            "Examples: {:?} writes none; {made} made from its domain, each replaced as corrections are kept",
            scenario.name
        );
    }
}

/// The file a scenario argument names: a path as given, else a name under `scenarios/`
/// of the working directory or the data directory, where the shipped scenarios are
/// written on first use (`betr::scenario::catalog`).
fn find_scenario(arg: &Path) -> Result<PathBuf> {
    let var = |k: &str| std::env::var(k).ok();
    Ok(betr::scenario::catalog::Catalog::standard(&var).find(arg)?)
}

/// `A & ~B` → the literals, checked against the scenario's vocabulary.
fn parse_conditions(scenario: &Scenario, text: &str) -> Result<Vec<Condition>> {
    let formula = parse_formula(scenario, "--add", text)?;
    let dnf = formula.to_dnf();
    match dnf.0.as_slice() {
        [one] if !one.is_empty() => Ok(one.clone()),
        _ => bail!(
            "--add {}: expected one condition or a conjunction ('A & ~B'), found {formula}",
            excerpt(text, None)
        ),
    }
}

/// A goal formula for `flag`, its text echoed in an error as an excerpt around the
/// column the error is about.
fn parse_formula(scenario: &Scenario, flag: &str, text: &str) -> Result<Formula> {
    scenario
        .parse_goal(text)
        .map_err(|e| anyhow::anyhow!("{flag} {}: {e}", excerpt(text, Some(e.at()))))
}

/// The goal to plan: `--goal`, else the scenario's.
fn goal_of(scenario: &Scenario, goal: Option<&str>) -> Result<Formula> {
    match goal {
        Some(text) => parse_formula(scenario, "--goal", text),
        None => scenario
            .goal
            .clone()
            .with_context(|| format!("scenario {:?} has no goal; pass --goal", scenario.name)),
    }
}

/// A count flag refused by clap, with its range, outside `min..=max`.
fn ranged(min: u64, max: u64) -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::<usize>::new().range(min..=max)
}

/// The executor `--executor COMMAND` names: `mujoco` (the MuJoCo cell, installed on first
/// use), or the program started with its arguments (the command line split as a shell
/// splits it); none when the flag is not given.
fn executor_of(command: Option<&str>) -> Result<Option<Box<dyn betr::executor::Executor>>> {
    let Some(command) = command else {
        return Ok(None);
    };
    let words = shlex::split(command)
        .with_context(|| format!("--executor {command:?}: an unclosed quote or escape"))?;
    let Some((program, args)) = words.split_first() else {
        bail!("--executor is empty: give the command that starts the executor");
    };
    let executor =
        start_executor(program, args).with_context(|| format!("--executor {command:?}"))?;
    Ok(Some(executor))
}

/// Start the executor `program` names (`mujoco`: the MuJoCo cell) with `args`.
fn start_executor(
    program: &str,
    args: &[String],
) -> Result<Box<dyn betr::executor::Executor>, betr::executor::ExecutorError> {
    Ok(if program == betr::executor::mujoco::NAME {
        Box::new(betr::executor::mujoco::spawn(args, offline(), &|line| {
            eprintln!("{line}")
        })?)
    } else {
        Box::new(betr::executor::ProcessExecutor::spawn(program, args)?)
    })
}

/// An executor for each session an evaluation runs, from `--executor COMMAND`.
#[cfg(feature = "lab")]
fn executor_factory(
    command: &str,
) -> Result<
    impl Fn() -> Result<Box<dyn betr::executor::Executor>, betr::executor::ExecutorError> + Sync + use<>,
> {
    let words = shlex::split(command)
        .with_context(|| format!("--executor {command:?}: an unclosed quote or escape"))?;
    if words.is_empty() {
        bail!("--executor is empty: give the command that starts the executor");
    }
    Ok(move || start_executor(&words[0], &words[1..]))
}

/// The async runtime of a one-shot command, or of the workbench's screen: one thread (the
/// model and the server calls are awaited one at a time; the workbench's engine has
/// threads of its own).
fn runtime() -> Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the async runtime")
}
