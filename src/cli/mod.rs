//! Command-line front end: parses arguments, drives the library, prints results.

mod tree_cmds;
mod verify_cmd;

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
    },
    /// Plan, run until an action fails, insert conditions as that action's first
    /// preconditions, re-plan and run to success; print and optionally save the tree.
    Repair {
        scenario: PathBuf,
        /// Conditions to insert (a conjunction: 'A & B'); repeat for successive failures.
        #[arg(long = "add", required = true)]
        add: Vec<String>,
        /// Insert the first --add at this action (e.g. 'PickUp "Chips"') instead of the failing one.
        #[arg(long)]
        at: Option<String>,
        /// Start from this saved tree instead of planning.
        #[arg(long)]
        tree: Option<PathBuf>,
        /// Write the repaired tree here (atomically).
        #[arg(long)]
        save: Option<PathBuf>,
    },
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
}

pub fn run(cli: Cli) -> Result<ExitCode> {
    let glyphs = if cli.ascii {
        &betr::bt::ASCII
    } else {
        &betr::bt::UNICODE
    };
    match cli.command {
        Command::Plan { scenario, goal } => {
            tree_cmds::plan(&load(&scenario)?, goal.as_deref(), glyphs)
        }
        Command::Run {
            scenario,
            tree,
            trace,
            max_ticks,
        } => tree_cmds::run(&load(&scenario)?, tree.as_deref(), trace, max_ticks, glyphs),
        Command::Repair {
            scenario,
            add,
            at,
            tree,
            save,
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
            tree_cmds::repair(
                &scenario,
                &additions,
                at.as_ref(),
                tree.as_deref(),
                save.as_deref(),
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
