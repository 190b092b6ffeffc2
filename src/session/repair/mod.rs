//! Repairing a failure: the question asked of the model about a failed action
//! ([`question`], [`ask`]), the conditions screened in simulation before it is asked
//! ([`shortlist`], [`screen`]), what betr found for the proposal it offers ([`evidence`]),
//! the values of a parameter a failure is about ([`values`], [`value_bounds`]) and what a
//! person writes instead ([`edit`]). The engine starts a question and takes its answer.

pub mod ask;
pub mod edit;
pub mod evidence;
pub mod question;
pub mod screen;
pub mod shortlist;
pub mod value_bounds;
mod value_levels;
pub mod values;
