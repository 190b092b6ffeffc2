//! What a person writes for the pending proposal or the current failure, read over the
//! scenario's vocabulary by the front end before it reaches the engine: conditions that
//! must hold before the failed action (`~"any object" on "blue cube"`, `A & ~B`) or a value
//! for the parameter it lacks (`5 N`, `"shovel"`). The engine checks the result against
//! what it is working on (conditions for a failure that calls for them, a value within
//! what the robot can do).
//!
//! The text says which it is: conditions are tried first; a number is a value, and so is
//! a quoted category, or a word that is no condition in a domain that declares categorical
//! values (a tool's name).

use std::fmt;

use crate::domain::action::{ActionError, parse_value};
use crate::domain::{Condition, Value};
use crate::goal::GoalError;
use crate::scenario::{GoalTextError, Scenario};

/// A person's edit, read.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// Conditions that must hold before the failed action: one, or a conjunction.
    Conditions(Vec<Condition>),
    /// A value for the parameter the failed action lacks.
    Value(Value),
}

impl fmt::Display for Edit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Edit::Conditions(conditions) => {
                for (i, c) in conditions.iter().enumerate() {
                    if i > 0 {
                        f.write_str(" & ")?;
                    }
                    write!(f, "{c}")?;
                }
                Ok(())
            }
            Edit::Value(value) => write!(f, "{value}"),
        }
    }
}

/// Why an edit could not be read; each names the text as typed (trimmed) and what was
/// wrong where: the column of a syntax error, the atom the vocabulary does not know, the
/// byte of a value that is not one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EditError {
    #[error("'{text}': {error}; a condition of this scene reads like {example}")]
    Syntax {
        text: String,
        error: GoalError,
        /// A condition of the scenario in use, in its own words.
        example: String,
    },
    /// An atom the scene does not have, with where it stands and the atoms most like it.
    #[error("'{text}': {error}")]
    Vocabulary {
        text: String,
        error: Box<GoalTextError>,
    },
    #[error("'{text}': expected one condition or a conjunction ('A & ~B'), found {formula}")]
    NotAConjunction { text: String, formula: String },
    #[error("'{text}': {error}")]
    Value { text: String, error: ActionError },
}

/// Read `text` as conditions over `scenario`'s vocabulary, or else as a value.
pub fn parse_edit(scenario: &Scenario, text: &str) -> Result<Edit, EditError> {
    let text = text.trim();
    let not_conditions = match parse_conditions(scenario, text) {
        Ok(conditions) => return Ok(Edit::Conditions(conditions)),
        Err(e) => e,
    };
    match parse_value(text) {
        Ok(value @ Value::Number { .. }) => Ok(Edit::Value(value)),
        Ok(value) if text.starts_with('"') || declares_categories(scenario) => {
            Ok(Edit::Value(value))
        }
        // A number with a bad unit is a value gone wrong, not a condition.
        Err(error) if text.starts_with(|c: char| c.is_ascii_digit() || "+-.".contains(c)) => {
            Err(EditError::Value {
                text: text.to_string(),
                error,
            })
        }
        _ => Err(not_conditions),
    }
}

/// One condition or a conjunction, every atom in the vocabulary.
fn parse_conditions(scenario: &Scenario, text: &str) -> Result<Vec<Condition>, EditError> {
    let formula = scenario.parse_goal(text).map_err(|error| match error {
        GoalTextError::Syntax(error) => EditError::Syntax {
            text: text.to_string(),
            error,
            example: example(scenario),
        },
        error @ GoalTextError::Vocabulary { .. } => EditError::Vocabulary {
            text: text.to_string(),
            error: Box::new(error),
        },
    })?;
    match formula.to_dnf().0.as_slice() {
        [one] if !one.is_empty() => Ok(one.clone()),
        _ => Err(EditError::NotAConjunction {
            text: text.to_string(),
            formula: formula.to_string(),
        }),
    }
}

/// A condition of `scenario` for messages: the negation of its first atom relating two
/// objects (else of its first atom), in the scene's own words.
pub fn example(scenario: &Scenario) -> String {
    let atoms = scenario.domain.vocabulary.ground_atoms();
    atoms
        .iter()
        .find(|a| a.args.len() == 2)
        .or_else(|| atoms.first())
        .map_or_else(String::new, |a| Condition::neg(a.clone()).to_string())
}

/// How many conditions of a scene the edit line completes from, at most.
const MAX_COMPLETIONS: usize = 20_000;

