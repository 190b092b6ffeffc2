//! Whether one arm at some joint values collides: with the scene's solids, the torso, the
//! other arms (held still where they are) or itself. Everything that does not move during
//! the arm's motion is placed once, in the world frame, when the check is made; a test is
//! then a ball-against-ball rejection followed by parry3d's exact test of the convex
//! shapes.

use std::cell::RefCell;

use nalgebra::{Isometry3, Point3};
use parry3d::query;
use parry3d::shape::SharedShape;

use crate::robot::{Chain, LinkShape, Robot, RobotShapes};

use super::MotionError;

/// A solid of the scene, in the world frame.
#[derive(Clone)]
pub struct Solid {
    pub name: String,
    pub pose: Isometry3<f32>,
    pub shape: SharedShape,
}

impl std::fmt::Debug for Solid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Solid")
            .field("name", &self.name)
            .field("pose", &self.pose)
            .finish_non_exhaustive()
    }
}

/// A shape that stays where it is while the arm moves.
#[derive(Clone)]
struct Still {
    /// What a person calls it: the scene solid's name, or the robot link's.
    name: String,
    pose: Isometry3<f32>,
    shape: SharedShape,
    center: Point3<f32>,
    radius: f32,
    /// Part of the torso or a link fixed beside it (the other arm's first link): the
    /// links this arm's first joint carries touch these by design.
    torso: bool,
    /// What it is, for [`ArmCheck::tested_pairs`].
    part: Part,
}

/// A part of what an arm's check tests: a link of the robot (an index into the
/// description's links), a scene solid (by name) or what the hand carries (an index into
/// [`ArmCheck::carrying`]'s parts).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Part {
    Link(usize),
    Solid(String),
    Carried(usize),
}

/// The collision test of one arm's configurations.
pub struct ArmCheck<'a> {
    chain: &'a Chain,
    /// The arm's shapes, per carried link (see [`RobotShapes::arms`]).
    shapes: &'a [Vec<LinkShape>],
    /// The robot's root in the world.
    base: Isometry3<f64>,
    still: Vec<Still>,
    /// Pairs of carried links (indices) that are tested against each other.
    self_pairs: Vec<(usize, usize)>,
    /// What the hand holds, in the flange's frame: it moves with the arm and is tested
    /// against everything that stays still.
    carried: Vec<Solid>,
    frames: RefCell<Vec<Isometry3<f64>>>,
}

