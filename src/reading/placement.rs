//! Whether a goal puts where the request puts: "deliver dessert to table 1" or "a dessert
//! at the bar" ask for a condition that relates the item to the place, and a goal that has
//! them only in separate conditions (`Exists_Dessert & RobotNear_Table1`: made, and the
//! robot there) has not put the dessert anywhere. The relating conditions are the scene's
//! predicates of two arguments whose slots take the item and the place.

use crate::domain::{Atom, Object};
use crate::goal::Formula;
use crate::goal::rewrite::map_atoms;

use super::english::SOURCES;
use super::request::Request;
use super::request::asked::find_phrase;
use super::request::mentions::mentions;
use super::request::sent::{PLACE_WITHIN, Sent, relating};
use super::words::terms;

/// The first item the request sends to a place that `goal` has in a condition but never
/// in one with that place, if any.
pub fn not_put(goal: &Formula, request: &Request) -> Option<Sent> {
    if relating(request.vocabulary).is_empty() {
        return None;
    }
    let atoms = goal.atoms();
    let asked = said_predicates(request);
    request
        .sent()
        .iter()
        .find(|s| {
            let about_item: Vec<&Atom> =
                atoms.iter().filter(|a| a.args.contains(&s.item)).collect();
            let together = about_item.iter().any(|a| a.args.contains(&s.place));
            // "Hold the cup at the bar" asks for holding in its own words.
            let unasked = about_item.iter().any(|a| !asked.contains(&a.predicate));
            unasked && !together
        })
        .cloned()
}

/// `goal` with each item the request sends to a place put there: in a conjunction, a
/// condition about the item alone (made, `Exists_Dessert`) becomes the one relating
/// condition (`On_Dessert_Table1`) and one about the place alone (the robot there) goes.
/// `None` when nothing changes, or when more than one predicate could relate them.
pub fn put_there(goal: &Formula, request: &Request) -> Option<Formula> {
    let relating = relating(request.vocabulary);
    let [relation] = relating.as_slice() else {
        return None;
    };
    // With one relating predicate, what the request sends is sent by it.
    let sent = request.sent();
    if sent.is_empty() {
        return None;
    }
    put_sent(goal, request, sent, &relation.name)
}

/// `goal` with each item of `sent` put at its place by `relation`, as [`put_there`] does;
/// `None` when nothing changes.
pub(super) fn put_sent(
    goal: &Formula,
    request: &Request,
    sent: &[Sent],
    relation: &str,
) -> Option<Formula> {
    let asked = said_predicates(request);
    let rewritten = rewrite(goal, sent, relation, &asked);
    (rewritten != *goal).then_some(rewritten)
}

/// `goal` with each item the request sends to a place moved there from a place the
/// request never names ("bring yogurt to the bar" read as yogurt on the second bar):
/// small models pick a place of the same kind, or one of an example; or from the place
/// the request says it comes from ("the lettuce in from the cold frame to the bench").
pub fn moved_there(goal: &Formula, request: &Request) -> Option<Formula> {
    let relating = relating(request.vocabulary);
    let sent = request.sent();
    if sent.is_empty() {
        return None;
    }
    let named: Vec<&String> = request.mentions().iter().map(|(_, _, name)| name).collect();
    let sources = sources(request);
    let moved = map_atoms(goal, &|a| {
        let to = match a.args.as_slice() {
            [item, place]
                if relating.iter().any(|p| p.name == a.predicate)
                    && (!named.contains(&place) || sources.contains(place)) =>
            {
                // Only an item sent to one place is moved: "chips to table 1 and table 2"
                // does not say which one the second bar was meant to be.
                let places: Vec<&Sent> = sent.iter().filter(|s| &s.item == item).collect();
                match places.as_slice() {
                    [one] => Some(one.place.clone()),
                    _ => None,
                }
            }
            _ => None,
        };
        match to {
            Some(place) => Atom::new(a.predicate.clone(), vec![a.args[0].clone(), place]),
            None => a.clone(),
        }
    });
    (moved != *goal).then_some(moved)
}

/// The predicates the request names by their own words ("hold" for the one it says
/// holding): a condition about an item alone that the request asks for in its own
/// words ("hold the cup at the bar") is not a misplaced one.
fn said_predicates(request: &Request) -> Vec<String> {
    request
        .vocabulary
        .predicates
        .iter()
        .filter(|p| {
            std::iter::once(&p.name)
                .chain(&p.words.says)
                .any(|phrase| find_phrase(&request.words, &terms(phrase)).is_some())
        })
        .map(|p| p.name.clone())
        .collect()
}

fn rewrite(goal: &Formula, sent: &[Sent], relation: &str, asked: &[String]) -> Formula {
    let put = match goal {
        Formula::Atom(_) => Formula::and(put_each(vec![goal.clone()], sent, relation, asked)),
        _ => within(goal, sent, relation, asked),
    };
    // An alternative about an item alone ("a dessert to table 1, or water to table 2"
    // read as a dessert made, or the water there) is put there when no condition of the
    // goal is about that place.
    let about: Vec<String> = put.atoms().into_iter().flat_map(|a| a.args).collect();
    let open: Vec<Sent> = sent
        .iter()
        .filter(|s| !about.contains(&s.place))
        .cloned()
        .collect();
    alternatives_put(&put, &open, relation, asked)
}

