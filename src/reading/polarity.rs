//! Whether a goal asks for a condition the other way round from the request: "do not open
//! the curtain" read as `~Closed_Curtain`, "a moderate temperature" read as
//! `Low_ACTemperature`. The scene file lists, per predicate, the words that say it holds
//! and those that say its opposite. A clause of the request with such a word, about an
//! object the clause names (or the one object the predicate can be about), asks for that
//! condition, turned around by each negation before the word in the clause ("don't
//! forget to turn on" asks for it on).

use std::fmt;

use crate::domain::{Atom, Predicate, Vocabulary};
use crate::goal::Formula;
use crate::goal::rewrite::{flipped, undo_each};

use super::english::{NUMBERING, clause_start, is_negation, is_number_word};
use super::kinds::every_of_kind_in;
use super::placement::mentions;
use super::request::Request;
use super::words::{every_term, same_word, terms};

/// A condition the request asks for one way and the goal has the other way.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnedAround {
    pub atom: Atom,
    /// Whether the request asks for the atom to hold.
    pub wanted: bool,
    /// The request's word that says which way.
    pub word: String,
}

impl fmt::Display for TurnedAround {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (asked, has) = if self.wanted {
            (self.atom.to_string(), format!("~{}", self.atom))
        } else {
            (format!("~{}", self.atom), self.atom.to_string())
        };
        write!(
            f,
            "the request says \"{}\", which asks for {asked}, where the goal has {has}",
            self.word
        )
    }
}

/// A condition of `goal` that the request asks for the other way round, if any.
pub fn turned_around(goal: &Formula, request: &Request) -> Option<TurnedAround> {
    request
        .asked()
        .iter()
        .find_map(|(subject, wanted, word, _)| {
            let pick = |a: &Atom| subject.matches(a);
            let signs = signs_of(goal, &pick, true);
            if signs.is_empty() || signs.contains(wanted) {
                return None;
            }
            Some(TurnedAround {
                atom: first_matching(goal, &pick)?,
                wanted: *wanted,
                word: word.clone(),
            })
        })
}

/// `goal` with every condition the request asks for the other way round turned around.
/// `None` when nothing is turned around.
pub fn turned_back(goal: &Formula, request: &Request) -> Option<Formula> {
    // Each atom is turned once: a second finding about it would undo the first.
    undo_each(
        goal,
        |g| turned_around(g, request),
        |t| t.atom.clone(),
        |g, t| flipped(g, &t.atom),
    )
}

/// A condition the request asks for in its own words, in a sentence that offers no
/// choice, and that `goal` has no condition about at all ("don't forget to turn on the
/// hall light" read as the deliveries alone); with whether it is asked to hold and the
/// word that asks for it.
pub fn left_unanswered(goal: &Formula, request: &Request) -> Option<(Atom, bool, String)> {
    let atoms = goal.atoms();
    request
        .asked()
        .iter()
        .filter(|(_, _, _, choice)| !choice)
        .find(|(subject, _, _, _)| !atoms.iter().any(|a| subject.matches(a)))
        .and_then(|(subject, wanted, word, _)| {
            let atom = Atom::new(subject.predicate.clone(), vec![subject.object.clone()]);
            let takes_one = request
                .vocabulary
                .predicates
                .iter()
                .any(|p| p.name == subject.predicate && p.arg_types.len() == 1);
            takes_one.then_some((atom, *wanted, word.clone()))
        })
}

/// `goal` with every condition [`left_unanswered`] finds put beside it, the way the
/// request asks for it. `None` when nothing is left unanswered.
pub fn with_unanswered(goal: &Formula, request: &Request) -> Option<Formula> {
    undo_each(
        goal,
        |g| left_unanswered(g, request),
        |(atom, _, _)| atom.clone(),
        |g, (atom, wanted, _)| {
            let condition = Formula::Atom(atom.clone());
            let condition = if *wanted {
                condition
            } else {
                Formula::Not(Box::new(condition))
            };
            Formula::and(vec![g.clone(), condition])
        },
    )
}

/// What a clause asks about: a predicate and the object it is about.
pub(super) struct Subject {
    predicate: String,
    object: String,
}

impl Subject {
    /// The condition it is about.
    pub(super) fn atom(&self) -> Atom {
        Atom::new(self.predicate.clone(), vec![self.object.clone()])
    }

    fn matches(&self, atom: &Atom) -> bool {
        atom.predicate == self.predicate && atom.args.first() == Some(&self.object)
    }
}

/// A condition the request asks for one way: what it is about, whether it is asked to
/// hold, the word that says so, and whether its sentence offers a choice ("or",
/// "either"): a condition asked there may be one alternative of several.
pub(super) type Asked = (Subject, bool, String, bool);

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

/// `text` without the words that only announce a number ("table No. 6", "table number
/// one", "bar nr 2"), which would stand between a name's words and, as "No.", end a
/// sentence or read as a negation.
pub fn without_numbering(text: &str) -> String {
    let tokens: Vec<&str> = text.split_whitespace().collect();
    let announces = |i: usize| {
        NUMBERING.contains(&tokens[i].to_lowercase().as_str())
            && tokens.get(i + 1).is_some_and(|next| {
                let next = next.to_lowercase();
                let next = next.trim_matches(|c: char| !c.is_alphanumeric());
                next.starts_with(|c: char| c.is_ascii_digit()) || is_number_word(next)
            })
    };
    (0..tokens.len())
        .filter(|&i| !announces(i))
        .map(|i| tokens[i])
        .collect::<Vec<&str>>()
        .join(" ")
}

/// The clauses of `sentence`, as [`every_term`] gives their words: split at punctuation
/// and before the words that start a clause; "n't" is the word "not". The clause splitter
/// [`Request::new`] reads a request's negation scopes with.
pub(super) fn clauses(sentence: &str) -> Vec<Vec<String>> {
    let text = without_numbering(sentence)
        .replace("n't", " not")
        .replace("n’t", " not")
        .replace("N'T", " not");
    let mut out: Vec<Vec<String>> = Vec::new();
    for piece in text.split([',', '.', ';', ':', '!', '?', '(', ')']) {
        let mut clause: Vec<String> = Vec::new();
        for word in every_term(piece) {
            if clause_start(&word).is_some() {
                if !clause.is_empty() {
                    out.push(std::mem::take(&mut clause));
                }
                continue;
            }
            clause.push(word);
        }
        if !clause.is_empty() {
            out.push(clause);
        }
    }
    out
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

/// The sign (held or negated) of each place `goal` has an atom that `pick` picks.
fn signs_of(goal: &Formula, pick: &dyn Fn(&Atom) -> bool, positive: bool) -> Vec<bool> {
    match goal {
        Formula::Atom(a) => {
            if pick(a) {
                vec![positive]
            } else {
                Vec::new()
            }
        }
        Formula::Not(inner) => signs_of(inner, pick, !positive),
        Formula::And(items) | Formula::Or(items) => items
            .iter()
            .flat_map(|i| signs_of(i, pick, positive))
            .collect(),
    }
}

/// The first atom of `goal` that `pick` picks.
fn first_matching(goal: &Formula, pick: &dyn Fn(&Atom) -> bool) -> Option<Atom> {
    goal.atoms_in_order().into_iter().find(|a| pick(a))
}

#[cfg(test)]
#[path = "polarity_tests.rs"]
mod tests;
