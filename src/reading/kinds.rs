//! The objects of a kind: a request that says "both vents", "all the tables" or "every
//! bench" asks the same of each of the scene's objects whose name says that kind, though
//! it names none of them by itself; one that says "either tote" asks it of one of the
//! two, whichever. A goal that has the condition for some of every one only has read the
//! plural as one object, and one that has it for one tote (or for both, side by side) has
//! made the choice the request left open; a check that counts the words a condition
//! answers to must not take the second bench's condition for one no word asks for.

use crate::domain::{Atom, Vocabulary};
use crate::goal::Formula;
use crate::goal::rewrite::rename;

use super::english::{Quantity, may_precede_thing, quantity};
use super::lexicon::Lexicon;
use super::request::Request;
use super::words::{is_number, same_word, terms};

/// The objects a quantifier asks something of, with the words that said so ("both
/// benches") and whether it asks it of each or of one.
#[derive(Debug, Clone, PartialEq)]
pub struct EveryOfKind {
    pub objects: Vec<String>,
    pub said: String,
    pub quantity: Quantity,
}

/// The kinds `words` (a request's, or a clause's, as [`super::words::every_term`] gives
/// them) ask something of every object of, or of one: a quantifier, then (past articles
/// and "of") the words of a name, the last one what the object is, that at least two of
/// the scene's objects share — exactly two after "both" or "either" (an "either" that an
/// "or" follows offers its own choice). [`Request::every_of_kind`] keeps the whole
/// request's, sentence by sentence.
pub fn every_of_kind_in(
    words: &[String],
    vocabulary: &Vocabulary,
    lexicon: &Lexicon,
) -> Vec<EveryOfKind> {
    let mut out = Vec::new();
    for (at, word) in words.iter().enumerate() {
        let Some(quantity) = quantity(word) else {
            continue;
        };
        let mut next = at + 1;
        while words
            .get(next)
            .is_some_and(|w| may_precede_thing(w) || w == "of")
        {
            next += 1;
        }
        let noun: Vec<&String> = words[next.min(words.len())..]
            .iter()
            .take_while(|w| lexicon.names_an_object(w))
            .collect();
        if noun.is_empty() {
            continue;
        }
        let objects: Vec<String> = vocabulary
            .objects
            .iter()
            .filter(|o| {
                let own: Vec<String> = terms(&o.name)
                    .into_iter()
                    .chain(lexicon.words(&o.name).iter().cloned())
                    .collect();
                // The noun's last word is what the object is (its name's last word but a
                // number, or a called name's): a bench light is a light, not a bench.
                let heads: Vec<String> = std::iter::once(o.name.as_str())
                    .chain(o.called.iter().map(String::as_str))
                    .filter_map(|n| terms(n).into_iter().rev().find(|w| !is_number(w)))
                    .collect();
                let head = noun
                    .last()
                    .is_some_and(|n| heads.iter().any(|h| same_word(h, n)));
                head && noun.iter().all(|n| own.iter().any(|w| same_word(w, n)))
            })
            .map(|o| o.name.clone())
            .collect();
        // "Either yogurt or an apple" offers its own choice: "either" is no quantifier
        // when an "or" follows it.
        if quantity == Quantity::OneOf && words[next..].iter().any(|w| w == "or") {
            continue;
        }
        let enough = if word == "both" || quantity == Quantity::OneOf {
            objects.len() == 2
        } else {
            objects.len() >= 2
        };
        if enough && !out.iter().any(|k: &EveryOfKind| k.objects == objects) {
            let said: Vec<&str> = words[at..next + noun.len()]
                .iter()
                .map(String::as_str)
                .collect();
            out.push(EveryOfKind {
                objects,
                said: said.join(" "),
                quantity,
            });
        }
    }
    out
}

/// Whether every atom of `part` is about an object of a kind the request asks something of
/// (each, or one): such a condition is asked for though no word names its object alone.
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
    let kinds = request.every_of_kind();
    for kind in kinds.iter().filter(|k| k.quantity == Quantity::Every) {
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
                    let same = Formula::Atom(Atom::new(atom.predicate.clone(), args));
                    let wanted = if holds {
                        same
                    } else {
                        Formula::Not(Box::new(same))
                    };
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

/// A condition of `goal` about one object of a kind the request leaves the choice of
/// ("either tote"), held for it alone or for each side by side: the kind, the conjuncts
/// that made the choice, and the choice left open.
struct Chosen<'k> {
    kind: &'k EveryOfKind,
    made: Vec<Formula>,
    open: Formula,
}

fn chosen<'k>(goal: &Formula, kinds: &'k [EveryOfKind]) -> Option<Chosen<'k>> {
    let items = goal.conjuncts();
    let about = |item: &Formula, object: &str| {
        literal(item).is_some_and(|(atom, _)| atom.args.iter().any(|a| a == object))
    };
    for kind in kinds.iter().filter(|k| k.quantity == Quantity::OneOf) {
        // The first object of the kind the goal has a condition about: what it asks of
        // that one ("a full jug at bed three": full, and there) is asked of whichever.
        let Some(first) = kind
            .objects
            .iter()
            .find(|o| items.iter().any(|i| about(i, o)))
        else {
            continue;
        };
        let of_first: Vec<&Formula> = items.iter().filter(|i| about(i, first)).collect();
        let each: Vec<Formula> = kind
            .objects
            .iter()
            .map(|o| Formula::and(of_first.iter().map(|i| rename(i, first, o)).collect()))
            .collect();
        let open = Formula::or(each);
        if items.contains(&open) {
            continue;
        }
        let made: Vec<Formula> = items
            .iter()
            .filter(|i| kind.objects.iter().any(|o| about(i, o)))
            .cloned()
            .collect();
        return Some(Chosen { kind, made, open });
    }
    None
}

