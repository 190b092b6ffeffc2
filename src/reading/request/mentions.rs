//! Where a request's words name the scene's objects.

use crate::domain::Object;
use crate::reading::words::{same_word, terms};

use super::Mention;

/// Where `words` name one of `objects` by its name's words in a row or by what it is
/// called, the longest name first, skipping the positions in `taken`: (start, length,
/// object). A name of several words also names its object with the words spread over a
/// short stretch, in any order ("table 6 by the window" for window table 6), once no
/// name has them in a row. A name with a word beside it from a longer name of another
/// object that shares its words ("the other bar", where the other bar counter is another
/// place than the bar) names neither.
pub(in crate::reading) fn mentions(
    words: &[String],
    objects: &[&Object],
    taken: &[usize],
) -> Vec<Mention> {
    let mut phrases: Vec<(Vec<String>, &str)> = objects
        .iter()
        .flat_map(|o| {
            std::iter::once(&o.name)
                .chain(&o.called)
                .map(move |p| (terms(p), o.name.as_str()))
        })
        .filter(|(t, _)| !t.is_empty())
        .collect();
    phrases.sort_by_key(|(t, _)| std::cmp::Reverse(t.len()));
    let mut used: Vec<usize> = taken.to_vec();
    let mut out = Vec::new();
    for spread in [false, true] {
        for (phrase, name) in &phrases {
            if spread && phrase.len() < 2 {
                continue;
            }
            let mut start = 0;
            while start < words.len() {
                let Some(end) = named_at(words, phrase, start, spread, &used) else {
                    start += 1;
                    continue;
                };
                let span = start..end;
                used.extend(span.clone());
                let beside: Vec<&String> = [span.start.checked_sub(1), Some(span.end)]
                    .into_iter()
                    .flatten()
                    .filter_map(|i| words.get(i))
                    .collect();
                let other_longer = phrases.iter().any(|(other, other_name)| {
                    other_name != name
                        && other.len() > phrase.len()
                        && phrase.iter().all(|p| other.contains(p))
                        && beside.iter().any(|b| other.iter().any(|o| same_word(o, b)))
                });
                if !other_longer {
                    out.push((start, end - start, name.to_string()));
                }
                start = end;
            }
        }
    }
    out.sort();
    out
}

/// How many more words a name's words may be spread over than it has.
const SPREAD: usize = 2;

/// Where a mention of `phrase` starting at `start` ends: its words in a row or, when
/// `spread`, each of them once within the name's length and [`SPREAD`] words, beginning
/// with one of them; none of the words on the way in `used`.
fn named_at(
    words: &[String],
    phrase: &[String],
    start: usize,
    spread: bool,
    used: &[usize],
) -> Option<usize> {
    if !spread {
        let end = start + phrase.len();
        let row = words.get(start..end)?;
        let fits = phrase.iter().zip(row).all(|(p, w)| same_word(p, w));
        return (fits && !(start..end).any(|i| used.contains(&i))).then_some(end);
    }
    if !phrase.iter().any(|p| same_word(p, &words[start])) {
        return None;
    }
    let mut left: Vec<&String> = phrase.iter().collect();
    let stretch = words.len().min(start + phrase.len() + SPREAD);
    for (i, word) in words.iter().enumerate().take(stretch).skip(start) {
        if used.contains(&i) {
            return None;
        }
        if let Some(k) = left.iter().position(|p| same_word(p, word)) {
            left.remove(k);
            if left.is_empty() {
                return Some(i + 1);
            }
        }
    }
    None
}
