//! Sessions, headless: the [`Engine`] (a state machine that owns a task from instruction
//! to saved policy; commands in, events out), the resolve loop that drives it unattended,
//! the questions asked of a model, and policies that last. Front ends (CLI, TUI) drive
//! them and show the events they emit; nothing here prints or reads a terminal.

pub mod ask;
pub mod edit;
pub mod engine;
pub mod goal_checks;
pub mod interpret;
mod interpret_parts;
mod judge;
pub mod knowledge;
pub mod placement;
pub mod planned;
pub mod polarity;
pub mod policy;
pub mod resolve;
pub mod screen;
pub mod shortlist;
pub mod side_by_side;
pub mod types;
pub mod value_bounds;
mod value_levels;
pub mod values;

pub use crate::planner::RunLimits;
pub use ask::missing_value;
pub use edit::{Edit, EditError, parse_edit};
pub use engine::{Command, Engine, EngineHandle, Setup};
pub use goal_checks::check_goal;
pub use interpret::{Interpretation, interpret};
pub use knowledge::{KeptRule, Knowledge, KnowledgeError, Refusal};
pub use planned::{PlanSummary, Prediction};
pub use policy::{Policy, PolicyStore};
pub use resolve::{resolve, resolve_with_scenes};
pub use types::{BreakReason, Ending, Event, NoModel, Options, Proposal, Resolved, SessionError};
