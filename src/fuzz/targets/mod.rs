//! One target per reader, and what they share: the checks of error positions and the
//! generators of goals and trees over a scenario's vocabulary.

mod btcpp;
mod cassette;
mod goal;
mod groot2;
mod journal;
mod policy;
mod recording;
mod reply;
mod scenario;
mod tree;
mod wav;

use std::borrow::Cow;

use super::{Corpus, FuzzError, Rng, Target, Violation, broken, ensure};
use crate::bt::{NodeKind, Tree};
use crate::domain::{ActionCall, Atom, Condition, Domain, Value};
use crate::goal::Formula;

pub(super) fn build(name: &str, corpus: &Corpus) -> Result<Box<dyn Target>, FuzzError> {
    Ok(match name {
        "goal" => Box::new(goal::GoalTarget::new(corpus)),
        "reply" => Box::new(reply::ReplyTarget::new(corpus)),
        "tree" => Box::new(tree::TreeTarget::new(corpus)),
        "btcpp" => Box::new(btcpp::BtcppTarget::new(corpus)),
        "scenario" => Box::new(scenario::ScenarioTarget::new(corpus)),
        "policy" => Box::new(policy::PolicyTarget::new(corpus)),
        "cassette" => Box::new(cassette::CassetteTarget::new()),
        "journal" => Box::new(journal::JournalTarget::new(corpus)),
        "wav" => Box::new(wav::WavTarget::new()),
        "recording" => Box::new(recording::RecordingTarget::new(corpus)),
        "groot2" => Box::new(groot2::Groot2Target::new()),
        other => {
            return Err(FuzzError::UnknownTarget {
                name: other.to_string(),
            });
        }
    })
}

/// The input as text (invalid UTF-8 replaced, as a reader of text files would refuse it
/// before parsing).
fn text_of(input: &[u8]) -> Cow<'_, str> {
    String::from_utf8_lossy(input)
}

fn strings(items: &[&str]) -> Vec<String> {
    items.iter().map(|s| (*s).to_string()).collect()
}

fn pairs(items: &[(&str, &str)]) -> Vec<(String, String)> {
    items
        .iter()
        .map(|(a, b)| ((*a).to_string(), (*b).to_string()))
        .collect()
}

/// A byte offset an error names lies in `text` (or just past it) on a character boundary.
fn check_offset(text: &str, at: usize, rule: &'static str) -> Result<(), Violation> {
    ensure(at <= text.len() && text.is_char_boundary(at), rule, || {
        format!("offset {at} in a text of {} bytes: {text:?}", text.len())
    })
}

/// A 1-based line and character column an error names lie in `text`: the line exists
/// (lines end at `\n`) and the column is at most one past its last character.
fn check_line_column(
    text: &str,
    line: usize,
    column: usize,
    rule: &'static str,
) -> Result<(), Violation> {
    let lines: Vec<&str> = text.split('\n').collect();
    let Some(content) = line.checked_sub(1).and_then(|i| lines.get(i)) else {
        return Err(broken(
            rule,
            format!("line {line} of a text of {} lines", lines.len()),
        ));
    };
    let width = content.chars().count();
    ensure((1..=width + 1).contains(&column), rule, || {
        format!("line {line}, column {column}, but the line has {width} characters: {content:?}")
    })
}

/// Atoms of `domain`'s vocabulary: every predicate over fitting objects (or the wildcard),
/// at most `limit`.
fn atoms_of(domain: &Domain, limit: usize) -> Vec<Atom> {
    let v = &domain.vocabulary;
    let mut out = Vec::new();
    for p in &v.predicates {
        let mut args: Vec<String> = Vec::new();
        for (i, types) in p.arg_types.iter().enumerate() {
            let fitting: Vec<&str> = v.objects_fitting(types).collect();
            let pick = fitting.get(out.len() % fitting.len().max(1)).copied();
            args.push(
                pick.unwrap_or(if i == 0 { "any object" } else { "x" })
                    .to_string(),
            );
        }
        out.push(Atom::new(p.name.clone(), args));
        if out.len() >= limit {
            break;
        }
    }
    out.extend(
        v.ground_atoms()
            .into_iter()
            .take(limit.saturating_sub(out.len())),
    );
    out
}

