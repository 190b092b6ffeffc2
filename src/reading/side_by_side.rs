//! Things a request names side by side: "fries or a dessert", "milk and some yogurt". Both
//! are asked for, the same way; a goal that has one in its conditions and not the other has
//! left one out ("fries or a dessert" read as the dessert alone), and the goal with the
//! left-out one beside it — in the same condition, joined as the request joins them — is
//! a candidate.

use crate::domain::{Atom, Object};
use crate::goal::Formula;
use crate::goal::rewrite::undo_each;

use super::english::may_precede_thing;
use super::placement::named_in;
use super::request::Request;
use super::request::mentions::mentions;

/// Two things named side by side, one of which the goal leaves out.
#[derive(Debug, Clone, PartialEq)]
pub struct LeftOut {
    /// The one the goal has.
    pub kept: String,
    pub left_out: String,
    /// Joined by "or" (else by "and").
    pub choice: bool,
    /// The left-out one is named first.
    pub first: bool,
}

/// The first pair of things the request names side by side that `goal` has only one of.
/// A thing counts as had only in a condition whose other objects the request names: "not
/// on the bar and bar 2" read as chips not on the bar and a bottled drink, never named,
/// not on bar 2 has left bar 2 out of what the request asks about.
pub fn left_out(goal: &Formula, request: &Request) -> Option<LeftOut> {
    let atoms = goal.atoms();
    let objects: Vec<&Object> = request.vocabulary.objects.iter().collect();
    let named = named_in(request, &objects);
    let has = |object: &str| {
        atoms.iter().any(|a| {
            a.args.iter().any(|x| x == object)
                && a.args.iter().all(|x| {
                    x == object || named.contains(x) || !objects.iter().any(|o| o.name == *x)
                })
        })
    };
    side_by_side(request)
        .into_iter()
        .find_map(
            |(before, after, choice)| match (has(&before), has(&after)) {
                (true, false) => Some(LeftOut {
                    kept: before,
                    left_out: after,
                    choice,
                    first: false,
                }),
                (false, true) => Some(LeftOut {
                    kept: after,
                    left_out: before,
                    choice,
                    first: true,
                }),
                _ => None,
            },
        )
}

/// `goal` with each thing it left out put beside the one named with it: each condition
/// about the kept one becomes that condition and the same about the left-out one, joined
/// by `|` for "or" and `&` for "and" (a negated one always by `&`: "not the cup or the
/// juice" wants neither).
pub fn with_left_out(goal: &Formula, request: &Request) -> Option<Formula> {
    undo_each(
        goal,
        |g| left_out(g, request),
        |gap| gap.left_out.clone(),
        beside,
    )
}

fn beside(goal: &Formula, gap: &LeftOut) -> Formula {
    let about_kept = |a: &Atom| a.args.contains(&gap.kept);
    let twin = |a: &Atom| {
        Atom::new(
            a.predicate.clone(),
            a.args
                .iter()
                .map(|x| {
                    if *x == gap.kept {
                        gap.left_out.clone()
                    } else {
                        x.clone()
                    }
                })
                .collect::<Vec<String>>(),
        )
    };
    let pair = |kept: Formula, other: Formula, negated: bool| {
        let items = if gap.first {
            vec![other, kept]
        } else {
            vec![kept, other]
        };
        if gap.choice && !negated {
            Formula::Or(items)
        } else {
            Formula::And(items)
        }
    };
    match goal {
        Formula::Atom(a) if about_kept(a) => pair(goal.clone(), Formula::Atom(twin(a)), false),
        Formula::Not(inner) => match inner.as_ref() {
            Formula::Atom(a) if about_kept(a) => pair(
                goal.clone(),
                Formula::Not(Box::new(Formula::Atom(twin(a)))),
                true,
            ),
            _ => Formula::Not(Box::new(beside(inner, gap))),
        },
        Formula::And(items) => Formula::and(items.iter().map(|i| beside(i, gap)).collect()),
        Formula::Or(items) => Formula::Or(items.iter().map(|i| beside(i, gap)).collect()),
        Formula::Atom(_) => goal.clone(),
    }
}

/// The pairs of things of a kind the request names right before and after "or" or "and",
/// sentence by sentence in its order, each with whether "or" joins them.
fn side_by_side(request: &Request) -> Vec<(String, String, bool)> {
    let vocabulary = request.vocabulary;
    let objects: Vec<&Object> = vocabulary.objects.iter().collect();
    let kind_of = |name: &str| {
        vocabulary
            .objects
            .iter()
            .find(|o| o.name == name)
            .map(|o| o.types.clone())
            .unwrap_or_default()
    };
    let mut out = Vec::new();
    for words in &request.sentences {
        let named = mentions(words, &objects, &[]);
        for (at, word) in words.iter().enumerate() {
            let choice = match word.as_str() {
                "or" => true,
                "and" => false,
                _ => continue,
            };
            let Some((_, _, before)) = named.iter().find(|(start, len, _)| start + len == at)
            else {
                continue;
            };
            let mut next = at + 1;
            while words.get(next).is_some_and(|w| may_precede_thing(w)) {
                next += 1;
            }
            let Some((_, _, after)) = named.iter().find(|(start, _, _)| *start == next) else {
                continue;
            };
            let same_kind = kind_of(before).iter().any(|t| kind_of(after).contains(t));
            if before != after && same_kind {
                out.push((before.clone(), after.clone(), choice));
            }
        }
    }
    out
}

#[cfg(test)]
#[path = "side_by_side_tests.rs"]
mod tests;
