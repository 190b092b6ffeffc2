//! `betr plan`, `betr run`, `betr repair`.

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use betr::bt::path_text;
use betr::bt::{self, Glyphs, NodeId, NodeKind, TickRecord, Tree};
use betr::domain::{ActionCall, Condition};
use betr::planner::{Outcome, Plan, Planner, RunEnd, run_tree};
use betr::scenario::Scenario;
use betr::session::policy::{self, Approval, Fix, Policy};
use betr::world::{self, World};
use rerun::TextLogLevel as Level;

use super::values::Setting;
use super::viz_flags::{VizFlags, run_streamed};

const WORLD_FAILED: u8 = 1;

pub fn plan(scenario: &Scenario, goal: Option<&str>, glyphs: &Glyphs) -> Result<ExitCode> {
    let goal = super::goal_of(scenario, goal)?;
    let world = world::load(scenario)?;
    let dnf = goal.to_dnf();
    println!("Scenario: {}", scenario.name);
    println!("Goal:     {goal}");
    if dnf.is_false() {
        println!(
            "\nThe goal is contradictory: no state of the world satisfies it, so no tree can achieve it."
        );
        return Ok(ExitCode::from(WORLD_FAILED));
    }
    let started = Instant::now();
    let plan = Planner::new(&scenario.domain).plan(&dnf, world.as_ref())?;
    let elapsed = started.elapsed();
    println!(
        "Planned in {:.2} ms: {} expansion(s), {} reordering(s), {} simulated tick(s)\n",
        elapsed.as_secs_f64() * 1e3,
        plan.expansions,
        plan.reorders,
        plan.simulated_ticks
    );
    let record = final_record(scenario, &plan.tree, world.as_ref());
    print_tree(&plan.tree, record.as_ref(), glyphs);
    Ok(report_outcome(&plan))
}

