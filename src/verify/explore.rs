//! Breadth-first exploration of every state reachable from the initial state, and the
//! checks over the resulting graph.
//!
//! States get their index in discovery order, so a lower index is never deeper: the first
//! violating state found by index is one with a shortest path, and the BFS parents give
//! that path (the shortest counterexample). Exploration stops at `max_states`; then the
//! graph is partial and a property that no explored state violates is "unknown", never
//! "holds".

use std::collections::{HashMap, VecDeque};

use super::abstraction::{Expr, Model, State};

/// One transition: a tick in which the first `fail` actions reached fail (0: nominal), or
/// a disturbance (index into `Model::disturbances`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edge {
    Tick { fail: u16 },
    Disturb(u32),
}

/// What the tree does from a state on its own (no failure, no disturbance).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Nominal {
    /// The root returns Success and no action runs.
    Success,
    /// The root returns Failure and no action runs.
    DeadEnd,
    /// An action executes, leading to this state.
    Step(u32),
}

/// Bounds and switches of one exploration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    pub max_states: usize,
    pub max_ticks: u64,
    pub action_failures: bool,
}

/// The explored state graph.
pub struct Graph {
    pub states: Vec<State>,
    /// How each state (but the first) was first reached.
    pub parent: Vec<Option<(u32, Edge)>>,
    /// Outgoing transitions of the expanded states (self-loops included).
    pub edges: Vec<Vec<(u32, Edge)>>,
    pub nominal: Vec<Nominal>,
    /// False when `max_states` stopped the exploration.
    pub complete: bool,
    pub transitions: usize,
    /// The first (state, tick) in which an action started without a declared precondition:
    /// (state, failures in that tick, action, condition).
    pub first_unmet: Option<(u32, u16, usize, usize)>,
}

impl Graph {
    /// Number of states whose transitions are known (a prefix of the BFS order).
    pub fn expanded(&self) -> usize {
        self.edges.len()
    }

    /// The shortest transition sequence from the initial state to `target`.
    pub fn path_to(&self, target: u32) -> Vec<(u32, Edge)> {
        let mut out = Vec::new();
        let mut at = target;
        while let Some(Some((from, edge))) = self.parent.get(at as usize) {
            out.push((*from, *edge));
            at = *from;
        }
        out.reverse();
        out
    }
}

/// Explore from the model's initial state.
pub fn explore(model: &Model, limits: &Limits) -> Graph {
    let mut g = Graph {
        states: vec![model.initial.clone()],
        parent: vec![None],
        edges: Vec::new(),
        nominal: Vec::new(),
        complete: true,
        transitions: 0,
        first_unmet: None,
    };
    let mut index: HashMap<State, u32> = HashMap::new();
    index.insert(model.initial.clone(), 0);
    let mut next = 0usize;
    while next < g.states.len() {
        let s = g.states[next].clone();
        let (nominal_next, mut successors) = successors(model, &s, limits, &mut g, next);
        let new = successors
            .iter()
            .filter(|(st, _)| !index.contains_key(st))
            .map(|(st, _)| st)
            .collect::<std::collections::HashSet<_>>()
            .len();
        if g.states.len() + new > limits.max_states {
            g.complete = false;
            break;
        }
        let mut out = Vec::with_capacity(successors.len());
        let mut nominal_index = None;
        for (i, (state, edge)) in successors.drain(..).enumerate() {
            let id = match index.get(&state) {
                Some(&id) => id,
                None => {
                    let id = g.states.len() as u32;
                    index.insert(state.clone(), id);
                    g.states.push(state);
                    g.parent.push(Some((next as u32, edge)));
                    id
                }
            };
            if i == 0 {
                nominal_index = Some(id);
            }
            out.push((id, edge));
        }
        g.transitions += out.len();
        g.edges.push(out);
        g.nominal.push(match (nominal_next, nominal_index) {
            (Nominal::Step(_), Some(id)) => Nominal::Step(id),
            (Nominal::Step(_), None) => Nominal::DeadEnd,
            (other, _) => other,
        });
        next += 1;
    }
    g
}

/// The successors of `s`, the nominal tick first.
fn successors(
    model: &Model,
    s: &State,
    limits: &Limits,
    g: &mut Graph,
    at: usize,
) -> (Nominal, Vec<(State, Edge)>) {
    let mut out = Vec::new();
    let mut nominal = Nominal::DeadEnd;
    let mut fail = 0u16;
    loop {
        let r = model.tick(s, usize::from(fail));
        if g.first_unmet.is_none()
            && let Some(&(action, condition)) = r.unmet.first()
        {
            g.first_unmet = Some((at as u32, fail, action, condition));
        }
        let next = match r.executed {
            Some(a) => {
                let action = &model.actions[a];
                model.apply(s, &action.add, &action.del)
            }
            None => s.clone(),
        };
        if fail == 0 {
            nominal = match (r.executed, r.root) {
                (Some(_), _) => Nominal::Step(0),
                (None, crate::bt::Outcome::Success) => Nominal::Success,
                (None, _) => Nominal::DeadEnd,
            };
        }
        out.push((next, Edge::Tick { fail }));
        if r.executed.is_none() || !limits.action_failures || fail == u16::MAX {
            break;
        }
        fail += 1;
    }
    for (j, d) in model.disturbances.iter().enumerate() {
        if d.pre.iter().all(|&c| model.holds(s, c)) {
            out.push((model.apply(s, &d.add, &d.del), Edge::Disturb(j as u32)));
        }
    }
    (nominal, out)
}

