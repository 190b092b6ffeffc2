//! Trying a proposed change in simulation: the tree with the change applied is re-planned
//! in a copy of the planning world (the cell's own motion checks, the symbolic world's
//! hidden rules), and the change counts as helping only if the failure it was asked about
//! is gone or has moved on. Proposals are screened this way before anyone is asked to
//! approve them, and an approved change is checked the same way before it is kept.

use crate::bt::{NodeId, NodeKind, Tree};
use crate::domain::{ActionCall, Condition};
use crate::planner::{Outcome, Plan, Planner, RepairError, run_tree, set_value};
use crate::verify::{self, Checks, VerifyConfig};
use crate::world::World;

use super::super::types::Proposal;

/// The failure a change is meant to fix.
#[derive(Debug, Clone, PartialEq)]
pub struct FailureAt {
    pub node: NodeId,
    pub action: ActionCall,
    pub error: String,
}

impl FailureAt {
    /// Whether `outcome` is this failure again: the same action failing with the same
    /// error.
    fn recurs_in(&self, outcome: &Outcome) -> bool {
        matches!(outcome, Outcome::ActionFailed { action, error, .. }
            if self.action.same_invocation(action) && &self.error == error)
    }
}

/// The tree with a proposal applied, re-planned; and on how many actions a value was set.
pub fn apply(
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
            let changed = set_value(&mut tree, skill, object, param, value);
            Ok((planner.grow(tree, world), changed))
        }
    }
}

/// How a change that helped helped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The whole tree succeeds.
    Succeeds,
    /// The failure is gone; the tree now stops at an action it had before the change.
    MovesOn,
    /// The failure is gone; the tree now stops at an action the change brought in.
    FailsItself,
}

/// Why a change did not help, in words the model can be told.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotHelped {
    #[error("{action}! still fails with the same error: {error}")]
    SameFailure { action: ActionCall, error: String },
    #[error("after the change, {condition} cannot be achieved: {reason}")]
    Unreachable {
        condition: Condition,
        reason: String,
    },
    #[error("after the change, {0}")]
    Exhausted(String),
    /// A value after which the action that needed it still fails (with another error).
    #[error("{action}! failed: {error}")]
    ValueFails { action: ActionCall, error: String },
    #[error(
        "the tree then succeeds without {0}! ever completing: the change closes the action's branch instead of giving it what it lacks"
    )]
    GoesAround(ActionCall),
    #[error("{0}")]
    NotApplied(String),
}

/// Whether a change helped: the failure is gone or has moved on.
pub fn helped(before: Option<&FailureAt>, after: &Outcome) -> Result<(), NotHelped> {
    verdict(before, after).map(|_| ())
}

fn verdict(before: Option<&FailureAt>, after: &Outcome) -> Result<Verdict, NotHelped> {
    match (before, after) {
        (_, Outcome::Success) => Ok(Verdict::Succeeds),
        (Some(f), Outcome::ActionFailed { action, error, .. }) if f.recurs_in(after) => {
            Err(NotHelped::SameFailure {
                action: action.clone(),
                error: error.clone(),
            })
        }
        (_, Outcome::ActionFailed { .. }) => Ok(Verdict::MovesOn),
        (
            _,
            Outcome::Unreachable {
                condition, reason, ..
            },
        ) => Err(NotHelped::Unreachable {
            condition: condition.clone(),
            reason: reason.clone(),
        }),
        (_, Outcome::Exhausted { reason }) => Err(NotHelped::Exhausted(reason.clone())),
    }
}

/// A copy of the tree and the planning world in which proposals are tried before they
/// are offered. Owned, so a model call can carry it across its awaits.
pub struct Screen {
    pub scenario: std::sync::Arc<crate::scenario::Scenario>,
    pub tree: Tree,
    pub world: Box<dyn World>,
    pub failure: FailureAt,
}

impl Screen {
    /// Ok when `proposal` fixes the failure in simulation; otherwise what happened, in
    /// words the model can be told. A value passes only when the action that needed it
    /// no longer fails at all (a different error of the same action, such as "the hammer
    /// slips" after "no grasp force", means the value is wrong).
    pub fn check(&self, proposal: &Proposal) -> Result<(), NotHelped> {
        self.try_change(proposal).map(|_| ())
    }

    /// Whether, with `proposal` applied and carried out, the failing action still fails
    /// with the same error: what the change made true is not what the action lacks.
    pub fn still_fails(&self, proposal: &Proposal) -> bool {
        self.replan(proposal)
            .is_ok_and(|plan| self.failure.recurs_in(&plan.outcome))
    }

