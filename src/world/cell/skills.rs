//! The cell's skills, by name. Each one checks, on its first tick, everything the real
//! cell would refuse — an object the robot has never seen, a missing or wrong value, a
//! full hand, a point out of reach, a load over the payload, and for grasp, place, put-in
//! and flip a collision along the approach path — and returns the effect it will have
//! when it completes. The texts are those the paper's skills report.
//!
//! Approach paths are straight: grasping and flipping come down from `approach` above the
//! object to where the fingers close; placing comes down onto the support's top face;
//! putting into a container comes in along its opening (down through a top opening,
//! horizontally through a front one). The gripper's solid, and the held object with it,
//! is swept along that line against every other solid.

use nalgebra::{Point3, UnitQuaternion, Vector3};

use super::geometry::{CONTACT_GAP, Footprints, Opening, Part, Pose, path_collides};
use super::values::judge;
use super::{CellWorld, Effect, Held};
use crate::domain::{ActionCall, Value};

/// Why the cell refuses an action; the texts are what the skill reports (and what the
/// model reads when it is asked about the failure).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SkillFailure {
    #[error("No collision free path found")]
    NoPath,
    /// The real arm found no path: the motion's own message, and whether the planning
    /// world's gripper sweep had found the way clear.
    #[error("{message}{}", if *predicted { DISAGREEMENT_NOTE } else { "" })]
    ArmNoPath { message: String, predicted: bool },
    /// No real arm reaches the pose; the inverse kinematics' message.
    #[error("Position out of reach: {0}")]
    ArmOutOfReach(String),
    #[error("Position out of reach")]
    OutOfReach,
    #[error("Torque limit exceeded")]
    Torque,
    #[error("Object {0:?} is not in the dictionary")]
    UnknownObject(String),
    #[error("The {name} {value:?} is not in the cell")]
    UnknownCategory { name: String, value: String },
    /// A value the scenario judges wrong, in the scenario's own words.
    #[error("{0}")]
    Judged(String),
    #[error("{0:?} has no lock")]
    NoLock(String),
    #[error("The cell cannot perform {skill} on {objects} object(s)")]
    Unsupported { skill: String, objects: usize },
    #[error("The gripper holds {held:?}; it needs a free hand to {what} {object:?}")]
    HandFull {
        held: String,
        what: &'static str,
        object: String,
    },
    #[error("{object:?} is fixed in place and cannot be {done}")]
    Fixed { object: String, done: &'static str },
    #[error("Payload limit exceeded: {object:?} weighs {mass} kg, an arm carries {payload} kg")]
    Payload {
        object: String,
        mass: f32,
        payload: f32,
    },
    #[error("{0:?} has no lid or door to open")]
    NoLid(String),
    #[error("The gripper does not hold {0:?}")]
    NotHeld(String),
    #[error("{0:?} cannot be placed on itself")]
    OnItself(String),
    #[error("{0:?} has no opening to put things in")]
    NoOpening(String),
    #[error("{0:?} cannot be put in itself")]
    InItself(String),
}
/// Said after an arm's message when the planning world found the way clear.
pub const DISAGREEMENT_NOTE: &str =
    " (the planning world predicted success: planning and execution disagree)";

/// How many free spots on a large support the real arm tries before giving up.
pub(super) const ARM_SPOTS: usize = 12;
/// How many free spots on a large support are tried before giving up.
const MAX_SPOTS: usize = 24;
/// Clearance beyond which a spot is as good as any other.
const ENOUGH_CLEARANCE: f32 = 0.1;

