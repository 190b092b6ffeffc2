//! The abstraction the planner reasons in, compiled for fast exploration.
//!
//! A state is the set of facts that are true, kept as a bitset over the atoms that matter:
//! the atoms the tree's conditions, its actions' preconditions, the disturbances' guards
//! and the properties observe (wildcards included), restricted to those that can ever be
//! true (initially true, or added by an action of the tree or a disturbance). Every other
//! atom cannot change anything the tree or a property sees, so it is left out.
//!
//! One abstract tick evaluates the tree over a state with the reactive, memoryless
//! semantics of `bt` (every tick from the root; a Sequence stops at the first child that
//! does not succeed, a Fallback at the first that does not fail). The first action reached
//! executes: its declared effects apply and the tick ends (an action takes one abstract
//! tick). With action failures allowed, an action may instead fail, leaving the state
//! unchanged; the tick then goes on as the Failure makes it (a Fallback tries its next
//! child). The root returning Success on a tick where no action was reached is success; it
//! returning Failure that way is a dead end.

use std::collections::HashMap;

use super::config::Disturbance;

mod read;
use crate::bt::{NodeId, Tree};
use crate::domain::{ANY_OBJECT, ActionCall, Atom, AtomPattern, Condition, Domain};
use crate::goal::Formula;
use read::{RawNode, RawTree, Universe, observed_disturbances, read_tree, universe_of};

/// A set of facts as a bitset over `Model::atoms`.
pub type State = Box<[u64]>;

/// Whether `atom` is an instance of `pattern` (whose `"any object"` arguments match
/// any object).
pub fn instance_of(pattern: &Atom, atom: &Atom) -> bool {
    pattern.predicate == atom.predicate
        && pattern.args.len() == atom.args.len()
        && pattern
            .args
            .iter()
            .zip(&atom.args)
            .all(|(p, a)| p == ANY_OBJECT || p == a)
}

/// A condition compiled to the bits of the atoms that make its positive form true.
#[derive(Debug, Clone)]
pub struct CondBits {
    pub condition: Condition,
    bits: Vec<usize>,
}

impl CondBits {
    /// The atoms (indices into `Model::atoms`) of which at least one must be true for the
    /// positive form to hold.
    pub fn bits(&self) -> &[usize] {
        &self.bits
    }
}

/// A formula compiled over condition ids.
#[derive(Debug, Clone)]
pub enum Expr {
    /// A positive condition (its id into `Model::conditions`).
    Atom(usize),
    Not(Box<Expr>),
    And(Vec<Expr>),
    Or(Vec<Expr>),
}

#[derive(Debug, Clone)]
pub enum CNode {
    Sequence(Vec<usize>),
    Fallback(Vec<usize>),
    Condition(usize),
    Action(usize),
}

/// An action node of the tree with its declared preconditions and effects.
#[derive(Debug, Clone)]
pub struct CAction {
    pub node: NodeId,
    pub path: Vec<usize>,
    pub call: ActionCall,
    /// Condition ids of the declared preconditions.
    pub pre: Vec<usize>,
    pub add: Vec<usize>,
    pub del: Vec<usize>,
}

/// One grounding of a declared disturbance.
#[derive(Debug, Clone)]
pub struct CDisturbance {
    pub description: String,
    /// The objects its parameters stand for, e.g. `a = "red cube", b = "blue cube"`.
    pub grounding: String,
    pub pre: Vec<usize>,
    pub add: Vec<usize>,
    pub del: Vec<usize>,
}

/// What one abstract tick did.
#[derive(Debug, Clone, PartialEq)]
pub struct TickResult {
    /// The action that executed (index into `Model::actions`).
    pub executed: Option<usize>,
    /// Actions that were reached and failed, in tick order.
    pub failed: Vec<usize>,
    /// Actions reached (executed or failed) whose declared precondition (condition id)
    /// did not hold when they started.
    pub unmet: Vec<(usize, usize)>,
    /// What the root returned (`Running` when an action executed).
    pub root: crate::bt::Outcome,
}

/// Why a tree cannot be compiled for model checking.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, serde::Serialize, serde::Deserialize)]
pub enum ModelError {
    #[error(
        "action {call}! at node {path} names no skill of the scenario, so its effects are unknown"
    )]
    UnknownAction { call: String, path: String },
    #[error("disturbance {0:?} has more than {1} groundings; narrow its parameter types")]
    TooManyGroundings(String, usize),
}

/// Groundings of one disturbance beyond this are refused.
const MAX_GROUNDINGS: usize = 100_000;

/// The compiled tree, actions, disturbances and properties over one atom universe.
#[derive(Debug, Clone)]
pub struct Model {
    pub atoms: Vec<Atom>,
    pub conditions: Vec<CondBits>,
    pub nodes: Vec<CNode>,
    pub actions: Vec<CAction>,
    pub disturbances: Vec<CDisturbance>,
    pub properties: Vec<Expr>,
    pub initial: State,
    words: usize,
}

