//! The engine's debugger: statuses a person forces on nodes, breakpoints, and stopping a
//! run at them.
//!
//! Forced statuses apply to every tick of the execution world until cleared. Breakpoints
//! are looked for only while running: before each tick the engine ticks a fork of the
//! execution world with a copy of the ticker and the same forced statuses, and when that
//! preview enters a node with a breakpoint (visits it where the last tick did not), it
//! stops before performing the tick. A run resumed from there performs that tick without
//! looking again, or it would stop at the same place for ever; a single tick is always
//! performed. Both are keyed by node ids, so a tree that replaces the current one (a
//! plan, an undo, a load) clears them; a change of the current tree keeps those whose
//! nodes are still in it.

use std::collections::BTreeSet;

use crate::bt::{Forced, ForcedStatuses, NodeId, Status, TickRecord, Tree};
use crate::planner::WorldLeaves;

use super::super::types::{BreakReason, Event};
use super::Engine;

/// What the debugger keeps between ticks.
#[derive(Debug, Default)]
pub(super) struct Debugger {
    pub(super) forced: ForcedStatuses,
    breakpoints: BTreeSet<NodeId>,
    on_failure: bool,
    /// The tick a breakpoint stopped the run before, until a tick is performed or the
    /// world is reset.
    stopped_before: Option<u64>,
}

impl Debugger {
    /// Forget where the last run stopped (the world starts again, tick numbers too).
    pub(super) fn forget_stop(&mut self) {
        self.stopped_before = None;
    }
}

impl Engine {
    /// Force `node`'s status (none: clear it).
    pub(super) fn force(&mut self, node: NodeId, status: Option<Forced>) {
        if let Some(why) = self.unmarkable(node, "force") {
            return self.error(why);
        }
        let changed = match status {
            Some(s) => self.run.debug.forced.insert(node, s) != Some(s),
            None => self.run.debug.forced.remove(&node).is_some(),
        };
        if changed {
            self.emit_forced();
        }
    }

    pub(super) fn cycle_force(&mut self, node: NodeId) {
        let next = next_forced(self.run.debug.forced.get(&node).copied());
        self.force(node, next);
    }

    pub(super) fn toggle_breakpoint(&mut self, node: NodeId) {
        if let Some(why) = self.unmarkable(node, "break at") {
            return self.error(why);
        }
        if !self.run.debug.breakpoints.remove(&node) {
            self.run.debug.breakpoints.insert(node);
        }
        self.emit_breakpoints();
    }

    pub(super) fn break_on_failure(&mut self, on: bool) {
        if self.run.debug.on_failure != on {
            self.run.debug.on_failure = on;
            self.emit_breakpoints();
        }
    }

    /// Why `node` cannot be marked, if it cannot.
    fn unmarkable(&self, node: NodeId, what: &str) -> Option<String> {
        match &self.task.tree {
            None => Some(format!("nothing to {what}: plan first")),
            Some(tree) if !tree.contains(node) => Some(format!("no node {node} in the tree")),
            Some(_) => None,
        }
    }

    fn emit_forced(&self) {
        self.emit(Event::Forced {
            forced: self
                .run
                .debug
                .forced
                .iter()
                .map(|(n, s)| (*n, *s))
                .collect(),
        });
    }

    fn emit_breakpoints(&self) {
        self.emit(Event::Breakpoints {
            nodes: self.run.debug.breakpoints.iter().copied().collect(),
            on_failure: self.run.debug.on_failure,
        });
    }

    /// Clear every forced status and breakpoint: the tree is being replaced, and their
    /// ids would name other nodes in the new one.
    pub(super) fn clear_marks(&mut self) {
        let forced = !self.run.debug.forced.is_empty();
        let breakpoints = !self.run.debug.breakpoints.is_empty();
        self.run.debug.forced.clear();
        self.run.debug.breakpoints.clear();
        if forced {
            self.emit_forced();
        }
        if breakpoints {
            self.emit_breakpoints();
        }
        if forced || breakpoints {
            self.notice(
                "forced statuses and breakpoints cleared: the tree was replaced, so their node ids would name other nodes",
            );
        }
    }

    /// Drop the marks of nodes `tree` no longer has (a change of the current tree keeps
    /// the ids of the nodes it leaves).
    pub(super) fn prune_marks(&mut self, tree: &Tree) {
        let forced = self.run.debug.forced.len();
        let breakpoints = self.run.debug.breakpoints.len();
        self.run.debug.forced.retain(|n, _| tree.contains(*n));
        self.run.debug.breakpoints.retain(|n| tree.contains(*n));
        if self.run.debug.forced.len() != forced {
            self.emit_forced();
        }
        if self.run.debug.breakpoints.len() != breakpoints {
            self.emit_breakpoints();
        }
    }

