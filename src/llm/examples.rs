//! Choosing the worked examples a prompt shows: the few of a domain's pool that are most
//! like the request, by BM25 over words (no network, no embeddings).
//!
//! Fixed examples in every prompt invite a small model to paste an example's goal or
//! place into unrelated answers; examples chosen per request, from a pool whose names
//! vary, show it the predicates and phrasings that matter for this request instead.
//! An example's goal takes part in the match too, its atoms split into words
//! (`Active_TubeLight` → active, tube, light), so "switch the tube light on" finds
//! examples about that light even when they are phrased differently.

use std::collections::HashMap;

use crate::reading::Request;
use crate::reading::words::terms;
use crate::scenario::{Example, ExampleSource};

/// BM25's usual constants: term-frequency saturation and length normalisation.
const K1: f64 = 1.2;
const B: f64 = 0.75;

/// The `k` examples most like `request`, least similar first (so the closest sits
/// right before the request). Ties keep pool order; an example whose goal equals one
/// already chosen is skipped, so the choice shows `k` different goals.
pub fn nearest<'a>(pool: &'a [Example], request: &str, k: usize) -> Vec<&'a Example> {
    if k == 0 || pool.is_empty() {
        return Vec::new();
    }
    let docs: Vec<Vec<String>> = pool
        .iter()
        .map(|e| {
            let mut t = terms(&e.instruction);
            t.extend(terms(&e.goal));
            t
        })
        .collect();
    let n = docs.len() as f64;
    let average = docs.iter().map(Vec::len).sum::<usize>() as f64 / n;
    let mut document_frequency: HashMap<&str, usize> = HashMap::new();
    for d in &docs {
        let mut seen: Vec<&str> = d.iter().map(String::as_str).collect();
        seen.sort_unstable();
        seen.dedup();
        for t in seen {
            *document_frequency.entry(t).or_default() += 1;
        }
    }
    let mut query = terms(request);
    query.sort_unstable();
    query.dedup();
    let score = |doc: &[String]| -> f64 {
        query
            .iter()
            .map(|q| {
                let tf = doc.iter().filter(|t| *t == q).count() as f64;
                if tf == 0.0 {
                    return 0.0;
                }
                let df = document_frequency.get(q.as_str()).copied().unwrap_or(0) as f64;
                let idf = ((n - df + 0.5) / (df + 0.5) + 1.0).ln();
                let norm = K1 * (1.0 - B + B * doc.len() as f64 / average.max(1.0));
                idf * tf * (K1 + 1.0) / (tf + norm)
            })
            .sum()
    };
    let mut ranked: Vec<(usize, f64)> = docs
        .iter()
        .enumerate()
        .map(|(i, d)| (i, score(d)))
        .collect();
    ranked.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut chosen: Vec<&Example> = Vec::with_capacity(k);
    for (i, _) in ranked {
        let e = &pool[i];
        if chosen.iter().any(|c| c.goal == e.goal) {
            continue;
        }
        chosen.push(e);
        if chosen.len() == k {
            break;
        }
    }
    chosen.reverse();
    chosen
}

