//! The resolve loop, headless: interpret the instruction with a language model, plan a
//! tree, simulate it; when an action fails, ask the model for the missing preconditions
//! (or the missing parameter value), let a person approve the proposal, repair the tree and
//! simulate again, until the tree succeeds or the rounds run out.
//!
//! Front ends pass an approval callback and an event sink; the loop never prints. A
//! proposal that does not change the failure is reported and undone, so the tree only
//! ever keeps changes that helped.
use crate::bt::Tree;
use crate::domain::{Condition, Scenario};
use crate::llm::LanguageModel;
use crate::llm::prompt::Context;
use crate::planner::{Outcome, Plan, Planner, RepairError, RunEnd, path_text, run_tree};
use crate::world::{self, World};

use super::ask::{ask_conditions, ask_value, interpret, missing_value};
use super::types::{Ending, Event, Options, Proposal, Resolved, SessionError};

/// The whole loop for `scenario`: `instruction` (else the scenario's) → goal → tree → success.
pub async fn resolve(
    scenario: &Scenario,
    instruction: Option<&str>,
    model: &dyn LanguageModel,
    options: &Options,
    approve: &mut dyn FnMut(&Proposal) -> bool,
    emit: &mut dyn FnMut(&Event),
) -> Result<Resolved, SessionError> {
    let instruction = instruction
        .map(str::to_string)
        .or_else(|| scenario.instruction.clone())
        .ok_or_else(|| SessionError::NoInstruction(scenario.name.clone()))?;
    let world = world::load(scenario)?;
    let answer = interpret(scenario, &world.facts(), &instruction, model, options, emit).await?;
    let planner = Planner::new(&scenario.domain);
    let mut plan = planner.plan(&answer.goal.to_dnf(), world.as_ref())?;
    let mut rounds = 0;
    let mut repairs = 0;
    let ending = loop {
        let (node, action, error) = match &plan.outcome {
            Outcome::Success => break confirm(scenario, &plan.tree, world.as_ref()),
            Outcome::ActionFailed {
                node,
                action,
                error,
            } => (*node, action.clone(), error.clone()),
            other => {
                break Ending::GaveUp {
                    reason: describe(other),
                };
            }
        };
        emit(&Event::ActionFailed {
            action: action.clone(),
            node_path: path_text(&plan.tree.path(node).unwrap_or_default()),
            error: error.clone(),
        });
        if rounds >= options.max_rounds {
            break Ending::GaveUp {
                reason: format!(
                    "{} round(s) asked and {action}! still fails: {error}",
                    rounds
                ),
            };
        }
        rounds += 1;
        let facts = facts_at_failure(scenario, &plan.tree, world.as_ref());
        let ctx = Context {
            scenario,
            facts: &facts,
            instruction: &instruction,
            variant: &options.variant,
        };
        let proposed = match missing_value(scenario, &action, &error) {
            Some(param) => ask_value(&ctx, model, options, &action, param, &error, emit).await?,
            None => ask_conditions(&ctx, model, options, node, &action, &error, emit).await?,
        };
        let Some((proposal, reasoning, substitutions)) = proposed else {
            continue;
        };
        emit(&Event::Proposal {
            proposal: proposal.clone(),
            reasoning,
            substitutions,
        });
        if !approve(&proposal) {
            emit(&Event::Rejected);
            break Ending::Rejected;
        }
        emit(&Event::Approved);
        let (next, valued_nodes) = match apply(&planner, &plan.tree, &proposal, world.as_ref()) {
            Ok(next) => next,
            Err(e) => {
                emit(&Event::DidNotHelp {
                    reason: e.to_string(),
                });
                continue;
            }
        };
        match helped(&plan.outcome, &next.outcome) {
            Ok(()) => {
                emit(&Event::Repaired {
                    added_nodes: next.new_nodes.len(),
                    valued_nodes,
                });
                repairs += 1;
                plan = next;
            }
            Err(reason) => emit(&Event::DidNotHelp { reason }),
        }
    };
    match &ending {
        Ending::Success { ticks } => emit(&Event::Success { ticks: *ticks }),
        Ending::GaveUp { reason } => emit(&Event::GaveUp {
            reason: reason.clone(),
        }),
        Ending::Rejected => {}
    }
    Ok(Resolved {
        goal: answer.goal,
        tree: plan.tree,
        ending,
        rounds,
        repairs,
    })
}

fn apply(
    planner: &Planner,
    tree: &Tree,
    proposal: &Proposal,
    world: &dyn World,
) -> Result<(Plan, usize), RepairError> {
    match proposal {
        Proposal::Conditions {
            node, conditions, ..
        } => Ok((planner.repair(tree.clone(), *node, conditions, world)?, 0)),
        Proposal::Value {
            skill,
            object,
            param,
            value,
        } => {
            let mut tree = tree.clone();
            let changed = crate::planner::set_value(&mut tree, skill, object, param, value);
            Ok((planner.grow(tree, world), changed))
        }
    }
}

/// Whether a change helped: the failure is gone or has moved on.
fn helped(before: &Outcome, after: &Outcome) -> Result<(), String> {
    match (before, after) {
        (_, Outcome::Success) => Ok(()),
        (
            Outcome::ActionFailed {
                action: a,
                error: e,
                ..
            },
            Outcome::ActionFailed {
                action: b,
                error: f,
                ..
            },
        ) if a.same_invocation(b) && e == f => {
            Err(format!("{b}! still fails with the same error: {f}"))
        }
        (_, Outcome::ActionFailed { .. }) => Ok(()),
        (_, other) => Err(format!("after the change, {}", describe(other))),
    }
}

fn describe(outcome: &Outcome) -> String {
    match outcome {
        Outcome::Success => "the tree succeeds".into(),
        Outcome::ActionFailed { action, error, .. } => format!("{action}! fails: {error}"),
        Outcome::Unreachable {
            condition, reason, ..
        } => format!("{condition} cannot be achieved: {reason}"),
        Outcome::Exhausted { reason } => reason.clone(),
    }
}

/// The facts when the tree stops in a fresh simulation (where the failure happens).
fn facts_at_failure(scenario: &Scenario, tree: &Tree, world: &dyn World) -> Vec<Condition> {
    let mut sim = world.fork();
    let mut facts = sim.facts();
    let max = Planner::new(&scenario.domain).options.max_ticks;
    run_tree(tree, sim.as_mut(), &scenario.domain, max, |_, w| {
        facts = w.facts();
        true
    });
    facts
}

/// Run the tree in a fresh copy of the world: success must be seen, not assumed.
fn confirm(scenario: &Scenario, tree: &Tree, world: &dyn World) -> Ending {
    let mut sim = world.fork();
    let max = Planner::new(&scenario.domain).options.max_ticks;
    let report = run_tree(tree, sim.as_mut(), &scenario.domain, max, |_, _| true);
    match report.end {
        RunEnd::Success => Ending::Success {
            ticks: report.ticks,
        },
        RunEnd::Failure { .. } => Ending::GaveUp {
            reason: "the planner reported success but the tree fails when run".into(),
        },
        RunEnd::TickLimit => Ending::GaveUp {
            reason: format!("the tree still runs after {} ticks", report.ticks),
        },
    }
}
