//! The parts of the screen. Each handles its own keys (`event`) and draws itself
//! (`draw`) from its state; they talk to the app through its event queue.

pub mod dictation;
pub mod help;
pub mod input;
pub mod llm_pane;
pub mod status_bar;
pub mod tree_pane;
pub mod world_pane;
