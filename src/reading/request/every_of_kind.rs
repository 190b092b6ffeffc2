//! The kinds a request asks for every object of ("both vents", "all the tables", "every
//! bench").

use crate::domain::Vocabulary;
use crate::reading::english::{is_quantifier, may_precede_thing};
use crate::reading::lexicon::Lexicon;
use crate::reading::words::{is_number, same_word, terms};

/// The objects a quantifier asks for each of, with the words that said so ("both
/// benches").
#[derive(Debug, Clone, PartialEq)]
pub struct EveryOfKind {
    pub objects: Vec<String>,
    pub said: String,
}

/// The kinds `words` (a request's, or a clause's, as [`every_term`](crate::reading::words::every_term) gives
/// them) ask for every object of: a quantifier, then (past articles and "of") the words
/// of a name, the last one what the object is, that at least two of the scene's objects
/// share — exactly two after "both". [`Request::every_of_kind`](super::Request::every_of_kind) keeps the whole request's.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Object;
    use crate::reading::Request;

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
}
