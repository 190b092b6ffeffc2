//! Condition leaf (drawn `-->`, written `... ?`): ask the world whether a literal holds.
//!
//! Returns `Success` when `Leaves::check` says the condition holds and `Failure` otherwise;
//! never `Running`. Reactive and memoryless: it is re-checked on every tick that reaches it
//! (so a guard that stops holding stops its sequence at once), and nothing about earlier
//! ticks is kept.

use super::status::Outcome;
use super::tick::Leaves;
use crate::domain::Condition;

/// Check `condition` once.
pub(super) fn tick(leaves: &mut dyn Leaves, condition: &Condition) -> Outcome {
    if leaves.check(condition) {
        Outcome::Success
    } else {
        Outcome::Failure
    }
}