/// A random formula over `atoms`, at most `depth` levels deep.
fn random_formula(rng: &mut Rng, atoms: &[Atom], depth: usize) -> Formula {
    if depth == 0 || rng.chance(30) {
        let atom = rng
            .pick(atoms)
            .cloned()
            .unwrap_or_else(|| Atom::new("Active", ["AC"]));
        return Formula::Atom(atom);
    }
    match rng.below(3) {
        0 => Formula::Not(Box::new(random_formula(rng, atoms, depth - 1))),
        k => {
            let items = (0..1 + rng.small(4))
                .map(|_| random_formula(rng, atoms, depth - 1))
                .collect();
            if k == 1 {
                Formula::And(items)
            } else {
                Formula::Or(items)
            }
        }
    }
}

/// A random leaf: a condition over `atoms` or an action of `domain`'s skills (with a value
/// when the skill takes one).
fn random_leaf(rng: &mut Rng, atoms: &[Atom], domain: &Domain) -> NodeKind {
    if rng.chance(50) || domain.skills.is_empty() {
        let atom = rng
            .pick(atoms)
            .cloned()
            .unwrap_or_else(|| Atom::new("Active", ["AC"]));
        let c = if rng.chance(30) {
            Condition::neg(atom)
        } else {
            Condition::pos(atom)
        };
        return NodeKind::Condition(c);
    }
    let Some(skill) = rng.pick(&domain.skills) else {
        return NodeKind::Action(ActionCall::new("Sweep", Vec::<String>::new()));
    };
    let objects: Vec<&str> = domain
        .vocabulary
        .objects
        .iter()
        .map(|o| o.name.as_str())
        .collect();
    let args: Vec<String> = skill
        .params
        .iter()
        .map(|_| rng.pick(&objects).copied().unwrap_or("x").to_string())
        .collect();
    let mut call = ActionCall::new(skill.name.clone(), args);
    for v in &skill.values {
        if rng.chance(50) {
            let value = match (&v.unit, v.categories.first()) {
                (Some(unit), _) => Value::Number {
                    value: (rng.below(2000) as f64) / 10.0,
                    unit: unit.clone(),
                },
                (None, Some(c)) => Value::Category(c.clone()),
                (None, None) => Value::Category("tool".into()),
            };
            call.values.push((v.name.clone(), value));
        }
    }
    NodeKind::Action(call)
}

/// A random tree of about `size` nodes over `domain`.
fn random_tree(rng: &mut Rng, atoms: &[Atom], domain: &Domain, size: usize) -> Tree {
    let root_kind = if rng.chance(10) {
        random_leaf(rng, atoms, domain)
    } else if rng.chance(50) {
        NodeKind::Sequence
    } else {
        NodeKind::Fallback
    };
    let mut tree = Tree::new(root_kind);
    let mut composites = vec![tree.root()];
    if !tree.kind(tree.root()).is_ok_and(NodeKind::is_composite) {
        return tree;
    }
    let mut childless = vec![tree.root()];
    for _ in 0..size {
        let Some(&parent) = rng.pick(&composites) else {
            break;
        };
        let kind = if rng.chance(25) {
            if rng.chance(50) {
                NodeKind::Sequence
            } else {
                NodeKind::Fallback
            }
        } else {
            random_leaf(rng, atoms, domain)
        };
        let composite = kind.is_composite();
        let Ok(id) = tree.add_child(parent, kind) else {
            break;
        };
        childless.retain(|c| *c != parent);
        if composite {
            composites.push(id);
            childless.push(id);
        }
    }
    // Every composite needs a child to be a valid tree.
    for c in childless {
        let leaf = random_leaf(rng, atoms, domain);
        let _ = tree.add_child(c, leaf);
    }
    tree
}
