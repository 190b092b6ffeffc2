//! Arm motions in joint space: the collision test of one arm's configurations against the
//! scene's solids, the torso, the other arm and itself (`check.rs`), and collision-free
//! paths by RRT-Connect with shortcutting (`rrt.rs`).
//!
//! A motion that finds no path fails with "No collision free path found", naming what
//! blocked it where that is known: what the goal configuration hits, or the solid that
//! stopped the search most often.

mod check;
mod rrt;

pub use check::{ArmCheck, Part, Solid};
pub use rrt::{JointPath, PlanOptions, plan};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    #[error("No collision free path found for {arm}: {why}")]
    NoPath {
        arm: String,
        why: String,
        /// The solid or link that blocked the motion, when known.
        blocker: Option<String>,
    },
    #[error("the {what} configuration of {arm} is outside its joint limits")]
    OutsideLimits { what: &'static str, arm: String },
    #[error("the robot has no arm {0}")]
    NoArm(usize),
}

#[cfg(test)]
mod tests;