/// Worked examples made from the scene's own words for what `request` asks: each
/// condition of one object it asks for in the words the scene lists
/// ([`Request::asked_of_one_object`]), said with the first phrase the scene lists for it
/// (or for its opposite, when it is asked not to hold) and the object's name ("don't leave
/// the pharmacy cabinet open": "Close PharmacyCabinet." with `~Open_PharmacyCabinet`);
/// then each item it sends to a place ([`Request::sent_by_the_relation`]), said with the
/// relation's first phrase ("to" when it lists none). At most `most`, in that order; none
/// for a condition whose predicate lists no phrase the way it is asked, or not even one
/// for the other way.
pub fn from_scene_words(request: &Request, most: usize) -> Vec<Example> {
    let vocabulary = request.vocabulary;
    let mut made: Vec<Example> = Vec::new();
    for (atom, wanted) in request.asked_of_one_object() {
        let Some(predicate) = vocabulary.predicate(&atom.predicate) else {
            continue;
        };
        let (says, opposite) = (&predicate.words.says, &predicate.words.opposite);
        let phrase = match (wanted, says.first(), opposite.first()) {
            (true, Some(p), _) | (false, _, Some(p)) => p.clone(),
            (false, Some(p), None) => format!("do not {p}"),
            _ => continue,
        };
        let Some(object) = atom.args.first() else {
            continue;
        };
        let goal = if wanted {
            atom.to_string()
        } else {
            format!("~{atom}")
        };
        if made.iter().any(|e| e.goal == goal) {
            continue;
        }
        let mut instruction = format!("{phrase} {object}.");
        if let Some(first) = instruction.get(..1) {
            instruction = first.to_uppercase() + &instruction[1..];
        }
        made.push(Example {
            instruction,
            goal,
            source: ExampleSource::Made,
        });
        if made.len() == most {
            return made;
        }
    }
    // Then the items it sends to a place, with the scene's one relation that puts an
    // item at a place, said with the relation's first phrase ("Specimen to Bed3.").
    for atom in request.sent_by_the_relation() {
        let Some(predicate) = vocabulary.predicate(&atom.predicate) else {
            continue;
        };
        let [item, place] = atom.args.as_slice() else {
            continue;
        };
        let goal = atom.to_string();
        if made.iter().any(|e| e.goal == goal) {
            continue;
        }
        let phrase = predicate.words.says.first().map_or("to", String::as_str);
        made.push(Example {
            instruction: format!("{item} {phrase} {place}."),
            goal,
            source: ExampleSource::Made,
        });
        if made.len() == most {
            break;
        }
    }
    made
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ex(instruction: &str, goal: &str) -> Example {
        Example {
            instruction: instruction.into(),
            goal: goal.into(),
            source: Default::default(),
        }
    }

    #[test]
    fn the_closest_example_comes_last_and_goals_are_not_repeated() {
        let pool = vec![
            ex("Turn the tube light on", "Active_TubeLight"),
            ex("Bring an apple to the second table", "On_Apple_Table2"),
            ex("Put an apple on table two", "On_Apple_Table2"),
            ex("Close the curtain", "Closed_Curtain"),
            ex("Wipe the chairs", "IsClean_Chairs"),
        ];
        let chosen = nearest(&pool, "Could I have an apple at table 2?", 2);
        assert_eq!(chosen.len(), 2);
        assert_eq!(chosen[1].goal, "On_Apple_Table2");
        assert_ne!(chosen[0].goal, "On_Apple_Table2");
        // The goal's words count: "light" finds the light example.
        let chosen = nearest(&pool, "it is dark, I need light", 1);
        assert_eq!(chosen[0].goal, "Active_TubeLight");
    }

    #[test]
    fn the_scene_words_a_request_uses_and_the_items_it_sends_make_examples() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml");
        let cafe = crate::scenario::Scenario::load(&path).expect("cafe scenario");
        let lexicon = crate::reading::Lexicon::new(&cafe.domain.vocabulary, &cafe.examples);
        let made = |text: &str, most: usize| -> Vec<(String, String)> {
            let request = Request::new(text, &cafe, &lexicon);
            from_scene_words(&request, most)
                .into_iter()
                .map(|e| (e.instruction, e.goal))
                .collect()
        };
        // Said with the scene's first phrase for the condition or for its opposite, the
        // negation read: "don't leave the tube light on" asks for it off.
        assert_eq!(
            made("Close the curtain and don't leave the tube light on.", 3),
            [
                ("Close Curtain.".to_string(), "Closed_Curtain".to_string()),
                (
                    "Off TubeLight.".to_string(),
                    "~Active_TubeLight".to_string()
                ),
            ]
        );
        assert_eq!(
            made("Close the curtain and don't leave the tube light on.", 1).len(),
            1
        );
        // An item sent to a place, with the scene's one relation of an item and a place
        // (the cafe's `On` lists no phrase: "to").
        assert_eq!(
            made("Bring a coffee to table 2 and close the curtain.", 3),
            [
                ("Close Curtain.".to_string(), "Closed_Curtain".to_string()),
                (
                    "Coffee to Table2.".to_string(),
                    "On_Coffee_Table2".to_string()
                ),
            ]
        );
        // Nothing where the request asks nothing in the scene's words of an object it
        // names and sends nothing anywhere.
        assert!(made("What a nice day it is.", 3).is_empty());
    }

    #[test]
    fn k_bounds_the_choice() {
        let pool = vec![ex("Close the curtain", "Closed_Curtain")];
        assert!(nearest(&pool, "anything", 0).is_empty());
        assert_eq!(nearest(&pool, "anything", 5).len(), 1);
        assert!(nearest(&[], "anything", 3).is_empty());
    }
}