    /// One tick of a run: stop before it at a breakpoint it would enter, else perform it
    /// and, with break-on-failure, stop after it when a node failed.
    pub(super) fn run_step(&mut self) {
        if let Some((node, tick)) = self.breakpoint_ahead() {
            self.run.debug.stopped_before = Some(tick);
            self.stop_running();
            return self.emit_hit(node, tick, BreakReason::Breakpoint);
        }
        let before = self.run.last.clone();
        self.tick();
        // A failure that ends the run is told by its own events (an action failed, the
        // tree gave up).
        if !self.is_running() || !self.run.debug.on_failure {
            return;
        }
        let Some(after) = self.run.last.clone() else {
            return;
        };
        if let Some(node) = self
            .task
            .tree
            .as_ref()
            .and_then(|t| newly_failed(t, before.as_deref(), &after))
        {
            self.stop_running();
            self.emit_hit(node, after.tick, BreakReason::Failure);
        }
    }

    /// The first node with a breakpoint that the next tick would enter, and that tick's
    /// number; the tick is tried on a fork of the execution world with a copy of the
    /// ticker, so nothing of the session changes.
    fn breakpoint_ahead(&self) -> Option<(NodeId, u64)> {
        if self.run.debug.breakpoints.is_empty() {
            return None;
        }
        let next = self.run.ticker.tick_count() + 1;
        if self.run.debug.stopped_before == Some(next) {
            return None;
        }
        let tree = self.task.tree.as_ref()?;
        let mut world = self.run.exec.fork();
        let mut ticker = self.run.ticker.clone();
        let mut leaves = WorldLeaves {
            world: world.as_mut(),
            domain: &self.settings.scenario.domain,
        };
        let preview = ticker.tick_forced(tree, &mut leaves, &self.run.debug.forced);
        let entered = |n: &NodeId| {
            self.run
                .last
                .as_ref()
                .is_none_or(|last| !last.visited.contains(n))
        };
        preview
            .visited
            .iter()
            .find(|n| self.run.debug.breakpoints.contains(n) && entered(n))
            .map(|n| (*n, next))
    }

    fn emit_hit(&self, node: NodeId, tick: u64, reason: BreakReason) {
        let node_path = self
            .task
            .tree
            .as_ref()
            .and_then(|t| t.path(node).ok())
            .unwrap_or_default();
        self.emit(Event::BreakpointHit {
            node,
            node_path,
            tick,
            reason,
        });
    }
}

/// The node to name when `after` made something fail: among the nodes that fail in
/// `after` and succeeded or ran in `before` (or are actions whose step failed), the first
/// leaf in tick order (where the failure came from), else the first of them.
fn newly_failed(tree: &Tree, before: Option<&TickRecord>, after: &TickRecord) -> Option<NodeId> {
    let was_fine = |n: NodeId| {
        before.is_some_and(|b| matches!(b.status(n), Status::Success | Status::Running))
    };
    let failed: Vec<NodeId> = after
        .visited
        .iter()
        .copied()
        .filter(|&n| after.status(n) == Status::Failure)
        .filter(|&n| was_fine(n) || after.failures.iter().any(|(f, _)| *f == n))
        .collect();
    failed
        .iter()
        .copied()
        .find(|&n| tree.kind(n).is_ok_and(|k| k.is_leaf()))
        .or_else(|| failed.first().copied())
}

/// The status after `current` in the cycle failure → success → running → none.
pub fn next_forced(current: Option<Forced>) -> Option<Forced> {
    match current {
        None => Some(Forced::Failure),
        Some(Forced::Failure) => Some(Forced::Success),
        Some(Forced::Success) => Some(Forced::Running),
        Some(Forced::Running) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forcing_cycles_through_every_status_and_back_to_none() {
        let mut seen = Vec::new();
        let mut at = None;
        for _ in 0..4 {
            at = next_forced(at);
            seen.push(at);
        }
        assert_eq!(
            seen,
            [
                Some(Forced::Failure),
                Some(Forced::Success),
                Some(Forced::Running),
                None
            ]
        );
    }
    use crate::bt::{NodeKind, Outcome};
    use crate::domain::Condition;

    fn record(statuses: Vec<Status>, failures: Vec<(NodeId, String)>) -> TickRecord {
        TickRecord {
            tick: 2,
            root: Outcome::Running,
            visited: (0..statuses.len() as u32)
                .map(NodeId)
                .filter(|n| statuses[n.index()] != Status::Idle)
                .collect(),
            statuses,
            halted: Vec::new(),
            failures,
            completed: Vec::new(),
            forced: Vec::new(),
        }
    }

    #[test]
    fn the_leaf_that_stopped_holding_is_named() {
        use Status::{Failure as F, Idle as I, Running as R, Success as S};
        // [0] fallback, [1] sequence, [2] guard?, [3] other?
        let mut t = Tree::new(NodeKind::Fallback);
        let seq = t.add_child(t.root(), NodeKind::Sequence).unwrap();
        let guard = Condition::parse("Guard").unwrap();
        let guard = t.add_child(seq, NodeKind::Condition(guard)).unwrap();
        let other = Condition::parse("Other").unwrap();
        t.add_child(t.root(), NodeKind::Condition(other)).unwrap();
        let before = record(vec![R, R, S, I], Vec::new());
        let after = record(vec![F, F, F, F], Vec::new());
        assert_eq!(newly_failed(&t, Some(&before), &after), Some(guard));
        // Failing again is no news, and neither is the first tick's failing.
        assert_eq!(newly_failed(&t, Some(&after), &after), None);
        assert_eq!(newly_failed(&t, None, &after), None);
    }
}
