//! Behavior trees: an arena tree, reactive ticking against any leaf executor, a text
//! format that round-trips, and a renderer.
//!
//! Control nodes are reactive and memoryless (like BT.CPP's `ReactiveSequence` /
//! `ReactiveFallback` and py_trees' `Sequence(memory=False)`): every tick starts again at
//! the first child, so a condition that stops holding halts the action it guards.

pub mod action;
pub mod condition;
pub mod fallback;
pub mod render;
pub mod sequence;
pub mod status;
pub mod text;
pub mod tick;
pub mod tree;

#[cfg(test)]
mod test_util;

pub use action::ActionStep;
pub use render::{ASCII, Glyphs, UNICODE, render};
pub use status::{Forced, Outcome, Status};
pub use text::{ParseError, parse, to_text};

/// The deepest nesting a tree read from outside may have (the root at depth 0). Ticking,
/// verifying and drawing a tree recurse once per level, so a deeper one would overflow the
/// stack; trees people write and the planner grows are tens of levels deep.
pub const MAX_DEPTH: usize = 256;
pub use tick::{ForcedStatuses, Leaves, TickRecord, Ticker};
pub use tree::{NodeId, NodeKind, Purpose, Tree, TreeError, path_text};
