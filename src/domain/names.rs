//! Names a person or a model wrote that the scene may not have: how alike two names are,
//! and the listed names offered instead ("did you mean …?"). Nothing here replaces a
//! name; callers refuse the one they were given and show what is offered.

/// How alike a listed name must be, by default, to be offered for one the scene lacks.
pub const MIN_SIMILARITY: f64 = 0.6;

/// How many listed names are offered at most.
const OFFERED: usize = 3;

/// How similar two names are, from 0 (nothing shared) to 1 (equal ignoring case, spaces
/// and underscores). A name contained in the other scores at least 0.75.
pub fn similarity(a: &str, b: &str) -> f64 {
    let norm = |s: &str| -> String {
        s.chars()
            .filter(|c| !matches!(c, ' ' | '_' | '-'))
            .flat_map(char::to_lowercase)
            .collect()
    };
    let (a, b) = (norm(a), norm(b));
    if a.is_empty() || b.is_empty() {
        return 0.0;
    }
    let mut s = strsim::normalized_damerau_levenshtein(&a, &b);
    let (short, long) = if a.len() <= b.len() {
        (&a, &b)
    } else {
        (&b, &a)
    };
    if short.chars().count() >= 3 && long.contains(short.as_str()) {
        s = s.max(0.75);
    }
    s
}

/// The listed names most like `name` (most alike first), each at least `min_similarity`
/// alike, at most three.
pub fn nearest<'a>(
    name: &str,
    listed: impl Iterator<Item = &'a str>,
    min_similarity: f64,
) -> Vec<String> {
    let mut scored: Vec<(&str, f64)> = listed
        .map(|o| (o, similarity(name, o)))
        .filter(|(_, s)| *s >= min_similarity)
        .collect();
    scored.sort_by(|x, y| y.1.total_cmp(&x.1));
    scored
        .into_iter()
        .take(OFFERED)
        .map(|(o, _)| o.to_string())
        .collect()
}

/// ` (did you mean "a" or "b"?)`, or nothing when no listed name is alike. A name with
/// quotes of its own (a condition over quoted objects) is set in single quotes, as typed.
pub fn did_you_mean(nearest: &[String]) -> String {
    let quoted: Vec<String> = nearest
        .iter()
        .map(|n| {
            if n.contains('"') {
                format!("'{n}'")
            } else {
                format!("{n:?}")
            }
        })
        .collect();
    match quoted.as_slice() {
        [] => String::new(),
        [one] => format!(" (did you mean {one}?)"),
        [rest @ .., last] => format!(" (did you mean {} or {last}?)", rest.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn similarity_is_sensible() {
        assert_eq!(similarity("coffee", "Coffee"), 1.0);
        assert!(similarity("Cofee", "Coffee") > 0.8);
        assert!(similarity("Table6", "WindowTable6") >= 0.75);
        assert!(similarity("Fries", "Chips") < 0.5);
        assert_eq!(similarity("", "x"), 0.0);
    }

    #[test]
    fn the_nearest_names_come_most_alike_first_and_only_when_alike_enough() {
        let listed = ["red cube", "blue cube", "green cube", "red cup", "table"];
        let near = nearest("purple cube", listed.into_iter(), 0.5);
        assert_eq!(
            near.first().map(String::as_str),
            Some("blue cube"),
            "{near:?}"
        );
        assert!(near.len() <= 3);
        assert!(nearest("purple cube", listed.into_iter(), 0.99).is_empty());
        assert_eq!(did_you_mean(&[]), "");
        assert_eq!(
            did_you_mean(&["\"red cube\" on \"table\"".into()]),
            " (did you mean '\"red cube\" on \"table\"'?)"
        );
        assert_eq!(
            did_you_mean(&["a".into(), "b".into(), "c".into()]),
            " (did you mean \"a\", \"b\" or \"c\"?)"
        );
    }
}
