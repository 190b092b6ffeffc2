//! Reactive backchaining (Colledanchise et al., "Towards Blended Reactive Planning and
//! Acting using Behavior Trees"), as BETR-XP-LLM uses it.
//!
//! The tree starts as the goal: a Fallback over the DNF's conjunctions, each a Sequence of
//! goal conditions. It is ticked in a fresh copy of the world until it stops running. When
//! it fails, the first failing condition that has not been expanded is replaced by
//! `Fallback(condition, Sequence(preconditions of the best skill achieving it, skill))`.
//! When an action undoes a condition that an earlier sibling subtree had achieved, the
//! later subtree is moved before the earlier one (a conflict). Planning ends when the tree
//! succeeds in simulation, when an action fails there (what the simulator knows and the
//! skills do not: the trigger for failure resolution), or when a condition cannot be
//! achieved, which is reported with its path and the reason.

pub mod achievers;
pub mod exec;
mod grow;

use crate::bt::{NodeId, NodeKind, Tree};
use crate::domain::{ActionCall, Condition, Domain};
use crate::goal::Dnf;
use crate::world::World;

pub use exec::{RunEnd, RunLimits, RunReport, WorldLeaves, postcondition_failure, run_tree};

/// Bounds that keep planning finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanOptions {
    /// Expansions, reorderings and alternative choices, together.
    pub max_iterations: usize,
    /// How many expansions may nest below one goal condition.
    pub max_depth: usize,
    /// Ticks per simulated run of the tree.
    pub max_ticks: u64,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            max_iterations: 400,
            max_depth: 12,
            max_ticks: RunLimits::DEFAULT.plan_ticks,
        }
    }
}

/// How planning ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The tree reaches Success in simulation.
    Success,
    /// An action failed in simulation: the skill model misses something the world enforces.
    ActionFailed {
        node: NodeId,
        action: ActionCall,
        error: String,
    },
    /// A condition the tree needs cannot be achieved by any skill.
    Unreachable {
        node: NodeId,
        condition: Condition,
        path: Vec<usize>,
        reason: String,
    },
    /// A bound ran out (ticks or iterations) before the tree succeeded.
    Exhausted { reason: String },
}

/// The tree after planning, how planning ended and what it did.
#[derive(Debug, Clone)]
pub struct Plan {
    pub tree: Tree,
    pub outcome: Outcome,
    pub expansions: usize,
    pub reorders: usize,
    pub simulated_ticks: u64,
    /// Nodes added by this planning call (ids are stable, so these stay valid).
    pub new_nodes: Vec<NodeId>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RepairError {
    #[error("node {0:?} is not an action of the tree")]
    NotAnAction(NodeId),
    #[error("no action {0} in the tree")]
    NoSuchAction(String),
    #[error("nothing to add: {0} already precede the action")]
    NothingNew(String),
    #[error("a goal with no satisfiable conjunction cannot be planned")]
    FalseGoal,
}

pub struct Planner<'a> {
    pub domain: &'a Domain,
    pub options: PlanOptions,
}

impl<'a> Planner<'a> {
    pub fn new(domain: &'a Domain) -> Self {
        Planner {
            domain,
            options: PlanOptions::default(),
        }
    }

    /// The tree that states the goal before any expansion.
    pub fn goal_tree(dnf: &Dnf) -> Result<Tree, RepairError> {
        let conjunction =
            |tree: &mut Tree, parent: Option<NodeId>, literals: &[Condition]| -> NodeId {
                let single = literals.len() == 1;
                match (parent, single) {
                    (None, true) => tree.root(),
                    (None, false) => {
                        for l in literals {
                            add(tree, tree.root(), NodeKind::Condition(l.clone()));
                        }
                        tree.root()
                    }
                    (Some(p), true) => add(tree, p, NodeKind::Condition(literals[0].clone())),
                    (Some(p), false) => {
                        let seq = add(tree, p, NodeKind::Sequence);
                        for l in literals {
                            add(tree, seq, NodeKind::Condition(l.clone()));
                        }
                        seq
                    }
                }
            };
        match dnf.0.as_slice() {
            [] => Err(RepairError::FalseGoal),
            [only] if only.len() == 1 => Ok(Tree::new(NodeKind::Condition(only[0].clone()))),
            [only] => {
                let mut tree = Tree::new(NodeKind::Sequence);
                conjunction(&mut tree, None, only);
                Ok(tree)
            }
            many => {
                let mut tree = Tree::new(NodeKind::Fallback);
                let root = tree.root();
                for c in many {
                    conjunction(&mut tree, Some(root), c);
                }
                Ok(tree)
            }
        }
    }

    /// Plan a tree for `goal`, ticking it in copies of `world`.
    pub fn plan(&self, goal: &Dnf, world: &dyn World) -> Result<Plan, RepairError> {
        let tree = Self::goal_tree(goal)?;
        Ok(self.grow(tree, world))
    }

    /// Keep expanding an existing tree (a loaded policy, or one just edited).
    pub fn grow(&self, tree: Tree, world: &dyn World) -> Plan {
        grow::Growth::new(self, tree).run(world)
    }

