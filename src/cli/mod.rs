//! Command-line front end: parses arguments, drives the library, prints results.

mod eval_cmd;
mod llm_cmds;
mod model_cmd;
mod tree_cmds;
mod values;
mod verify_cmd;
mod voice_cmd;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

use betr::domain::{Condition, Scenario};
use betr::goal::Formula;

#[derive(Parser)]
#[command(
    name = "betr",
    version,
    about = "Instruction → goal → behavior tree, repaired when the world disagrees"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Print trees with ASCII symbols instead of Unicode.
    #[arg(long, global = true)]
    pub ascii: bool,
}

#[derive(Subcommand)]
pub enum Command {
    /// Check the planned (or a saved) tree before it runs: structural rules, then every
    /// reachable state of the abstraction; exit 1 with a counterexample when violated.
    Verify {
        scenario: PathBuf,
        /// A tree in betr's text format to verify instead of planning one.
        #[arg(long)]
        tree: Option<PathBuf>,
        /// A property to check besides the scenario's: 'always F', 'never F', 'eventually F'.
        #[arg(long = "property")]
        properties: Vec<String>,
        /// Write the model for the SPIN model checker: --export promela FILE.
        #[arg(long, num_args = 2, value_names = ["FORMAT", "FILE"])]
        export: Option<Vec<String>>,
        /// Let every action also fail (leaving the state unchanged).
        #[arg(long)]
        failures: bool,
        /// Ignore the disturbances the scenario declares.
        #[arg(long)]
        no_disturbances: bool,
        /// Stop exploring after this many states (the result is then "unknown").
        #[arg(long, default_value_t = 200_000)]
        max_states: usize,
        /// Ticks within which the tree must succeed from every reachable state.
        #[arg(long, default_value_t = 10_000)]
        max_ticks: u64,
    },
    /// Reproduce the paper's experiments.
    Eval {
        #[command(subcommand)]
        experiment: EvalExperiment,
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
    },
    /// Tick the planned tree (or a saved one) in a fresh world until success or failure.
    Run {
        scenario: PathBuf,
        /// A tree in betr's text format to run instead of planning one.
        #[arg(long)]
        tree: Option<PathBuf>,
        /// Print the running action and failures at every tick.
        #[arg(long)]
        trace: bool,
        /// Give up after this many ticks.
        #[arg(long, default_value_t = 10_000)]
        max_ticks: u64,
        /// Run in the scenario's `[world.variants.NAME]` world (e.g. `clear`: without the obstacle).
        #[arg(long)]
        variant: Option<String>,
    },
    /// Plan, run until an action fails, insert conditions as that action's first
    /// preconditions, re-plan and run to success; print and optionally save the tree.
    Repair {
        scenario: PathBuf,
        /// Conditions to insert (a conjunction: 'A & B'); repeat for successive failures.
        #[arg(long = "add", required_unless_present = "set")]
        add: Vec<String>,
        /// A value parameter for every action that uses it with the object, e.g.
        /// "force of egg = 5 N" (repeatable; applied before any --add).
        #[arg(long = "set")]
        set: Vec<String>,
        /// Insert the first --add at this action (e.g. 'PickUp "Chips"') instead of the failing one.
        #[arg(long)]
        at: Option<String>,
        /// Start from this saved tree instead of planning.
        #[arg(long)]
        tree: Option<PathBuf>,
        /// Write the repaired tree here (atomically).
        #[arg(long)]
        save: Option<PathBuf>,
        /// Plan and repair in the scenario's `[world.variants.NAME]` world.
        #[arg(long)]
        variant: Option<String>,
    },
    /// Ask a language model for the goal an instruction means in the scenario.
    Interpret {
        scenario: PathBuf,
        /// The instruction (default: the scenario's).
        #[arg(conflicts_with = "audio")]
        instruction: Option<String>,
        /// Dictate the instruction: transcribe this WAV file, print the transcript and use
        /// it once confirmed (or corrected) on the terminal, or with --yes.
        #[arg(long, value_name = "FILE.wav")]
        audio: Option<PathBuf>,
        /// Use a dictated transcript without asking (it is still printed).
        #[arg(long, short = 'y')]
        yes: bool,
        #[command(flatten)]
        llm: llm_cmds::LlmFlags,
        #[command(flatten)]
        stt: voice_cmd::SttFlags,
    },
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
    Resolve {
        scenario: PathBuf,
        /// An instruction instead of the scenario's.
        #[arg(long, conflicts_with = "audio")]
        instruction: Option<String>,
        /// Dictate the instruction from a WAV file (printed; confirmed on the terminal or
        /// by --yes).
        #[arg(long, value_name = "FILE.wav")]
        audio: Option<PathBuf>,
        /// Approve every proposal (and a dictated transcript) without asking.
        #[arg(long, short = 'y')]
        yes: bool,
        /// Questions about failures before giving up.
        #[arg(long, default_value_t = 5)]
        max_rounds: usize,
        /// Where to save the final tree (default: policies/<scenario>.bt on success).
        #[arg(long)]
        save: Option<PathBuf>,
        #[command(flatten)]
        llm: llm_cmds::LlmFlags,
        #[command(flatten)]
        stt: voice_cmd::SttFlags,
    },
}