/// How `goal` makes the choice a request's "either" leaves open.
pub fn choice_made(goal: &Formula, request: &Request) -> Option<String> {
    let found = chosen(goal, request.every_of_kind())?;
    let made: Vec<String> = found.made.iter().map(ToString::to_string).collect();
    Some(format!(
        "the request says \"{}\", which leaves the choice between {}; {goal} asks for {}",
        found.kind.said,
        found.kind.objects.join(" and "),
        made.join(" and ")
    ))
}

/// `goal` with the choice [`choice_made`] finds left open again.
pub fn with_choice_open(goal: &Formula, request: &Request) -> Option<Formula> {
    let found = chosen(goal, request.every_of_kind())?;
    let mut items: Vec<Formula> = goal
        .conjuncts()
        .into_iter()
        .filter(|i| !found.made.contains(i))
        .collect();
    items.push(found.open);
    Some(Formula::and(items))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Object;

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
    fn a_quantifier_names_every_object_of_its_kind() {
        let v = scene(&[
            "Bench1",
            "Bench2",
            "BenchLight",
            "UvLamp",
            "TubeRack",
            "BloodTube",
        ]);
        let lexicon = Lexicon::new(&v, &[]);
        let r = Request::in_scene("Clean both benches and the lamp.", &v, &[], &lexicon);
        let kinds = r.every_of_kind();
        assert_eq!(kinds.len(), 1, "{kinds:?}");
        assert_eq!(kinds[0].objects, ["Bench1", "Bench2"]);
        // The words after the quantifier narrow the kind: "tube racks" is not the tube.
        let r = Request::in_scene("Move all the tube racks.", &v, &[], &lexicon);
        assert!(r.every_of_kind().is_empty(), "one tube rack is no kind");
        // "both" of three is not every one; "each with" names no kind.
        let v3 = scene(&["Table1", "Table2", "Table3"]);
        let lexicon3 = Lexicon::new(&v3, &[]);
        let r = Request::in_scene("Wipe both tables.", &v3, &[], &lexicon3);
        assert!(r.every_of_kind().is_empty());
        let r = Request::in_scene("Wipe all of the tables.", &v3, &[], &lexicon3);
        assert_eq!(r.every_of_kind()[0].objects.len(), 3);
        let r = Request::in_scene("Two coffees, each with milk.", &v3, &[], &lexicon3);
        assert!(r.every_of_kind().is_empty());
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
    fn either_of_a_kind_of_two_leaves_the_choice_open() {
        let v = scene(&["Tote1", "Tote2", "Conveyor", "BigBox"]);
        let lexicon = Lexicon::new(&v, &[]);
        let r = Request::in_scene(
            "Scan either tote and start the conveyor.",
            &v,
            &[],
            &lexicon,
        );
        assert_eq!(r.every_of_kind()[0].quantity, Quantity::OneOf);
        let one = goal("Scanned_Tote1 & Running_Conveyor");
        assert!(choice_made(&one, &r).is_some_and(|m| m.contains("either tote")));
        let open = goal("Running_Conveyor & (Scanned_Tote1 | Scanned_Tote2)");
        assert_eq!(with_choice_open(&one, &r), Some(open.clone()));
        // Both, side by side, also made the choice.
        let both = goal("Scanned_Tote1 & Scanned_Tote2 & Running_Conveyor");
        assert_eq!(with_choice_open(&both, &r), Some(open.clone()));
        assert_eq!(choice_made(&open, &r), None);
        // "Either" asks nothing of every tote, and the other tote is asked for.
        assert_eq!(fewer_than_every(&one, &r), None);
        assert!(asked_of_every(
            &goal("Scanned_Tote1 | Scanned_Tote2"),
            r.every_of_kind()
        ));
        // "Either … or" offers its own choice, whatever the kind of the first thing.
        let r = Request::in_scene("Scan either tote or the big box.", &v, &[], &lexicon);
        assert!(r.every_of_kind().is_empty(), "{:?}", r.every_of_kind());
        // "Either" before a name of one object leaves no choice of a kind.
        let r = Request::in_scene(
            "Either scan the big box or start the conveyor.",
            &v,
            &[],
            &lexicon,
        );
        assert!(r.every_of_kind().is_empty(), "{:?}", r.every_of_kind());
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

    #[test]
    fn what_is_asked_of_the_one_chosen_is_asked_of_whichever() {
        let v = scene(&["Jug1", "Jug2", "Bed3", "Room2Door"]);
        let lexicon = Lexicon::new(&v, &[]);
        let r = Request::in_scene(
            "A full jug needs to end up at bed three, either jug will do.",
            &v,
            &[],
            &lexicon,
        );
        let g = goal("Full_Jug1 & At_Jug1_Bed3 & ~Open_Room2Door");
        assert_eq!(
            with_choice_open(&g, &r),
            Some(goal(
                "~Open_Room2Door & ((Full_Jug1 & At_Jug1_Bed3) | (Full_Jug2 & At_Jug2_Bed3))"
            ))
        );
    }
}
