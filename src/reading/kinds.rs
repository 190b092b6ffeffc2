//! Every object of a kind: a request that says "both vents", "all the tables" or "every
//! bench" asks the same of each of the scene's objects whose name says that kind, though
//! it names none of them by itself. A goal that has the condition for some of them only
//! has read the plural as one object; a check that counts the words a condition answers
//! to must not take the second bench's condition for one no word asks for.

use crate::domain::{Atom, Condition, Vocabulary};
use crate::goal::Formula;

use super::english::{is_quantifier, may_precede_thing};
use super::lexicon::Lexicon;
use super::request::Request;
use super::words::{is_number, same_word, terms};

/// The objects a quantifier asks for each of, with the words that said so ("both
/// benches").
#[derive(Debug, Clone, PartialEq)]
pub struct EveryOfKind {
    pub objects: Vec<String>,
    pub said: String,
}

/// The kinds `words` (a request's, or a clause's, as [`super::words::every_term`] gives
/// them) ask for every object of: a quantifier, then (past articles and "of") the words
/// of a name, the last one what the object is, that at least two of the scene's objects
/// share — exactly two after "both". [`Request::every_of_kind`] keeps the whole request's.
pub fn every_of_kind_in(
    words: &[String],
    vocabulary: &Vocabulary,
    lexicon: &Lexicon,
) -> Vec<EveryOfKind> {
    let mut out = Vec::new();
    for (at, word) in words.iter().enumerate() {
        if !is_quantifier(word) {
            continue;
        }
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
        let enough = if word == "both" {
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
            });
        }
    }
    out
}

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
