//! A request read as the wishes it is made of. People string several wishes together
//! ("Please turn on the hall light. And, can you bring water to table 2? Thank you."), and
//! a small model reads such a request worse than it reads each wish alone: it leaves one
//! out, mixes their parts, or turns a negation around. A request is cut where a new wish
//! begins — at the end of a sentence, before "also", "and then", "alternatively" and the
//! like after a comma, and before "and", "but" or "or" followed by a verb of asking ("clean
//! the chairs and deliver coffee", "either clear the table or turn off the light") — and
//! each piece that names an object becomes a part. Pieces
//! that name none ("Thank you.", "It looks like it needs a good cleaning.") stay with the
//! part before them, so no part is read without the thing it is about.
//!
//! Parts are joined by "and", unless a part offers itself as the alternative to the one
//! before ("If not, ...", "Or ...", "Alternatively, ..."); "and" joins groups of
//! alternatives, as it does in speech ("A. Or B. Also C" is (A or B) and C).

pub use super::english::Join;
use super::english::{
    BACK_REFERENCES, CONJUNCTIONS, asks, is_negated_form, is_negation, may_precede_verb,
    wish_openers,
};
use super::lexicon::Lexicon;
use super::words::terms;

/// One wish of a request, as the person wrote it, without the connective that joined it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Part {
    pub text: String,
    /// How it joins the part before it (`And` for the first).
    pub join: Join,
}

/// The parts of `request`, in order: one part when it is a single wish (or names no
/// object at all).
pub fn split(request: &str, lexicon: &Lexicon) -> Vec<Part> {
    // Each piece with the words as written, joining word included, for a piece kept with
    // another ("pick up and hold a bottle").
    let mut pieces: Vec<(Part, &str)> = Vec::new();
    for (i, sentence) in sentences(request).into_iter().enumerate() {
        for (j, (clause, joined)) in clauses(sentence).into_iter().enumerate() {
            let (join, text) = match joined {
                Some((join, word)) => (join, clause.get(word..).unwrap_or(clause)),
                None => opening(clause, j == 0 && i > 0),
            };
            let text = text.trim();
            if text.chars().any(char::is_alphanumeric) {
                let part = Part {
                    text: text.to_string(),
                    join,
                };
                pieces.push((
                    part,
                    if joined.is_some() {
                        clause.trim()
                    } else {
                        text
                    },
                ));
            }
        }
    }
    let names_something = |text: &str| terms(text).iter().any(|w| lexicon.names_an_object(w));
    let mut parts: Vec<Part> = Vec::new();
    let mut leading = String::new();
    for (piece, written) in pieces {
        if !names_something(&piece.text) {
            // Kept with the wish before it, or the one after when there is none yet.
            match parts.last_mut() {
                Some(last) => push_text(&mut last.text, written),
                None => push_text(&mut leading, written),
            }
            continue;
        }
        let own = if leading.is_empty() {
            &piece.text
        } else {
            written
        };
        let mut text = std::mem::take(&mut leading);
        push_text(&mut text, own);
        let join = if parts.is_empty() {
            Join::And
        } else {
            piece.join
        };
        parts.push(Part { text, join });
    }
    if parts.is_empty() {
        return vec![Part {
            text: request.trim().to_string(),
            join: Join::And,
        }];
    }
    if !leading.is_empty()
        && let Some(last) = parts.last_mut()
    {
        push_text(&mut last.text, &leading);
    }
    parts
}

fn push_text(to: &mut String, text: &str) {
    if !to.is_empty() {
        to.push(' ');
    }
    to.push_str(text);
}

/// The sentences of `text`: each ends at `.`, `?`, `!` or `;` followed by a space and a
/// word that does not begin with a digit ("table No. 6" goes on), or at the end.
fn sentences(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut start = 0;
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    for (k, &(at, c)) in chars.iter().enumerate() {
        if !matches!(c, '.' | '?' | '!' | ';') {
            continue;
        }
        let end = at + c.len_utf8();
        let rest = &text[end..];
        let after = rest.trim_start();
        let spaced = after.len() < rest.len();
        let next = after.chars().next();
        // "1.5" and "No. 6" go on; so does a run of marks ("?!") until its last one.
        let ends = match next {
            None => true,
            Some(n) => spaced && !n.is_ascii_digit(),
        };
        let run_goes_on = chars
            .get(k + 1)
            .is_some_and(|&(_, n)| matches!(n, '.' | '?' | '!'));
        if ends && !run_goes_on {
            out.push(&text[start..end]);
            start = end;
        }
    }
    if text[start..].chars().any(char::is_alphanumeric) {
        out.push(&text[start..]);
    }
    out
}

