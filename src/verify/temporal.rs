//! User properties in a small temporal language: `always F`, `never F`, `eventually F`,
//! with `F` a goal formula (`&`, `|`, `~`, parentheses over condition atoms).
//!
//! Semantics, over the runs of the tree from the initial state (tick by tick, and with
//! the disturbances and action failures the check allows):
//!
//! * `always F` — F holds in every reachable state;
//! * `never F` — F holds in no reachable state;
//! * `eventually F` — on every run F holds at some state. Runs are adversarial: a state
//!   the tree stays in (success, a dead end), a cycle of states, or a disturbance or
//!   failure that may repeat forever, all avoiding F, violate it.
//!
//! The keywords are only a prefix, so the formula keeps the goal parser's error columns
//! (shifted by the prefix) for located errors in scenario files.

use std::fmt;

use crate::domain::Vocabulary;
use crate::goal::Formula;

/// Which temporal operator a property uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Temporal {
    /// F holds in every reachable state.
    Always,
    /// F holds in no reachable state.
    Never,
    /// F holds at some state of every run.
    Eventually,
}

/// A parsed user property.
#[derive(Debug, Clone, PartialEq)]
pub struct Property {
    pub temporal: Temporal,
    pub formula: Formula,
}

/// Why a property could not be read; `at` is a byte offset into the property text.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct PropertyError {
    pub at: usize,
    pub message: String,
}

impl Temporal {
    pub fn keyword(self) -> &'static str {
        match self {
            Temporal::Always => "always",
            Temporal::Never => "never",
            Temporal::Eventually => "eventually",
        }
    }
}

impl Property {
    /// Parse `always F` / `never F` / `eventually F`.
    pub fn parse(text: &str) -> Result<Property, PropertyError> {
        let trimmed = text.trim_start();
        let lead = text.len() - trimmed.len();
        let keyword_end = trimmed
            .find(|c: char| c.is_whitespace())
            .unwrap_or(trimmed.len());
        let temporal = match &trimmed[..keyword_end] {
            "always" => Temporal::Always,
            "never" => Temporal::Never,
            "eventually" => Temporal::Eventually,
            other => {
                return Err(PropertyError {
                    at: lead,
                    message: format!(
                        "expected `always`, `never` or `eventually` followed by a goal formula, found {other:?}"
                    ),
                });
            }
        };
        let body_at = lead + keyword_end;
        let formula = Formula::parse(&text[body_at..]).map_err(|e| PropertyError {
            at: body_at + e.at,
            message: format!("expected {}, found {}", e.expected, e.found),
        })?;
        Ok(Property { temporal, formula })
    }

    /// Parse and check every atom against the vocabulary.
    pub fn parse_checked(text: &str, vocabulary: &Vocabulary) -> Result<Property, PropertyError> {
        let property = Property::parse(text)?;
        for atom in property.formula.atoms() {
            vocabulary.check_atom(&atom).map_err(|e| PropertyError {
                at: 0,
                message: e.to_string(),
            })?;
        }
        Ok(property)
    }
}

impl fmt::Display for Property {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.temporal.keyword(), self.formula)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_three_operators() {
        let p = Property::parse("never Holding_Coffee & Holding_Milk").unwrap();
        assert_eq!(p.temporal, Temporal::Never);
        assert_eq!(p.to_string(), "never Holding_Coffee & Holding_Milk");
        let p = Property::parse("  always ~\"any object\" on \"blue cube\"").unwrap();
        assert_eq!(p.temporal, Temporal::Always);
        let p = Property::parse("eventually (A | B)").unwrap();
        assert_eq!(p.temporal, Temporal::Eventually);
        assert_eq!(p.formula.atoms().len(), 2);
    }

    #[test]
    fn errors_point_into_the_text() {
        let e = Property::parse("sometimes A").unwrap_err();
        assert_eq!(e.at, 0);
        assert!(e.message.contains("`always`"), "{e}");
        let e = Property::parse("always A &").unwrap_err();
        assert_eq!(e.at, 10, "{e:?}");
        let e = Property::parse("never").unwrap_err();
        assert!(e.message.contains("condition"), "{e}");
    }

    #[test]
    fn atoms_are_checked_against_the_vocabulary() {
        let v = Vocabulary::default();
        let e = Property::parse_checked("always Active_AC", &v).unwrap_err();
        assert!(e.message.contains("unknown predicate"), "{e}");
    }
}
