//! The expansion loop: simulate, then expand a failing condition, reorder a conflict, or
//! try the next-best skill for an expansion whose subtree is stuck.

use std::collections::{HashMap, HashSet};

use super::achievers::{self, Candidate};
use super::exec::{RunEnd, run_tree};
use super::{Outcome, Plan, Planner};
use crate::bt::{NodeId, NodeKind, Status, TickRecord, Tree, TreeError, to_text};
use crate::domain::{Condition, GroundSkill};
use crate::world::World;

/// The condition an expansion Fallback achieves.
pub(super) fn expansion_condition(tree: &Tree, fallback: NodeId) -> Option<Condition> {
    let first = *tree.children(fallback).ok()?.first()?;
    match tree.kind(first).ok()? {
        NodeKind::Condition(c) if expansion_of(tree, first) == Some(fallback) => Some(c.clone()),
        _ => None,
    }
}

/// The expansion Fallback whose condition is `condition`, if it has been expanded.
pub(super) fn expansion_of(tree: &Tree, condition: NodeId) -> Option<NodeId> {
    let parent = tree.parent(condition).ok().flatten()?;
    let children = tree.children(parent).ok()?;
    let achiever = |n: &NodeId| match tree.kind(*n) {
        Ok(NodeKind::Action(_)) => true,
        Ok(NodeKind::Sequence) => tree
            .children(*n)
            .ok()
            .and_then(|c| c.last())
            .is_some_and(|last| matches!(tree.kind(*last), Ok(NodeKind::Action(_)))),
        _ => false,
    };
    (matches!(tree.kind(parent), Ok(NodeKind::Fallback))
        && children.len() > 1
        && children[0] == condition
        && children[1..].iter().all(achiever))
    .then_some(parent)
}

/// Why a failing condition could not be expanded; told as the reason it is unreachable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum ExpandError {
    #[error("node {node} is not a condition")]
    NotACondition { node: NodeId },
    #[error("expansion depth bound ({bound}) reached")]
    DepthBound { bound: usize },
    #[error("no skill has an effect that makes {target} true")]
    NoAchiever { target: Condition },
    #[error(
        "all {total} skill(s) achieving {target} need a condition that is itself being achieved above it"
    )]
    Circular { total: usize, target: Condition },
    #[error(transparent)]
    Tree(#[from] TreeError),
}

/// A later sibling subtree undid what an earlier one achieved: move it in front.
struct Conflict {
    sequence: NodeId,
    earlier: usize,
    later: usize,
}

pub(super) struct Growth<'p, 'd> {
    planner: &'p Planner<'d>,
    tree: Tree,
    before: usize,
    /// Conditions no skill can achieve here, with the reason.
    dead: HashMap<NodeId, ExpandError>,
    /// For each expansion (keyed by its Fallback), the skills not tried yet.
    alternatives: HashMap<NodeId, Vec<GroundSkill>>,
    /// Tree texts seen after a reordering, to stop reordering in circles.
    orders: HashSet<String>,
    expansions: usize,
    reorders: usize,
    ticks: u64,
}

enum Next {
    Continue,
    Done(Outcome),
}

impl<'p, 'd> Growth<'p, 'd> {
    pub(super) fn new(planner: &'p Planner<'d>, tree: Tree) -> Self {
        let before = tree.capacity();
        Growth {
            planner,
            tree,
            before,
            dead: HashMap::new(),
            alternatives: HashMap::new(),
            orders: HashSet::new(),
            expansions: 0,
            reorders: 0,
            ticks: 0,
        }
    }

    pub(super) fn run(mut self, world: &dyn World) -> Plan {
        let opts = self.planner.options;
        let mut outcome = Outcome::Exhausted {
            reason: format!("no plan after {} planning iterations", opts.max_iterations),
        };
        for _ in 0..opts.max_iterations {
            match self.iterate(world) {
                Next::Continue => {}
                Next::Done(o) => {
                    outcome = o;
                    break;
                }
            }
        }
        let new_nodes = self
            .tree
            .preorder()
            .into_iter()
            .filter(|n| n.index() >= self.before)
            .collect();
        Plan {
            tree: self.tree,
            outcome,
            expansions: self.expansions,
            reorders: self.reorders,
            simulated_ticks: self.ticks,
            new_nodes,
        }
    }

