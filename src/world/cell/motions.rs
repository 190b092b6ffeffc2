//! The skills' motions with real arms (the execution world): the gripper sweep's verdict
//! is what the planning world would predict, the arm's motion decides, and a failure the
//! sweep did not predict says that planning and execution disagree. Also the push along
//! the table (`slide`), which moves an item out from under or away from what is in the way.

use nalgebra::{Point3, UnitQuaternion, Vector3};
use parry3d::bounding_volume::BoundingVolume;

use super::geometry::{CONTACT_GAP, Part, Pose};
use super::skills::SkillFailure;
use super::{CellWorld, Effect, Held};

/// A motion the real arm makes for a skill: the tool straight from `above` to `at`,
/// pointing down turned by `turn`, with `exclude` left out of the obstacles (what is
/// grasped) and what the hand holds (turned with the hand).
struct Motion<'h> {
    above: Point3<f32>,
    at: Point3<f32>,
    turn: UnitQuaternion<f32>,
    exclude: Vec<usize>,
    carried: Option<&'h Held>,
}

/// How far outside a front opening the object is when a level hand starts its straight
/// way in.
const LEVEL_CLEARANCE: f32 = 0.03;
/// Room left between a slid object and what was over it (the wrist's width).
const SLIDE_MARGIN: f32 = 0.08;
impl CellWorld {
    /// Coming down onto `id` from above: the gripper sweep's verdict (after `reach`, the
    /// reach spheres'), and with real arms the arm's, which decides.
    pub(super) fn coming_down_onto(
        &self,
        id: usize,
        reach: Result<(), SkillFailure>,
    ) -> Result<(), SkillFailure> {
        let predicted = reach.and_then(|()| {
            if self.approach_is_clear(id) {
                Ok(())
            } else {
                Err(SkillFailure::NoPath)
            }
        });
        if self.arms.is_none() {
            return predicted;
        }
        let (end, _) = self.grip_pose(id);
        let at = Point3::from(end.translation.vector);
        let above = at + Vector3::z() * self.scene.robot.gripper.approach;
        self.arm_moves(
            &Motion {
                above,
                at,
                turn: UnitQuaternion::identity(),
                exclude: vec![id],
                carried: None,
            },
            predicted.is_ok(),
        )
    }

