//! Action leaf (drawn `-->`, written `... !`): run one step of a skill.
//!
//! Returns what `Leaves::step` reports: `Running` while the skill is under way, `Success`
//! when it finished, `Failure` (with the skill's error text) when it gave up. Reactive and
//! memoryless: the node keeps no state; the only thing the ticker remembers is whether it
//! was `Running` in the previous tick, which decides `started` (a fresh start) and whether
//! it must be halted when a tick no longer reaches it (its guard failed, or a
//! higher-priority fallback child succeeded).

use super::status::Outcome;
use super::tick::Leaves;
use super::tree::NodeId;
use crate::domain::ActionCall;

/// What one step of an action reported.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ActionStep {
    /// Still under way; tick again.
    Running,
    /// Finished successfully.
    Success,
    /// Gave up; carries the error text the skill reported.
    Failure(String),
}

impl ActionStep {
    /// The outcome the action node returns to its parent.
    pub fn outcome(&self) -> Outcome {
        match self {
            ActionStep::Running => Outcome::Running,
            ActionStep::Success => Outcome::Success,
            ActionStep::Failure(_) => Outcome::Failure,
        }
    }
}

/// Step `action` once; `started` is true when it was not `Running` in the previous tick.
pub(super) fn tick(
    leaves: &mut dyn Leaves,
    node: NodeId,
    action: &ActionCall,
    started: bool,
) -> ActionStep {
    leaves.step(node, action, started)
}
