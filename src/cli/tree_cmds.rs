//! `betr plan`, `betr run`, `betr repair`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};

use betr::bt::{self, Glyphs, NodeKind, TickRecord, Tree};
use betr::domain::{ActionCall, Condition};
use betr::scenario::Scenario;
use betr::session::{BreakReason, Command, RunLimits};

use super::engine_driver::{Driver, Run, RunEnd, Start};
use super::values::Setting;
use super::viz_flags::VizFlags;

const WORLD_FAILED: u8 = 1;
/// `betr run --break`: a breakpoint stopped the run (neither success nor failure).
const STOPPED_AT_BREAKPOINT: u8 = 3;

/// What `betr run` is asked.
#[derive(clap::Args)]
pub struct RunArgs {
    pub scenario: PathBuf,
    /// A tree file to run instead of planning one (betr text, a saved policy, or
    /// BehaviorTree.CPP v4 XML).
    #[arg(long)]
    pub tree: Option<PathBuf>,
    /// Print the running action and failures at every tick.
    #[arg(long)]
    pub trace: bool,
    /// Give up after this many ticks.
    #[arg(value_parser = clap::value_parser!(u64).range(1..=1_000_000_000), long, default_value_t = betr::session::RunLimits::DEFAULT.run_ticks)]
    pub max_ticks: u64,
    /// Run in the scenario's `[world.variants.NAME]` world (e.g. `clear`: without the obstacle).
    #[arg(long)]
    pub variant: Option<String>,
    /// Stop before the tick that would enter NODE: a node path as the tree prints it
    /// (`1.0.1.1`) or a leaf as it shows (`grasp "blue cube"!`, every leaf with that
    /// text); repeatable. Stopped at a breakpoint, the exit status is 3.
    #[arg(long = "break", value_name = "NODE")]
    pub breaks: Vec<String>,
    /// Stop after a tick in which a node that succeeded or ran fails, or an action fails
    /// while the tree goes on (exit status 3).
    #[arg(long)]
    pub break_on_failure: bool,
    /// Perform the actions in `mujoco` (the cell in MuJoCo physics, installed on first
    /// use) or in this program (a simulator or a robot bridge speaking betr's executor
    /// protocol: docs/EXECUTORS.md) instead of betr's world, which becomes its twin; split
    /// as a shell would: `--executor "python3 sim.py --seed 3"`.
    #[arg(long, value_name = "COMMAND")]
    pub executor: Option<String>,
    #[command(flatten)]
    pub viz: super::viz_flags::VizFlags,
    #[command(flatten)]
    pub knowledge: super::knowledge_cmd::KnowledgeFlags,
}

/// What `betr repair` is asked.
#[derive(clap::Args)]
pub struct RepairArgs {
    pub scenario: PathBuf,
    /// Conditions to insert (a conjunction: 'A & B'); repeat for successive failures.
    #[arg(long = "add", required_unless_present = "set")]
    pub add: Vec<String>,
    /// A value parameter for every action that uses it with the object, e.g.
    /// "force of egg = 5 N" (repeatable; applied before any --add).
    #[arg(long = "set")]
    pub set: Vec<String>,
    /// Insert the first --add at this action (e.g. 'PickUp "Chips"') instead of the failing one.
    #[arg(long)]
    pub at: Option<String>,
    /// Start from this tree file instead of planning (betr text, a saved policy, or
    /// BehaviorTree.CPP v4 XML).
    #[arg(long)]
    pub tree: Option<PathBuf>,
    /// Write the repaired tree here (atomically).
    #[arg(long)]
    pub save: Option<PathBuf>,
    /// Plan and repair in the scenario's `[world.variants.NAME]` world.
    #[arg(long)]
    pub variant: Option<String>,
    #[command(flatten)]
    pub viz: super::viz_flags::VizFlags,
    #[command(flatten)]
    pub knowledge: super::knowledge_cmd::KnowledgeFlags,
}

/// `betr run`: the scenario's planned tree (or a tree file) run in a fresh world.
pub fn run_command(args: &RunArgs, glyphs: &Glyphs) -> Result<ExitCode> {
    let scenario = super::load_with(&args.scenario, &args.knowledge)?;
    run(&scenario, args, glyphs)
}

