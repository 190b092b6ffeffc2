//! Sessions: the loops a person runs, headless. Front ends (CLI, TUI) drive them and show
//! the events they emit; nothing here prints or reads a terminal.

pub mod ask;
pub mod resolve;
pub mod types;

pub use ask::{interpret, missing_value};
pub use resolve::resolve;
pub use types::{Ending, Event, Options, Proposal, Resolved, SessionError};
