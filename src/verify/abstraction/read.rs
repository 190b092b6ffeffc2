//! Reading a tree for the abstraction: its nodes, actions and observed conditions, the
//! disturbances that matter to them, and the atoms the model tracks as bits.

use std::collections::{BTreeSet, HashMap};

use super::{Conds, Ground, ModelError, changes_observed, ground_disturbances, instance_of};
use crate::bt::{NodeId, NodeKind, Tree};
use crate::domain::{ActionCall, Atom, AtomPattern, Condition, Domain};
use crate::verify::config::Disturbance;

/// An action of the tree as read, before its atoms become bits.
pub(super) struct RawAction {
    pub(super) node: NodeId,
    pub(super) path: Vec<usize>,
    pub(super) call: ActionCall,
    pub(super) pre: Vec<(usize, bool)>,
    pub(super) add: Vec<Atom>,
    pub(super) del: Vec<AtomPattern>,
}

/// The tree read node by node (in preorder): the conditions it observes, its nodes and
/// its actions.
pub(super) struct RawTree {
    pub(super) conds: Conds,
    pub(super) nodes: Vec<(NodeId, RawNode)>,
    pub(super) actions: Vec<RawAction>,
}

pub(super) fn read_tree(domain: &Domain, tree: &Tree) -> Result<RawTree, ModelError> {
    let mut conds = Conds::default();
    let mut nodes: Vec<(NodeId, RawNode)> = Vec::new();
    let mut actions = Vec::new();
    let mut order: HashMap<NodeId, usize> = HashMap::new();
    for id in tree.preorder() {
        order.insert(id, order.len());
    }
    for id in tree.preorder() {
        let kind = tree.kind(id).map_err(|_| ModelError::UnknownAction {
            call: id.to_string(),
            path: String::new(),
        })?;
        let children: Vec<usize> = tree
            .children(id)
            .unwrap_or_default()
            .iter()
            .filter_map(|c| order.get(c).copied())
            .collect();
        let node = match kind {
            NodeKind::Sequence => RawNode::Sequence(children),
            NodeKind::Fallback => RawNode::Fallback(children),
            NodeKind::Condition(c) => RawNode::Condition(conds.id(c), c.negated),
            NodeKind::Action(call) => {
                let path = tree.path(id).unwrap_or_default();
                let ground = domain
                    .resolve(call)
                    .ok_or_else(|| ModelError::UnknownAction {
                        call: call.to_string(),
                        path: crate::bt::path_text(&path),
                    })?;
                let pre = ground
                    .pre
                    .iter()
                    .map(|p| (conds.id(p), p.negated))
                    .collect();
                actions.push(RawAction {
                    node: id,
                    path,
                    call: call.clone(),
                    pre,
                    add: ground.add,
                    del: ground.del,
                });
                RawNode::Action(actions.len() - 1)
            }
        };
        nodes.push((id, node));
    }
    Ok(RawTree {
        conds,
        nodes,
        actions,
    })
}

/// The disturbances that matter: those that change an observed atom. Their guards are
/// then observed too, which can make further disturbances matter (a fixpoint).
pub(super) fn observed_disturbances(
    domain: &Domain,
    disturbances: &[Disturbance],
    conds: &mut Conds,
) -> Result<Vec<Ground>, ModelError> {
    let mut grounds = ground_disturbances(domain, disturbances)?;
    let mut kept: Vec<Ground> = Vec::new();
    loop {
        let before = kept.len();
        let (relevant, rest): (Vec<Ground>, Vec<Ground>) = grounds
            .into_iter()
            .partition(|g| changes_observed(g, &conds.list));
        grounds = rest;
        for g in &relevant {
            for p in &g.pre {
                conds.id(p);
            }
        }
        kept.extend(relevant);
        if kept.len() == before {
            return Ok(kept);
        }
    }
}

/// The atoms the model tracks (those that can be true and that some condition observes),
/// each a bit, with lookups from atoms and patterns to bits.
pub(super) struct Universe {
    pub(super) atoms: Vec<Atom>,
    pub(super) index: HashMap<Atom, usize>,
    pub(super) by_predicate: HashMap<String, Vec<usize>>,
}

impl Universe {
    pub(super) fn new(candidates: BTreeSet<Atom>, observers: &[Condition]) -> Universe {
        let exact: std::collections::HashSet<&Atom> = observers
            .iter()
            .filter(|c| !c.atom.has_wildcard())
            .map(|c| &c.atom)
            .collect();
        let mut wild: HashMap<&str, Vec<&Atom>> = HashMap::new();
        for c in observers.iter().filter(|c| c.atom.has_wildcard()) {
            wild.entry(c.atom.predicate.as_str())
                .or_default()
                .push(&c.atom);
        }
        let observed = |a: &Atom| {
            exact.contains(a)
                || wild
                    .get(a.predicate.as_str())
                    .is_some_and(|ps| ps.iter().any(|p| instance_of(p, a)))
        };
        let atoms: Vec<Atom> = candidates.into_iter().filter(|a| observed(a)).collect();
        let index = atoms
            .iter()
            .enumerate()
            .map(|(i, a)| (a.clone(), i))
            .collect();
        let mut by_predicate: HashMap<String, Vec<usize>> = HashMap::new();
        for (i, a) in atoms.iter().enumerate() {
            by_predicate.entry(a.predicate.clone()).or_default().push(i);
        }
        Universe {
            atoms,
            index,
            by_predicate,
        }
    }

    /// The bits of the atoms `pattern` names (one, or every instance of a wildcard).
    pub(super) fn matching(&self, pattern: &Atom) -> Vec<usize> {
        if !pattern.has_wildcard() {
            return self.index.get(pattern).copied().into_iter().collect();
        }
        self.of_predicate(&pattern.predicate, |a| instance_of(pattern, a))
    }

    /// The bits a delete effect clears.
    pub(super) fn deleted(&self, pattern: &AtomPattern) -> Vec<usize> {
        self.of_predicate(&pattern.predicate, |a| pattern.matches(a))
    }

    /// The bits an add effect sets (atoms outside the universe are not tracked).
    pub(super) fn added(&self, adds: &[Atom]) -> Vec<usize> {
        adds.iter()
            .filter_map(|a| self.index.get(a).copied())
            .collect()
    }

    fn of_predicate(&self, predicate: &str, keep: impl Fn(&Atom) -> bool) -> Vec<usize> {
        self.by_predicate
            .get(predicate)
            .map(|is| {
                is.iter()
                    .copied()
                    .filter(|&i| keep(&self.atoms[i]))
                    .collect()
            })
            .unwrap_or_default()
    }
}

pub(super) enum RawNode {
    Sequence(Vec<usize>),
    Fallback(Vec<usize>),
    Condition(usize, bool),
    Action(usize),
}

/// The universe: atoms that can be true (initially, or added by an action or a
/// disturbance) and that some condition observes.
pub(super) fn universe_of(
    initial: &[Condition],
    actions: &[RawAction],
    grounds: &[Ground],
    observed: &[Condition],
) -> Universe {
    let mut candidates: BTreeSet<Atom> = initial
        .iter()
        .filter(|c| !c.negated)
        .map(|c| c.atom.clone())
        .collect();
    for action in actions {
        candidates.extend(action.add.iter().cloned());
    }
    for g in grounds {
        candidates.extend(g.add.iter().cloned());
    }
    Universe::new(candidates, observed)
}
