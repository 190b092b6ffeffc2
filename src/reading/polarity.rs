//! Whether a goal asks for a condition the other way round from the request: "do not open
//! the curtain" read as `~Closed_Curtain`, "a moderate temperature" read as
//! `Low_ACTemperature`. The scene file lists, per predicate, the words that say it holds
//! and those that say its opposite. A clause of the request with such a word, about an
//! object the clause names (or the one object the predicate can be about), asks for that
//! condition, turned around by each negation before the word in the clause ("don't
//! forget to turn on" asks for it on).

use std::fmt;

use crate::domain::Atom;
use crate::goal::Formula;
use crate::goal::rewrite::{flipped, undo_each};

use super::request::Request;

/// A condition the request asks for one way and the goal has the other way.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnedAround {
    pub atom: Atom,
    /// Whether the request asks for the atom to hold.
    pub wanted: bool,
    /// The request's word that says which way.
    pub word: String,
}

impl fmt::Display for TurnedAround {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (asked, has) = if self.wanted {
            (self.atom.to_string(), format!("~{}", self.atom))
        } else {
            (format!("~{}", self.atom), self.atom.to_string())
        };
        write!(
            f,
            "the request says \"{}\", which asks for {asked}, where the goal has {has}",
            self.word
        )
    }
}

/// A condition of `goal` that the request asks for the other way round, if any.
pub fn turned_around(goal: &Formula, request: &Request) -> Option<TurnedAround> {
    request
        .asked()
        .iter()
        .find_map(|(subject, wanted, word, _)| {
            let pick = |a: &Atom| subject.matches(a);
            let signs = signs_of(goal, &pick, true);
            if signs.is_empty() || signs.contains(wanted) {
                return None;
            }
            Some(TurnedAround {
                atom: first_matching(goal, &pick)?,
                wanted: *wanted,
                word: word.clone(),
            })
        })
}

/// `goal` with every condition the request asks for the other way round turned around.
/// `None` when nothing is turned around.
pub fn turned_back(goal: &Formula, request: &Request) -> Option<Formula> {
    // Each atom is turned once: a second finding about it would undo the first.
    undo_each(
        goal,
        |g| turned_around(g, request),
        |t| t.atom.clone(),
        |g, t| flipped(g, &t.atom),
    )
}

/// A condition the request asks for in its own words, in a sentence that offers no
/// choice, and that `goal` has no condition about at all ("don't forget to turn on the
/// hall light" read as the deliveries alone); with whether it is asked to hold and the
/// word that asks for it.
pub fn left_unanswered(goal: &Formula, request: &Request) -> Option<(Atom, bool, String)> {
    let atoms = goal.atoms();
    request
        .asked()
        .iter()
        .filter(|(_, _, _, choice)| !choice)
        .find(|(subject, _, _, _)| !atoms.iter().any(|a| subject.matches(a)))
        .and_then(|(subject, wanted, word, _)| {
            let atom = Atom::new(subject.predicate.clone(), vec![subject.object.clone()]);
            let takes_one = request
                .vocabulary
                .predicates
                .iter()
                .any(|p| p.name == subject.predicate && p.arg_types.len() == 1);
            takes_one.then_some((atom, *wanted, word.clone()))
        })
}

/// `goal` with every condition [`left_unanswered`] finds put beside it, the way the
/// request asks for it. `None` when nothing is left unanswered.
pub fn with_unanswered(goal: &Formula, request: &Request) -> Option<Formula> {
    undo_each(
        goal,
        |g| left_unanswered(g, request),
        |(atom, _, _)| atom.clone(),
        |g, (atom, wanted, _)| {
            let condition = Formula::Atom(atom.clone());
            let condition = if *wanted {
                condition
            } else {
                Formula::Not(Box::new(condition))
            };
            Formula::and(vec![g.clone(), condition])
        },
    )
}

/// The sign (held or negated) of each place `goal` has an atom that `pick` picks.
fn signs_of(goal: &Formula, pick: &dyn Fn(&Atom) -> bool, positive: bool) -> Vec<bool> {
    match goal {
        Formula::Atom(a) => {
            if pick(a) {
                vec![positive]
            } else {
                Vec::new()
            }
        }
        Formula::Not(inner) => signs_of(inner, pick, !positive),
        Formula::And(items) | Formula::Or(items) => items
            .iter()
            .flat_map(|i| signs_of(i, pick, positive))
            .collect(),
    }
}

/// The first atom of `goal` that `pick` picks.
fn first_matching(goal: &Formula, pick: &dyn Fn(&Atom) -> bool) -> Option<Atom> {
    goal.atoms_in_order().into_iter().find(|a| pick(a))
}

#[cfg(test)]
#[path = "polarity_tests.rs"]
mod tests;