    /// The copy of the tree with `proposal` applied, re-planned in the copy of the world.
    fn replan(&self, proposal: &Proposal) -> Result<Plan, RepairError> {
        let planner = Planner::new(&self.scenario.domain);
        apply(&planner, &self.tree, proposal, self.world.as_ref()).map(|(plan, _)| plan)
    }

    /// Whether the tree as it is fails in this copy of the world as it did: a world that
    /// lacks what the failure came from (a twin without the hidden rule, a scene without
    /// the physics) runs it to success, and then no change can be told from another.
    pub fn reproduces(&self) -> bool {
        let mut sim = self.world.fork();
        let planner = Planner::new(&self.scenario.domain);
        let report = run_tree(
            &self.tree,
            sim.as_mut(),
            &self.scenario.domain,
            planner.options.max_ticks,
            |_, _| true,
        );
        !matches!(report.end, crate::planner::RunEnd::Success)
    }

    /// Whether running `tree` in a copy of the world completes the failed action.
    fn completes_failed_action(&self, tree: &Tree) -> bool {
        let mut sim = self.world.fork();
        let mut completed = false;
        let planner = Planner::new(&self.scenario.domain);
        run_tree(
            tree,
            sim.as_mut(),
            &self.scenario.domain,
            planner.options.max_ticks,
            |record, _| {
                completed |= record.completed.iter().any(|n| {
                    matches!(tree.kind(*n), Ok(NodeKind::Action(a)) if a.same_invocation(&self.failure.action))
                });
                !completed
            },
        );
        completed
    }

    /// The conditions of `fixes` after which the tree breaks a property the scenario
    /// declares that the tree as it is keeps, each with that property: a fix that makes
    /// the robot do what the scenario forbids is not offered. Verified in the planner's
    /// model, as an approved change is; nothing to check when the scenario declares no
    /// property (or its checks cannot be read: the change's own check says why).
    pub fn breaking(&self, fixes: &[Condition]) -> Vec<(Condition, String)> {
        let Ok(config) = VerifyConfig::from_scenario(&self.scenario) else {
            return Vec::new();
        };
        if config.properties.is_empty() {
            return Vec::new();
        }
        let initial = self.world.facts();
        let checks = Checks::declared(config);
        let broken = |tree: &Tree| {
            let report = verify::verify(&checks.input(&self.scenario.domain, tree, &initial));
            report
                .failures()
                .into_iter()
                .filter(|f| report.is_declared_property(f))
                .collect::<Vec<String>>()
        };
        let before = broken(&self.tree);
        fixes
            .iter()
            .filter_map(|condition| {
                let plan = self
                    .replan(&Proposal::Conditions {
                        action: self.failure.action.clone(),
                        node: self.failure.node,
                        conditions: vec![condition.clone()],
                    })
                    .ok()?;
                broken(&plan.tree)
                    .into_iter()
                    .find(|f| !before.contains(f))
                    .map(|f| (condition.clone(), f))
            })
            .collect()
    }

    /// As [`Screen::check`], saying whether the whole tree then succeeds.
    pub fn try_change(&self, proposal: &Proposal) -> Result<Verdict, NotHelped> {
        let plan = self
            .replan(proposal)
            .map_err(|e| NotHelped::NotApplied(e.to_string()))?;
        if let (Proposal::Value { .. }, Outcome::ActionFailed { action, error, .. }) =
            (proposal, &plan.outcome)
            && self.failure.action.same_invocation(action)
        {
            return Err(NotHelped::ValueFails {
                action: action.clone(),
                error: error.clone(),
            });
        }
        let verdict = verdict(Some(&self.failure), &plan.outcome)?;
        // A missing precondition lets the action succeed. A condition after which the
        // tree succeeds without the action ever completing only closes its branch, so a
        // goal with alternatives takes another way ("the chips somewhere else" makes the
        // robot bring the dessert): that goes around the failure, it does not fix it.
        if matches!(proposal, Proposal::Conditions { .. })
            && verdict == Verdict::Succeeds
            && !self.completes_failed_action(&plan.tree)
        {
            return Err(NotHelped::GoesAround(self.failure.action.clone()));
        }
        Ok(match &plan.outcome {
            Outcome::ActionFailed { node, .. } if node.index() >= self.tree.capacity() => {
                Verdict::FailsItself
            }
            _ => verdict,
        })
    }
}