/// Collects conditions, deduplicated, before the universe is known.
#[derive(Default)]
struct Conds {
    list: Vec<Condition>,
    ids: HashMap<Condition, usize>,
}

impl Conds {
    fn id(&mut self, c: &Condition) -> usize {
        let c = Condition::pos(c.atom.clone()); // bits are for the positive form
        if let Some(&i) = self.ids.get(&c) {
            return i;
        }
        self.list.push(c.clone());
        self.ids.insert(c, self.list.len() - 1);
        self.list.len() - 1
    }
}

struct Ground {
    description: String,
    grounding: String,
    pre: Vec<Condition>,
    add: Vec<Atom>,
    del: Vec<AtomPattern>,
}

impl Model {
    /// Compile `tree` over `domain` from `initial` facts, with disturbances (already
    /// filtered by the caller when they are off) and property formulas.
    pub fn build(
        domain: &Domain,
        tree: &Tree,
        initial: &[Condition],
        disturbances: &[Disturbance],
        properties: &[&Formula],
    ) -> Result<Model, ModelError> {
        let RawTree {
            mut conds,
            nodes: raw_nodes,
            actions: raw_actions,
        } = read_tree(domain, tree)?;
        for atom in properties.iter().flat_map(|f| f.atoms()) {
            conds.id(&Condition::pos(atom));
        }
        let grounds = observed_disturbances(domain, disturbances, &mut conds)?;
        let ground_pre: Vec<Vec<(usize, bool)>> = grounds
            .iter()
            .map(|g| g.pre.iter().map(|p| (conds.id(p), p.negated)).collect())
            .collect();
        let universe = universe_of(initial, &raw_actions, &grounds, &conds.list);
        let mut signs = Signs::new(
            conds
                .list
                .iter()
                .map(|c| CondBits {
                    condition: c.clone(),
                    bits: universe.matching(&c.atom),
                })
                .collect(),
        );
        let actions = raw_actions
            .iter()
            .map(|a| CAction {
                node: a.node,
                path: a.path.clone(),
                call: a.call.clone(),
                pre: a.pre.iter().map(|&(c, n)| signs.id(c, n)).collect(),
                add: universe.added(&a.add),
                del: a.del.iter().flat_map(|p| universe.deleted(p)).collect(),
            })
            .collect();
        let nodes = raw_nodes
            .into_iter()
            .map(|(_, node)| match node {
                RawNode::Sequence(c) => CNode::Sequence(c),
                RawNode::Fallback(c) => CNode::Fallback(c),
                RawNode::Condition(c, n) => CNode::Condition(signs.id(c, n)),
                RawNode::Action(a) => CNode::Action(a),
            })
            .collect();
        let disturbances = grounds
            .iter()
            .zip(&ground_pre)
            .map(|(g, pre)| CDisturbance {
                description: g.description.clone(),
                grounding: g.grounding.clone(),
                pre: pre.iter().map(|&(c, n)| signs.id(c, n)).collect(),
                add: universe.added(&g.add),
                del: g.del.iter().flat_map(|p| universe.deleted(p)).collect(),
            })
            .collect();
        let properties = properties
            .iter()
            .map(|f| compile_formula(f, &conds.ids))
            .collect();
        let words = universe.atoms.len().div_ceil(64).max(1);
        let initial = initial_state(&universe, initial, words);
        Ok(Model {
            atoms: universe.atoms,
            conditions: signs.conditions,
            nodes,
            actions,
            disturbances,
            properties,
            initial,
            words,
        })
    }

    pub fn holds(&self, state: &State, condition: usize) -> bool {
        let c = &self.conditions[condition];
        c.bits.iter().any(|&i| bit(state, i)) != c.condition.negated
    }

    pub fn eval(&self, state: &State, e: &Expr) -> bool {
        match e {
            Expr::Atom(c) => self.holds(state, *c),
            Expr::Not(x) => !self.eval(state, x),
            Expr::And(v) => v.iter().all(|x| self.eval(state, x)),
            Expr::Or(v) => v.iter().any(|x| self.eval(state, x)),
        }
    }

    /// One abstract tick where the first `fail` actions reached fail.
    pub fn tick(&self, state: &State, fail: usize) -> TickResult {
        let mut result = TickResult {
            executed: None,
            failed: Vec::new(),
            unmet: Vec::new(),
            root: crate::bt::Outcome::Failure,
        };
        let mut budget = fail;
        result.root = self.eval_node(0, state, &mut budget, &mut result);
        result
    }

    fn eval_node(
        &self,
        n: usize,
        state: &State,
        budget: &mut usize,
        r: &mut TickResult,
    ) -> crate::bt::Outcome {
        use crate::bt::Outcome::{Failure, Running, Success};
        match &self.nodes[n] {
            CNode::Sequence(children) => {
                for &c in children {
                    match self.eval_node(c, state, budget, r) {
                        Success => {}
                        other => return other,
                    }
                }
                Success
            }
            CNode::Fallback(children) => {
                for &c in children {
                    match self.eval_node(c, state, budget, r) {
                        Failure => {}
                        other => return other,
                    }
                }
                Failure
            }
            CNode::Condition(c) => {
                if self.holds(state, *c) {
                    Success
                } else {
                    Failure
                }
            }
            CNode::Action(a) => {
                for &p in &self.actions[*a].pre {
                    if !self.holds(state, p) {
                        r.unmet.push((*a, p));
                    }
                }
                if *budget > 0 {
                    *budget -= 1;
                    r.failed.push(*a);
                    Failure
                } else {
                    r.executed = Some(*a);
                    Running
                }
            }
        }
    }

