//! The words of a text as every reader of requests sees them: lower case, split at
//! anything that is not a letter or digit and inside symbol names (`WindowTable6` →
//! window, table, 6), numbers written as words turned into digits, crude endings removed;
//! and when two such words are one word.

use super::english::{is_stopword, number_digit};

/// The words of `text` a match is made on: lower case, split at anything that is not a
/// letter or digit, at lower-to-upper case changes and where an acronym ends, stop words
/// dropped, crude plural and verb endings removed.
pub fn terms(text: &str) -> Vec<String> {
    every_term(text)
        .into_iter()
        .filter(|w| !is_stopword(w))
        .collect()
}

/// [`terms`] with the stop words kept: "on", "up" and "so" matter where a request's
/// small words are read ("turn the light on").
pub fn every_term(text: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut current = String::new();
    let mut previous: Option<char> = None;
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        let next = chars.peek().copied();
        // A word ends at anything else than a letter or digit, at a lower-to-upper case
        // change (`TubeLight`), where an acronym gives way to a word (`ACTemperature`,
        // `NFCJuice`) and between letters and digits (`Table3`).
        let boundary = !c.is_alphanumeric()
            || previous.is_some_and(|p| {
                (c.is_uppercase() && (p.is_lowercase() || p.is_ascii_digit()))
                    || (c.is_uppercase()
                        && p.is_uppercase()
                        && next.is_some_and(char::is_lowercase))
                    || (c.is_ascii_digit() != p.is_ascii_digit() && p.is_alphanumeric())
            });
        if boundary && !current.is_empty() {
            words.push(std::mem::take(&mut current));
        }
        if c.is_alphanumeric() {
            current.extend(c.to_lowercase());
            previous = Some(c);
        } else {
            previous = None;
        }
    }
    if !current.is_empty() {
        words.push(current);
    }
    words
        .into_iter()
        .map(|w| number_digit(&w).map_or_else(|| stem(&w), str::to_string))
        .collect()
}

fn stem(word: &str) -> String {
    for suffix in ["ing", "ed", "s"] {
        if let Some(root) = word.strip_suffix(suffix)
            && root.chars().count() >= 3
            && !root.ends_with('s')
        {
            return root.to_string();
        }
    }
    word.to_string()
}

/// Whether `word` is written in digits (numbers written as words are digits in [`terms`]).
pub fn is_number(word: &str) -> bool {
    !word.is_empty() && word.chars().all(|c| c.is_ascii_digit())
}

/// Two words that are one after crude stemming ("close" and "closed" → "clos"), or
/// spellings of one longer word.
pub fn same_word(a: &str, b: &str) -> bool {
    let shorter = a.len().min(b.len());
    let k = shorter.min(5);
    let longer = a.len().max(b.len());
    a == b
        || (shorter >= 4
            && longer - shorter <= ENDING_AT_MOST
            && a.get(..k).is_some()
            && a.get(..k) == b.get(..k))
        // Spelling variants of longer words ("yoghurt", "yogurt"); short words one letter
        // apart are different words ("water", "waiter").
        || (shorter >= SPELLING_VARIANT_FROM && strsim::levenshtein(a, b) <= 1)
}

/// How much longer one word may be than another with the same beginning and still be
/// the same word with an ending ("clean", "cleaning"): "water" is not "watermelon".
const ENDING_AT_MOST: usize = 4;

/// How long both words must be before one letter more, less or other is a spelling variant.
const SPELLING_VARIANT_FROM: usize = 6;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terms_split_words_and_atoms() {
        assert_eq!(terms("Active_TubeLight"), ["active", "tube", "light"]);
        assert_eq!(
            terms("Could you switch on the lights, please?"),
            ["switch", "light"]
        );
        assert_eq!(
            terms("\"blue cube\" on \"table\""),
            ["blue", "cube", "table"]
        );
        assert_eq!(terms("WindowTable4"), ["window", "table", "4"]);
        assert_eq!(terms("Low_ACTemperature"), ["low", "ac", "temperature"]);
        assert_eq!(terms("NFCJuice"), ["nfc", "juice"]);
        assert_eq!(terms("the third table"), ["3", "table"]);
        assert_eq!(
            terms("QuietTable9, table nine"),
            ["quiet", "table", "9", "table", "9"]
        );
    }
}
