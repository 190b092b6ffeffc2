//! What planning did and what its simulation predicts, in the session's words, so front
//! ends report a plan without reaching into the planner.

use std::time::Duration;

use crate::bt::{NodeId, Tree, path_text};
use crate::domain::{ActionCall, Condition};
use crate::planner::{Outcome, Plan};

/// How the planner's simulation of the tree ended.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Prediction {
    /// The tree reaches success in simulation.
    Success,
    /// An action fails in simulation.
    ActionFails {
        action: ActionCall,
        node: NodeId,
        node_path: String,
        error: String,
    },
    /// A condition the tree needs cannot be achieved by any skill.
    Unreachable {
        condition: Condition,
        node_path: String,
        reason: String,
    },
    /// A bound ran out before the tree succeeded.
    Exhausted { reason: String },
}

impl Prediction {
    /// The planner's outcome for `tree`, with node paths written out.
    pub fn of(outcome: &Outcome, tree: &Tree) -> Prediction {
        match outcome {
            Outcome::Success => Prediction::Success,
            Outcome::ActionFailed {
                node,
                action,
                error,
            } => Prediction::ActionFails {
                action: action.clone(),
                node: *node,
                node_path: path_text(&tree.path(*node).unwrap_or_default()),
                error: error.clone(),
            },
            Outcome::Unreachable {
                condition,
                path,
                reason,
                ..
            } => Prediction::Unreachable {
                condition: condition.clone(),
                node_path: path_text(path),
                reason: reason.clone(),
            },
            Outcome::Exhausted { reason } => Prediction::Exhausted {
                reason: reason.clone(),
            },
        }
    }

    pub fn is_success(&self) -> bool {
        matches!(self, Prediction::Success)
    }
}

impl std::fmt::Display for Prediction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Prediction::Success => write!(f, "the tree succeeds in simulation"),
            Prediction::ActionFails {
                action,
                node_path,
                error,
                ..
            } => write!(
                f,
                "{action}! (node {node_path}) failed in simulation: {error}"
            ),
            Prediction::Unreachable {
                condition,
                node_path,
                reason,
            } => write!(
                f,
                "{condition}? (node {node_path}) cannot be achieved: {reason}"
            ),
            Prediction::Exhausted { reason } => write!(f, "{reason}"),
        }
    }
}

/// What one planning call did.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlanSummary {
    pub nodes: usize,
    pub expansions: usize,
    pub reorders: usize,
    pub simulated_ticks: u64,
    pub elapsed: Duration,
    pub prediction: Prediction,
}

impl PlanSummary {
    pub fn of(plan: &Plan, elapsed: Duration) -> PlanSummary {
        PlanSummary {
            nodes: plan.tree.len(),
            expansions: plan.expansions,
            reorders: plan.reorders,
            simulated_ticks: plan.simulated_ticks,
            elapsed,
            prediction: Prediction::of(&plan.outcome, &plan.tree),
        }
    }

    /// One line for a log: the size of the tree and what the simulation predicts.
    pub fn log_line(&self) -> String {
        let what = match &self.prediction {
            Prediction::Success => "the simulation reaches success".to_string(),
            Prediction::ActionFails { action, error, .. } => {
                format!("the simulation predicts {action}! fails: {error}")
            }
            Prediction::Unreachable {
                condition, reason, ..
            } => format!("{condition} cannot be achieved: {reason}"),
            Prediction::Exhausted { reason } => reason.clone(),
        };
        format!(
            "{} node(s), {} expansion(s); {what}",
            self.nodes, self.expansions
        )
    }
}
