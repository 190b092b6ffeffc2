//! What a person submits, read before any model is asked: a goal formula over the
//! scenario's vocabulary, or an instruction for a model to read. Text written as a
//! formula — with an operator (`&`, `|`, `~`, parentheses), a quoted object or a name
//! joined by underscores — is read strictly as a goal: an atom the scene does not have
//! refuses it, with where it stands and the atoms most like it, and it never goes to a
//! model. Empty text is refused too.

use crate::excerpt::excerpt;
use crate::goal::Formula;
use crate::scenario::{GoalTextError, Scenario};

/// What submitted text is.
#[derive(Debug, Clone, PartialEq)]
pub enum Submitted {
    /// A goal formula that fits the scene.
    Goal(Formula),
    /// Words for a model to read as a goal (trimmed).
    Instruction(String),
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SubmitError {
    #[error("nothing to submit: type an instruction or a goal")]
    Empty,
    #[error("{text} is written as a goal formula, and it does not fit the scene: {error}")]
    Goal {
        text: String,
        error: Box<GoalTextError>,
    },
}

impl SubmitError {
    /// What is wrong, without the text itself: for where the text is shown already (the
    /// line it was typed in).
    pub fn reason(&self) -> String {
        match self {
            SubmitError::Empty => self.to_string(),
            SubmitError::Goal { error, .. } => {
                format!("a goal formula that does not fit the scene: {error}")
            }
        }
    }
}

/// Read `text` against `scenario`: a goal, an instruction, or a refusal.
pub fn read(scenario: &Scenario, text: &str) -> Result<Submitted, SubmitError> {
    let text = text.trim();
    if text.is_empty() {
        return Err(SubmitError::Empty);
    }
    match scenario.parse_goal(text) {
        Ok(goal) => Ok(Submitted::Goal(goal)),
        Err(error @ GoalTextError::Vocabulary { .. }) if written_as_formula(text) => {
            Err(SubmitError::Goal {
                text: excerpt(text, Some(error.at())),
                error: Box::new(error),
            })
        }
        Err(_) => Ok(Submitted::Instruction(text.to_string())),
    }
}

/// Whether text that reads as a formula was written as one, rather than being a word or
/// two of plain language (`coffee`) that happens to read as an atom.
fn written_as_formula(text: &str) -> bool {
    text.contains(['&', '|', '~', '(', ')', '"', '_'])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn cafe() -> Scenario {
        Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/no_coffee.toml"))
            .unwrap()
    }

    #[test]
    fn a_formula_with_one_unknown_predicate_is_refused_where_it_stands() {
        let s = cafe();
        let text = "On_Coffee_Table1 & Active_AC & Clean_Floor";
        let e = read(&s, text).unwrap_err();
        let said = e.to_string();
        assert!(said.contains("column 32"), "{said}");
        assert!(said.contains("\"Clean\""), "{said}");
        assert!(said.contains("did you mean \"IsClean_Floor\""), "{said}");
        let e = read(&s, "On_Cofee_Table1").unwrap_err().to_string();
        assert!(e.contains("did you mean \"On_Coffee_Table1\""), "{e}");
    }

    #[test]
    fn goals_instructions_and_empty_text() {
        let s = cafe();
        assert!(matches!(
            read(&s, " On_Coffee_Table1 & Active_AC "),
            Ok(Submitted::Goal(_))
        ));
        assert_eq!(
            read(&s, " Bring a coffee to table 1 "),
            Ok(Submitted::Instruction("Bring a coffee to table 1".into()))
        );
        // One word that reads as an atom is plain language, for the model.
        assert_eq!(
            read(&s, "Coffee"),
            Ok(Submitted::Instruction("Coffee".into()))
        );
        assert_eq!(read(&s, " \n\t"), Err(SubmitError::Empty));
    }
}
