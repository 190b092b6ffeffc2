//! Ticking: one pass over the tree from the root, against any leaf executor (`Leaves`).
//!
//! Control nodes are reactive and memoryless (see `sequence.rs`, `fallback.rs`): every tick
//! starts at the root and re-checks every condition on the way to the running action. The
//! only memory is in the `Ticker`: which actions were `Running` in the previous tick (to
//! tell a fresh start from a continuation, and to halt actions the new tick no longer
//! reaches) and how many ticks have run.
//!
//! One private function, `Exec::execute_tick`, wraps every node: it records the visit and
//! the status and dispatches to the node kind's own logic, unless the node's status is
//! forced (`Ticker::tick_forced`, a debugger's "force"): then it returns the forced status
//! without touching the leaves. A forced action is neither stepped nor remembered as
//! Running (it never started in the world), and one that was Running in the world before
//! it was forced is halted there, since nothing steps it any more.

use std::collections::BTreeMap;

use super::action::{self, ActionStep};
use super::status::{Forced, Outcome, Status};
use super::tree::{NodeId, NodeKind, Tree};
use super::{condition, fallback, sequence};
use crate::domain::{ActionCall, Condition};

/// What the leaves of a tree are evaluated against: a simulator, a robot, or a test script.
pub trait Leaves {
    /// Does `condition` hold now?
    fn check(&mut self, condition: &Condition) -> bool;
    /// Advance `action` (node `node`) by one tick.
    /// `started` is true when the action was not Running in the previous tick (a fresh start).
    fn step(&mut self, node: NodeId, action: &ActionCall, started: bool) -> ActionStep;
    /// Stop `action`, which was Running in the previous tick and is no longer reached.
    fn halt(&mut self, node: NodeId, action: &ActionCall);
}

/// Nodes whose result is forced, with the status each returns.
pub type ForcedStatuses = BTreeMap<NodeId, Forced>;

/// Everything one tick did.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TickRecord {
    /// The tick's number, starting at 1.
    pub tick: u64,
    /// What the root returned.
    pub root: Outcome,
    /// Status of every node, indexed by `NodeId::index()`; `len == tree.capacity()`.
    /// `Idle` for nodes the tick did not reach (and for removed nodes).
    #[serde(with = "super::status::letters")]
    pub statuses: Vec<Status>,
    /// Nodes in the order they were ticked.
    pub visited: Vec<NodeId>,
    /// Actions halted after this tick (Running before, not reached now).
    pub halted: Vec<NodeId>,
    /// Actions that returned Failure this tick, with the error text.
    pub failures: Vec<(NodeId, String)>,
    /// Actions that returned Success this tick.
    pub completed: Vec<NodeId>,
    /// Nodes that returned a forced status this tick (not their own), in tick order.
    #[serde(default)]
    pub forced: Vec<NodeId>,
}

impl TickRecord {
    /// The status `id` showed in this tick; `Idle` for ids this record does not cover
    /// (e.g. nodes added after the tick).
    pub fn status(&self, id: NodeId) -> Status {
        self.statuses.get(id.index()).copied().unwrap_or_default()
    }

    /// The running tip: the action that returned `Running` this tick, if any. (Only actions
    /// originate `Running`, and a reactive tree stops at the first one, so it is the
    /// last-visited running node.)
    pub fn running_action(&self) -> Option<NodeId> {
        self.visited
            .iter()
            .rev()
            .copied()
            .find(|&id| self.status(id) == Status::Running)
    }
}

/// Ticks a tree, remembering which actions were Running in the previous tick.
#[derive(Clone, Debug, Default)]
pub struct Ticker {
    /// Actions that returned Running in the previous tick, with the call they ran.
    running: Vec<(NodeId, ActionCall)>,
    ticks: u64,
}

impl Ticker {
    pub fn new() -> Self {
        Ticker::default()
    }

    /// Number of ticks run since creation or the last `reset`.
    pub fn tick_count(&self) -> u64 {
        self.ticks
    }

    /// The actions that returned Running in the latest tick (in tick order).
    pub fn running(&self) -> Vec<NodeId> {
        self.running.iter().map(|(id, _)| *id).collect()
    }

    /// Forget the running actions and the tick count, without halting anything.
    pub fn reset(&mut self) {
        self.running.clear();
        self.ticks = 0;
    }

    /// Tick `tree` once from the root. The tree may have been edited since the previous
    /// tick (ids are stable). Afterwards, every action that was Running in the previous tick
    /// and was not reached by this one is halted (`Leaves::halt`) and shows `Halted`.
    pub fn tick(&mut self, tree: &Tree, leaves: &mut dyn Leaves) -> TickRecord {
        self.tick_forced(tree, leaves, &ForcedStatuses::new())
    }

