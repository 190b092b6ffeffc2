//! The planner's vocabulary: conditions, actions, skills and scenario files.

pub mod action;
pub(crate) mod as_text;
pub mod condition;
pub mod learned;
pub mod names;

pub use action::{ActionCall, Value};
pub use condition::{ANY_OBJECT, Atom, Condition};
pub mod skill;
pub mod template;
pub mod vocabulary;

pub use learned::{LearnError, LearnedRule, Misfit};
pub use skill::{AtomPattern, Domain, GroundSkill, Param, Skill, ValueParam};
pub use template::{TemplateError, TemplateFitError};
pub use vocabulary::{Object, Predicate, StateWords, Vocabulary, VocabularyError};