    fn iterate(&mut self, world: &dyn World) -> Next {
        let domain = self.planner.domain;
        let mut sim = world.fork();
        let mut conflict = None;
        let mut detector = FlipDetector::default();
        let report = run_tree(
            &self.tree,
            sim.as_mut(),
            domain,
            self.planner.options.max_ticks,
            |record, now| {
                conflict = detector.observe(&self.tree, domain, record, now);
                conflict.is_none()
            },
        );
        self.ticks += report.ticks;
        if let Some(c) = conflict {
            return self.reorder(c);
        }
        let Some(last) = report.last else {
            return Next::Done(Outcome::Exhausted {
                reason: "the tree was never ticked".into(),
            });
        };
        match report.end {
            RunEnd::Success => Next::Done(Outcome::Success),
            RunEnd::TickLimit => Next::Done(Outcome::Exhausted {
                reason: format!(
                    "the tree still runs after {} simulated ticks (conditions keep undoing each other)",
                    self.planner.options.max_ticks
                ),
            }),
            RunEnd::Failure {
                action: Some((node, error)),
            } => match self.tree.kind(node) {
                Ok(NodeKind::Action(a)) => Next::Done(Outcome::ActionFailed {
                    node,
                    action: a.clone(),
                    error,
                }),
                _ => Next::Done(Outcome::Exhausted { reason: error }),
            },
            RunEnd::Failure { action: None } => self.expand_next(&last, sim.as_ref()),
        }
    }

    /// Expand the first failing condition (in tick order) that can still be expanded.
    fn expand_next(&mut self, last: &TickRecord, sim: &dyn World) -> Next {
        let failing: Vec<NodeId> = last
            .visited
            .iter()
            .copied()
            .filter(|n| {
                last.status(*n) == Status::Failure
                    && matches!(self.tree.kind(*n), Ok(NodeKind::Condition(_)))
            })
            .collect();
        let protected: Vec<Condition> = last
            .visited
            .iter()
            .filter(|n| last.status(**n) == Status::Success)
            .filter_map(|n| match self.tree.kind(*n) {
                Ok(NodeKind::Condition(c)) => Some(c.clone()),
                _ => None,
            })
            .collect();
        for node in failing {
            if self.dead.contains_key(&node) || self.is_expanded(node) {
                continue;
            }
            match self.expand(node, sim, &protected) {
                Ok(()) => return Next::Continue,
                Err(reason) => {
                    tracing::debug!(node = %node, %reason, "cannot expand");
                    self.dead.insert(node, reason);
                    if self.try_alternative(node) {
                        return Next::Continue;
                    }
                }
            }
        }
        // Nothing left to expand: report the first dead condition the tick reached.
        let culprit = last
            .visited
            .iter()
            .find(|n| self.dead.contains_key(n))
            .copied();
        match culprit.and_then(|n| Some((n, self.condition(n)?))) {
            Some((node, condition)) => Next::Done(Outcome::Unreachable {
                path: self.tree.path(node).unwrap_or_default(),
                reason: self
                    .dead
                    .get(&node)
                    .map(ToString::to_string)
                    .unwrap_or_default(),
                node,
                condition,
            }),
            None => Next::Done(Outcome::Exhausted {
                reason: "the tree fails but no failing condition can be expanded".into(),
            }),
        }
    }

    fn condition(&self, node: NodeId) -> Option<Condition> {
        match self.tree.kind(node) {
            Ok(NodeKind::Condition(c)) => Some(c.clone()),
            _ => None,
        }
    }

    /// A condition is expanded when it is the first child of a Fallback whose other children
    /// are ways to achieve it: actions, or sequences ending in an action. (The goal's root
    /// Fallback also starts with a condition, but its other children are goal conditions.)
    fn is_expanded(&self, node: NodeId) -> bool {
        self.expansion_of(node).is_some()
    }

    fn expansion_of(&self, condition: NodeId) -> Option<NodeId> {
        expansion_of(&self.tree, condition)
    }

    /// The conditions being achieved above `node` (the first children of enclosing
    /// expansions), nearest first.
    fn goals_above(&self, node: NodeId) -> Vec<Condition> {
        let mut out = Vec::new();
        let mut cur = self.tree.parent(node).ok().flatten();
        while let Some(p) = cur {
            if matches!(self.tree.kind(p), Ok(NodeKind::Fallback))
                && let Some(first) = self.tree.children(p).ok().and_then(|c| c.first().copied())
                && let Some(c) = self.condition(first)
                && self.expansion_of(first) == Some(p)
            {
                out.push(c);
            }
            cur = self.tree.parent(p).ok().flatten();
        }
        out
    }

