//! What a text (a model's reasoning about a failure) claims about the scene's conditions,
//! read from its words: in each clause, an object of the scene, then a predicate's words
//! ("on", "near the robot", "grasped", or the words the scene lists for it and for its
//! opposite), then — for a relation — a second object; between the first object and the
//! predicate, a word that links them ("is", "lies", "must be"), or the object is only what
//! a verb acts on ("place the cube on the table"). A negation between them turns the
//! claim round; a word of need ("must", "needs to") makes it a claim about what is
//! missing rather than about what holds. Clauses that only suppose ("if", "once", "would")
//! claim nothing. Nothing here knows the world: [`Claim`]s are checked by those who do.

use crate::domain::{Atom, Condition, Object, Predicate, Vocabulary};

use super::english::{
    ARTICLES, BEING, HYPOTHETICAL, MISSING, NEEDING, is_negated_form, is_negation,
};
use super::words::{every_term, same_word};

/// A condition of the scene the text says holds (or does not), or is needed.
#[derive(Debug, Clone, PartialEq)]
pub struct Claim {
    pub condition: Condition,
    /// Said as what must hold for the action, not as what holds.
    pub needed: bool,
    /// Said to be what the failure lacks ("the missing condition is …").
    pub as_missing: bool,
    /// The clause it was read from, as written.
    pub said: String,
}

/// The claims of `text` about conditions over `vocabulary`'s objects.
pub fn claims(text: &str, vocabulary: &Vocabulary) -> Vec<Claim> {
    let forms = predicate_forms(vocabulary);
    let mut found = Vec::new();
    for clause in clauses(text) {
        let raw: Vec<String> = clause.split_whitespace().map(str::to_lowercase).collect();
        if raw.iter().any(|w| {
            let word = w.trim_matches(|c: char| !c.is_alphanumeric());
            HYPOTHETICAL.contains(&word)
        }) {
            continue;
        }
        let words = every_term(clause);
        // "wasn't" is read as "wasn" and "t": both parts of a contraction negate.
        let contracted: Vec<String> = raw
            .iter()
            .filter(|w| is_negated_form(w))
            .flat_map(|w| every_term(w))
            .collect();
        let mentions = mentions(&words, &vocabulary.objects);
        let as_missing = words.iter().any(|w| listed(MISSING, w));
        for form in &forms {
            for span in phrase_spans(&words, &form.words) {
                let Some((condition, needed)) =
                    claim_at(&words, &mentions, form, span, &contracted)
                else {
                    continue;
                };
                let said = clause.trim();
                if !found
                    .iter()
                    .any(|c: &Claim| c.condition == condition && c.said == said)
                {
                    found.push(Claim {
                        condition,
                        needed,
                        as_missing: needed && as_missing,
                        said: said.to_string(),
                    });
                }
            }
        }
    }
    found
}

/// A way of saying a predicate: its words, and whether they say its opposite.
struct Form<'a> {
    predicate: &'a Predicate,
    words: Vec<String>,
    opposite: bool,
}

/// Every predicate of one or two objects with the words that say it: its own name, the
/// words the scene lists for it, and those for its opposite.
fn predicate_forms(vocabulary: &Vocabulary) -> Vec<Form<'_>> {
    let mut forms = Vec::new();
    for predicate in &vocabulary.predicates {
        if !(1..=2).contains(&predicate.arg_types.len()) {
            continue;
        }
        let said = std::iter::once((&predicate.name, false))
            .chain(predicate.words.says.iter().map(|w| (w, false)))
            .chain(predicate.words.opposite.iter().map(|w| (w, true)));
        for (phrase, opposite) in said {
            let words = every_term(phrase);
            if !words.is_empty() {
                forms.push(Form {
                    predicate,
                    words,
                    opposite,
                });
            }
        }
    }
    forms
}

/// An object named in the words: where its name starts and ends (exclusive).
struct Mention<'a> {
    start: usize,
    end: usize,
    object: &'a Object,
}

/// The objects `words` name, by their names or what they are called, longest first where
/// two overlap ("blue cube" over "cube").
fn mentions<'a>(words: &[String], objects: &'a [Object]) -> Vec<Mention<'a>> {
    let mut all: Vec<Mention> = Vec::new();
    for object in objects {
        for name in std::iter::once(&object.name).chain(&object.called) {
            let name_words = every_term(name);
            for (start, end) in phrase_spans(words, &name_words) {
                all.push(Mention { start, end, object });
            }
        }
    }
    all.sort_by_key(|m| (m.start, std::cmp::Reverse(m.end)));
    let mut kept: Vec<Mention> = Vec::new();
    for m in all {
        if kept.last().is_none_or(|k| m.start >= k.end) {
            kept.push(m);
        }
    }
    kept
}

/// Where `phrase` stands in `words` (its first word, and the word after its last), its
/// words in order with articles allowed between ("near the robot" says `near robot`).
fn phrase_spans(words: &[String], phrase: &[String]) -> Vec<(usize, usize)> {
    let Some(first) = phrase.first() else {
        return Vec::new();
    };
    let alike = |a: &str, b: &str| if b.len() < 4 { a == b } else { same_word(a, b) };
    (0..words.len())
        .filter_map(|start| {
            if !alike(&words[start], first) {
                return None;
            }
            let mut at = start + 1;
            for want in &phrase[1..] {
                while at < words.len() && ARTICLES.contains(&words[at].as_str()) {
                    at += 1;
                }
                if at >= words.len() || !alike(&words[at], want) {
                    return None;
                }
                at += 1;
            }
            Some((start, at))
        })
        .collect()
}

