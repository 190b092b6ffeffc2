//! What the request's words say about how an item relates to a place, when the scene has
//! more than one way: "put the baby down in the crib" asks for `in`, so a goal that has
//! the baby `on` the crib has misread it; and a convention's words ("bring me the kit",
//! where what is brought goes on the tray) ask for the convention's relation to its place
//! for each item they name, so a goal that has the kit held instead has misread it.

use crate::domain::{Atom, Object, Predicate};
use crate::goal::Formula;
use crate::goal::rewrite::map_atoms;

use super::placement::put_sent;
use super::request::Request;
use super::request::asked::find_phrase;
use super::request::mentions::mentions;
use super::request::sent::{PLACE_WITHIN, Sent, relating};
use super::words::every_term;

/// `goal` with each condition relating two objects by a predicate other than the one the
/// request names right before the second ("in the crib" read as `on`) given the one it
/// names, with the word that names it; `None` when nothing changes or the scene has one
/// such predicate only.
pub fn relation_as_said(goal: &Formula, request: &Request) -> Option<(Formula, String)> {
    let vocabulary = request.vocabulary;
    let relating = relating(vocabulary);
    if relating.len() < 2 {
        return None;
    }
    let words = &request.unnumbered_words;
    let named = request.mentions();
    let swap = |a: &Atom| -> Option<(Atom, String)> {
        let [_, place] = a.args.as_slice() else {
            return None;
        };
        if !relating.iter().any(|p| p.name == a.predicate) {
            return None;
        }
        let (p, word) = named
            .iter()
            .filter(|(_, _, name)| name == place)
            .find_map(|(start, _, _)| said_before(words, *start, &relating))?;
        let swapped = Atom::new(p.name.clone(), a.args.clone());
        (p.name != a.predicate && vocabulary.check_atom(&swapped).is_ok())
            .then_some((swapped, word))
    };
    let changed = map_atoms(goal, &|a| swap(a).map_or_else(|| a.clone(), |(s, _)| s));
    let word = goal.atoms().iter().find_map(swap)?.1;
    (changed != *goal).then_some((changed, word))
}

/// The relating predicate whose name or word ends nearest before `start`, within
/// [`PLACE_WITHIN`] words, with the word.
fn said_before<'a>(
    words: &[String],
    start: usize,
    relating: &[&'a Predicate],
) -> Option<(&'a Predicate, String)> {
    (start.saturating_sub(PLACE_WITHIN)..start)
        .rev()
        .find_map(|end| {
            relating.iter().find_map(|p| {
                std::iter::once(&p.name)
                    .chain(&p.words.says)
                    .find(|phrase| {
                        let t = every_term(phrase);
                        !t.is_empty() && t.len() <= end + 1 && words[end + 1 - t.len()..=end] == t
                    })
                    .map(|phrase| (*p, phrase.clone()))
            })
        })
}

/// `goal` with each item named in a sentence that says a convention's words put where
/// the convention puts it ("bring me the first aid kit" read as the kit held, where what
/// is brought goes on the tray), with the word; `None` when no convention of the scene
/// applies or nothing changes. Only a condition about the item alone, not asked for in
/// its predicate's own words, is replaced, as [`super::placement::put_there`] does.
pub fn convention_followed(goal: &Formula, request: &Request) -> Option<(Formula, String)> {
    let vocabulary = request.vocabulary;
    for c in request.conventions {
        let Some(puts) = &c.puts else {
            continue;
        };
        if !c.objects.iter().all(|o| vocabulary.object(o).is_some()) {
            continue;
        }
        let items: Vec<&Object> = vocabulary
            .objects
            .iter()
            .filter(|o| {
                o.name != puts.place
                    && vocabulary
                        .check_atom(&Atom::new(
                            puts.relation.clone(),
                            [o.name.clone(), puts.place.clone()],
                        ))
                        .is_ok()
            })
            .collect();
        for words in &request.sentences {
            let Some(word) = puts
                .words
                .iter()
                .find(|w| find_phrase(words, &every_term(w)).is_some())
            else {
                continue;
            };
            let mut sent: Vec<Sent> = Vec::new();
            for (_, _, item) in mentions(words, &items, &[]) {
                if !sent.iter().any(|s| s.item == item) {
                    sent.push(Sent {
                        item,
                        place: puts.place.clone(),
                    });
                }
            }
            if let Some(g) = put_sent(goal, request, &sent, &puts.relation) {
                return Some((g, word.clone()));
            }
        }
    }
    None
}

#[cfg(test)]
#[path = "relation_words_tests.rs"]
mod tests;
