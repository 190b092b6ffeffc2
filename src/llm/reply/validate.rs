//! Checking atoms from a reply against the scenario's vocabulary. A name the scene does
//! not have is never replaced by one it has: an unknown object is an error naming it and
//! the nearest listed objects of the right type; an unknown predicate, a wrong arity or a
//! wrong type is an error that names the offending text.

use crate::domain::names::nearest;
use crate::domain::{ANY_OBJECT, Atom, Condition, Vocabulary, VocabularyError};
use crate::goal::Formula;

use super::ReplyError;

/// Validate an atom; an object the scene lacks is an error naming it and the listed
/// objects of its place at least `min_similarity` alike.
pub fn atom(vocabulary: &Vocabulary, atom: Atom, min_similarity: f64) -> Result<Atom, ReplyError> {
    match vocabulary.check_atom(&atom) {
        Ok(()) => Ok(atom),
        Err(VocabularyError::UnknownObject { atom: text, object }) => {
            let types = atom
                .args
                .iter()
                .position(|a| *a == object)
                .and_then(|position| {
                    vocabulary
                        .predicate(&atom.predicate)
                        .and_then(|p| p.arg_types.get(position))
                })
                .cloned()
                .unwrap_or_default();
            let nearest = nearest(&object, vocabulary.objects_fitting(&types), min_similarity);
            Err(ReplyError::UnknownObject {
                text,
                object,
                nearest,
            })
        }
        Err(e) => Err(ReplyError::Invalid {
            text: atom.to_string(),
            reason: e.to_string(),
        }),
    }
}

pub fn condition(
    vocabulary: &Vocabulary,
    c: Condition,
    min_similarity: f64,
) -> Result<Condition, ReplyError> {
    Ok(Condition {
        atom: atom(vocabulary, c.atom, min_similarity)?,
        negated: c.negated,
    })
}

/// Validate every atom of a formula.
pub fn formula(
    vocabulary: &Vocabulary,
    f: Formula,
    min_similarity: f64,
) -> Result<Formula, ReplyError> {
    Ok(match f {
        Formula::Atom(a) => Formula::Atom(atom(vocabulary, a, min_similarity)?),
        Formula::Not(inner) => Formula::Not(Box::new(formula(vocabulary, *inner, min_similarity)?)),
        Formula::And(items) => Formula::And(
            items
                .into_iter()
                .map(|i| formula(vocabulary, i, min_similarity))
                .collect::<Result<_, _>>()?,
        ),
        Formula::Or(items) => Formula::Or(
            items
                .into_iter()
                .map(|i| formula(vocabulary, i, min_similarity))
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
    fn the_wildcard_is_not_an_object_to_check() {
        assert!(is_wildcard("any object"));
        assert!(!is_wildcard("blue cube"));
    }
}