    /// Move a real arm for `motion`; on success the move is kept for the action's end.
    /// `predicted`: whether the planning world's abstraction found the way clear.
    fn arm_moves(&self, motion: &Motion<'_>, predicted: bool) -> Result<(), SkillFailure> {
        let Some(arms) = &self.arms else {
            return Ok(());
        };
        let carried: Vec<crate::motion::Solid> = motion
            .carried
            .map(|held| {
                self.scene.solids[held.id]
                    .body
                    .parts
                    .iter()
                    .map(|p| crate::motion::Solid {
                        name: self.name(held.id).to_string(),
                        pose: motion.turn * held.grip * p.local,
                        shape: p.shape.clone(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        let mut exclude = motion.exclude.clone();
        if let Some(h) = motion.carried {
            exclude.push(h.id);
        }
        let solids = self.arm_solids(&exclude);
        let base = nalgebra::Isometry3::translation(
            f64::from(self.state.base.x),
            f64::from(self.state.base.y),
            0.0,
        );
        let reach = super::arms::Reach {
            base,
            configs: &self.state.arms,
            solids: &solids,
            carried: &carried,
            above: super::arms::turned_from_above(&motion.above, &motion.turn),
            at: super::arms::turned_from_above(&motion.at, &motion.turn),
            only: motion.carried.and_then(|h| h.arm),
            lets_go: motion.carried.is_some(),
        };
        let (made, effort) = arms.reach(&reach);
        // A skill may try several spots: what it took is the sum over all of them.
        let effort = {
            let mut spent = self.spent.borrow_mut();
            spent.arm = effort.arm;
            spent.attempts += effort.attempts;
            spent.seconds += effort.seconds;
            *spent
        };
        let refused = |blocker: Option<String>| {
            self.last_motion
                .replace(Some(super::arms::LastMotion::Refused { effort, blocker }));
        };
        match made {
            Ok(mut m) => {
                m.effort = effort;
                self.planned.replace(Some(m));
                Ok(())
            }
            Err(super::arms::Refusal::OutOfReach(why)) => {
                refused(None);
                Err(SkillFailure::ArmOutOfReach(why))
            }
            Err(super::arms::Refusal::NoPath { message, blocker }) => {
                refused(blocker);
                Err(SkillFailure::ArmNoPath { message, predicted })
            }
        }
    }

    /// Every solid (and lid) but `exclude`, part by part, as the arms' obstacles.
    fn arm_solids(&self, exclude: &[usize]) -> Vec<crate::motion::Solid> {
        let mut out = Vec::new();
        for (i, s) in self.scene.solids.iter().enumerate() {
            let pose = self.state.poses[i];
            if let Some(lid) = &s.lid {
                let rel = if self.state.lid_open[i] {
                    lid.open
                } else {
                    lid.closed
                };
                for p in lid.body.parts.iter() {
                    out.push(crate::motion::Solid {
                        name: format!("{} lid", s.name),
                        pose: pose * rel * p.local,
                        shape: p.shape.clone(),
                    });
                }
            }
            if exclude.contains(&i) || self.is_held(i) {
                continue;
            }
            for p in s.body.parts.iter() {
                out.push(crate::motion::Solid {
                    name: s.name.clone(),
                    pose: pose * p.local,
                    shape: p.shape.clone(),
                });
            }
        }
        out
    }

    /// Letting the held object go at `pose`, come in along `direction` over `travel`: the
    /// gripper sweep's verdict, and with real arms the arm's, which decides.
    /// The arm lets go `drop` metres short of `pose` along the way in (into a container
    /// through its top, the object just inside the rim). With real arms and `level`
    /// (through a front opening, `pose` that far inside it), the hand comes in level, its
    /// tool pointing along the way in rather than down, with the object it holds turned
    /// with it, and sets it down just inside the opening: a hand pointing down would have
    /// its wrist inside the container, and one reaching to the back its elbow. Where the
    /// object comes to rest.
    pub(super) fn release(
        &self,
        held: &Held,
        pose: &Pose,
        direction: Vector3<f32>,
        travel: f32,
        drop: f32,
        level: Option<f32>,
    ) -> Result<Pose, SkillFailure> {
        let clear = self.release_path_clear(held, pose, direction, travel);
        if self.arms.is_none() {
            return if clear {
                Ok(*pose)
            } else {
                Err(SkillFailure::NoPath)
            };
        }
        let body = &self.scene.solids[held.id].body;
        let (turn, rest, travel) = match level {
            Some(inside) => {
                // The tool (down, -z, when it grasped) turned to point along the way in,
                // the object turned with it, resting on the same floor.
                let turn = UnitQuaternion::rotation_between(&-Vector3::z(), &-direction)
                    .unwrap_or_else(UnitQuaternion::identity);
                let flat = body.aabb(pose);
                let c = flat.center();
                let turned = body.resting(turn * pose.rotation, c.x, c.y, flat.mins.z);
                let b = body.aabb(&turned);
                let half = (b.maxs - b.mins).component_mul(&direction).abs().sum() / 2.0;
                let back = (inside - half - CONTACT_GAP).max(0.0);
                let rest = Pose::translation(direction.x * back, direction.y * back, 0.0) * turned;
                // In a straight line only from just outside the opening: the way there is
                // the arm's path.
                (turn, rest, 2.0 * half + CONTACT_GAP + LEVEL_CLEARANCE)
            }
            None => (UnitQuaternion::identity(), *pose, travel),
        };
        let grip = Pose::from_parts(Default::default(), turn) * held.grip;
        let end = Pose::translation(0.0, 0.0, CONTACT_GAP) * rest * grip.inverse();
        let at = Point3::from(end.translation.vector) + direction * drop.clamp(0.0, travel);
        self.arm_moves(
            &Motion {
                above: Point3::from(end.translation.vector) + direction * travel,
                at,
                turn,
                exclude: Vec::new(),
                carried: Some(held),
            },
            clear,
        )?;
        Ok(rest)
    }

    /// Push `x` along the table (towards the robot or sideways, the middle of the robot
    /// first, never through what is in the way) until nothing is over it or beside it, leaving `SLIDE_MARGIN` between it and what was over it; the
    /// spot must be free and within reach.
    pub(super) fn slide(&self, x: usize) -> Result<Effect, SkillFailure> {
        let solid = &self.scene.solids[x];
        if solid.fixed {
            return Err(SkillFailure::Fixed {
                object: solid.name.clone(),
                done: "slid",
            });
        }
        self.free_hand("slide", x)?;
        self.reachable(x)?;
        let covers: Vec<usize> = (0..self.scene.solids.len())
            .filter(|o| self.over(*o, x) || self.beside(*o, x))
            .collect();
        let b = self.aabb(x);
        let c = b.center();
        if covers.is_empty() {
            return Ok(Effect::Move {
                id: x,
                pose: self.state.poses[x],
            });
        }
        let mut around = self.aabb(covers[0]);
        for o in &covers[1..] {
            around.merge(&self.aabb(*o));
        }
        let (hx, hy) = ((b.maxs.x - b.mins.x) / 2.0, (b.maxs.y - b.mins.y) / 2.0);
        let across_x = b.mins.x < around.maxs.x && around.mins.x < b.maxs.x;
        let across_y = b.mins.y < around.maxs.y && around.mins.y < b.maxs.y;
        // A push never goes through what is in the way: only the ways that lead off it.
        let mut moves: Vec<(f32, f32)> = [
            (around.mins.x - hx - SLIDE_MARGIN - c.x, 0.0),
            (0.0, around.mins.y - hy - SLIDE_MARGIN - c.y),
            (0.0, around.maxs.y + hy + SLIDE_MARGIN - c.y),
        ]
        .into_iter()
        .filter(|&(dx, dy)| {
            if dx < 0.0 {
                !(across_y && b.mins.x >= around.maxs.x)
            } else if dy < 0.0 {
                !(across_x && b.mins.y >= around.maxs.y)
            } else if dy > 0.0 {
                !(across_x && b.maxs.y <= around.mins.y)
            } else {
                false
            }
        })
        .collect();
        // Towards the middle of the robot first (both arms reach there, neither under what
        // was over it), then the shortest.
        let middle = self.state.base.y;
        moves.sort_by(|a, b| {
            (c.y + a.1 - middle)
                .abs()
                .total_cmp(&(c.y + b.1 - middle).abs())
                .then((a.0.abs() + a.1.abs()).total_cmp(&(b.0.abs() + b.1.abs())))
        });
        let rotation = self.state.poses[x].rotation;
        let table_top = b.mins.z;
        let others = self.obstacles(&[x]);
        for (dx, dy) in moves {
            let pose = solid.body.resting(rotation, c.x + dx, c.y + dy, table_top);
            let point = Point3::new(c.x + dx, c.y + dy, b.maxs.z);
            if !self.scene.robot.reaches(self.state.base, &point) {
                continue;
            }
            let free = solid.body.parts.iter().all(|p| {
                let part = Part {
                    local: Pose::translation(0.0, 0.0, CONTACT_GAP) * pose * p.local,
                    shape: p.shape.clone(),
                };
                !super::geometry::overlaps_any(&part, &others, &self.counter)
            });
            if free {
                return Ok(Effect::Move { id: x, pose });
            }
        }
        Err(SkillFailure::NoPath)
    }
}