impl CellWorld {
    /// Check an action on its first tick; on success, what it will do when it completes.
    pub(super) fn start(&self, action: &ActionCall) -> Result<Effect, SkillFailure> {
        let mut ids = Vec::new();
        for a in &action.args {
            match self.id(a) {
                Some(i) if self.state.known[i] || action.skill == "look_for" => ids.push(i),
                _ => return Err(SkillFailure::UnknownObject(a.clone())),
            }
        }
        if let Some(skill) = self.domain.skill_for(action) {
            if let Some(error) = judge(action, &skill.values, &self.scene.judges) {
                return Err(SkillFailure::Judged(error));
            }
            for (name, value) in &action.values {
                if let Value::Category(c) = value
                    && skill
                        .values
                        .iter()
                        .any(|v| v.name == *name && v.unit.is_none())
                    && self.id(c).is_none()
                {
                    return Err(SkillFailure::UnknownCategory {
                        name: name.clone(),
                        value: c.clone(),
                    });
                }
            }
        }
        match (action.skill.as_str(), ids.as_slice()) {
            ("grasp", [x]) => self.grasp(*x),
            ("place", [x, s]) => self.place_on(*x, *s),
            ("put_in", [x, c]) => self.put_in(*x, *c),
            ("flip", [x]) => self.flip(*x),
            ("open", [x]) => self.open_part(*x),
            ("unlock", [x]) => {
                self.free_hand("unlock", *x)?;
                self.reachable(*x)?;
                if !self.scene.solids[*x].lockable {
                    return Err(SkillFailure::NoLock(self.name(*x).to_string()));
                }
                Ok(Effect::Unlock(*x))
            }
            ("look_for", [x]) => Ok(Effect::Know(*x)),
            ("move_base", [x]) => self
                .scene
                .robot
                .base_to_reach(self.state.base, &self.reach_point(*x))
                .map(Effect::Base)
                .ok_or(SkillFailure::OutOfReach),
            ("scoop", [x, c]) => {
                self.free_hand("scoop", *x)?;
                self.reachable(*x)?;
                self.reachable(*c)?;
                let pose = self.cavity_rest(*x, *c)?.0;
                Ok(Effect::Move { id: *x, pose })
            }
            ("slide", [x]) => self.slide(*x),
            ("wipe", [x]) => {
                self.free_hand("wipe", *x)?;
                self.reachable(*x)?;
                Ok(Effect::Clean(*x))
            }
            (name, _) => Err(SkillFailure::Unsupported {
                skill: name.to_string(),
                objects: ids.len(),
            }),
        }
    }

    pub(super) fn reachable(&self, id: usize) -> Result<(), SkillFailure> {
        if self
            .scene
            .robot
            .reaches(self.state.base, &self.reach_point(id))
        {
            Ok(())
        } else {
            Err(SkillFailure::OutOfReach)
        }
    }

    pub(super) fn free_hand(&self, what: &'static str, id: usize) -> Result<(), SkillFailure> {
        match &self.state.held {
            Some(h) => Err(SkillFailure::HandFull {
                held: self.name(h.id).to_string(),
                what,
                object: self.name(id).to_string(),
            }),
            None => Ok(()),
        }
    }

    /// The tool pose that closes the fingers on `id` from above, and the half width the
    /// gripper opens to.
    pub(super) fn grip_pose(&self, id: usize) -> (Pose, f32) {
        let b = self.aabb(id);
        let c = b.center();
        let height = b.maxs.z - b.mins.z;
        let depth = self.scene.robot.gripper.grip_depth.min(height / 2.0);
        let half_width = (b.maxs.y - b.mins.y) / 2.0;
        (Pose::translation(c.x, c.y, b.maxs.z - depth), half_width)
    }

    /// Come down onto `id` with the gripper open around it: is the way clear?
    pub(super) fn approach_is_clear(&self, id: usize) -> bool {
        let (end, half_width) = self.grip_pose(id);
        let start = Pose::translation(0.0, 0.0, self.scene.robot.gripper.approach) * end;
        let parts = self.scene.robot.gripper_parts(half_width);
        let collided = path_collides(&parts, &start, &end, &self.obstacles(&[id]), &self.counter);
        self.record_approach(parts, start, end, vec![id], collided);
        !collided
    }

    fn grasp(&self, x: usize) -> Result<Effect, SkillFailure> {
        let solid = &self.scene.solids[x];
        if solid.fixed {
            return Err(SkillFailure::Fixed {
                object: solid.name.clone(),
                done: "grasped",
            });
        }
        self.free_hand("grasp", x)?;
        let reach = self.reachable(x);
        if self.arms.is_none() {
            reach.clone()?;
        }
        if solid.mass > self.scene.robot.payload {
            return Err(SkillFailure::Payload {
                object: solid.name.clone(),
                mass: solid.mass,
                payload: self.scene.robot.payload,
            });
        }
        self.coming_down_onto(x, reach)?;
        let (tool, half_width) = self.grip_pose(x);
        Ok(Effect::Grasp(Held {
            id: x,
            grip: tool.inverse() * self.state.poses[x],
            half_width,
            from: self.aabb(x).center(),
            arm: self.planned.borrow().as_ref().map(|m| m.arm),
        }))
    }

