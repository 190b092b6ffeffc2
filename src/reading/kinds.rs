//! Every object of a kind: a request that says "both vents", "all the tables" or "every
//! bench" asks the same of each of the scene's objects whose name says that kind, though
//! it names none of them by itself. A goal that has the condition for some of them only
//! has read the plural as one object; a check that counts the words a condition answers
//! to must not take the second bench's condition for one no word asks for.

use crate::domain::{Atom, Condition};
use crate::goal::Formula;

use super::request::Request;
use super::request::every_of_kind::EveryOfKind;

/// Whether every atom of `part` is about an object of a kind the request asks for each
/// of: such a condition is asked for though no word names its object alone.
pub fn asked_of_every(part: &Formula, kinds: &[EveryOfKind]) -> bool {
    let atoms = part.atoms();
    !atoms.is_empty()
        && atoms.iter().all(|a| {
            kinds
                .iter()
                .any(|k| a.args.iter().any(|arg| k.objects.contains(arg)))
        })
}

/// A condition of `goal` (a conjunct that is an atom or a negated atom) about some objects
/// of a kind the request asks for every object of, and not the others: the kind, the
/// objects left out, and the conditions they are left out of.
struct LeftOut<'k> {
    kind: &'k EveryOfKind,
    /// For each condition shown for some objects: the conditions for the objects left out.
    missing: Vec<Formula>,
}

fn literal(f: &Formula) -> Option<(&Atom, bool)> {
    match f {
        Formula::Atom(a) => Some((a, true)),
        Formula::Not(inner) => match inner.as_ref() {
            Formula::Atom(a) => Some((a, false)),
            _ => None,
        },
        _ => None,
    }
}

fn left_out<'r>(goal: &Formula, request: &'r Request) -> Option<LeftOut<'r>> {
    let items = goal.conjuncts();
    for kind in request.every_of_kind() {
        // A condition about an object the request names by itself ("lay bed two flat"
        // beside "rails up on every bed") is said of that object, not of the kind; the
        // kind's own words ("both bars", where one bar is called Bar) name none by itself.
        let said: Vec<&str> = kind.said.split(' ').collect();
        let named: Vec<&str> = request
            .mentions()
            .iter()
            .filter(|(first, count, _)| {
                request
                    .unnumbered_words
                    .get(*first..first + count)
                    .is_some_and(|run| run.iter().any(|w| !said.contains(&w.as_str())))
            })
            .map(|(_, _, name)| name.as_str())
            .collect();
        let mut missing: Vec<Formula> = Vec::new();
        for item in &items {
            let Some((atom, holds)) = literal(item) else {
                continue;
            };
            for (slot, arg) in atom.args.iter().enumerate() {
                if !kind.objects.contains(arg) || named.contains(&arg.as_str()) {
                    continue;
                }
                for other in kind.objects.iter().filter(|o| *o != arg) {
                    let mut args = atom.args.clone();
                    args[slot] = other.clone();
                    let wanted = Formula::literal(&Condition {
                        atom: Atom::new(atom.predicate.clone(), args),
                        negated: !holds,
                    });
                    if !items.contains(&wanted) && !missing.contains(&wanted) {
                        missing.push(wanted);
                    }
                }
            }
        }
        if !missing.is_empty() {
            return Some(LeftOut { kind, missing });
        }
    }
    None
}

/// How `goal` reads a request's "both"/"all"/"every" as fewer objects than the kind has.
pub fn fewer_than_every(goal: &Formula, request: &Request) -> Option<String> {
    let found = left_out(goal, request)?;
    let missing: Vec<String> = found.missing.iter().map(ToString::to_string).collect();
    Some(format!(
        "the request says \"{}\", which asks it of {}; {goal} leaves out {}",
        found.kind.said,
        found.kind.objects.join(" and "),
        missing.join(", ")
    ))
}

/// `goal` with the conditions [`fewer_than_every`] finds left out put beside it.
pub fn with_every(goal: &Formula, request: &Request) -> Option<Formula> {
    let found = left_out(goal, request)?;
    let mut items = goal.conjuncts();
    items.extend(found.missing);
    Some(Formula::and(items))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Object, Vocabulary};
    use crate::reading::lexicon::Lexicon;

    fn scene(names: &[&str]) -> Vocabulary {
        Vocabulary {
            objects: names
                .iter()
                .map(|n| Object {
                    name: n.to_string(),
                    types: vec!["thing".into()],
                    called: Vec::new(),
                })
                .collect(),
            ..Vocabulary::default()
        }
    }

    fn goal(text: &str) -> Formula {
        Formula::parse(text).expect("a goal")
    }

    #[test]
    fn a_goal_with_one_of_both_gets_the_other_with_the_same_sign() {
        let v = scene(&["RoofVent", "SideVent", "Heater"]);
        let lexicon = Lexicon::new(&v, &[]);
        let r = Request::in_scene("Close both vents and start the heater.", &v, &[], &lexicon);
        let g = goal("~Open_RoofVent & Running_Heater");
        assert!(fewer_than_every(&g, &r).is_some_and(|m| m.contains("both vent")));
        assert_eq!(
            with_every(&g, &r),
            Some(goal("~Open_RoofVent & Running_Heater & ~Open_SideVent"))
        );
        // Both there: nothing to find.
        let whole = goal("~Open_RoofVent & ~Open_SideVent & Running_Heater");
        assert_eq!(fewer_than_every(&whole, &r), None);
        assert!(asked_of_every(&goal("~Open_SideVent"), r.every_of_kind()));
        assert!(!asked_of_every(&goal("Running_Heater"), r.every_of_kind()));
        // A request without a quantifier asks nothing of the kind.
        let r = Request::in_scene("Close the roof vent.", &v, &[], &lexicon);
        assert_eq!(fewer_than_every(&goal("~Open_RoofVent"), &r), None);
    }

    #[test]
    fn a_condition_about_an_object_the_request_names_is_not_the_quantifiers() {
        let v = scene(&["Bed1", "Bed2", "Bed3", "Jug1"]);
        let lexicon = Lexicon::new(&v, &[]);
        let r = Request::in_scene(
            "Night round: rails up on every bed, and lay bed two flat.",
            &v,
            &[],
            &lexicon,
        );
        // Bed two's head is said of bed two alone; every bed's rails of each.
        let g = goal("RailsUp_Bed1 & ~HeadUp_Bed2");
        assert_eq!(
            with_every(&g, &r),
            Some(goal(
                "RailsUp_Bed1 & ~HeadUp_Bed2 & RailsUp_Bed2 & RailsUp_Bed3"
            ))
        );
        assert_eq!(
            fewer_than_every(
                &goal("RailsUp_Bed1 & RailsUp_Bed2 & RailsUp_Bed3 & ~HeadUp_Bed2"),
                &r
            ),
            None
        );
    }
}