/// Whether the tree, left alone, reaches Success from every reachable state.
#[derive(Debug, Clone, PartialEq)]
pub enum Liveness {
    /// It does; `worst` is the most ticks any reachable state needs.
    Holds { worst: u64 },
    /// This reachable state is a dead end.
    DeadEnd(u32),
    /// The nominal run from `entry` returns to `entry` through `cycle` without success.
    Livelock { entry: u32, cycle: Vec<u32> },
    /// The nominal run from this state needs more ticks than the bound.
    TooSlow { state: u32, ticks: u64 },
    /// The exploration bound left some run unfinished.
    Unknown,
}

#[derive(Clone, Copy, PartialEq)]
enum Val {
    Pending,
    OnPath,
    Ticks(u64),
    Bad,
    Unknown,
}

pub fn check_liveness(g: &Graph, max_ticks: u64) -> Liveness {
    let n = g.expanded();
    let mut val = vec![Val::Pending; g.states.len()];
    let mut bad_roots: Vec<u32> = Vec::new();
    for (s, nominal) in g.nominal.iter().enumerate() {
        if *nominal == Nominal::DeadEnd {
            bad_roots.push(s as u32);
        }
    }
    for start in 0..n {
        if val[start] != Val::Pending {
            continue;
        }
        let mut path: Vec<usize> = Vec::new();
        let mut cur = start;
        let end = loop {
            match val[cur] {
                Val::Ticks(_) | Val::Bad | Val::Unknown => break val[cur],
                Val::OnPath => {
                    let from = path.iter().position(|&p| p == cur).unwrap_or(0);
                    if let Some(&first) = path[from..].iter().min() {
                        bad_roots.push(first as u32);
                    }
                    break Val::Bad;
                }
                Val::Pending => {}
            }
            if cur >= n {
                break Val::Unknown;
            }
            match g.nominal[cur] {
                Nominal::Success => {
                    val[cur] = Val::Ticks(0);
                    break Val::Ticks(0);
                }
                Nominal::DeadEnd => {
                    val[cur] = Val::Bad;
                    break Val::Bad;
                }
                Nominal::Step(next) => {
                    val[cur] = Val::OnPath;
                    path.push(cur);
                    cur = next as usize;
                }
            }
        };
        let mut v = end;
        for &p in path.iter().rev() {
            v = match v {
                Val::Ticks(t) => Val::Ticks(t + 1),
                other => other,
            };
            val[p] = v;
        }
    }
    if let Some(&first) = bad_roots.iter().min() {
        if g.nominal.get(first as usize) == Some(&Nominal::DeadEnd) {
            return Liveness::DeadEnd(first);
        }
        let mut cycle = Vec::new();
        let mut cur = first;
        while let Some(Nominal::Step(next)) = g.nominal.get(cur as usize) {
            cycle.push(*next);
            if *next == first || cycle.len() > g.states.len() {
                break;
            }
            cur = *next;
        }
        return Liveness::Livelock {
            entry: first,
            cycle,
        };
    }
    let mut worst = 0;
    for (s, v) in val.iter().enumerate().take(n) {
        match v {
            Val::Ticks(t) if *t > max_ticks => {
                return Liveness::TooSlow {
                    state: s as u32,
                    ticks: *t,
                };
            }
            Val::Ticks(t) => worst = worst.max(*t),
            _ => {}
        }
    }
    if !g.complete || val.iter().take(n).any(|v| *v == Val::Unknown) {
        return Liveness::Unknown;
    }
    Liveness::Holds { worst }
}

/// The first state (by BFS order) where `want` differs from the formula's value.
pub fn first_state_where(model: &Model, g: &Graph, e: &Expr, want: bool) -> Option<u32> {
    (0..g.states.len())
        .find(|&s| model.eval(&g.states[s], e) == want)
        .map(|s| s as u32)
}

/// `eventually F`: a run from the initial state that never reaches F.
#[derive(Debug, Clone, PartialEq)]
pub enum Eventually {
    Holds,
    /// A path (from the initial state) to `entry`, then a cycle back to it, all avoiding F.
    Lasso {
        prefix: Vec<(u32, Edge)>,
        cycle: Vec<(u32, Edge)>,
    },
    Unknown,
}