    fn flip(&self, x: usize) -> Result<Effect, SkillFailure> {
        if self.scene.solids[x].fixed {
            return Err(SkillFailure::Fixed {
                object: self.name(x).to_string(),
                done: "flipped",
            });
        }
        self.free_hand("flip", x)?;
        let reach = self.reachable(x);
        if self.arms.is_none() {
            reach.clone()?;
        }
        self.coming_down_onto(x, reach)?;
        let pose = self.state.poses[x];
        let b = self.aabb(x);
        let c = b.center();
        let turned = super::geometry::flipped(pose.rotation);
        let pose = self.scene.solids[x]
            .body
            .resting(turned, c.x, c.y, b.mins.z);
        Ok(Effect::Move { id: x, pose })
    }

    fn open_part(&self, x: usize) -> Result<Effect, SkillFailure> {
        let s = &self.scene.solids[x];
        let Some(lid) = &s.lid else {
            return Err(SkillFailure::NoLid(s.name.clone()));
        };
        self.free_hand("open", x)?;
        let handle = lid.body.aabb(&(self.state.poses[x] * lid.closed)).center();
        if !self.scene.robot.reaches(self.state.base, &handle) {
            return Err(SkillFailure::OutOfReach);
        }
        if self.state.locked[x] {
            return Err(SkillFailure::Torque);
        }
        Ok(Effect::Open(x))
    }

    /// The held object, which must be `x`.
    fn holding(&self, x: usize) -> Result<&Held, SkillFailure> {
        match &self.state.held {
            Some(h) if h.id == x => Ok(h),
            _ => Err(SkillFailure::NotHeld(self.name(x).to_string())),
        }
    }

    /// The gripper and the held object, in the tool's frame.
    fn carried(&self, held: &Held) -> Vec<Part> {
        let mut parts = self.scene.robot.gripper_parts(held.half_width);
        parts.extend(self.scene.solids[held.id].body.parts.iter().map(|p| Part {
            local: held.grip * p.local,
            shape: p.shape.clone(),
        }));
        parts
    }

    /// Bring the held object to rest at `pose`, coming in along `direction` (pointing from
    /// the target back out towards where the motion starts) over `travel` metres.
    pub(super) fn release_path_clear(
        &self,
        held: &Held,
        pose: &Pose,
        direction: Vector3<f32>,
        travel: f32,
    ) -> bool {
        let end = Pose::translation(0.0, 0.0, CONTACT_GAP) * pose * held.grip.inverse();
        let start = Pose::from_parts((direction * travel).into(), UnitQuaternion::identity()) * end;
        let parts = self.carried(held);
        let collided = path_collides(
            &parts,
            &start,
            &end,
            &self.obstacles(&[held.id]),
            &self.counter,
        );
        self.record_approach(parts, start, end, vec![held.id], collided);
        !collided
    }

    fn place_on(&self, x: usize, s: usize) -> Result<Effect, SkillFailure> {
        let held = self.holding(x)?.clone();
        if x == s {
            return Err(SkillFailure::OnItself(self.name(x).to_string()));
        }
        let body = &self.scene.solids[x].body;
        let rotation = (self.state.poses[x]).rotation;
        let top = self.aabb(s);
        let foot = body.aabb(&Pose::from_parts(Default::default(), rotation));
        let (hx, hy) = (
            (foot.maxs.x - foot.mins.x) / 2.0,
            (foot.maxs.y - foot.mins.y) / 2.0,
        );
        let spots = self.spots(x, s, hx, hy, &held);
        if spots.is_empty() {
            return Err(SkillFailure::OutOfReach);
        }
        let approach = self.scene.robot.gripper.approach;
        let tries = if self.arms.is_some() {
            ARM_SPOTS
        } else {
            MAX_SPOTS
        };
        let mut first_refusal = None;
        for (px, py) in spots.into_iter().take(tries) {
            let pose = body.resting(rotation, px, py, top.maxs.z);
            match self.release(&held, &pose, Vector3::z(), approach, 0.0, None) {
                Ok(pose) => return Ok(Effect::Release { id: x, pose }),
                Err(e) => {
                    first_refusal.get_or_insert(e);
                }
            }
        }
        Err(first_refusal.unwrap_or(SkillFailure::NoPath))
    }