/// `betr repair`: the flags read against the scenario, then the repair.
pub fn repair_command(args: &RepairArgs, glyphs: &Glyphs) -> Result<ExitCode> {
    let scenario_path = super::find_scenario(&args.scenario)?;
    let scenario = super::load_with(&scenario_path, &args.knowledge)?;
    if let Some(path) = &args.save {
        betr::store::check_writable(path).context("--save")?;
    }
    let additions = args
        .add
        .iter()
        .map(|a| super::parse_conditions(&scenario, a))
        .collect::<Result<Vec<_>>>()?;
    let at = args
        .at
        .as_deref()
        .map(|a| {
            ActionCall::parse(a)
                .with_context(|| format!("--at {a:?} is not an action like 'PickUp \"Chips\"'"))
        })
        .transpose()?;
    let settings = args
        .set
        .iter()
        .map(|s| super::values::parse_setting(&scenario, s))
        .collect::<Result<Vec<_>>>()?;
    repair(
        &scenario,
        &RepairRequest {
            scenario_path: &scenario_path,
            additions: &additions,
            settings: &settings,
            at: at.as_ref(),
            tree_file: args.tree.as_deref(),
            save: args.save.as_deref(),
            variant: args.variant.as_deref(),
            viz: &args.viz,
        },
        glyphs,
    )
}

pub fn plan(scenario: &Scenario, goal: Option<&str>, glyphs: &Glyphs) -> Result<ExitCode> {
    let goal_given = goal.is_some();
    let goal = super::goal_of(scenario, goal)?;
    outln!("Scenario: {}", scenario.name);
    outln!("Goal:     {goal}");
    if goal.to_dnf().is_false() {
        outln!(
            "\nThe goal is contradictory: no state of the world satisfies it, so no tree can achieve it."
        );
        return Ok(ExitCode::from(WORLD_FAILED));
    }
    let mut session = Driver::start(Start::new(scenario))?;
    let summary = session.plan(goal_given.then_some(goal))?;
    outln!(
        "Planned in {:.2} ms: {} expansion(s), {} reordering(s), {} simulated tick(s)\n",
        summary.elapsed.as_secs_f64() * 1e3,
        summary.expansions,
        summary.reorders,
        summary.simulated_ticks
    );
    let run = session.run(|_| {})?;
    print_tree(&*session.tree()?, run.last.as_deref(), glyphs);
    outln!("\n{}", summary.prediction);
    Ok(if summary.prediction.is_success() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(WORLD_FAILED)
    })
}

fn run(scenario: &Scenario, args: &RunArgs, glyphs: &Glyphs) -> Result<ExitCode> {
    let (variant, viz) = (args.variant.as_deref(), &args.viz);
    let start = Start {
        variant,
        limits: RunLimits {
            run_ticks: args.max_ticks,
            ..RunLimits::DEFAULT
        },
        viz: viz.open(false, betr::viz::ViewerLife::OutlivesCommand, scenario)?,
        record: viz.recorder(scenario, &scenario_file(scenario), variant)?,
        executor: super::executor_of(args.executor.as_deref())?,
        ..Start::new(scenario)
    };
    let mut session = with_tree(start, args.tree.as_deref(), false)?;
    let tree = session.tree()?;
    let mut breaks = Vec::new();
    for text in &args.breaks {
        breaks.extend(
            tree.find(text)
                .with_context(|| format!("--break {text:?}"))?,
        );
    }
    if !breaks.is_empty() || args.break_on_failure {
        session.set_breakpoints(&breaks, args.break_on_failure)?;
    }
    let run = session.run(|r| {
        if args.trace {
            print_trace(&tree, r);
        }
    })?;
    print_tree(&tree, run.last.as_deref(), glyphs);
    outln!("\n{}", run_end_text(&run, &tree));
    Ok(match run.end {
        RunEnd::Success { .. } => ExitCode::SUCCESS,
        RunEnd::Break { .. } => ExitCode::from(STOPPED_AT_BREAKPOINT),
        _ => ExitCode::from(WORLD_FAILED),
    })
}