    fn expand(
        &mut self,
        node: NodeId,
        sim: &dyn World,
        protected: &[Condition],
    ) -> Result<(), ExpandError> {
        let domain = self.planner.domain;
        let Some(condition) = self.condition(node) else {
            return Err(ExpandError::NotACondition { node });
        };
        let above = self.goals_above(node);
        if above.len() >= self.planner.options.max_depth {
            return Err(ExpandError::DepthBound {
                bound: self.planner.options.max_depth,
            });
        }
        // A wildcard condition is achieved through the object that falsifies it now.
        let mut target = condition.clone();
        let mut candidates = achievers::rank(domain, sim, &target, protected, &above);
        if candidates.is_empty()
            && condition.negated
            && let Some(witness) = achievers::wildcard_witnesses(domain, sim, &condition)
                .into_iter()
                .next()
        {
            target = witness;
            candidates = achievers::rank(domain, sim, &target, protected, &above);
        }
        if candidates.is_empty() {
            return Err(ExpandError::NoAchiever { target });
        }
        // A skill that needs a condition already being achieved above would loop.
        let total = candidates.len();
        let usable: Vec<Candidate> = candidates
            .into_iter()
            .filter(|c| {
                !c.skill
                    .pre
                    .iter()
                    .any(|p| above.contains(p) || *p == condition)
            })
            .collect();
        let Some((first, rest)) = usable.split_first() else {
            return Err(ExpandError::Circular { total, target });
        };
        let fallback = self.tree.wrap(node, NodeKind::Fallback)?;
        self.attach(fallback, &first.skill)?;
        tracing::debug!(condition = %condition, skill = %first.skill.call, score = first.score, "expanded");
        self.alternatives
            .insert(fallback, rest.iter().map(|c| c.skill.clone()).collect());
        self.expansions += 1;
        Ok(())
    }

    /// Add `Sequence(preconditions..., action)` (or the bare action) under `fallback`.
    fn attach(&mut self, fallback: NodeId, skill: &GroundSkill) -> Result<(), TreeError> {
        let tree = &mut self.tree;
        let parent = if skill.pre.is_empty() {
            fallback
        } else {
            let seq = tree.add_child(fallback, NodeKind::Sequence)?;
            for p in &skill.pre {
                tree.add_child(seq, NodeKind::Condition(p.clone()))?;
            }
            seq
        };
        // Values already set for this skill and object (grasp force of the egg) carry over.
        let mut call = skill.call.clone();
        if let Some((_, known)) = tree
            .actions()
            .into_iter()
            .find(|(_, a)| a.same_invocation(&call) && !a.values.is_empty())
        {
            call.values = known.values.clone();
        }
        tree.add_child(parent, NodeKind::Action(call))?;
        Ok(())
    }

    /// `node` is stuck: give the nearest enclosing expansion its next-best skill.
    fn try_alternative(&mut self, node: NodeId) -> bool {
        let mut cur = self.tree.parent(node).ok().flatten();
        while let Some(p) = cur {
            if let Some(list) = self.alternatives.get_mut(&p)
                && !list.is_empty()
            {
                let next = list.remove(0);
                let old: Vec<NodeId> = self
                    .tree
                    .children(p)
                    .map(|c| c[1..].to_vec())
                    .unwrap_or_default();
                for child in old {
                    if self.tree.remove_subtree(child).is_err() {
                        return false;
                    }
                }
                self.dead.retain(|n, _| self.tree.kind(*n).is_ok());
                return self.attach(p, &next).is_ok();
            }
            cur = self.tree.parent(p).ok().flatten();
        }
        false
    }

    fn reorder(&mut self, c: Conflict) -> Next {
        let lead = |tree: &Tree, index: usize| {
            let child = tree.children(c.sequence).ok()?.get(index).copied()?;
            lead_condition(tree, child)
        };
        let (earlier, later) = (lead(&self.tree, c.earlier), lead(&self.tree, c.later));
        if self
            .tree
            .move_child(c.sequence, c.later, c.earlier)
            .is_err()
        {
            return Next::Done(Outcome::Exhausted {
                reason: "internal: a conflict named a child that is not there".into(),
            });
        }
        self.reorders += 1;
        tracing::debug!(sequence = %c.sequence, from = c.later, to = c.earlier, "reordered a conflict");
        if self.orders.insert(to_text(&self.tree)) {
            return Next::Continue;
        }
        match (earlier, later) {
            (Some((node, condition)), Some((_, other))) => Next::Done(Outcome::Unreachable {
                path: self.tree.path(node).unwrap_or_default(),
                reason: format!(
                    "{condition} and {other} undo each other: achieving either one makes the other false, in every order tried"
                ),
                node,
                condition,
            }),
            _ => Next::Done(Outcome::Exhausted {
                reason:
                    "sibling subtrees keep undoing each other's conditions in every order tried"
                        .into(),
            }),
        }
    }
}