pub fn check_eventually(model: &Model, g: &Graph, e: &Expr) -> Eventually {
    let avoid = |s: u32| !model.eval(&g.states[s as usize], e);
    if !avoid(0) {
        return Eventually::Holds;
    }
    let n = g.expanded();
    // BFS over states avoiding F, with parents, from the initial state.
    let mut parent: HashMap<u32, Option<(u32, Edge)>> = HashMap::new();
    parent.insert(0, None);
    let mut order = vec![0u32];
    let mut queue = VecDeque::from([0u32]);
    let mut partial = false;
    while let Some(s) = queue.pop_front() {
        if s as usize >= n {
            partial = true;
            continue;
        }
        for &(t, edge) in &g.edges[s as usize] {
            if avoid(t) && !parent.contains_key(&t) {
                parent.insert(t, Some((s, edge)));
                order.push(t);
                queue.push_back(t);
            }
        }
    }
    let succ = |s: u32| -> Vec<(u32, Edge)> {
        g.edges
            .get(s as usize)
            .map(|es| es.iter().copied().filter(|(t, _)| avoid(*t)).collect())
            .unwrap_or_default()
    };
    let cyclic = cyclic_states(&order, &succ);
    // The cyclic state reached first by the BFS has the shortest prefix.
    let Some(&entry) = order.iter().find(|s| cyclic.contains(s)) else {
        return if partial || !g.complete {
            Eventually::Unknown
        } else {
            Eventually::Holds
        };
    };
    let mut prefix = Vec::new();
    let mut at = entry;
    while let Some(Some((from, edge))) = parent.get(&at) {
        prefix.push((*from, *edge));
        at = *from;
    }
    prefix.reverse();
    Eventually::Lasso {
        prefix,
        cycle: shortest_cycle(entry, &succ),
    }
}

/// The shortest sequence of transitions from `entry` back to itself.
fn shortest_cycle(entry: u32, succ: &dyn Fn(u32) -> Vec<(u32, Edge)>) -> Vec<(u32, Edge)> {
    let mut parent: HashMap<u32, (u32, Edge)> = HashMap::new();
    let mut queue = VecDeque::from([entry]);
    while let Some(s) = queue.pop_front() {
        for (t, edge) in succ(s) {
            if t == entry {
                let mut out = vec![(s, edge)];
                let mut at = s;
                while at != entry {
                    let Some(&(from, e)) = parent.get(&at) else {
                        break;
                    };
                    out.push((from, e));
                    at = from;
                }
                out.reverse();
                return out;
            }
            if let std::collections::hash_map::Entry::Vacant(v) = parent.entry(t) {
                v.insert((s, edge));
                queue.push_back(t);
            }
        }
    }
    Vec::new()
}

/// States of `vertices` that lie on a cycle (Tarjan's strongly connected components,
/// iteratively so that deep graphs cannot overflow the stack).
fn cyclic_states(
    vertices: &[u32],
    succ: &dyn Fn(u32) -> Vec<(u32, Edge)>,
) -> std::collections::HashSet<u32> {
    let mut index: HashMap<u32, (usize, usize)> = HashMap::new(); // (index, lowlink)
    let mut on_stack = std::collections::HashSet::new();
    let mut stack: Vec<u32> = Vec::new();
    let mut out = std::collections::HashSet::new();
    let mut counter = 0;
    for &root in vertices {
        if index.contains_key(&root) {
            continue;
        }
        let mut calls: Vec<(u32, Vec<u32>, usize)> = Vec::new();
        index.insert(root, (counter, counter));
        counter += 1;
        stack.push(root);
        on_stack.insert(root);
        calls.push((root, succ(root).into_iter().map(|(t, _)| t).collect(), 0));
        while let Some((v, succs, pos)) = calls.last_mut() {
            let v = *v;
            if let Some(&w) = succs.get(*pos) {
                *pos += 1;
                match index.get(&w).copied() {
                    None => {
                        index.insert(w, (counter, counter));
                        counter += 1;
                        stack.push(w);
                        on_stack.insert(w);
                        calls.push((w, succ(w).into_iter().map(|(t, _)| t).collect(), 0));
                    }
                    Some((wi, _)) if on_stack.contains(&w) => {
                        if let Some(e) = index.get_mut(&v) {
                            e.1 = e.1.min(wi);
                        }
                    }
                    Some(_) => {}
                }
                continue;
            }
            let self_loop = succs.contains(&v);
            calls.pop();
            let (vi, vl) = index.get(&v).copied().unwrap_or((0, 0));
            if let Some((u, _, _)) = calls.last()
                && let Some(e) = index.get_mut(u)
            {
                e.1 = e.1.min(vl);
            }
            if vl == vi {
                let mut component = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack.remove(&w);
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 || self_loop {
                    out.extend(component);
                }
            }
        }
    }
    out
}
