//! The items a request sends to a place, by the scene's relations of an item and a place.

use crate::domain::{Object, Predicate, Vocabulary};
use crate::reading::english::{MOVING_VERBS, SOURCES, TOWARDS};
use crate::reading::words::same_word;

use super::Request;
use super::mentions::mentions;

/// How far after such a word the place's name may start ("to the third table").
pub(in crate::reading) const PLACE_WITHIN: usize = 3;

/// An item the request sends to a place.
#[derive(Debug, Clone, PartialEq)]
pub struct Sent {
    pub item: String,
    pub place: String,
}

/// The predicates of two arguments that take an item and a place.
pub(in crate::reading) fn relating(vocabulary: &Vocabulary) -> Vec<&Predicate> {
    vocabulary
        .predicates
        .iter()
        .filter(|p| p.arg_types.len() == 2)
        .collect()
}

/// The items the request sends to a place, each with its place: an item named before
/// "to"/"at"/"on" and a place named right after, in one clause, with no verb of the
/// robot's own moving between them; items named after an earlier place go to the next.
/// Items and places are the objects the scene's relating predicates take.
/// [`Request::sent`] keeps them.
pub(in crate::reading) fn sent(request: &Request) -> Vec<Sent> {
    let vocabulary = request.vocabulary;
    let relating = relating(vocabulary);
    let fits = |o: &Object, slot: usize| {
        relating
            .iter()
            .any(|p| p.arg_types.get(slot).is_some_and(|t| o.fits(t)))
    };
    let items: Vec<&Object> = vocabulary.objects.iter().filter(|o| fits(o, 0)).collect();
    let places: Vec<&Object> = vocabulary.objects.iter().filter(|o| fits(o, 1)).collect();
    let mut out: Vec<Sent> = Vec::new();
    for words in &request.clauses {
        let place_spans = mentions(words, &places, &[]);
        let covered: Vec<usize> = place_spans
            .iter()
            .flat_map(|(at, len, _)| *at..at + len)
            .collect();
        let item_spans = mentions(words, &items, &covered);
        let mut waiting: Vec<String> = Vec::new();
        let mut sent_unnamed = false;
        for (at, word) in words.iter().enumerate() {
            if MOVING_VERBS.iter().any(|m| same_word(m, word)) {
                waiting.clear();
                sent_unnamed = false;
            }
            if let Some((_, _, item)) = item_spans.iter().find(|(start, _, _)| *start == at)
                && !waiting.contains(item)
            {
                // Items sent somewhere no name says ("coffee to the table by the door")
                // are not sent to the place of the next item ("and water to table 2");
                // with no item between ("coffee to me at table 2"), they are.
                if std::mem::take(&mut sent_unnamed) {
                    waiting.clear();
                }
                waiting.push(item.clone());
            }
            if !TOWARDS.contains(&word.as_str()) || waiting.is_empty() {
                continue;
            }
            let place = place_spans
                .iter()
                .find(|(start, _, _)| *start > at && *start <= at + PLACE_WITHIN);
            let Some((start, _, place)) = place else {
                sent_unnamed = true;
                continue;
            };
            // "In from the cold frame": the place the item comes from; where it goes is
            // said next.
            if words[at + 1..*start]
                .iter()
                .any(|w| SOURCES.contains(&w.as_str()))
            {
                continue;
            }
            for item in waiting.drain(..) {
                if item != *place {
                    out.push(Sent {
                        item,
                        place: place.clone(),
                    });
                }
            }
        }
    }
    out
}

#[cfg(test)]
#[path = "sent_tests.rs"]
mod tests;
