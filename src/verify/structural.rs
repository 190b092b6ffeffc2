//! Structural checks: fast rules over the tree's shape and the skills' declarations,
//! without exploring states. They run before any execution.
//!
//! Reasoning follows one tick of the reactive tree. Going down, each node knows which
//! literals hold when it is ticked: a Sequence's child knows what its earlier siblings
//! guarantee by having succeeded (a condition: itself; an action: its declared
//! postconditions; a Sequence: the union of its children's; a Fallback: what every child
//! guarantees), and a Fallback's child knows the negation of each earlier sibling
//! condition that failed.
//!
//! Rules: every action's declared preconditions are known to hold when it is ticked;
//! no node is unreachable (after a Fallback child that can never fail, or a Sequence
//! child that can never succeed); every atom is in the vocabulary and every action names
//! a skill; no two Sequence siblings undo each other (the later one's actions undo what
//! the earlier one guarantees, and the earlier one's actions undo conditions the later
//! one needs), which makes a reactive tree oscillate.

use super::abstraction::instance_of;
use super::{Finding, Rule};
use crate::bt::path_text;
use crate::bt::{NodeId, NodeKind, Tree};
use crate::domain::{Condition, Domain};

/// A literal known to hold, and the node that makes it known.
#[derive(Debug, Clone)]
struct Known {
    condition: Condition,
    from: NodeId,
}

/// Whether knowing `k` means `c` holds (equal, or a concrete instance of a positive
/// wildcard, or a negated wildcard covering a negated concrete atom).
fn implies(k: &Condition, c: &Condition) -> bool {
    if k == c {
        return true;
    }
    if k.negated != c.negated {
        return false;
    }
    if c.negated {
        k.atom.has_wildcard() && instance_of(&k.atom, &c.atom)
    } else {
        c.atom.has_wildcard() && instance_of(&c.atom, &k.atom)
    }
}

fn known_to_hold<'a>(known: &'a [Known], c: &Condition) -> Option<&'a Known> {
    known.iter().find(|k| implies(&k.condition, c))
}

struct Checker<'a> {
    domain: &'a Domain,
    tree: &'a Tree,
    findings: Vec<Finding>,
}

/// Run every structural rule on `tree`.
pub fn check(domain: &Domain, tree: &Tree) -> Vec<Finding> {
    let mut c = Checker {
        domain,
        tree,
        findings: Vec::new(),
    };
    c.visit(tree.root(), &[]);
    c.oscillations();
    c.findings
}

