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

use crate::scenario::Example;

/// BM25's usual constants: term-frequency saturation and length normalisation.
const K1: f64 = 1.2;
const B: f64 = 0.75;

/// Words that say nothing about what is asked.
const STOPWORDS: &[&str] = &[
    "a", "an", "the", "to", "of", "and", "or", "in", "on", "at", "for", "me", "my", "i", "im",
    "you", "your", "please", "could", "would", "can", "will", "it", "is", "be", "some", "that",
    "this", "with", "by", "up", "we", "us", "our", "just", "so", "do", "id", "like", "want",
    "there", "here", "its", "am", "are", "was", "get", "let", "mind", "any", "object",
];

/// The words of `text` a match is made on: lower case, split at anything that is not a
/// letter or digit, at lower-to-upper case changes and where an acronym ends, stop words
/// dropped, crude plural and verb endings removed.
pub fn terms(text: &str) -> Vec<String> {
    every_term(text)
        .into_iter()
        .filter(|w| !STOPWORDS.contains(&w.as_str()))
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
        .map(|w| number(&w).map_or_else(|| stem(&w), str::to_string))
        .collect()
}

/// Numbers written as words, cardinal or ordinal, as digits ("table three", "the third
/// table" and `Table3` share the word 3).
fn number(word: &str) -> Option<&'static str> {
    const NUMBERS: [(&str, &str, &str); 10] = [
        ("one", "first", "1"),
        ("two", "second", "2"),
        ("three", "third", "3"),
        ("four", "fourth", "4"),
        ("five", "fifth", "5"),
        ("six", "sixth", "6"),
        ("seven", "seventh", "7"),
        ("eight", "eighth", "8"),
        ("nine", "ninth", "9"),
        ("ten", "tenth", "10"),
    ];
    NUMBERS
        .iter()
        .find(|(cardinal, ordinal, _)| word == *cardinal || word == *ordinal)
        .map(|(_, _, digit)| *digit)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn ex(instruction: &str, goal: &str) -> Example {
        Example {
            instruction: instruction.into(),
            goal: goal.into(),
        }
    }

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
    fn k_bounds_the_choice() {
        let pool = vec![ex("Close the curtain", "Closed_Curtain")];
        assert!(nearest(&pool, "anything", 0).is_empty());
        assert_eq!(nearest(&pool, "anything", 5).len(), 1);
        assert!(nearest(&[], "anything", 3).is_empty());
    }
}