    /// Insert `conditions` as the FIRST preconditions of `action`, then expand them like
    /// any other precondition. This is how a proposal from an LLM or a person enters.
    pub fn repair(
        &self,
        mut tree: Tree,
        action: NodeId,
        conditions: &[Condition],
        world: &dyn World,
    ) -> Result<Plan, RepairError> {
        if !matches!(tree.kind(action), Ok(NodeKind::Action(_))) {
            return Err(RepairError::NotAnAction(action));
        }
        let parent = tree.parent(action).ok().flatten();
        let seq = match parent {
            Some(p)
                if matches!(tree.kind(p), Ok(NodeKind::Sequence))
                    && tree.children(p).ok().and_then(|c| c.last().copied()) == Some(action) =>
            {
                p
            }
            _ => tree
                .wrap(action, NodeKind::Sequence)
                .map_err(|_| RepairError::NotAnAction(action))?,
        };
        // Preconditions already there, whether plain or already expanded.
        let existing: Vec<Condition> = tree
            .children(seq)
            .map(|c| c.to_vec())
            .unwrap_or_default()
            .into_iter()
            .filter_map(|child| match tree.kind(child) {
                Ok(NodeKind::Condition(c)) => Some(c.clone()),
                Ok(NodeKind::Fallback) => grow::expansion_condition(&tree, child),
                _ => None,
            })
            .collect();
        let fresh: Vec<&Condition> = conditions
            .iter()
            .filter(|c| !existing.contains(c))
            .collect();
        if fresh.is_empty() {
            let names: Vec<String> = conditions.iter().map(ToString::to_string).collect();
            return Err(RepairError::NothingNew(names.join(", ")));
        }
        let before = tree.capacity();
        for (i, c) in fresh.into_iter().enumerate() {
            tree.insert_child(seq, i, NodeKind::Condition(c.clone()))
                .map_err(|_| RepairError::NotAnAction(action))?;
        }
        let mut plan = self.grow(tree, world);
        let mut added: Vec<NodeId> = plan
            .tree
            .preorder()
            .into_iter()
            .filter(|n| n.index() >= before)
            .collect();
        added.retain(|n| !plan.new_nodes.contains(n));
        added.extend(plan.new_nodes.iter().copied());
        plan.new_nodes = added;
        Ok(plan)
    }

    /// Repair at the first action of the tree whose text is `action` (`--at` on the CLI).
    pub fn repair_at(
        &self,
        tree: Tree,
        action: &ActionCall,
        conditions: &[Condition],
        world: &dyn World,
    ) -> Result<Plan, RepairError> {
        let node = find_action(&tree, action)
            .ok_or_else(|| RepairError::NoSuchAction(action.to_string()))?;
        self.repair(tree, node, conditions, world)
    }
}

/// The first action node (in tick order) that performs `action` on the same objects.
pub fn find_action(tree: &Tree, action: &ActionCall) -> Option<NodeId> {
    tree.preorder()
        .into_iter()
        .find(|n| matches!(tree.kind(*n), Ok(NodeKind::Action(a)) if a.same_invocation(action)))
}

fn add(tree: &mut Tree, parent: NodeId, kind: NodeKind) -> NodeId {
    // `parent` always comes from this tree, so adding cannot fail; keep the root otherwise.
    tree.add_child(parent, kind).unwrap_or(parent)
}

/// A node of a tree (from a file or a person) that does not fit the scenario.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("node {} ({text}): {reason}", crate::bt::path_text(path))]
pub struct TreeCheckError {
    pub path: Vec<usize>,
    pub text: String,
    pub reason: String,
}

/// Check every leaf of `tree` against the domain: conditions must use the vocabulary and
/// actions must name a skill that accepts their objects.
pub fn check_tree(domain: &Domain, tree: &Tree) -> Result<(), TreeCheckError> {
    for node in tree.preorder() {
        let error = |text: String, reason: String| TreeCheckError {
            path: tree.path(node).unwrap_or_default(),
            text,
            reason,
        };
        match tree.kind(node) {
            Ok(NodeKind::Condition(c)) => domain
                .vocabulary
                .check_condition(c)
                .map_err(|e| error(format!("{c}?"), e.to_string()))?,
            Ok(NodeKind::Action(a)) => {
                if domain.resolve(a).is_none() {
                    let known: Vec<&str> = domain.skills.iter().map(|s| s.name.as_str()).collect();
                    return Err(error(
                        format!("{a}!"),
                        format!(
                            "no skill of this name accepts these objects (skills: {})",
                            known.join(", ")
                        ),
                    ));
                }
            }
            Ok(NodeKind::Sequence | NodeKind::Fallback) | Err(_) => {}
        }
    }
    Ok(())
}

/// Set a value parameter (grasp force, speed, tool) on every action of `tree` that uses
/// `skill` with `object` as its first argument; returns how many nodes changed. Later
/// expansions copy values from these nodes (see `grow`), so the value reaches every node
/// that ever uses that skill with that object.
pub fn set_value(
    tree: &mut Tree,
    skill: &str,
    object: &str,
    name: &str,
    value: &crate::domain::Value,
) -> usize {
    let mut changed = 0;
    for node in tree.preorder() {
        if let Ok(NodeKind::Action(a)) = tree.kind_mut(node)
            && a.skill == skill
            && a.args.first().is_some_and(|o| o == object)
        {
            a.set_value(name, value.clone());
            changed += 1;
        }
    }
    changed
}

#[cfg(test)]
mod tests;