#[derive(Subcommand)]
pub enum EvalExperiment {
    /// Goal interpretation on the 100 LLM-OBTEA cafe instructions.
    Goals {
        /// The dataset directory (easy.txt, medium.txt, hard.txt).
        #[arg(long, default_value = "../shared/datasets/llm-obtea")]
        dataset: std::path::PathBuf,
        /// Score these recorded answers (one line per case, easy then medium then hard)
        /// instead of asking a model.
        #[arg(long)]
        answers: std::path::PathBuf,
        /// The scenario whose vocabulary answers must use.
        #[arg(long, default_value = "scenarios/cafe/cafe.toml")]
        scenario: std::path::PathBuf,
        /// Where to write results.json, results.csv, table.md and accuracy.png.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
}

pub fn run(cli: Cli) -> Result<ExitCode> {
    let glyphs = if cli.ascii {
        &betr::bt::ASCII
    } else {
        &betr::bt::UNICODE
    };
    match cli.command {
        Command::Eval {
            experiment:
                EvalExperiment::Goals {
                    dataset,
                    answers,
                    scenario,
                    out,
                },
        } => eval_cmd::goals_from_answers(&dataset, &answers, &scenario, out.as_deref()),
        Command::Model { action } => model_cmd::run(action),
        Command::Transcribe { file, config, stt } => {
            voice_cmd::transcribe(&file, config.as_deref(), &stt)
        }
        Command::Interpret {
            scenario,
            instruction,
            audio,
            yes,
            llm,
            stt,
        } => {
            let scenario = load(&scenario)?;
            let instruction = match &audio {
                Some(audio) => Some(voice_cmd::dictate(audio, llm.config.as_deref(), &stt, yes)?),
                None => instruction,
            };
            llm_cmds::interpret(&scenario, instruction.as_deref(), &llm)
        }
        Command::Resolve {
            scenario,
            instruction,
            audio,
            yes,
            max_rounds,
            save,
            llm,
            stt,
        } => {
            let loaded = load(&scenario)?;
            let instruction = match &audio {
                Some(audio) => Some(voice_cmd::dictate(audio, llm.config.as_deref(), &stt, yes)?),
                None => instruction,
            };
            llm_cmds::resolve(
                &loaded,
                &llm_cmds::ResolveArgs {
                    instruction: instruction.as_deref(),
                    yes,
                    max_rounds,
                    save: save.as_deref(),
                    scenario_path: &scenario,
                },
                &llm,
                glyphs,
            )
        }
        Command::Plan { scenario, goal } => {
            tree_cmds::plan(&load(&scenario)?, goal.as_deref(), glyphs)
        }
        Command::Run {
            scenario,
            tree,
            trace,
            max_ticks,
            variant,
        } => tree_cmds::run(
            &load(&scenario)?,
            tree.as_deref(),
            trace,
            max_ticks,
            variant.as_deref(),
            glyphs,
        ),
        Command::Repair {
            scenario,
            add,
            set,
            at,
            tree,
            save,
            variant,
        } => {
            let scenario = load(&scenario)?;
            let additions = add
                .iter()
                .map(|a| parse_conditions(&scenario, a))
                .collect::<Result<Vec<_>>>()?;
            let at = at
                .map(|a| {
                    betr::domain::ActionCall::parse(&a).with_context(|| {
                        format!("--at {a:?} is not an action like 'PickUp \"Chips\"'")
                    })
                })
                .transpose()?;
            let settings = set
                .iter()
                .map(|s| values::parse_setting(&scenario, s))
                .collect::<Result<Vec<_>>>()?;
            tree_cmds::repair(
                &scenario,
                &tree_cmds::RepairRequest {
                    additions: &additions,
                    settings: &settings,
                    at: at.as_ref(),
                    tree_file: tree.as_deref(),
                    save: save.as_deref(),
                    variant: variant.as_deref(),
                },
                glyphs,
            )
        }
        Command::Verify {
            scenario,
            tree,
            properties,
            export,
            failures,
            no_disturbances,
            max_states,
            max_ticks,
        } => verify_cmd::verify(
            &load(&scenario)?,
            &verify_cmd::Args {
                tree,
                properties,
                export,
                failures,
                no_disturbances,
                max_states,
                max_ticks,
                ascii: cli.ascii,
            },
        ),
    }
}

/// Resolve a scenario argument: a path, or a name under `scenarios/` with or without `.toml`.
fn load(arg: &Path) -> Result<Scenario> {
    let candidates = [
        arg.to_path_buf(),
        Path::new("scenarios").join(arg),
        Path::new("scenarios").join(arg).with_extension("toml"),
    ];
    let Some(path) = candidates.iter().find(|p| p.is_file()) else {
        bail!(
            "scenario {} not found (tried {})",
            arg.display(),
            candidates
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    };
    Ok(Scenario::load(path)?)
}

/// `A & ~B` → the literals, checked against the scenario's vocabulary.
fn parse_conditions(scenario: &Scenario, text: &str) -> Result<Vec<Condition>> {
    let formula = scenario
        .parse_goal(text)
        .map_err(|e| anyhow::anyhow!("--add {text:?}: {e}"))?;
    let dnf = formula.to_dnf();
    match dnf.0.as_slice() {
        [one] if !one.is_empty() => Ok(one.clone()),
        _ => bail!(
            "--add {text:?}: expected one condition or a conjunction ('A & ~B'), found {formula}"
        ),
    }
}

/// The goal to plan: `--goal`, else the scenario's.
fn goal_of(scenario: &Scenario, goal: Option<&str>) -> Result<Formula> {
    match goal {
        Some(text) => scenario
            .parse_goal(text)
            .map_err(|e| anyhow::anyhow!("--goal {text:?}: {e}")),
        None => scenario
            .goal
            .clone()
            .with_context(|| format!("scenario {:?} has no goal; pass --goal", scenario.name)),
    }
}