/// The file a scenario was loaded from.
fn scenario_file(scenario: &Scenario) -> PathBuf {
    scenario
        .files
        .last()
        .map(|f| f.path.clone())
        .unwrap_or_default()
}

/// An engine with its tree: the file's (`grow`: expanded in this world) or the one planned
/// for the scenario's goal.
fn with_tree(start: Start, tree_file: Option<&Path>, grow: bool) -> Result<Driver> {
    let scenario = start.scenario;
    let mut session = Driver::start(start)?;
    match tree_file {
        Some(path) => {
            session.load(path.to_path_buf(), grow)?;
        }
        None => {
            super::goal_of(scenario, None)?;
            session.plan(None)?;
        }
    }
    Ok(session)
}

/// How a run ended, as `betr run` and `betr repair` say it.
fn run_end_text(run: &Run, tree: &Tree) -> String {
    match &run.end {
        RunEnd::Success { executor } => betr::tui::strings::success(run.ticks, executor.as_deref()),
        RunEnd::ActionFailed {
            action,
            node_path,
            error,
        } => format!(
            "FAILED after {} tick(s) at {action}! (node {node_path}): {error}",
            run.ticks
        ),
        RunEnd::Stopped { .. } if run.still_running() => {
            format!("STILL RUNNING after {} tick(s); stopped", run.ticks)
        }
        RunEnd::Stopped { .. } => format!(
            "FAILED after {} tick(s): the tree's conditions do not hold and nothing it can do changes that",
            run.ticks
        ),
        RunEnd::Break {
            node,
            node_path,
            tick,
            reason: BreakReason::Breakpoint,
        } => format!(
            "BREAKPOINT at {} (node {node_path}) before tick {tick}",
            leaf_text(tree, *node)
        ),
        RunEnd::Break {
            node,
            node_path,
            tick,
            reason: BreakReason::Failure,
        } => format!(
            "BREAKPOINT on failure at {} (node {node_path}): it failed in tick {tick}",
            leaf_text(tree, *node)
        ),
    }
}

/// Why a run did not succeed, as the planner says it of its simulation.
fn failure_text(end: &RunEnd) -> String {
    match end {
        RunEnd::Success { .. } => "it succeeds".into(),
        RunEnd::ActionFailed {
            action,
            node_path,
            error,
        } => format!("{action}! (node {node_path}) failed in simulation: {error}"),
        RunEnd::Stopped { reason } => reason.clone(),
        RunEnd::Break { node_path, .. } => format!("the run stopped at node {node_path}"),
    }
}

/// What `betr repair` was asked to do.
pub struct RepairRequest<'a> {
    pub scenario_path: &'a Path,
    pub additions: &'a [Vec<Condition>],
    pub settings: &'a [Setting],
    pub at: Option<&'a ActionCall>,
    pub tree_file: Option<&'a Path>,
    pub save: Option<&'a Path>,
    pub variant: Option<&'a str>,
    pub viz: &'a VizFlags,
}

fn repair(scenario: &Scenario, request: &RepairRequest, glyphs: &Glyphs) -> Result<ExitCode> {
    let RepairRequest {
        scenario_path,
        additions,
        settings,
        at,
        tree_file,
        save,
        variant,
        viz,
    } = *request;
    let start = Start {
        scenario_path: Some(scenario_path),
        variant,
        viz: viz.open(false, betr::viz::ViewerLife::OutlivesCommand, scenario)?,
        record: viz.recorder(scenario, scenario_path, variant)?,
        ..Start::new(scenario)
    };
    let mut session = with_tree(start, tree_file, true)?;
    // The run before the repair finds the failure (and shows it in the 3D view).
    let mut before = session.run(|_| {})?;
    if !settings.is_empty() {
        if let RunEnd::ActionFailed { action, error, .. } = &before.end {
            outln!("{action}! failed in simulation: {error}");
        }
        for setting in settings {
            apply_setting(&mut session, setting)?;
        }
        before = session.run(|_| {})?;
    }
    for (i, conditions) in additions.iter().enumerate() {
        let at_action = if i == 0 { at } else { None };
        add_conditions(&mut session, &before, conditions, at_action)?;
        before = session.run(|_| {})?;
    }
    // Saved before anything is printed: the tree is kept whatever happens to the output.
    if let Some(path) = save {
        session
            .save(path.to_path_buf())
            .with_context(|| format!("saving the repaired tree to {}", path.display()))?;
    }
    outln!();
    let tree = session.tree()?;
    print_tree(&tree, before.last.as_deref(), glyphs);
    outln!("\n{}", bt::to_text(&tree));
    if let Some(path) = save {
        outln!("Saved to {}", path.display());
    }
    match before.end {
        RunEnd::Success { .. } => {
            outln!("SUCCESS after {} tick(s)", before.ticks);
            Ok(ExitCode::SUCCESS)
        }
        _ => {
            outln!(
                "The repaired tree still fails: {}",
                failure_text(&before.end)
            );
            Ok(ExitCode::from(WORLD_FAILED))
        }
    }
}

