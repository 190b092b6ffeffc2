//! Word error rate: the word-level edit distance (substitutions + deletions + insertions)
//! between a reference and a transcript, over the reference's word count, after both are
//! normalised (lower case, punctuation removed, hyphens split).

/// Words of `text`, normalised for scoring.
pub fn normalise(text: &str) -> Vec<String> {
    text.to_lowercase()
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '\'' {
                c
            } else {
                ' '
            }
        })
        .collect::<String>()
        .split_whitespace()
        .map(|w| w.trim_matches('\'').to_string())
        .filter(|w| !w.is_empty())
        .collect()
}

/// The edit operations of the best alignment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WordErrors {
    pub substitutions: usize,
    pub deletions: usize,
    pub insertions: usize,
    pub reference_words: usize,
}

impl WordErrors {
    pub fn errors(&self) -> usize {
        self.substitutions + self.deletions + self.insertions
    }

    /// Errors over reference words (0 for an empty reference and transcript, 1 per
    /// inserted word when only the reference is empty).
    pub fn rate(&self) -> f64 {
        if self.reference_words == 0 {
            return self.insertions as f64;
        }
        self.errors() as f64 / self.reference_words as f64
    }
}

/// Align `hypothesis` to `reference` (Levenshtein over words).
pub fn word_errors(reference: &str, hypothesis: &str) -> WordErrors {
    let (r, h) = (normalise(reference), normalise(hypothesis));
    // cost[j] for the current row: (total, subs, dels, ins) of aligning r[..i] with h[..j].
    let mut prev: Vec<(usize, WordErrors)> = (0..=h.len())
        .map(|j| {
            (
                j,
                WordErrors {
                    insertions: j,
                    ..WordErrors::default()
                },
            )
        })
        .collect();
    for (i, rw) in r.iter().enumerate() {
        let mut row = Vec::with_capacity(h.len() + 1);
        let mut first = prev[0].1;
        first.deletions += 1;
        row.push((i + 1, first));
        for (j, hw) in h.iter().enumerate() {
            let (diag_cost, mut diag) = prev[j];
            let same = rw == hw;
            if !same {
                diag.substitutions += 1;
            }
            let mut best = (diag_cost + usize::from(!same), diag);
            let (up_cost, mut up) = prev[j + 1];
            if up_cost + 1 < best.0 {
                up.deletions += 1;
                best = (up_cost + 1, up);
            }
            let (left_cost, mut left) = row[j];
            if left_cost + 1 < best.0 {
                left.insertions += 1;
                best = (left_cost + 1, left);
            }
            row.push(best);
        }
        prev = row;
    }
    let mut result = prev[h.len()].1;
    result.reference_words = r.len();
    result
}

/// The word error rate of `hypothesis` against `reference`.
pub fn word_error_rate(reference: &str, hypothesis: &str) -> f64 {
    word_errors(reference, hypothesis).rate()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalisation_ignores_case_and_punctuation() {
        assert_eq!(
            normalise(" Put the test-tube in the Centrifuge. "),
            ["put", "the", "test", "tube", "in", "the", "centrifuge"]
        );
        assert_eq!(normalise("robot's 'cup'"), ["robot's", "cup"]);
        assert_eq!(word_error_rate("Put the cup.", "put the CUP"), 0.0);
    }

    #[test]
    fn each_kind_of_error_is_counted() {
        let r = "put the blue cube on the green cube";
        let e = word_errors(r, "put a blue cube on the green cube");
        assert_eq!((e.substitutions, e.deletions, e.insertions), (1, 0, 0));
        let e = word_errors(r, "put blue cube on the green cube");
        assert_eq!((e.substitutions, e.deletions, e.insertions), (0, 1, 0));
        let e = word_errors(r, "put the blue cube right on the green cube");
        assert_eq!((e.substitutions, e.deletions, e.insertions), (0, 0, 1));
        assert!((word_error_rate(r, "put blue cube on the green cube") - 0.125).abs() < 1e-12);
        assert_eq!(word_error_rate(r, ""), 1.0);
        assert_eq!(word_error_rate("", ""), 0.0);
        assert_eq!(word_error_rate("", "uh um"), 2.0);
    }
}