    /// Reachable spots on the top of `s` for a footprint of half size `hx` × `hy`, best
    /// first: the most clearance from other solids (up to `ENOUGH_CLEARANCE`), then the
    /// nearest to where the object was picked up. A small top has one spot, its centre.
    fn spots(&self, x: usize, s: usize, hx: f32, hy: f32, held: &Held) -> Vec<(f32, f32)> {
        let top = self.aabb(s);
        let c = top.center();
        let step = 2.0 * hx.max(hy) + 0.01;
        let nx = (((top.maxs.x - top.mins.x) / 2.0 - hx) / step)
            .floor()
            .max(0.0) as i32;
        let ny = (((top.maxs.y - top.mins.y) / 2.0 - hy) / step)
            .floor()
            .max(0.0) as i32;
        let others = Footprints::new(
            (0..self.scene.solids.len())
                .filter(|o| *o != x && *o != s && !self.is_held(*o))
                .map(|o| self.aabb(o))
                .filter(|b| b.maxs.z > top.maxs.z + CONTACT_GAP)
                .collect(),
            ENOUGH_CLEARANCE,
        );
        let mut scored = Vec::new();
        for i in -nx..=nx {
            for j in -ny..=ny {
                let (px, py) = (c.x + i as f32 * step, c.y + j as f32 * step);
                let point = Point3::new(px, py, top.maxs.z + 2.0 * hx.max(hy));
                if !self.scene.robot.reaches(self.state.base, &point) {
                    continue;
                }
                let gap = others.gap((px, py), (hx, hy), ENOUGH_CLEARANCE);
                let from = (px - held.from.x).hypot(py - held.from.y);
                scored.push((-gap, from, px, py));
            }
        }
        scored.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        scored.into_iter().map(|(_, _, x, y)| (x, y)).collect()
    }

    /// Where `x` rests on the floor of `c`'s cavity, the direction and length of the way
    /// in, and how far that rest is from the opening.
    fn cavity_rest(
        &self,
        x: usize,
        c: usize,
    ) -> Result<(Pose, Vector3<f32>, f32, f32), SkillFailure> {
        let Some((cavity, half, opening)) =
            self.scene.solids[c].body.cavity_at(&self.state.poses[c])
        else {
            return Err(SkillFailure::NoOpening(self.name(c).to_string()));
        };
        // The lowest point of the cavity in the world, whichever way the container is turned.
        let r = cavity.rotation.to_rotation_matrix();
        let m = r.matrix();
        let depth = m[(2, 0)].abs() * half.x + m[(2, 1)].abs() * half.y + m[(2, 2)].abs() * half.z;
        let centre = cavity.translation.vector;
        let floor = Point3::new(centre.x, centre.y, centre.z - depth);
        let pose = self.scene.solids[x].body.resting(
            self.state.poses[x].rotation,
            floor.x,
            floor.y,
            floor.z,
        );
        let approach = self.scene.robot.gripper.approach;
        Ok(match opening {
            // Into a top opening the arm comes straight down, whichever way the container
            // is turned: an upside-down cup's bottom is then in the way.
            Opening::Top => (pose, Vector3::z(), 2.0 * half.z + approach, half.z),
            Opening::Front => {
                let out = cavity.rotation * -Vector3::x();
                let flat = Vector3::new(out.x, out.y, 0.0)
                    .try_normalize(1e-6)
                    .unwrap_or(-Vector3::x());
                (pose, flat, 2.0 * half.x + approach, half.x)
            }
        })
    }

    fn put_in(&self, x: usize, c: usize) -> Result<Effect, SkillFailure> {
        let held = self.holding(x)?.clone();
        if x == c {
            return Err(SkillFailure::InItself(self.name(x).to_string()));
        }
        self.reachable(c)?;
        let (pose, direction, travel, inside) = self.cavity_rest(x, c)?;
        // Through a top opening that is open (nothing over it, not turned down) the hand
        // lets go with the object's bottom at the rim; otherwise it must go all the way in.
        let drop = if direction == Vector3::z() && self.open(c) {
            let bottom = self.scene.solids[x].body.aabb(&pose).mins.z;
            self.aabb(c).maxs.z - bottom
        } else {
            0.0
        };
        // Through a front opening the hand comes in level.
        let level = (direction.z.abs() < 0.5).then_some(inside);
        let pose = self.release(&held, &pose, direction, travel, drop, level)?;
        Ok(Effect::Release { id: x, pose })
    }
}