    /// The state after `del` then `add`.
    pub fn apply(&self, state: &State, add: &[usize], del: &[usize]) -> State {
        let mut next = state.clone();
        for &i in del {
            next[i / 64] &= !(1 << (i % 64));
        }
        for &i in add {
            next[i / 64] |= 1 << (i % 64);
        }
        next
    }

    /// The atoms true in `state`.
    pub fn facts(&self, state: &State) -> Vec<&Atom> {
        (0..self.atoms.len())
            .filter(|&i| bit(state, i))
            .map(|i| &self.atoms[i])
            .collect()
    }

    /// Words per state (for memory estimates).
    pub fn words(&self) -> usize {
        self.words
    }
}

/// Whether a disturbance adds or deletes an atom that one of `observed` can see.
fn changes_observed(g: &Ground, observed: &[Condition]) -> bool {
    observed.iter().any(|c| {
        g.add.iter().any(|a| instance_of(&c.atom, a)) || g.del.iter().any(|d| d.overlaps(&c.atom))
    })
}

pub fn bit(state: &State, i: usize) -> bool {
    state.get(i / 64).is_some_and(|w| w & (1 << (i % 64)) != 0)
}

fn compile_formula(f: &Formula, ids: &HashMap<Condition, usize>) -> Expr {
    match f {
        Formula::Atom(a) => match ids.get(&Condition::pos(a.clone())) {
            Some(&i) => Expr::Atom(i),
            None => Expr::Or(Vec::new()),
        },
        Formula::Not(x) => Expr::Not(Box::new(compile_formula(x, ids))),
        Formula::And(v) => Expr::And(v.iter().map(|x| compile_formula(x, ids)).collect()),
        Formula::Or(v) => Expr::Or(v.iter().map(|x| compile_formula(x, ids)).collect()),
    }
}

/// Every grounding of every disturbance over the objects its parameters admit.
fn ground_disturbances(
    domain: &Domain,
    disturbances: &[Disturbance],
) -> Result<Vec<Ground>, ModelError> {
    let vocabulary = &domain.vocabulary;
    let mut out = Vec::new();
    for d in disturbances {
        let mut combos: Vec<Vec<String>> = vec![Vec::new()];
        for p in &d.params {
            let objects: Vec<&str> = p.candidates(vocabulary).collect();
            if combos.len().saturating_mul(objects.len()) > MAX_GROUNDINGS {
                return Err(ModelError::TooManyGroundings(
                    d.description.clone(),
                    MAX_GROUNDINGS,
                ));
            }
            combos = combos
                .into_iter()
                .flat_map(|c| {
                    objects.iter().map(move |o| {
                        let mut next = c.clone();
                        next.push((*o).to_string());
                        next
                    })
                })
                .collect();
        }
        for args in combos {
            let (pre, add, del) =
                crate::domain::skill::ground_templates(&d.pre, &d.add, &d.del, &args);
            out.push(Ground {
                description: d.description.clone(),
                grounding: d
                    .params
                    .iter()
                    .zip(&args)
                    .map(|(p, a)| format!("{} = \"{a}\"", p.name))
                    .collect::<Vec<_>>()
                    .join(", "),
                pre,
                add,
                del,
            });
        }
    }
    Ok(out)
}

/// The conditions' bits, with a negated condition added once as a node over its positive
/// atom's bits plus a sign.
struct Signs {
    conditions: Vec<CondBits>,
    negated: HashMap<usize, usize>,
}

impl Signs {
    fn new(conditions: Vec<CondBits>) -> Signs {
        Signs {
            conditions,
            negated: HashMap::new(),
        }
    }

    /// The id of condition `id`, negated when `negated`.
    fn id(&mut self, id: usize, negated: bool) -> usize {
        if !negated {
            return id;
        }
        let conditions = &mut self.conditions;
        *self.negated.entry(id).or_insert_with(|| {
            let base = &conditions[id];
            let negation = CondBits {
                condition: base.condition.negate(),
                bits: base.bits.clone(),
            };
            conditions.push(negation);
            conditions.len() - 1
        })
    }
}

/// The initial state's bits: the initially true atoms of the universe.
fn initial_state(universe: &Universe, initial: &[Condition], words: usize) -> Box<[u64]> {
    let mut state = vec![0u64; words].into_boxed_slice();
    for c in initial.iter().filter(|c| !c.negated) {
        if let Some(&i) = universe.index.get(&c.atom) {
            state[i / 64] |= 1 << (i % 64);
        }
    }
    state
}