/// Every condition of `scenario`'s vocabulary as written (`"red cube" on "blue cube"`,
/// `On_Coffee_Table1`), with the `"any object"` forms of relations: what the edit line
/// completes from.
pub fn vocabulary_words(scenario: &Scenario) -> Vec<String> {
    let mut words: Vec<String> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for atom in scenario.domain.vocabulary.ground_atoms() {
        if atom.is_quoted_form() && atom.args.len() == 2 {
            for slot in 0..2 {
                let mut args = atom.args.clone();
                args[slot] = crate::domain::ANY_OBJECT.to_string();
                let any = crate::domain::Atom::new(atom.predicate.clone(), args).to_string();
                if seen.insert(any.clone()) {
                    words.push(any);
                }
            }
        }
        let text = atom.to_string();
        if seen.insert(text.clone()) {
            words.push(text);
        }
        if words.len() >= MAX_COMPLETIONS {
            break;
        }
    }
    words
}

/// Whether a skill of the domain takes a value given by category (such as a tool).
fn declares_categories(scenario: &Scenario) -> bool {
    scenario
        .domain
        .skills
        .iter()
        .flat_map(|s| &s.values)
        .any(|v| v.unit.is_none())
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    fn scenario(file: &str) -> Scenario {
        Scenario::load(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("scenarios/cell")
                .join(file),
        )
        .unwrap()
    }

    #[test]
    fn conditions_are_read_over_the_vocabulary() {
        let s = scenario("red_on_blue.toml");
        let edit = parse_edit(&s, "  ~\"any object\" on \"blue cube\" ").unwrap();
        assert_eq!(edit.to_string(), "~\"any object\" on \"blue cube\"");
        let Edit::Conditions(conditions) = edit else {
            panic!("{edit:?}");
        };
        assert!(conditions[0].negated);
    }

    #[test]
    fn numbers_and_quoted_categories_are_values() {
        let s = scenario("params/egg.toml");
        assert_eq!(
            parse_edit(&s, "5 N").unwrap(),
            Edit::Value(Value::Number {
                value: 5.0,
                unit: "N".into()
            })
        );
        assert_eq!(
            parse_edit(&s, "\"shovel\"").unwrap(),
            Edit::Value(Value::Category("shovel".into()))
        );
        // A bare word is a tool where the domain has tools, not elsewhere.
        let sand = scenario("params/sand.toml");
        assert_eq!(
            parse_edit(&sand, "shovel").unwrap(),
            Edit::Value(Value::Category("shovel".into()))
        );
        assert!(matches!(
            parse_edit(&scenario("red_on_blue.toml"), "shovel"),
            Err(EditError::Syntax { .. } | EditError::Vocabulary { .. })
        ));
    }

    #[test]
    fn errors_say_what_was_wrong_and_where() {
        let s = scenario("red_on_blue.toml");
        let e = parse_edit(&s, "\"purple cube\" on \"blue cube\"").unwrap_err();
        assert!(matches!(e, EditError::Vocabulary { .. }), "{e:?}");
        assert!(e.to_string().contains("\"purple cube\""), "{e}");
        // A misspelt object is offered the scene's object most like it.
        let e = parse_edit(&s, "~\"any object\" on \"blue cub\"").unwrap_err();
        assert!(
            e.to_string()
                .contains("(did you mean '\"any object\" on \"blue cube\"'?)"),
            "{e}"
        );
        let e = parse_edit(&s, "~\"blue cube\" on \"blue cube\" | ").unwrap_err();
        assert!(matches!(e, EditError::Syntax { .. }), "{e:?}");
        assert!(e.to_string().contains("column"), "{e}");
        // The example is the scene's own, never another scene's.
        let e = parse_edit(&s, "on_ blue").unwrap_err();
        assert!(e.to_string().contains("reads like ~\""), "{e}");
        assert!(!e.to_string().contains("Coffee"), "{e}");
        let e = parse_edit(
            &s,
            "\"red cube\" on \"blue cube\" | \"red cube\" on \"green cube\"",
        )
        .unwrap_err();
        assert!(matches!(e, EditError::NotAConjunction { .. }), "{e:?}");
        let e = parse_edit(&s, "1e999 N").unwrap_err();
        assert!(matches!(e, EditError::Value { .. }), "{e:?}");
        assert!(e.to_string().starts_with("'1e999 N': at byte 0"), "{e}");
    }
}