/// A sentence cut before each comma-led opener ([`wish_openers`]), and before each joining
/// word followed by a verb of asking; a clause cut at a joining word begins with it and
/// comes with how it joins and the word's length, one cut at an opener keeps the opener
/// for [`opening`] to read.
fn clauses(sentence: &str) -> Vec<(&str, Option<(Join, usize)>)> {
    let mut by_opener = Vec::new();
    let mut start = 0;
    for (at, _) in sentence.match_indices(',') {
        let after = &sentence[at + 1..];
        if opener(after).is_some() && sentence[start..at].chars().any(char::is_alphanumeric) {
            by_opener.push(&sentence[start..at]);
            start = at + 1;
        }
    }
    by_opener.push(&sentence[start..]);
    let mut out = Vec::new();
    for clause in by_opener {
        let mut join = None;
        let mut rest = clause;
        while let Some((cut, after, how)) = verb_join(rest) {
            out.push((&rest[..cut], join));
            join = Some((how, after - cut));
            rest = &rest[cut..];
        }
        out.push((rest, join));
    }
    out
}

/// The first joining word of `clause` that a verb of asking follows, after some words of
/// the clause: where the word starts, where it ends, and how it joins.
fn verb_join(clause: &str) -> Option<(usize, usize, Join)> {
    let words = word_spans(clause);
    let lower = |k: usize| clause[words[k].0..words[k].1].to_lowercase();
    for k in 1..words.len() {
        let Some((_, how)) = CONJUNCTIONS.iter().find(|(w, _)| *w == lower(k)) else {
            continue;
        };
        let mut next = k + 1;
        while next < words.len() && may_precede_verb(&lower(next)) {
            next += 1;
        }
        if next >= words.len() || !asks(&lower(next)) {
            continue;
        }
        if *how == Join::Or && (0..k).any(|i| is_negation(&lower(i)) || is_negated_form(&lower(i)))
        {
            continue;
        }
        // "make a dessert and bring it to table 3": the wish after is about the one before.
        if (next..words.len()).any(|i| BACK_REFERENCES.contains(&lower(i).as_str())) {
            continue;
        }
        return Some((words[k].0, words[k].1, *how));
    }
    None
}

/// The byte spans of the words of `text` (letters, digits and apostrophes).
fn word_spans(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    for (at, c) in text.char_indices() {
        let in_word = c.is_alphanumeric() || c == '\'' || c == '’';
        match (in_word, start) {
            (true, None) => start = Some(at),
            (false, Some(s)) => {
                out.push((s, at));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, text.len()));
    }
    out
}

/// The opener `text` begins with, as whole words, and the length of text it takes.
fn opener(text: &str) -> Option<(Join, usize)> {
    let lower = text.to_lowercase();
    let trimmed = lower.trim_start();
    let skipped = lower.len() - trimmed.len();
    wish_openers()
        .into_iter()
        .find(|(words, _)| starts_with_words(trimmed, words))
        .map(|(words, join)| (join, skipped + words.len()))
}

fn starts_with_words(text: &str, words: &str) -> bool {
    text.starts_with(words)
        && text[words.len()..]
            .chars()
            .next()
            .is_none_or(|c| !c.is_alphanumeric() && c != '\'')
}

