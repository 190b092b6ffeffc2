//! Checking atoms from a reply against the scenario's vocabulary. An unknown object is
//! replaced by the most similar listed object of the right type (and the replacement is
//! reported); an unknown predicate, a wrong arity or a wrong type is an error that names
//! the offending text.

use crate::domain::{ANY_OBJECT, Atom, Condition, Vocabulary, VocabularyError};
use crate::goal::Formula;

use super::{ReplyError, Substitution};

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

/// Validate an atom, replacing unknown objects; `min_similarity` bounds how different a
/// replacement may be.
pub fn atom(
    vocabulary: &Vocabulary,
    mut atom: Atom,
    min_similarity: f64,
    substitutions: &mut Vec<Substitution>,
) -> Result<Atom, ReplyError> {
    // Each round fixes one argument; an atom has few.
    for _ in 0..=atom.args.len() {
        match vocabulary.check_atom(&atom) {
            Ok(()) => return Ok(atom),
            Err(VocabularyError::UnknownObject { atom: text, object }) => {
                let Some(position) = atom.args.iter().position(|a| *a == object) else {
                    break;
                };
                let types = vocabulary
                    .predicate(&atom.predicate)
                    .and_then(|p| p.arg_types.get(position))
                    .cloned()
                    .unwrap_or_default();
                let best = vocabulary
                    .objects_fitting(&types)
                    .map(|o| (o, similarity(&object, o)))
                    .max_by(|x, y| x.1.total_cmp(&y.1));
                match best {
                    Some((name, score)) if score >= min_similarity => {
                        let name = name.to_string();
                        atom.args[position] = name.clone();
                        substitutions.push(Substitution {
                            written: object,
                            used: name,
                            similarity: score,
                            in_text: text,
                        });
                    }
                    best => {
                        return Err(ReplyError::UnknownObject {
                            text,
                            object,
                            closest: best.map(|(n, s)| (n.to_string(), s)),
                        });
                    }
                }
            }
            Err(e) => {
                return Err(ReplyError::Invalid {
                    text: atom.to_string(),
                    reason: e.to_string(),
                });
            }
        }
    }
    Err(ReplyError::Invalid {
        text: atom.to_string(),
        reason: "its objects could not be matched to the scene".into(),
    })
}

pub fn condition(
    vocabulary: &Vocabulary,
    c: Condition,
    min_similarity: f64,
    substitutions: &mut Vec<Substitution>,
) -> Result<Condition, ReplyError> {
    Ok(Condition {
        atom: atom(vocabulary, c.atom, min_similarity, substitutions)?,
        negated: c.negated,
    })
}

/// Validate every atom of a formula.
pub fn formula(
    vocabulary: &Vocabulary,
    f: Formula,
    min_similarity: f64,
    substitutions: &mut Vec<Substitution>,
) -> Result<Formula, ReplyError> {
    Ok(match f {
        Formula::Atom(a) => Formula::Atom(atom(vocabulary, a, min_similarity, substitutions)?),
        Formula::Not(inner) => Formula::Not(Box::new(formula(
            vocabulary,
            *inner,
            min_similarity,
            substitutions,
        )?)),
        Formula::And(items) => Formula::And(
            items
                .into_iter()
                .map(|i| formula(vocabulary, i, min_similarity, substitutions))
                .collect::<Result<_, _>>()?,
        ),
        Formula::Or(items) => Formula::Or(
            items
                .into_iter()
                .map(|i| formula(vocabulary, i, min_similarity, substitutions))
                .collect::<Result<_, _>>()?,
        ),
    })
}

/// The wildcard never needs replacing.
pub fn is_wildcard(name: &str) -> bool {
    name == ANY_OBJECT
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
        assert!(is_wildcard("any object"));
    }
}
