//! Helpers shared by the `bt` unit tests.

use super::NodeKind;
use crate::domain::{ActionCall, Condition};

pub fn cond(text: &str) -> NodeKind {
    NodeKind::Condition(Condition::parse(text).unwrap())
}

pub fn act(text: &str) -> NodeKind {
    NodeKind::Action(ActionCall::parse(text).unwrap())
}