/// `goal` with each alternative that is a condition about an item alone, and sent to a
/// place in `sent`, put there.
fn alternatives_put(goal: &Formula, sent: &[Sent], relation: &str, asked: &[String]) -> Formula {
    let each = |items: &[Formula]| -> Vec<Formula> {
        items
            .iter()
            .map(|i| alternatives_put(i, sent, relation, asked))
            .collect()
    };
    match goal {
        Formula::Or(alts) => Formula::Or(
            alts.iter()
                .map(|a| match a {
                    Formula::Atom(atom) if about_alone(a, None, asked) => sent
                        .iter()
                        .find(|s| atom.args == [s.item.clone()])
                        .map_or_else(|| a.clone(), |s| placed(a, &s.place, relation)),
                    _ => alternatives_put(a, sent, relation, asked),
                })
                .collect(),
        ),
        Formula::And(items) => Formula::And(each(items)),
        Formula::Not(_) | Formula::Atom(_) => goal.clone(),
    }
}

/// [`rewrite`] below the top: each conjunction's items put where the request sends them,
/// an atom left as it is (it is an item of a conjunction, or an alternative).
fn within(goal: &Formula, sent: &[Sent], relation: &str, asked: &[String]) -> Formula {
    match goal {
        Formula::And(items) => {
            let items: Vec<Formula> = items
                .iter()
                .map(|i| within(i, sent, relation, asked))
                .collect();
            Formula::and(put_each(items, sent, relation, asked))
        }
        Formula::Or(items) => Formula::Or(
            items
                .iter()
                .map(|i| within(i, sent, relation, asked))
                .collect(),
        ),
        Formula::Not(_) | Formula::Atom(_) => goal.clone(),
    }
}

/// The conjuncts `items` with each item the request sends put at its place: the
/// condition about the item alone (or alternatives of such, one of them sent there)
/// becomes the relating condition, and a condition about the place alone goes. With no
/// condition about the place at all, the item is put there too ("deliver dessert to the
/// coffee station" read as a dessert made).
fn put_each(
    mut items: Vec<Formula>,
    sent: &[Sent],
    relation: &str,
    asked: &[String],
) -> Vec<Formula> {
    for s in sent {
        let alone = |f: &Formula, object: &str| about_alone(f, Some(object), asked);
        let item_at = items.iter().position(|f| {
            alone(f, &s.item)
                || matches!(f, Formula::Or(alts) if alts.iter().all(|a| about_alone(a, None, asked))
                    && alts.iter().any(|a| alone(a, &s.item)))
        });
        let Some(i) = item_at else {
            continue;
        };
        match items.iter().position(|f| alone(f, &s.place)) {
            Some(p) => {
                items[i] = placed(&items[i], &s.place, relation);
                items.remove(p);
            }
            None if !items
                .iter()
                .any(|f| f.atoms().iter().any(|a| a.args.contains(&s.place))) =>
            {
                items[i] = placed(&items[i], &s.place, relation);
            }
            None => {}
        }
    }
    items
}

/// Whether `f` is a condition about one object alone (`object`, or any) that the
/// request does not ask for in the predicate's own words.
fn about_alone(f: &Formula, object: Option<&str>, asked: &[String]) -> bool {
    matches!(f, Formula::Atom(a) if !asked.contains(&a.predicate)
        && matches!(a.args.as_slice(), [only] if object.is_none_or(|o| o == only)))
}

/// `f` (a condition about an item alone, or alternatives of such) with each item put at
/// `place`.
fn placed(f: &Formula, place: &str, relation: &str) -> Formula {
    match f {
        Formula::Atom(a) => match a.args.as_slice() {
            [item] => Formula::Atom(Atom::new(relation, vec![item.clone(), place.to_string()])),
            _ => f.clone(),
        },
        Formula::Or(alts) => Formula::Or(alts.iter().map(|a| placed(a, place, relation)).collect()),
        _ => f.clone(),
    }
}

/// The names of the scene's objects the request says things come from ("from the cold
/// frame").
fn sources(request: &Request) -> Vec<String> {
    let mut out = Vec::new();
    for (words, named) in request.clauses.iter().zip(request.clause_mentions()) {
        for (start, _, name) in named {
            let before = &words[start.saturating_sub(PLACE_WITHIN)..*start];
            if before.iter().any(|w| SOURCES.contains(&w.as_str())) {
                out.push(name.clone());
            }
        }
    }
    out
}

/// The names of the `objects` the whole request mentions (place numbers read as
/// digits), in the order found; a name may come more than once.
pub(super) fn named_in(request: &Request, objects: &[&Object]) -> Vec<String> {
    mentions(&request.unnumbered_words, objects, &[])
        .into_iter()
        .map(|(_, _, name)| name)
        .collect()
}

#[cfg(test)]
#[path = "placement_tests.rs"]
mod tests;