/// The condition a subtree stands for: the node itself, or the first condition down its
/// first children (an expansion's condition, a conjunction's first goal).
pub(super) fn lead_condition(tree: &Tree, node: NodeId) -> Option<(NodeId, Condition)> {
    match tree.kind(node).ok()? {
        NodeKind::Condition(c) => Some((node, c.clone())),
        NodeKind::Sequence | NodeKind::Fallback => {
            lead_condition(tree, *tree.children(node).ok()?.first()?)
        }
        NodeKind::Action(_) => None,
    }
}

/// Whether condition `node` is still needed after a tick that ended in `now`: not when a
/// fallback above it has a first child, a condition other than the way to `node`, that
/// holds now — what `node` was a precondition for is done ("the door open" for putting
/// the linen at bed 3, once the linen is there, may be undone by closing the door).
fn still_needed(tree: &Tree, node: NodeId, now: &dyn World) -> bool {
    let mut child = node;
    while let Ok(Some(parent)) = tree.parent(child) {
        if matches!(tree.kind(parent), Ok(NodeKind::Fallback))
            && let Some(&first) = tree.children(parent).ok().and_then(|c| c.first())
            && first != child
            && let Ok(NodeKind::Condition(goal)) = tree.kind(first)
            && now.check(goal)
        {
            return false;
        }
        child = parent;
    }
    true
}

/// Watches a simulated run for a condition that held, then stopped holding because an
/// action in a later sibling subtree undid it: either seen when the condition is ticked
/// again and fails, or at the end of the very tick that checked it (a stale success that
/// an action later in that tick invalidated, before anything re-checked it).
#[derive(Default)]
struct FlipDetector {
    /// Condition node → the tick at which it last succeeded.
    held_since: HashMap<NodeId, u64>,
    /// Actions that completed, with their tick.
    completed: Vec<(u64, NodeId)>,
}

impl FlipDetector {
    fn observe(
        &mut self,
        tree: &Tree,
        domain: &crate::domain::Domain,
        record: &TickRecord,
        now: &dyn World,
    ) -> Option<Conflict> {
        self.completed
            .extend(record.completed.iter().map(|a| (record.tick, *a)));
        let mut found = None;
        for &node in &record.visited {
            let Ok(NodeKind::Condition(condition)) = tree.kind(node) else {
                continue;
            };
            match record.status(node) {
                Status::Success if now.check(condition) => {
                    self.held_since.insert(node, record.tick);
                }
                Status::Success => {
                    self.held_since.remove(&node);
                    if found.is_none() && still_needed(tree, node, now) {
                        found = self.culprit(tree, domain, node, condition, record.tick);
                    }
                }
                Status::Failure => {
                    if let Some(since) = self.held_since.remove(&node)
                        && found.is_none()
                    {
                        found = self.culprit(tree, domain, node, condition, since);
                    }
                }
                Status::Idle | Status::Running | Status::Halted => {}
            }
        }
        found
    }

    fn culprit(
        &self,
        tree: &Tree,
        domain: &crate::domain::Domain,
        node: NodeId,
        condition: &Condition,
        since: u64,
    ) -> Option<Conflict> {
        for &(_, action) in self.completed.iter().filter(|(t, _)| *t >= since) {
            let Ok(NodeKind::Action(call)) = tree.kind(action) else {
                continue;
            };
            if !domain.resolve(call).is_some_and(|g| g.undoes(condition)) {
                continue;
            }
            let Ok(lca) = tree.lowest_common_ancestor(node, action) else {
                continue;
            };
            if !matches!(tree.kind(lca), Ok(NodeKind::Sequence)) {
                continue;
            }
            let children = tree.children(lca).ok()?;
            let position = |n: NodeId| {
                children
                    .iter()
                    .position(|c| *c == n || tree.is_ancestor(*c, n).unwrap_or(false))
            };
            let (Some(earlier), Some(later)) = (position(node), position(action)) else {
                continue;
            };
            // An action undoing its own preconditions (picking up empties the hand) is expected.
            if earlier < later && !matches!(tree.kind(children[later]), Ok(NodeKind::Action(_))) {
                return Some(Conflict {
                    sequence: lca,
                    earlier,
                    later,
                });
            }
        }
        None
    }
}
