//! Arm motions in joint space: the collision test of one arm's configurations against the
//! scene's solids, the torso, the other arm and itself (`check.rs`).

mod check;

pub use check::{ArmCheck, Solid};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    #[error("the robot has no arm {0}")]
    NoArm(usize),
}

#[cfg(test)]
mod tests;
