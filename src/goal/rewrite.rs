//! Rewrites of a goal's atoms that keep its shape: an argument renamed, every atom mapped,
//! one atom's sign turned, and findings undone one after another.

use crate::domain::Atom;

use super::Formula;

/// `goal` with each finding of `find` undone by `undo`, until `find` finds nothing or
/// finds again what it found before (undoing that twice would turn it back). `None` when
/// nothing was undone.
pub fn undo_each<F, K: PartialEq>(
    goal: &Formula,
    find: impl Fn(&Formula) -> Option<F>,
    key: impl Fn(&F) -> K,
    undo: impl Fn(&Formula, &F) -> Formula,
) -> Option<Formula> {
    let mut current = goal.clone();
    let mut done: Vec<K> = Vec::new();
    while let Some(finding) = find(&current) {
        let k = key(&finding);
        if done.contains(&k) {
            break;
        }
        current = undo(&current, &finding);
        done.push(k);
    }
    (!done.is_empty()).then_some(current)
}

/// `goal` with every argument `from` written `to`.
pub fn rename(goal: &Formula, from: &str, to: &str) -> Formula {
    map_atoms(goal, &|a| {
        Atom::new(
            a.predicate.clone(),
            a.args
                .iter()
                .map(|x| if x == from { to.to_string() } else { x.clone() })
                .collect::<Vec<String>>(),
        )
    })
}

/// `goal` with each atom replaced by what `f` makes of it; two items made the same are
/// one (`A & B` with B renamed to A is `A`).
pub fn map_atoms(goal: &Formula, f: &impl Fn(&Atom) -> Atom) -> Formula {
    match goal {
        Formula::Atom(a) => Formula::Atom(f(a)),
        Formula::Not(inner) => Formula::Not(Box::new(map_atoms(inner, f))),
        Formula::And(items) => Formula::and(items.iter().map(|i| map_atoms(i, f)).collect()),
        Formula::Or(items) => Formula::or(items.iter().map(|i| map_atoms(i, f)).collect()),
    }
}

/// `goal` with `atom` negated wherever it stands (a negated one loses its negation).
pub fn flipped(goal: &Formula, atom: &Atom) -> Formula {
    match goal {
        Formula::Atom(a) if a == atom => Formula::Not(Box::new(goal.clone())),
        Formula::Atom(_) => goal.clone(),
        Formula::Not(inner) => match inner.as_ref() {
            Formula::Atom(a) if a == atom => Formula::Atom(a.clone()),
            _ => Formula::Not(Box::new(flipped(inner, atom))),
        },
        Formula::And(items) => Formula::and(items.iter().map(|i| flipped(i, atom)).collect()),
        Formula::Or(items) => Formula::or(items.iter().map(|i| flipped(i, atom)).collect()),
    }
}