/// Set a `--set` value on every action of the tree that uses it; the engine grows the
/// tree again.
fn apply_setting(session: &mut Driver, setting: &Setting) -> Result<()> {
    let change = session
        .change(Command::SetValue(setting.clone()))
        .with_context(|| format!("--set {:?}", setting.text))?;
    outln!(
        "Setting {} = {} for {:?} on {} action(s)",
        setting
            .targets
            .first()
            .map(|(_, n)| n.as_str())
            .unwrap_or_default(),
        setting.value,
        setting.object,
        change.valued_nodes
    );
    Ok(())
}

/// Insert `conditions` before `at`, or as the first preconditions of the action that
/// failed in the run before.
fn add_conditions(
    session: &mut Driver,
    before: &Run,
    conditions: &[Condition],
    at: Option<&ActionCall>,
) -> Result<()> {
    let names = joined(conditions);
    match (&before.end, at) {
        (_, Some(action)) => outln!("Inserting {names} before {action}!"),
        (RunEnd::ActionFailed { action, error, .. }, None) => outln!(
            "{action}! failed in simulation: {error}\nInserting {names} as its first precondition(s)"
        ),
        (RunEnd::Success { .. }, None) => {
            bail!("the tree already succeeds before --add {names:?}: nothing fails to repair")
        }
        (RunEnd::Stopped { reason }, None) => bail!("cannot repair: {reason}"),
        (RunEnd::Break { node_path, .. }, None) => {
            bail!("cannot repair: the run stopped at node {node_path}, before anything failed")
        }
    }
    let change = session.change(Command::Insert {
        conditions: conditions.to_vec(),
        before: at.cloned(),
        author: "a person (betr repair)".into(),
    })?;
    outln!(
        "  added {} node(s), {} expansion(s)",
        change.added_nodes,
        change.summary.map_or(0, |s| s.expansions)
    );
    Ok(())
}

/// Conditions as `A & ~B`.
fn joined(conditions: &[Condition]) -> String {
    conditions
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(" & ")
}

fn print_tree(tree: &Tree, record: Option<&TickRecord>, glyphs: &Glyphs) {
    for line in bt::render(tree, record, glyphs) {
        outln!("{line}");
    }
}

fn print_trace(tree: &Tree, record: &TickRecord) {
    let running = record.running_action().map(|n| leaf_text(tree, n));
    let mut line = format!("tick {:>4}: {:?}", record.tick, record.root);
    if let Some(r) = running {
        line.push_str(&format!(", running {r}"));
    }
    for (node, error) in &record.failures {
        line.push_str(&format!(", {} failed: {error}", leaf_text(tree, *node)));
    }
    for node in &record.halted {
        line.push_str(&format!(", halted {}", leaf_text(tree, *node)));
    }
    outln!("{line}");
}

fn leaf_text(tree: &Tree, node: bt::NodeId) -> String {
    match tree.kind(node) {
        Ok(NodeKind::Action(a)) => format!("{a}!"),
        Ok(NodeKind::Condition(c)) => format!("{c}?"),
        Ok(NodeKind::Sequence) => "sequence".into(),
        Ok(NodeKind::Fallback) => "fallback".into(),
        Err(_) => format!("{node:?}"),
    }
}