    /// Tick as `tick` does, with the nodes in `forced` returning their forced status
    /// instead of running their own logic (see the module docs). An action that was
    /// Running and is forced now is halted and listed in `halted`, but shows its forced
    /// status.
    pub fn tick_forced(
        &mut self,
        tree: &Tree,
        leaves: &mut dyn Leaves,
        forced: &ForcedStatuses,
    ) -> TickRecord {
        self.ticks += 1;
        let mut record = TickRecord {
            tick: self.ticks,
            root: Outcome::Failure,
            statuses: vec![Status::Idle; tree.capacity()],
            visited: Vec::new(),
            halted: Vec::new(),
            failures: Vec::new(),
            completed: Vec::new(),
            forced: Vec::new(),
        };
        let mut exec = Exec {
            tree,
            leaves: &mut *leaves,
            record: &mut record,
            was_running: &self.running,
            forced,
        };
        record.root = exec.execute_tick(tree.root());

        for (id, call) in std::mem::take(&mut self.running) {
            let reached = record.status(id) != Status::Idle;
            if reached && !forced.contains_key(&id) {
                continue;
            }
            leaves.halt(id, current_call(tree, id, &call));
            if !reached && let Some(status) = record.statuses.get_mut(id.index()) {
                *status = Status::Halted;
            }
            record.halted.push(id);
        }
        self.running = record
            .visited
            .iter()
            .filter(|&&id| record.status(id) == Status::Running && !forced.contains_key(&id))
            .filter_map(|&id| Some((id, tree.kind(id).ok()?.as_action()?.clone())))
            .collect();
        record
    }

    /// Halt every action that was Running in the previous tick; returns their ids. Calling
    /// it again (before another tick) halts nothing.
    pub fn halt_all(&mut self, tree: &Tree, leaves: &mut dyn Leaves) -> Vec<NodeId> {
        std::mem::take(&mut self.running)
            .into_iter()
            .map(|(id, call)| {
                leaves.halt(id, current_call(tree, id, &call));
                id
            })
            .collect()
    }
}

/// The call to halt: the node's current action (edits may have changed its values; a
/// removed node keeps its kind as a tombstone), else the call that was running.
fn current_call<'a>(tree: &'a Tree, id: NodeId, remembered: &'a ActionCall) -> &'a ActionCall {
    tree.kind_any(id)
        .and_then(NodeKind::as_action)
        .unwrap_or(remembered)
}

/// The state of one tick in progress.
struct Exec<'a> {
    tree: &'a Tree,
    leaves: &'a mut dyn Leaves,
    record: &'a mut TickRecord,
    was_running: &'a [(NodeId, ActionCall)],
    forced: &'a ForcedStatuses,
}

impl Exec<'_> {
    /// Tick one node: record the visit, run the kind's logic (or take its forced status),
    /// record the status.
    fn execute_tick(&mut self, id: NodeId) -> Outcome {
        let tree = self.tree;
        let Ok(kind) = tree.kind(id) else {
            // Children lists only hold live nodes, so this is not reached.
            return Outcome::Failure;
        };
        self.record.visited.push(id);
        if let Some(forced) = self.forced.get(&id) {
            let outcome = forced.outcome();
            self.record.forced.push(id);
            if let Some(status) = self.record.statuses.get_mut(id.index()) {
                *status = outcome.into();
            }
            return outcome;
        }
        let children = tree.children(id).unwrap_or_default();
        let outcome = match kind {
            NodeKind::Sequence => sequence::tick(children, |c| self.execute_tick(c)),
            NodeKind::Fallback => fallback::tick(children, |c| self.execute_tick(c)),
            NodeKind::Condition(c) => condition::tick(&mut *self.leaves, c),
            NodeKind::Action(call) => {
                let started = !self.was_running.iter().any(|(n, _)| *n == id);
                let step = action::tick(&mut *self.leaves, id, call, started);
                match &step {
                    ActionStep::Running => {}
                    ActionStep::Success => self.record.completed.push(id),
                    ActionStep::Failure(error) => self.record.failures.push((id, error.clone())),
                }
                step.outcome()
            }
        };
        if let Some(status) = self.record.statuses.get_mut(id.index()) {
            *status = outcome.into();
        }
        outcome
    }
}

#[cfg(test)]
#[path = "tick_tests.rs"]
mod tests;
