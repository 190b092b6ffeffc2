//! The planner's vocabulary: conditions, actions, skills and scenario files.

pub mod action;
pub mod condition;

pub use action::{ActionCall, Value};
pub use condition::{ANY_OBJECT, Atom, Condition};
