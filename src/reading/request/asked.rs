//! What a request asks for one way in the scene's words: in each negation scope, the
//! words the scene lists for a condition and its opposite, turned around by the negations
//! before them, about the objects the scope names.

use crate::domain::{Atom, Predicate, Vocabulary};
use crate::reading::english::is_negation;
use crate::reading::words::{every_term, same_word, terms};

use super::Request;
use super::every_of_kind::every_of_kind_in;
use super::mentions::mentions;

/// What a clause asks about: a predicate and the object it is about.
pub(in crate::reading) struct Subject {
    pub(in crate::reading) predicate: String,
    pub(in crate::reading) object: String,
}

impl Subject {
    /// The condition it is about.
    pub(super) fn atom(&self) -> Atom {
        Atom::new(self.predicate.clone(), vec![self.object.clone()])
    }

    pub(in crate::reading) fn matches(&self, atom: &Atom) -> bool {
        atom.predicate == self.predicate && atom.args.first() == Some(&self.object)
    }
}

/// A condition the request asks for one way: what it is about, whether it is asked to
/// hold, the word that says so, and whether its sentence offers a choice ("or",
/// "either"): a condition asked there may be one alternative of several.
pub(in crate::reading) type Asked = (Subject, bool, String, bool);

/// The conditions `request` asks for one way, in its negation scopes ([`Request::scopes`]);
/// a condition asked for both ways is left out. [`Request::asked`] keeps them.
pub(super) fn asked_in_sentences(request: &Request) -> Vec<Asked> {
    let vocabulary = request.vocabulary;
    let mut found: Vec<Asked> = Vec::new();
    let mut both: Vec<(String, String)> = Vec::new();
    for scope in &request.scopes {
        let (clause, choice) = (&scope.words, scope.choice);
        // "Close both vents" asks it of each vent.
        let of_every: Vec<String> = every_of_kind_in(clause, vocabulary, request.lexicon)
            .into_iter()
            .flat_map(|k| k.objects)
            .collect();
        for predicate in &vocabulary.predicates {
            let Some((wanted, word)) = clause_polarity(clause, predicate) else {
                continue;
            };
            let mut named = subjects(clause, predicate, vocabulary);
            let slot = predicate.arg_types.first();
            for object in of_every
                .iter()
                .filter(|o| slot.is_some_and(|slot| vocabulary.fits(o, slot)))
            {
                if !named.contains(object) {
                    named.push(object.clone());
                }
            }
            for object in named {
                let key = (predicate.name.clone(), object.clone());
                if both.contains(&key) {
                    continue;
                }
                if let Some(i) = found
                    .iter()
                    .position(|(s, _, _, _)| s.predicate == key.0 && s.object == key.1)
                {
                    if found[i].1 != wanted {
                        found.remove(i);
                        both.push(key);
                    }
                    continue;
                }
                found.push((
                    Subject {
                        predicate: predicate.name.clone(),
                        object,
                    },
                    wanted,
                    word.clone(),
                    choice,
                ));
            }
        }
    }
    found
}

/// Where `phrase` (as [`terms`] gives it) starts in `words`, if it does.
pub fn find_phrase(words: &[String], phrase: &[String]) -> Option<usize> {
    if phrase.is_empty() || phrase.len() > words.len() {
        return None;
    }
    (0..=words.len() - phrase.len())
        .find(|&i| phrase.iter().zip(&words[i..]).all(|(p, w)| same_word(p, w)))
}

/// Which way `clause` asks for `predicate`, and the word that says so: the word's own way
/// turned around once for each negation before it. `None` when the clause has none of
/// its words, or words that ask both ways.
fn clause_polarity(clause: &[String], predicate: &Predicate) -> Option<(bool, String)> {
    let lists = [
        (true, &predicate.words.says),
        (false, &predicate.words.opposite),
    ];
    let mut ways: Vec<(bool, String)> = Vec::new();
    for (own_way, list) in lists {
        for word in list.iter() {
            let Some(at) = find_phrase(clause, &every_term(word)) else {
                continue;
            };
            let negations = clause[..at].iter().filter(|w| is_negation(w)).count();
            ways.push((own_way == (negations % 2 == 0), word.clone()));
        }
    }
    let (first_way, word) = ways.first()?.clone();
    ways.iter()
        .all(|(w, _)| *w == first_way)
        .then_some((first_way, word))
}

/// The objects `predicate` can be about that `clause` names (by their name's words in a
/// row, or what they are called); when it names none, the one object the predicate can be
/// about, if there is only one and the clause has a word of it.
fn subjects(clause: &[String], predicate: &Predicate, vocabulary: &Vocabulary) -> Vec<String> {
    let Some(slot) = predicate.arg_types.first() else {
        return Vec::new();
    };
    let fitting: Vec<&crate::domain::Object> =
        vocabulary.objects.iter().filter(|o| o.fits(slot)).collect();
    let mut named: Vec<String> = mentions(clause, &fitting, &[])
        .into_iter()
        .map(|(_, _, name)| name)
        .collect();
    named.dedup();
    match fitting.as_slice() {
        // The one object a predicate can be about needs no name, only a word of it ("too
        // low" about the temperature), so that a word alone ("a cool drink") asks nothing.
        [only] if named.is_empty() => {
            let own: Vec<String> = std::iter::once(&only.name)
                .chain(&only.called)
                .flat_map(|p| terms(p))
                .collect();
            if clause.iter().any(|w| own.iter().any(|o| same_word(o, w))) {
                vec![only.name.clone()]
            } else {
                Vec::new()
            }
        }
        _ => named,
    }
}
