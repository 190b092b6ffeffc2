//! Goals: propositional formulas over condition atoms, and their minimal DNF.
//!
//! A goal is written with `&` (and), `|` (or), `~` (not) and parentheses over atoms in
//! either syntax of [`crate::domain::condition`]:
//!
//! ```text
//! ~Closed_Curtain | Active_AC & ~Low_ACTemperature
//! ~"any object" on "blue cube" & "blue cube" on "green cube"
//! ```
//!
//! `~` binds tightest, then `&`, then `|`. The planner turns a goal into a disjunction of
//! conjunctions of literals with [`Formula::to_dnf`] and builds one branch per conjunction,
//! in the order the conjunctions' atoms first appear in the goal.
//!
//! Two goals can be compared by truth table ([`equivalent`]) or by the published scoring
//! rule, equality of minimal DNFs as sets of sets of literals ([`same_dnf`]).

mod dnf;
mod equiv;
mod formula;
mod parse;
mod qm;
pub mod rewrite;
mod truth;

pub use dnf::{Dnf, EXACT_ATOM_LIMIT, MAX_ALTERNATIVES, TooManyAlternatives};
pub use equiv::{EQUIV_ATOM_LIMIT, TooManyAtoms, equivalent, same_dnf};
pub use formula::Formula;

/// Why a goal could not be read.
///
/// `at` is a byte offset into the goal text; `column` is the 1-based character column of the
/// same place (goals are one line; a newline does not reset the column).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("column {column}: expected {expected}, found {found}")]
pub struct GoalError {
    pub at: usize,
    pub column: usize,
    pub expected: String,
    pub found: String,
}

impl GoalError {
    pub(crate) fn new(
        text: &str,
        at: usize,
        expected: impl Into<String>,
        found: impl Into<String>,
    ) -> Self {
        GoalError {
            at,
            column: column_of(text, at),
            expected: expected.into(),
            // What was found is echoed, so a long run of it is cut.
            found: crate::excerpt::shortened(&found.into(), 40),
        }
    }
}

/// The 1-based character column of byte offset `at` in `text`.
pub(crate) fn column_of(text: &str, at: usize) -> usize {
    text.get(..at).map_or(at, |s| s.chars().count()) + 1
}
