//! What a request is cut into before any object of the scene is looked for: its text
//! without the words that only announce a number, the clauses its negation scopes are read
//! in, and the choices it offers.

use crate::reading::english::{NUMBERING, clause_start, is_number_word, offers_choice};
use crate::reading::words::every_term;

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
/// [`Request::new`](super::Request::new) reads a request's negation scopes with.
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

/// How many choices a request offers: each "or" (and "if not", "otherwise", ...), and each
/// comma of a list that ends in "or" ("coffee, cake, or tea"). [`Request::new`](super::Request::new) reads
/// them once.
pub(super) fn choices_offered(request: &str) -> usize {
    let lower = request.to_lowercase();
    let mut choices = lower.matches("if not").count();
    for part in lower.split(['.', ';', ':', '!', '?']) {
        let words: Vec<&str> = part
            .split(|c: char| !c.is_alphanumeric() && c != ',')
            .filter(|w| !w.is_empty())
            .collect();
        let mut commas_since_choice = 0;
        for w in words {
            let word = w.trim_end_matches(',');
            if offers_choice(word) {
                choices += 1 + commas_since_choice;
                commas_since_choice = 0;
            }
            if w.ends_with(',') {
                commas_since_choice += 1;
            }
        }
    }
    choices
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_that_only_announce_a_number_are_left_out() {
        assert_eq!(
            without_numbering("Go to table No. 6 now"),
            "Go to table 6 now"
        );
        assert_eq!(
            without_numbering("table number one, please"),
            "table one, please"
        );
        assert_eq!(
            without_numbering("No juice, no. Bar nr 2"),
            "No juice, no. Bar 2"
        );
    }
}