/// How a clause joins the one before, and its text without the words that said so.
/// `sentence_start`: the clause begins a sentence (which may begin "Or", "And").
fn opening(clause: &str, sentence_start: bool) -> (Join, &str) {
    // Case is only ever changed for ASCII letters here, so byte offsets of the lower-case
    // text are the clause's own.
    let ascii_lower = clause.to_ascii_lowercase();
    let trimmed_len = ascii_lower.trim_start().len();
    let skipped = ascii_lower.len() - trimmed_len;
    let trimmed = &ascii_lower[skipped..];
    let found = opener(clause).or_else(|| {
        sentence_start
            .then(|| {
                CONJUNCTIONS
                    .iter()
                    .find(|(words, _)| starts_with_words(trimmed, words))
                    .map(|(words, join)| (*join, skipped + words.len()))
            })
            .flatten()
    });
    match found {
        Some((join, len)) if clause.is_char_boundary(len) => {
            let rest = clause[len..].trim_start_matches(|c: char| c == ',' || c.is_whitespace());
            (join, rest)
        }
        _ => (Join::And, clause),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cafe_lexicon() -> Lexicon {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml");
        let scenario = crate::scenario::Scenario::load(&path).expect("cafe scenario");
        Lexicon::new(&scenario.domain.vocabulary, &scenario.examples)
    }

    fn texts(parts: &[Part]) -> Vec<(Join, &str)> {
        parts.iter().map(|p| (p.join, p.text.as_str())).collect()
    }

    #[test]
    fn one_wish_is_one_part() {
        let lex = cafe_lexicon();
        let request = "Bring the milk and the chips to table No. 6 by the window, please.";
        let parts = split(request, &lex);
        assert_eq!(texts(&parts), vec![(Join::And, request)]);
        // Nothing named: the request as it is.
        assert_eq!(split("Thank you!", &lex)[0].text, "Thank you!");
        assert_eq!(split("", &lex).len(), 1);
    }

    #[test]
    fn sentences_and_comma_openers_begin_parts() {
        let lex = cafe_lexicon();
        let parts = split(
            "Switch the hall light off. Also, I would like a yogurt at the bar, and then open the curtain!",
            &lex,
        );
        assert_eq!(
            texts(&parts),
            vec![
                (Join::And, "Switch the hall light off."),
                (Join::And, "I would like a yogurt at the bar"),
                (Join::And, "open the curtain!"),
            ]
        );
    }

    #[test]
    fn alternatives_offered_in_their_own_sentence_join_by_or() {
        let lex = cafe_lexicon();
        let parts = split(
            "Could you tidy the floor? If not, bring some bread to table 3. Or at least turn on the AC.",
            &lex,
        );
        assert_eq!(
            texts(&parts),
            vec![
                (Join::And, "Could you tidy the floor?"),
                (Join::Or, "bring some bread to table 3."),
                (Join::Or, "turn on the AC."),
            ]
        );
        let parts = split("Bring a coffee to bar 2, or alternatively some milk.", &lex);
        assert_eq!(parts.len(), 2);
        assert_eq!(parts[1].join, Join::Or);
    }

    #[test]
    fn pieces_naming_nothing_stay_with_a_wish() {
        let lex = cafe_lexicon();
        let parts = split(
            "Hello there! Please mop the floor. It really needs it. And bring a tea to the bar. Thanks a lot.",
            &lex,
        );
        assert_eq!(
            texts(&parts),
            vec![
                (
                    Join::And,
                    "Hello there! Please mop the floor. It really needs it."
                ),
                (Join::And, "bring a tea to the bar. Thanks a lot."),
            ]
        );
    }

    #[test]
    fn a_joining_word_before_a_verb_of_asking_begins_a_wish() {
        let lex = cafe_lexicon();
        let parts = split(
            "Clean the chairs and deliver coffee to the coffee station.",
            &lex,
        );
        assert_eq!(
            texts(&parts),
            vec![
                (Join::And, "Clean the chairs"),
                (Join::And, "deliver coffee to the coffee station."),
            ]
        );
        let parts = split(
            "Could you please either clear the table or turn off the hall light?",
            &lex,
        );
        assert_eq!(
            texts(&parts),
            vec![
                (Join::And, "Could you please either clear the table"),
                (Join::Or, "turn off the hall light?"),
            ]
        );
        // A verb that names nothing stays with the wish it begins, its "and" kept.
        let parts = split("Please pick up and hold a bottle of spring water.", &lex);
        assert_eq!(
            texts(&parts),
            vec![(
                Join::And,
                "Please pick up and hold a bottle of spring water."
            )]
        );
        // "Don't ... or ..." asks for neither: no alternatives.
        let request = "Don't bring coffee or serve the dessert.";
        assert_eq!(texts(&split(request, &lex)), vec![(Join::And, request)]);
        // A wish about the thing of the one before is read with it.
        let request = "Make a dessert and bring it to table 3.";
        assert_eq!(split(request, &lex).len(), 1);
        // "and" before a thing, not a verb, joins two things of one wish.
        let request = "Bring the milk and the chips to the bar.";
        assert_eq!(split(request, &lex).len(), 1);
    }

    #[test]
    fn numbers_and_marks_do_not_end_sentences() {
        assert_eq!(
            sentences("Go to bar No. 2 now."),
            vec!["Go to bar No. 2 now."]
        );
        assert_eq!(
            sentences("Set 1.5 m/s?! Then stop."),
            vec!["Set 1.5 m/s?!", " Then stop."]
        );
        assert_eq!(sentences("Fine... ok"), vec!["Fine...", " ok"]);
        // Words only a person would write after a comma, not inside a word.
        assert!(opener("  alsoable").is_none());
        assert_eq!(opener(" also, x").map(|(j, _)| j), Some(Join::And));
        assert_eq!(opener(" or else x").map(|(j, _)| j), Some(Join::Or));
    }
}