pub fn run(
    scenario: &Scenario,
    tree_file: Option<&Path>,
    trace: bool,
    max_ticks: u64,
    variant: Option<&str>,
    viz: &VizFlags,
    glyphs: &Glyphs,
) -> Result<ExitCode> {
    let mut viz = viz.open(false)?;
    let world = world::load_variant(scenario, variant)?;
    let tree = match tree_file {
        Some(path) => super::export_cmd::load_tree(scenario, path)?.0,
        None => {
            let goal = super::goal_of(scenario, None)?;
            if let Some(v) = viz.as_mut() {
                v.log(Level::INFO, format!("goal: {goal}"));
            }
            Planner::new(&scenario.domain)
                .plan(&goal.to_dnf(), world.as_ref())?
                .tree
        }
    };
    let mut exec = world.fork();
    let report = run_streamed(
        &tree,
        exec.as_mut(),
        &scenario.domain,
        max_ticks,
        viz.as_mut(),
        |r| {
            if trace {
                print_trace(&tree, r);
            }
            true
        },
    );
    if let Some(v) = viz.as_mut() {
        v.log(Level::INFO, end_text(&report.end, &tree));
    }
    print_tree(&tree, report.last.as_ref(), glyphs);
    match report.end {
        RunEnd::Success => {
            println!("\nSUCCESS after {} tick(s)", report.ticks);
            Ok(ExitCode::SUCCESS)
        }
        RunEnd::Failure {
            action: Some((node, error)),
        } => {
            println!(
                "\nFAILED after {} tick(s) at {} (node {}): {error}",
                report.ticks,
                leaf_text(&tree, node),
                path_text(&tree.path(node).unwrap_or_default())
            );
            Ok(ExitCode::from(WORLD_FAILED))
        }
        RunEnd::Failure { action: None } => {
            println!(
                "\nFAILED after {} tick(s): the tree's conditions do not hold and nothing it can do changes that",
                report.ticks
            );
            Ok(ExitCode::from(WORLD_FAILED))
        }
        RunEnd::TickLimit => {
            println!("\nSTILL RUNNING after {} tick(s); stopped", report.ticks);
            Ok(ExitCode::from(WORLD_FAILED))
        }
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

pub fn repair(scenario: &Scenario, request: &RepairRequest, glyphs: &Glyphs) -> Result<ExitCode> {
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
    let mut viz = viz.open(false)?;
    let world = world::load_variant(scenario, variant)?;
    let planner = Planner::new(&scenario.domain);
    let mut plan = match tree_file {
        Some(path) => planner.grow(
            super::export_cmd::load_tree(scenario, path)?.0,
            world.as_ref(),
        ),
        None => planner.plan(&super::goal_of(scenario, None)?.to_dnf(), world.as_ref())?,
    };
    if viz.is_some() {
        // The run before the repair, so the recording shows what failed.
        let mut exec = world.fork();
        let before = run_streamed(
            &plan.tree,
            exec.as_mut(),
            &scenario.domain,
            planner.options.max_ticks,
            viz.as_mut(),
            |_| true,
        );
        if let Some(v) = viz.as_mut() {
            v.log(Level::INFO, end_text(&before.end, &plan.tree));
        }
    }
    if !settings.is_empty() {
        plan = apply_settings(plan, settings, &planner, world.as_ref())?;
    }
    // What each change was and the nodes it added, for the saved policy's header.
    let mut changes: Vec<(String, Vec<NodeId>)> = settings
        .iter()
        .map(|s| (format!("set {}", s.text), Vec::new()))
        .collect();
    for (i, conditions) in additions.iter().enumerate() {
        let at_action = if i == 0 { at } else { None };
        let (repaired, change) =
            add_conditions(plan, conditions, at_action, &planner, world.as_ref())?;
        plan = repaired;
        if let Some(v) = viz.as_mut() {
            v.log(
                Level::INFO,
                format!(
                    "repaired: inserted {}, {} node(s) added",
                    joined(conditions),
                    plan.new_nodes.len()
                ),
            );
        }
        changes.push((change, plan.new_nodes.clone()));
    }
    println!();
    let mut exec = world.fork();
    let report = run_streamed(
        &plan.tree,
        exec.as_mut(),
        &scenario.domain,
        planner.options.max_ticks,
        viz.as_mut(),
        |_| true,
    );
    if let Some(v) = viz.as_mut() {
        v.log(Level::INFO, end_text(&report.end, &plan.tree));
    }
    print_tree(&plan.tree, report.last.as_ref(), glyphs);
    println!("\n{}", bt::to_text(&plan.tree));
    if let Some(path) = save {
        let saved = repaired_policy(scenario, scenario_path, &plan.tree, &changes)?;
        betr::store::write_atomic(path, policy::render(&saved).as_bytes())
            .with_context(|| format!("saving the repaired tree to {}", path.display()))?;
        println!("Saved to {}", path.display());
    }
    match report.end {
        RunEnd::Success => {
            println!("SUCCESS after {} tick(s)", report.ticks);
            Ok(ExitCode::SUCCESS)
        }
        _ => {
            println!(
                "The repaired tree still fails: {}",
                describe(&plan.outcome, &plan.tree)
            );
            Ok(ExitCode::from(WORLD_FAILED))
        }
    }
}

/// Set each `--set` value on every action of the tree that uses it, then grow the tree
/// again; says what was set.
fn apply_settings(
    plan: Plan,
    settings: &[Setting],
    planner: &Planner,
    world: &dyn World,
) -> Result<Plan> {
    if let Outcome::ActionFailed { action, error, .. } = &plan.outcome {
        println!("{action}! failed in simulation: {error}");
    }
    let mut tree = plan.tree;
    for setting in settings {
        let changed = super::values::apply(&mut tree, setting);
        if changed == 0 {
            bail!(
                "--set {:?}: no action of the tree uses {} with {:?}",
                setting.text,
                setting
                    .targets
                    .iter()
                    .map(|(s, _)| s.as_str())
                    .collect::<Vec<_>>()
                    .join(" or "),
                setting.object
            );
        }
        println!(
            "Setting {} = {} for {:?} on {changed} action(s)",
            setting
                .targets
                .first()
                .map(|(_, n)| n.as_str())
                .unwrap_or_default(),
            setting.value,
            setting.object
        );
    }
    Ok(planner.grow(tree, world))
}

/// Insert `conditions` before `at`, or as the first preconditions of the action that
/// fails in simulation; the repaired plan and the change in words (for the policy).
fn add_conditions(
    plan: Plan,
    conditions: &[Condition],
    at: Option<&ActionCall>,
    planner: &Planner,
    world: &dyn World,
) -> Result<(Plan, String)> {
    let names = joined(conditions);
    let change = match (&plan.outcome, at) {
        (_, Some(action)) => format!("insert {names} before {action}!"),
        (Outcome::ActionFailed { action, .. }, None) => {
            format!("insert {names} as the first precondition(s) of {action}!")
        }
        _ => format!("insert {names}"),
    };
    let repaired = match (&plan.outcome, at) {
        (_, Some(action)) => {
            println!("Inserting {names} before {action}!");
            planner.repair_at(plan.tree, action, conditions, world)?
        }
        (
            Outcome::ActionFailed {
                node,
                action,
                error,
            },
            None,
        ) => {
            println!(
                "{action}! failed in simulation: {error}\nInserting {names} as its first precondition(s)"
            );
            planner.repair(plan.tree, *node, conditions, world)?
        }
        (Outcome::Success, None) => {
            bail!("the tree already succeeds before --add {names:?}: nothing fails to repair")
        }
        (other, None) => bail!("cannot repair: {}", describe(other, &plan.tree)),
    };
    println!(
        "  added {} node(s), {} expansion(s)",
        repaired.new_nodes.len(),
        repaired.expansions
    );
    Ok((repaired, change))
}

/// Conditions as `A & ~B`.
fn joined(conditions: &[Condition]) -> String {
    conditions
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(" & ")
}

/// How a run ended, as one line of the event log.
fn end_text(end: &RunEnd, tree: &Tree) -> String {
    match end {
        RunEnd::Success => "success".into(),
        RunEnd::Failure {
            action: Some((node, error)),
        } => format!("{} failed: {error}", leaf_text(tree, *node)),
        RunEnd::Failure { action: None } => "the tree failed".into(),
        RunEnd::TickLimit => "still running at the tick limit".into(),
    }
}

/// The repaired tree as a policy: the scenario, its goal, and per change the nodes it
/// added (so `betr export` can mark them), written by a person on the command line.
fn repaired_policy(
    scenario: &Scenario,
    scenario_path: &Path,
    tree: &Tree,
    changes: &[(String, Vec<NodeId>)],
) -> Result<Policy> {
    let at = policy::now_rfc3339();
    Ok(Policy {
        scenario: format!("{} ({})", scenario_path.display(), scenario.name),
        instruction: scenario.instruction.clone(),
        goal: super::goal_of(scenario, None)?.to_string(),
        saved_at: at.clone(),
        fixes: changes
            .iter()
            .map(|(change, nodes)| Fix {
                change: change.clone(),
                nodes: nodes
                    .iter()
                    .filter_map(|n| tree.path(*n).ok())
                    .map(|p| path_text(&p))
                    .collect(),
                model: "a person (betr repair)".into(),
                approval: Approval::Edited,
                at: at.clone(),
            })
            .collect(),
        tree: tree.clone(),
    })
}

/// The statuses of a full run of `tree` in a fresh copy of the scenario's world.
pub(super) fn final_record(
    scenario: &Scenario,
    tree: &Tree,
    world: &dyn World,
) -> Option<TickRecord> {
    let mut sim = world.fork();
    run_tree(
        tree,
        sim.as_mut(),
        &scenario.domain,
        Planner::new(&scenario.domain).options.max_ticks,
        |_, _| true,
    )
    .last
}

fn print_tree(tree: &Tree, record: Option<&TickRecord>, glyphs: &Glyphs) {
    for line in bt::render(tree, record, glyphs) {
        println!("{line}");
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
    println!("{line}");
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

fn describe(outcome: &Outcome, tree: &Tree) -> String {
    match outcome {
        Outcome::Success => "the tree succeeds in simulation".into(),
        Outcome::ActionFailed {
            node,
            action,
            error,
        } => format!(
            "{action}! (node {}) failed in simulation: {error}",
            path_text(&tree.path(*node).unwrap_or_default())
        ),
        Outcome::Unreachable {
            condition,
            path,
            reason,
            ..
        } => format!(
            "{condition}? (node {}) cannot be achieved: {reason}",
            path_text(path)
        ),
        Outcome::Exhausted { reason } => reason.clone(),
    }
}

fn report_outcome(plan: &Plan) -> ExitCode {
    println!("\n{}", describe(&plan.outcome, &plan.tree));
    match plan.outcome {
        Outcome::Success => ExitCode::SUCCESS,
        _ => ExitCode::from(WORLD_FAILED),
    }
}