impl<'a> ArmCheck<'a> {
    /// The check for arm `arm` of `robot` (root at `base` in the world), the other arms
    /// held at `others[i]` (the entry of `arm` itself is not used), among `solids`.
    pub fn new(
        robot: &'a Robot,
        shapes: &'a RobotShapes,
        base: Isometry3<f64>,
        arm: usize,
        others: &[Vec<f64>],
        solids: &[Solid],
    ) -> Result<ArmCheck<'a>, MotionError> {
        let chain = robot.arms.get(arm).ok_or(MotionError::NoArm(arm))?;
        let mut still: Vec<Still> = solids
            .iter()
            .map(|s| {
                let aabb = s.shape.compute_local_aabb();
                Still {
                    name: s.name.clone(),
                    pose: s.pose,
                    shape: s.shape.clone(),
                    center: s.pose * aabb.center(),
                    radius: aabb.half_extents().norm(),
                    torso: false,
                    part: Part::Solid(s.name.clone()),
                }
            })
            .collect();
        let base32 = base.cast::<f32>();
        for shape in &shapes.torso {
            still.push(placed(shape, base32, true));
        }
        for (other, other_chain) in robot.arms.iter().enumerate() {
            if other == arm {
                continue;
            }
            let q = others.get(other).ok_or(MotionError::NoArm(other))?;
            let mut frames = Vec::new();
            let poses = other_chain.link_poses(q, &mut frames);
            for ((pose, link_shapes), carried) in poses
                .iter()
                .zip(&shapes.arms[other])
                .zip(&other_chain.carried)
            {
                let at = (base * pose).cast::<f32>();
                // The other arm's first link sits on the torso beside this arm's.
                let on_torso = carried.joint == Some(0);
                for shape in link_shapes {
                    still.push(placed(shape, at, on_torso));
                }
            }
        }
        let joint_of = |i: usize| chain.carried[i].joint.unwrap_or(0);
        let mut self_pairs = Vec::new();
        for i in 0..chain.carried.len() {
            for k in i + 1..chain.carried.len() {
                // Links two joints apart or nearer touch through their joints.
                if joint_of(k).abs_diff(joint_of(i)) > 2 {
                    self_pairs.push((i, k));
                }
            }
        }
        Ok(ArmCheck {
            chain,
            shapes: &shapes.arms[arm],
            base,
            still,
            self_pairs,
            carried: Vec::new(),
            frames: RefCell::new(Vec::with_capacity(chain.dof())),
        })
    }

    /// The same check with `parts` (poses in the flange's frame) held in the hand.
    pub fn carrying(mut self, parts: Vec<Solid>) -> Self {
        self.carried = parts;
        self
    }

    pub fn chain(&self) -> &Chain {
        self.chain
    }

    /// What the arm at `q` hits, if anything: a name a person reads (a solid of the scene,
    /// a link of the robot, or two links of the arm).
    pub fn blocker(&self, q: &[f64]) -> Option<String> {
        let mut frames = self.frames.borrow_mut();
        let poses = self.chain.link_poses(q, &mut frames);
        let placed: Vec<Isometry3<f32>> = poses.iter().map(|p| (self.base * p).cast()).collect();
        for (i, (at, link_shapes)) in placed.iter().zip(self.shapes).enumerate() {
            let first = self.chain.carried[i].joint == Some(0);
            for shape in link_shapes {
                let pose = at * shape.local;
                let center = pose * shape.center;
                for s in &self.still {
                    if (s.torso && first) || (center - s.center).norm() > shape.radius + s.radius {
                        continue;
                    }
                    if intersects(&pose, &shape.shape, &s.pose, &s.shape) {
                        return Some(s.name.clone());
                    }
                }
            }
        }
        if !self.carried.is_empty() {
            let last = self.chain.dof().saturating_sub(1);
            let flange = (self.base * frames[last] * self.chain.flange).cast::<f32>();
            for part in &self.carried {
                let pose = flange * part.pose;
                let aabb = part.shape.compute_local_aabb();
                let (center, radius) = (pose * aabb.center(), aabb.half_extents().norm());
                for s in &self.still {
                    if (center - s.center).norm() > radius + s.radius {
                        continue;
                    }
                    if intersects(&pose, &part.shape, &s.pose, &s.shape) {
                        return Some(s.name.clone());
                    }
                }
            }
        }
        for &(i, k) in &self.self_pairs {
            for a in &self.shapes[i] {
                for b in &self.shapes[k] {
                    let (pa, pb) = (placed[i] * a.local, placed[k] * b.local);
                    if (pa * a.center - pb * b.center).norm() > a.radius + b.radius {
                        continue;
                    }
                    if intersects(&pa, &a.shape, &pb, &b.shape) {
                        return Some(format!("{} and {}", a.name, b.name));
                    }
                }
            }
        }
        None
    }

    pub fn is_free(&self, q: &[f64]) -> bool {
        self.chain.within_limits(q) && self.blocker(q).is_none()
    }

    /// Every pair of parts [`ArmCheck::blocker`] tests against each other, each once and
    /// in the same loops: the arm's links against what stays still (but its first link
    /// against the torso), what the hand carries against what stays still, and the arm's
    /// links more than two joints apart against each other. Another checker (the
    /// benchmark's anchor) tests these and nothing else, so both solve the same problem.
    pub fn tested_pairs(&self) -> Vec<(Part, Part)> {
        let mut pairs = std::collections::BTreeSet::new();
        for (i, link_shapes) in self.shapes.iter().enumerate() {
            let first = self.chain.carried[i].joint == Some(0);
            for shape in link_shapes {
                for s in self.still.iter().filter(|s| !(s.torso && first)) {
                    pairs.insert((Part::Link(shape.link), s.part.clone()));
                }
            }
        }
        for c in 0..self.carried.len() {
            for s in &self.still {
                pairs.insert((Part::Carried(c), s.part.clone()));
            }
        }
        for &(i, k) in &self.self_pairs {
            for a in &self.shapes[i] {
                for b in &self.shapes[k] {
                    pairs.insert((Part::Link(a.link), Part::Link(b.link)));
                }
            }
        }
        pairs.into_iter().collect()
    }
}

fn placed(shape: &LinkShape, at: Isometry3<f32>, torso: bool) -> Still {
    let pose = at * shape.local;
    Still {
        name: shape.name.clone(),
        pose,
        shape: shape.shape.clone(),
        center: pose * shape.center,
        radius: shape.radius,
        torso,
        part: Part::Link(shape.link),
    }
}

fn intersects(pa: &Isometry3<f32>, a: &SharedShape, pb: &Isometry3<f32>, b: &SharedShape) -> bool {
    // A pair parry cannot test is taken as touching: never a path through it.
    query::intersection_test(pa, a.as_ref(), pb, b.as_ref()).unwrap_or(true)
}
