//! Serial chains from the robot's root to each arm's tool flange, and their forward
//! kinematics.
//!
//! Written on nalgebra rather than with the `k` crate: `k` builds on an older nalgebra
//! than the cell (0.34), keeps its joint values inside the tree (so two arms planned at
//! once would share state), and a chain of seven joints is small. Fixed joints are folded
//! into the transform before the next moving joint when the chain is built, so forward
//! kinematics is one isometry product and one rotation per moving joint.

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::RobotError;
use super::urdf::{JointKind, Model};

/// A joint that moves, with everything fixed between it and the previous one folded in.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainJoint {
    pub name: String,
    /// This joint's frame (at value 0) in the frame of the previous moving joint's child
    /// link (the chain's root link for the first).
    pub before: Isometry3<f64>,
    pub axis: Unit<Vector3<f64>>,
    /// Rotation (true) or translation (false) along `axis`.
    pub rotates: bool,
    pub lower: f64,
    pub upper: f64,
}

/// A link carried by a chain: which moving joint it rides on (none: it is fixed to the
/// root) and where it sits in that joint's child frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Carried {
    pub link: usize,
    pub joint: Option<usize>,
    pub offset: Isometry3<f64>,
}

/// The moving joints from the root to one tool flange.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// The flange link's name (`yumi_link_7_r`).
    pub tip: String,
    pub joints: Vec<ChainJoint>,
    /// The flange in the last joint's child frame.
    pub flange: Isometry3<f64>,
    /// Every link the chain moves: those on the way and those hanging below the flange
    /// (a gripper, its fingers at their lower limits).
    pub carried: Vec<Carried>,
}

impl Chain {
    /// The chain from `model`'s root to the link `tip`.
    pub fn new(model: &Model, tip: &str) -> Result<Chain, RobotError> {
        let tip_index = model.link(tip).ok_or_else(|| RobotError::Urdf {
            file: model.file.clone(),
            message: format!("no link \"{tip}\" to end an arm at"),
        })?;
        let mut joints = Vec::new();
        let mut carried = Vec::new();
        let mut pending = Isometry3::identity();
        for j in model.path_to(tip_index) {
            match j.kind {
                JointKind::Fixed => pending *= j.origin,
                JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic => {
                    joints.push(ChainJoint {
                        name: j.name.clone(),
                        before: pending * j.origin,
                        axis: j.axis,
                        rotates: j.kind != JointKind::Prismatic,
                        lower: j.lower,
                        upper: j.upper,
                    });
                    pending = Isometry3::identity();
                }
            }
            if !joints.is_empty() {
                carried.push(Carried {
                    link: j.child,
                    joint: Some(joints.len() - 1),
                    offset: pending,
                });
            }
        }
        if joints.is_empty() {
            return Err(RobotError::Urdf {
                file: model.file.clone(),
                message: format!("no joint moves link \"{tip}\""),
            });
        }
        // The links below the flange ride on the last joint.
        let last = joints.len() - 1;
        let mut stack = vec![(tip_index, pending)];
        while let Some((link, at)) = stack.pop() {
            for j in model.child_joints(link) {
                let offset = at * j.transform_at(j.resting_value());
                carried.push(Carried {
                    link: j.child,
                    joint: Some(last),
                    offset,
                });
                stack.push((j.child, offset));
            }
        }
        Ok(Chain {
            tip: tip.to_string(),
            joints,
            flange: pending,
            carried,
        })
    }

    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Whether every value of `q` is within its joint's limits.
    pub fn within_limits(&self, q: &[f64]) -> bool {
        q.len() == self.joints.len()
            && self
                .joints
                .iter()
                .zip(q)
                .all(|(j, &v)| v >= j.lower && v <= j.upper)
    }

    /// Each moving joint's child frame in the root's frame, for joint values `q`.
    pub fn frames(&self, q: &[f64], out: &mut Vec<Isometry3<f64>>) {
        out.clear();
        let mut at = Isometry3::identity();
        for (j, &v) in self.joints.iter().zip(q) {
            at = at * j.before * joint_motion(&j.axis, j.rotates, v);
            out.push(at);
        }
    }

    /// The tool flange in the root's frame.
    pub fn fk(&self, q: &[f64]) -> Isometry3<f64> {
        let mut at = Isometry3::identity();
        for (j, &v) in self.joints.iter().zip(q) {
            at = at * j.before * joint_motion(&j.axis, j.rotates, v);
        }
        at * self.flange
    }

    /// Every carried link's pose in the root's frame, in [`Chain::carried`]'s order.
    pub fn link_poses(&self, q: &[f64], frames: &mut Vec<Isometry3<f64>>) -> Vec<Isometry3<f64>> {
        self.frames(q, frames);
        self.carried
            .iter()
            .map(|c| match c.joint {
                Some(j) => frames[j] * c.offset,
                None => c.offset,
            })
            .collect()
    }
}

/// The motion of a joint at `value`: a rotation about `axis` or a translation along it.
pub(super) fn joint_motion(axis: &Unit<Vector3<f64>>, rotates: bool, value: f64) -> Isometry3<f64> {
    if rotates {
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(axis, value),
        )
    } else {
        Isometry3::from_parts(
            Translation3::from(axis.into_inner() * value),
            UnitQuaternion::identity(),
        )
    }
}

/// The tool flanges of `model`: links that some revolute or continuous joint moves and
/// below which no revolute or continuous joint follows (the end of each arm), by name.
pub fn arm_tips(model: &Model) -> Vec<String> {
    let rotates = |k: JointKind| matches!(k, JointKind::Revolute | JointKind::Continuous);
    let mut tips = Vec::new();
    for (i, link) in model.links.iter().enumerate() {
        let moved = model.path_to(i).iter().any(|j| rotates(j.kind));
        if !moved || !model.parent_joint(i).is_some_and(|j| rotates(j.kind)) {
            continue;
        }
        let mut below = vec![i];
        let mut rotating_below = false;
        while let Some(l) = below.pop() {
            for j in model.child_joints(l) {
                rotating_below |= rotates(j.kind);
                below.push(j.child);
            }
        }
        if !rotating_below {
            tips.push(link.name.clone());
        }
    }
    tips
}