impl Checker<'_> {
    fn path(&self, n: NodeId) -> Vec<usize> {
        self.tree.path(n).unwrap_or_default()
    }

    fn text(&self, n: NodeId) -> String {
        match self.tree.kind(n) {
            Ok(NodeKind::Condition(c)) => format!("{c}?"),
            Ok(NodeKind::Action(a)) => format!("{a}!"),
            Ok(NodeKind::Sequence) => self.composite_text("sequence", n),
            Ok(NodeKind::Fallback) => self.composite_text("fallback", n),
            Err(_) => n.to_string(),
        }
    }

    /// A composite named by the condition it leads with (`fallback for Holding_Coffee?`).
    fn composite_text(&self, kind: &str, n: NodeId) -> String {
        let mut at = n;
        while let Some(&first) = self.tree.children(at).ok().and_then(|c| c.first()) {
            if let Ok(NodeKind::Condition(c)) = self.tree.kind(first) {
                return format!("the {kind} for {c}?");
            }
            at = first;
        }
        format!("the {kind} at {}", path_text(&self.path(n)))
    }

    fn children(&self, n: NodeId) -> Vec<NodeId> {
        self.tree.children(n).map(<[_]>::to_vec).unwrap_or_default()
    }

    fn push(&mut self, node: NodeId, rule: Rule, message: String, hint: String) {
        self.findings.push(Finding {
            path: self.path(node),
            rule,
            message,
            hint,
        });
    }

    /// What holds when `n` returns Success.
    fn guarantee(&self, n: NodeId) -> Vec<Known> {
        match self.tree.kind(n) {
            Ok(NodeKind::Condition(c)) => vec![Known {
                condition: c.clone(),
                from: n,
            }],
            Ok(NodeKind::Action(a)) => self
                .domain
                .resolve(a)
                .map(|g| g.postconditions())
                .unwrap_or_default()
                .into_iter()
                .map(|condition| Known { condition, from: n })
                .collect(),
            Ok(NodeKind::Sequence) => self
                .children(n)
                .into_iter()
                .flat_map(|c| self.guarantee(c))
                .collect(),
            Ok(NodeKind::Fallback) => {
                let children = self.children(n);
                let Some((first, rest)) = children.split_first() else {
                    return Vec::new();
                };
                let others: Vec<Vec<Known>> = rest.iter().map(|c| self.guarantee(*c)).collect();
                self.guarantee(*first)
                    .into_iter()
                    .filter(|k| {
                        others
                            .iter()
                            .all(|o| known_to_hold(o, &k.condition).is_some())
                    })
                    .collect()
            }
            Err(_) => Vec::new(),
        }
    }

    /// What holds after `n` returned Failure (only a failed condition says something).
    fn on_failure(&self, n: NodeId) -> Vec<Known> {
        match self.tree.kind(n) {
            Ok(NodeKind::Condition(c)) => vec![Known {
                condition: c.negate(),
                from: n,
            }],
            _ => Vec::new(),
        }
    }

    /// Why `n` can never succeed given `known`, if it cannot.
    fn never_succeeds(&self, n: NodeId, known: &[Known]) -> Option<String> {
        match self.tree.kind(n).ok()? {
            NodeKind::Condition(c) => known_to_hold(known, &c.negate()).map(|k| {
                format!(
                    "{c}? always fails here ({} is known from {} at {})",
                    k.condition,
                    self.text(k.from),
                    path_text(&self.path(k.from))
                )
            }),
            NodeKind::Action(_) => None,
            NodeKind::Sequence => {
                let mut ctx = known.to_vec();
                for c in self.children(n) {
                    if let Some(why) = self.never_succeeds(c, &ctx) {
                        return Some(why);
                    }
                    ctx.extend(self.guarantee(c));
                }
                None
            }
            NodeKind::Fallback => {
                let mut ctx = known.to_vec();
                let mut reasons = Vec::new();
                for c in self.children(n) {
                    reasons.push(self.never_succeeds(c, &ctx)?);
                    ctx.extend(self.on_failure(c));
                }
                Some(reasons.join("; "))
            }
        }
    }

    /// Why `n` can never fail given `known`, if it cannot. (An action can always fail.)
    fn never_fails(&self, n: NodeId, known: &[Known]) -> Option<String> {
        match self.tree.kind(n).ok()? {
            NodeKind::Condition(c) => known_to_hold(known, c).map(|k| {
                format!(
                    "{c}? always succeeds here (known from {} at {})",
                    self.text(k.from),
                    path_text(&self.path(k.from))
                )
            }),
            NodeKind::Action(_) => None,
            NodeKind::Sequence => {
                let mut ctx = known.to_vec();
                let mut reasons = Vec::new();
                for c in self.children(n) {
                    reasons.push(self.never_fails(c, &ctx)?);
                    ctx.extend(self.guarantee(c));
                }
                Some(reasons.join("; "))
            }
            NodeKind::Fallback => {
                let mut ctx = known.to_vec();
                for c in self.children(n) {
                    if let Some(why) = self.never_fails(c, &ctx) {
                        return Some(why);
                    }
                    ctx.extend(self.on_failure(c));
                }
                None
            }
        }
    }

    fn visit(&mut self, n: NodeId, known: &[Known]) {
        let Ok(kind) = self.tree.kind(n) else { return };
        match kind.clone() {
            NodeKind::Condition(c) => {
                if let Err(e) = self.domain.vocabulary.check_condition(&c) {
                    self.push(
                        n,
                        Rule::UnknownAtom,
                        format!("{c}? is not in the scenario's vocabulary: {e}"),
                        "use a predicate and objects the scenario declares (see its [[predicates]] and [objects])".into(),
                    );
                }
            }
            NodeKind::Action(a) => match self.domain.resolve(&a) {
                None => {
                    let skills: Vec<&str> =
                        self.domain.skills.iter().map(|s| s.name.as_str()).collect();
                    self.push(
                        n,
                        Rule::UnknownAction,
                        format!("{a}! names no skill that accepts these objects"),
                        format!("use one of the scenario's skills: {}", skills.join(", ")),
                    );
                }
                Some(g) => {
                    for p in &g.pre {
                        if known_to_hold(known, p).is_none() {
                            self.push(
                                n,
                                Rule::UnguardedPrecondition,
                                format!(
                                    "{a}! needs {p}, but no condition on its path checks it and no earlier sibling establishes it"
                                ),
                                format!(
                                    "insert {p}? (expanded if it can fail) in {a}'s sequence, before the action"
                                ),
                            );
                        }
                    }
                }
            },
            NodeKind::Sequence | NodeKind::Fallback => {
                let sequence = matches!(kind, NodeKind::Sequence);
                let mut ctx = known.to_vec();
                let children = self.children(n);
                for (i, &c) in children.iter().enumerate() {
                    self.visit(c, &ctx);
                    let blocked = if sequence {
                        self.never_succeeds(c, &ctx)
                    } else {
                        self.never_fails(c, &ctx)
                    };
                    if let (Some(why), Some(&next)) = (blocked, children.get(i + 1)) {
                        let (rule_word, stop) = if sequence {
                            ("never succeeds", "succeed")
                        } else {
                            ("never fails", "fail")
                        };
                        self.push(
                            next,
                            Rule::Unreachable,
                            format!(
                                "{} and every later sibling are never ticked: the earlier sibling {} at {} {rule_word} ({why})",
                                self.text(next),
                                self.text(c),
                                path_text(&self.path(c))
                            ),
                            format!(
                                "remove the unreachable children, or change {} so that it can {stop}",
                                self.text(c)
                            ),
                        );
                        break;
                    }
                    if sequence {
                        ctx.extend(self.guarantee(c));
                    } else {
                        ctx.extend(self.on_failure(c));
                    }
                }
            }
        }
    }

    /// Sequence siblings that undo each other.
    fn oscillations(&mut self) {
        for seq in self.tree.preorder() {
            if !matches!(self.tree.kind(seq), Ok(NodeKind::Sequence)) {
                continue;
            }
            let children = self.children(seq);
            for (i, &earlier) in children.iter().enumerate() {
                for &later in &children[i + 1..] {
                    if let Some(message) = self.undo_each_other(earlier, later) {
                        self.push(
                            later,
                            Rule::Oscillation,
                            message,
                            format!(
                                "move {} before {} (at {}), or guard one against the other",
                                self.text(later),
                                self.text(earlier),
                                path_text(&self.path(earlier))
                            ),
                        );
                    }
                }
            }
        }
    }

    fn undo_each_other(&self, earlier: NodeId, later: NodeId) -> Option<String> {
        let actions = |n: NodeId| -> Vec<(NodeId, crate::domain::GroundSkill)> {
            self.tree
                .subtree(n)
                .unwrap_or_default()
                .into_iter()
                .filter_map(|id| match self.tree.kind(id) {
                    Ok(NodeKind::Action(a)) => self.domain.resolve(a).map(|g| (id, g)),
                    _ => None,
                })
                .collect()
        };
        let conditions = |n: NodeId| -> Vec<Condition> {
            self.tree
                .subtree(n)
                .unwrap_or_default()
                .into_iter()
                .filter_map(|id| match self.tree.kind(id) {
                    Ok(NodeKind::Condition(c)) => Some(c.clone()),
                    _ => None,
                })
                .collect()
        };
        let guaranteed = self.guarantee(earlier);
        let (undoer, undone) = actions(later).into_iter().find_map(|(id, g)| {
            guaranteed
                .iter()
                .find(|k| g.undoes(&k.condition))
                .map(|k| (id, k.condition.clone()))
        })?;
        let needed = conditions(later);
        let (back, needed_undone) = actions(earlier)
            .into_iter()
            .find_map(|(id, g)| needed.iter().find(|c| g.undoes(c)).map(|c| (id, c.clone())))?;
        Some(format!(
            "{} undoes {undone}, which the earlier sibling ({}) establishes, and {} in that sibling undoes {needed_undone}, which {} needs: the reactive tree can oscillate between them",
            self.text(undoer),
            self.text(earlier),
            self.text(back),
            self.text(later)
        ))
    }
}
