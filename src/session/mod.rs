//! Sessions: the loops a person runs, headless. Front ends (CLI, TUI) drive them and show
//! the events they emit.

pub mod resolve;