/// The claim of a predicate's words at `(at, end)`: the object just before them (only words of
/// being, need and negation between), and for a relation the object just after; with
/// whether it is turned round and whether it says what is needed.
fn claim_at(
    words: &[String],
    mentions: &[Mention],
    form: &Form,
    (at, end): (usize, usize),
    contracted: &[String],
) -> Option<(Condition, bool)> {
    let subject = mentions.iter().rev().find(|m| m.end <= at)?;
    let between = &words[subject.end..at];
    let needs = |w: &String| listed(NEEDING, w);
    if !between
        .iter()
        .all(|w| listed(BEING, w) || needs(w) || is_negation(w) || contracted.contains(w))
    {
        return None;
    }
    // A statement links the object to what is said of it ("is", "must be"); without such a
    // word the object is what a verb acts on ("place the blue cube on the green cube").
    if !between
        .iter()
        .any(|w| listed(BEING, w) || needs(w) || contracted.contains(w))
    {
        return None;
    }
    let negated = between
        .iter()
        .any(|w| is_negation(w) || contracted.contains(w));
    let needed = between.iter().any(needs);
    let mut args = vec![subject.object.name.clone()];
    if form.predicate.arg_types.len() == 2 {
        let object = mentions.iter().find(|m| m.start >= end)?;
        let gap = &words[end..object.start];
        if !gap
            .iter()
            .all(|w| ARTICLES.contains(&w.as_str()) || matches!(w.as_str(), "top" | "of"))
        {
            return None;
        }
        args.push(object.object.name.clone());
    }
    let atom = Atom::new(form.predicate.name.clone(), args);
    let holds = negated == form.opposite;
    let condition = if holds {
        Condition::pos(atom)
    } else {
        Condition::neg(atom)
    };
    Some((condition, needed))
}

/// Whether `word` (as [`every_term`] writes it) is one of `list`.
fn listed(list: &[&str], word: &str) -> bool {
    list.iter()
        .any(|w| every_term(w).first().is_some_and(|t| t == word))
}

/// The clauses of a text: cut at sentence ends, semicolons and commas, and at the words
/// that join clauses (left out of both).
fn clauses(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    for sentence in text.split(['.', ';', '!', '?', ',', ':', '\n']) {
        let mut start = 0;
        for (i, _) in sentence.match_indices(' ') {
            let next = sentence[i + 1..].split(' ').next().unwrap_or("");
            if matches!(
                next.to_lowercase().as_str(),
                "and" | "but" | "because" | "so" | "since" | "while" | "whereas" | "which"
            ) {
                out.push(&sentence[start..i]);
                start = i + 1 + next.len();
            }
        }
        out.push(&sentence[start..]);
    }
    out.into_iter().filter(|c| !c.trim().is_empty()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn vocabulary(scenario: &str) -> Vocabulary {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(scenario);
        crate::scenario::Scenario::load(&path)
            .unwrap()
            .domain
            .vocabulary
    }

    /// What `text` claims over `scenario`'s vocabulary, in words.
    fn said_in(scenario: &str, text: &str) -> Vec<(String, bool)> {
        claims(text, &vocabulary(scenario))
            .into_iter()
            .map(|c| (c.condition.to_string(), c.needed))
            .collect()
    }

    fn said(text: &str) -> Vec<(String, bool)> {
        said_in("scenarios/cell/red_on_blue.toml", text)
    }

    #[test]
    fn relations_states_negations_and_needs_are_read() {
        assert_eq!(
            said("The red cube is on the blue cube, so the gripper cannot reach it."),
            [("\"red cube\" on \"blue cube\"".to_string(), false)]
        );
        assert_eq!(
            said("the missing condition is that the red cube must not be on the table"),
            [("~\"red cube\" on \"table\"".to_string(), true)]
        );
        assert_eq!(
            said("The blue cube was not near the robot."),
            [("~\"blue cube\" near robot".to_string(), false)]
        );
        assert_eq!(
            said("The blue cube wasn't near the robot."),
            [("~\"blue cube\" near robot".to_string(), false)]
        );
        assert_eq!(
            said("The red cube is still grasped"),
            [("\"red cube\" grasped".to_string(), false)]
        );
    }

    #[test]
    fn suppositions_and_loose_words_claim_nothing() {
        assert!(said("If the red cube is on the table, the grasp works.").is_empty());
        assert!(said("Once the red cube would be on the table it is free.").is_empty());
        // "on" without an object before it, and objects far apart, say no relation.
        assert!(said("Focus on the blue cube.").is_empty());
        assert!(said("The blue cube failed to move on top of the table.").is_empty());
        // What the robot was doing is no claim of what holds (the embedded model's own
        // words in scenario 1).
        assert!(
            said("The robot was trying to place the blue cube on the green cube, but it failed.")
                .is_empty()
        );
    }

    /// A claim is quoted as its clause says it, without the word that joined it on.
    #[test]
    fn a_clause_is_quoted_without_its_joining_word() {
        let claims = claims(
            "The blue cube was on the table and the red cube was on the table.",
            &vocabulary("scenarios/cell/red_on_blue.toml"),
        );
        let said: Vec<&str> = claims.iter().map(|c| c.said.as_str()).collect();
        assert_eq!(
            said,
            [
                "The blue cube was on the table",
                "the red cube was on the table"
            ]
        );
    }

    /// A domain the reader was not written for: symbol names, the scene's own words.
    #[test]
    fn a_domain_of_symbol_names_is_read_the_same_way() {
        let said = said_in(
            "scenarios/warehouse/warehouse.toml",
            "The small box is not on pallet 1 because the robot put it onto the conveyor. \
             The fragile box must be on the packing station.",
        );
        assert_eq!(
            said,
            [
                ("~On_SmallBox_Pallet1".to_string(), false),
                ("On_FragileBox_PackingStation".to_string(), true),
            ]
        );
    }
}
