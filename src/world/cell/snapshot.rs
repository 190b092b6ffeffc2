//! A read-only picture of the cell for display: every solid's convex parts at their world
//! poses with a colour and a label, the robot (base, arms as link segments, gripper), the
//! last approach path a skill swept with the segments where it collides, and the reach
//! spheres with the objects outside them; with real arms also the robot's description,
//! its joint values, the way the last motion went and what it cost or what blocked it.
//! Plain data: the 3D view draws it, nothing decides anything from it.

use std::sync::Arc;

use nalgebra::{Point3, Translation3, Vector3};
use parry3d::shape::SharedShape;

use super::CellWorld;
use super::arms::LastMotion;
use super::geometry::{Counter, Part, Pose, path_collides};
use crate::robot::Model;
use crate::world::World;

/// Segments an approach path is cut into to show where it collides.
pub const PATH_SEGMENTS: usize = 10;

/// What a skill swept last: the moving parts (tool frame), the straight motion, the
/// solids it ignored (the target, the held object), and whether it collided.
#[derive(Clone)]
pub struct SweptPath {
    pub parts: Vec<Part>,
    pub start: Pose,
    pub end: Pose,
    pub exclude: Vec<usize>,
    pub collided: bool,
}

/// One convex piece, in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub enum PartShape {
    /// A box with these half extents about the pose.
    Box {
        half: [f32; 3],
    },
    /// A cylinder standing along the pose's local y axis (parry's convention).
    Cylinder {
        radius: f32,
        half_height: f32,
    },
    Ball {
        radius: f32,
    },
    /// A capsule between two world points.
    Capsule {
        a: [f32; 3],
        b: [f32; 3],
        radius: f32,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct PartView {
    pub pose: Pose,
    pub shape: PartShape,
}

#[derive(Debug, Clone, PartialEq)]
pub struct SolidView {
    pub name: String,
    /// RGB, from a colour word in the name ("red cube"), else a neutral tone.
    pub colour: [u8; 3],
    pub fixed: bool,
    pub held: bool,
    pub parts: Vec<PartView>,
}

/// One arm as link segments: shoulder, elbow, hand.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmView {
    pub shoulder: [f32; 3],
    pub elbow: [f32; 3],
    pub hand: [f32; 3],
}

#[derive(Debug, Clone, PartialEq)]
pub struct RobotView {
    /// The torso as a box: centre and half extents.
    pub torso_center: [f32; 3],
    pub torso_half: [f32; 3],
    pub arms: Vec<ArmView>,
    /// The gripper's parts at the tool pose of the active arm.
    pub gripper: Vec<PartView>,
    /// Reach spheres: shoulder centres (world) and the radius.
    pub reach: f32,
}

/// The last approach path: tool positions along it and, per segment, whether it collides.
#[derive(Debug, Clone, PartialEq)]
pub struct ApproachView {
    pub points: Vec<[f32; 3]>,
    pub collided: Vec<bool>,
}

/// The robot's real arms, drawn from its description.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmsView {
    /// The description: links with their meshes, joints with their frames.
    pub model: Arc<Model>,
    /// The robot's root link in the world.
    pub base: Pose,
    /// Every arm's moving joints, by name, with their values now.
    pub joints: Vec<Vec<(String, f64)>>,
    /// The last motion made, to draw the arm moving along it.
    pub path: Option<ArmPathView>,
}

/// The way an arm went in its last motion.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmPathView {
    /// Index into [`ArmsView::joints`].
    pub arm: usize,
    /// Joint values from where the arm was to where it ended, close enough together to
    /// be drawn as a motion.
    pub joints: Vec<Vec<f64>>,
    /// The tool centre point (world) at each of them.
    pub tool: Vec<[f32; 3]>,
    /// Where on the way the fingers close or open.
    pub acts_at: usize,
}

/// The last motion asked of the arms: which arm, what finding it took, and its length or
/// what blocked it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotionView {
    pub arm: String,
    /// Joint-space length (radians) of the path; none when the arm found no path.
    pub length: Option<f64>,
    pub seconds: f64,
    /// Arm, grip and start combinations tried.
    pub attempts: usize,
    /// The solid (or link) the refused motion collided with, when known.
    pub blocker: Option<String>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct SceneSnapshot {
    pub solids: Vec<SolidView>,
    pub robot: RobotView,
    pub approach: Option<ApproachView>,
    /// Movable objects the robot cannot reach from where it stands.
    pub out_of_reach: Vec<String>,
    /// With real arms: the robot as its description draws it.
    pub arms: Option<ArmsView>,
    /// With real arms: the last motion asked of them.
    pub motion: Option<MotionView>,
}

impl CellWorld {
    /// The world as a cell, when it is one.
    pub fn of(world: &dyn World) -> Option<&CellWorld> {
        world.as_any()?.downcast_ref::<CellWorld>()
    }

    /// The scene of a world that is a cell (`None` for other worlds).
    pub fn scene_of(world: &dyn World) -> Option<SceneSnapshot> {
        CellWorld::of(world).map(CellWorld::scene)
    }

    /// The last motion asked of a cell's real arms (`None` for other worlds, worlds
    /// without real arms, and before the first motion).
    pub fn motion_of(world: &dyn World) -> Option<MotionView> {
        CellWorld::of(world).and_then(CellWorld::motion_view)
    }

    fn motion_view(&self) -> Option<MotionView> {
        let arms = self.arms.as_ref()?;
        Some(match self.last_motion.borrow().as_ref()? {
            LastMotion::Made(m) => MotionView {
                arm: arms.arm_name(m.arm).to_string(),
                length: Some(m.length),
                seconds: m.effort.seconds,
                attempts: m.effort.attempts,
                blocker: None,
            },
            LastMotion::Refused { effort, blocker } => MotionView {
                arm: arms.arm_name(effort.arm).to_string(),
                length: None,
                seconds: effort.seconds,
                attempts: effort.attempts,
                blocker: blocker.clone(),
            },
        })
    }

    /// Where a real arm holds solid `i` now: in the hand, at the tool of the arm's joint
    /// values (the solid's own pose stays where it was grasped until it is let go).
    fn held_by_arm(&self, i: usize) -> Option<Pose> {
        let held = self.state.held.as_ref().filter(|h| h.id == i)?;
        let arms = self.arms.as_ref()?;
        let arm = held.arm?;
        let (chain, q) = (arms.robot.arms.get(arm)?, self.state.arms.get(arm)?);
        let base = nalgebra::Isometry3::translation(
            f64::from(self.state.base.x),
            f64::from(self.state.base.y),
            0.0,
        );
        let tool = (base * chain.fk(q) * arms.tool)
            .translation
            .vector
            .cast::<f32>();
        let grasped_tool = self.state.poses[i] * held.grip.inverse();
        Some(Pose::from_parts(Translation3::from(tool), grasped_tool.rotation) * held.grip)
    }

    fn arms_view(&self) -> Option<ArmsView> {
        let arms = self.arms.as_ref()?;
        let joints = arms
            .robot
            .arms
            .iter()
            .zip(&self.state.arms)
            .map(|(chain, q)| {
                chain
                    .joints
                    .iter()
                    .zip(q)
                    .map(|(j, v)| (j.name.clone(), *v))
                    .collect()
            })
            .collect();
        let path = match self.last_motion.borrow().as_ref() {
            Some(LastMotion::Made(m)) => Some(ArmPathView {
                arm: m.arm,
                joints: m.path.clone(),
                tool: m.tool.clone(),
                acts_at: m.acts_at,
            }),
            _ => None,
        };
        Some(ArmsView {
            model: arms.model.clone(),
            base: Pose::translation(self.state.base.x, self.state.base.y, 0.0),
            joints,
            path,
        })
    }

    pub(super) fn record_approach(
        &self,
        parts: Vec<Part>,
        start: Pose,
        end: Pose,
        exclude: Vec<usize>,
        collided: bool,
    ) {
        *self.approach.borrow_mut() = Some(SweptPath {
            parts,
            start,
            end,
            exclude,
            collided,
        });
    }

    /// The cell as it is now, for display.
    pub fn scene(&self) -> SceneSnapshot {
        let mut solids = Vec::with_capacity(self.scene.solids.len());
        for (i, s) in self.scene.solids.iter().enumerate() {
            let pose = self.held_by_arm(i).unwrap_or(self.state.poses[i]);
            let mut parts: Vec<PartView> = s.body.parts.iter().map(|p| view(&pose, p)).collect();
            if let Some(lid) = &s.lid {
                let rel = if self.state.lid_open[i] {
                    lid.open
                } else {
                    lid.closed
                };
                let lid_pose = pose * rel;
                parts.extend(lid.body.parts.iter().map(|p| view(&lid_pose, p)));
            }
            solids.push(SolidView {
                name: s.name.clone(),
                colour: colour_of(&s.name),
                fixed: s.fixed,
                held: self.is_held(i),
                parts,
            });
        }
        let out_of_reach = (0..self.scene.solids.len())
            .filter(|i| !self.scene.solids[*i].fixed && !self.is_held(*i))
            .filter(|i| {
                !self
                    .scene
                    .robot
                    .reaches(self.state.base, &self.reach_point(*i))
            })
            .map(|i| self.scene.solids[i].name.clone())
            .collect();
        SceneSnapshot {
            solids,
            robot: self.robot_view(),
            approach: self.approach_view(),
            out_of_reach,
            arms: self.arms_view(),
            motion: self.motion_view(),
        }
    }

    /// Where the tool is: at the held object's grip, else at the end of a path a running
    /// skill sweeps, else nowhere in particular (the arms rest).
    fn tool_pose(&self) -> Option<(Pose, f32)> {
        if let Some(h) = &self.state.held {
            return Some((self.state.poses[h.id] * h.grip.inverse(), h.half_width));
        }
        if self.state.progress.is_empty() {
            return None;
        }
        let path = self.approach.borrow();
        path.as_ref()
            .filter(|p| !p.collided)
            .map(|p| (p.end, self.scene.robot.gripper.finger[0]))
    }

    fn robot_view(&self) -> RobotView {
        let robot = &self.scene.robot;
        let base = self.state.base;
        let shoulders: Vec<Point3<f32>> = robot
            .shoulders
            .iter()
            .map(|s| s + Vector3::new(base.x, base.y, 0.0))
            .collect();
        let top = shoulders.iter().map(|s| s.z).fold(0.0f32, f32::max);
        let width = shoulders
            .iter()
            .map(|s| (s.y - base.y).abs())
            .fold(0.05f32, f32::max);
        let tool = self.tool_pose();
        let active = tool.map(|(pose, _)| {
            robot
                .nearest_shoulder(base, &Point3::from(pose.translation.vector))
                .1
        });
        let arms = shoulders
            .iter()
            .map(|s| {
                let side = (s.y - base.y).signum();
                let hand = match (tool, active) {
                    (Some((pose, _)), Some(a)) if (a - s).norm() < 1e-4 => {
                        Point3::from(pose.translation.vector)
                    }
                    _ => s + Vector3::new(0.12, 0.08 * side, -0.18),
                };
                let elbow = elbow(s, &hand, robot.reach / 2.0, side);
                ArmView {
                    shoulder: s.coords.into(),
                    elbow: elbow.coords.into(),
                    hand: hand.coords.into(),
                }
            })
            .collect::<Vec<_>>();
        let gripper = match tool {
            Some((pose, half_width)) => robot
                .gripper_parts(half_width)
                .iter()
                .map(|p| view(&pose, p))
                .collect(),
            None => Vec::new(),
        };
        RobotView {
            torso_center: [base.x - 0.05, base.y, top / 2.0],
            torso_half: [0.08, width * 0.6, top / 2.0 + 0.04],
            arms,
            gripper,
            reach: robot.reach,
        }
    }

    fn approach_view(&self) -> Option<ApproachView> {
        let path = self.approach.borrow();
        let p = path.as_ref()?;
        let at = |t: f32| {
            let v = p
                .start
                .translation
                .vector
                .lerp(&p.end.translation.vector, t);
            Pose::from_parts(Translation3::from(v), p.end.rotation)
        };
        let n = PATH_SEGMENTS;
        let points = (0..=n)
            .map(|k| at(k as f32 / n as f32).translation.vector.into())
            .collect();
        let scratch = Counter::default();
        let obstacles = self.obstacles(&p.exclude);
        let collided = (0..n)
            .map(|k| {
                p.collided
                    && path_collides(
                        &p.parts,
                        &at(k as f32 / n as f32),
                        &at((k + 1) as f32 / n as f32),
                        &obstacles,
                        &scratch,
                    )
            })
            .collect();
        Some(ApproachView { points, collided })
    }
}

/// The elbow of a two-link arm (links `link` long) from `shoulder` to `hand`, bent up
/// and outwards.
fn elbow(shoulder: &Point3<f32>, hand: &Point3<f32>, link: f32, side: f32) -> Point3<f32> {
    let d = hand - shoulder;
    let dist = d.norm().max(1e-6);
    let mid = shoulder + d / 2.0;
    let rise = (link * link - (dist / 2.0).powi(2)).max(0.0).sqrt();
    let out = Vector3::new(0.0, side, 1.0);
    let dir = d / dist;
    let bend = (out - dir * out.dot(&dir))
        .try_normalize(1e-6)
        .unwrap_or_else(Vector3::z);
    mid + bend * rise
}

fn view(pose: &Pose, part: &Part) -> PartView {
    let world = pose * part.local;
    PartView {
        pose: world,
        shape: shape_of(&part.shape, &world),
    }
}

fn shape_of(shape: &SharedShape, world: &Pose) -> PartShape {
    if let Some(c) = shape.as_cuboid() {
        return PartShape::Box {
            half: c.half_extents.into(),
        };
    }
    if let Some(c) = shape.as_cylinder() {
        return PartShape::Cylinder {
            radius: c.radius,
            half_height: c.half_height,
        };
    }
    if let Some(b) = shape.as_ball() {
        return PartShape::Ball { radius: b.radius };
    }
    if let Some(c) = shape.as_capsule() {
        return PartShape::Capsule {
            a: (world * c.segment.a).coords.into(),
            b: (world * c.segment.b).coords.into(),
            radius: c.radius,
        };
    }
    let b = shape.compute_local_aabb();
    PartShape::Box {
        half: b.half_extents().into(),
    }
}

/// A colour for a solid from a colour word in its name; fixtures and the rest in
/// neutral tones.
pub fn colour_of(name: &str) -> [u8; 3] {
    const WORDS: &[(&str, [u8; 3])] = &[
        ("red", [220, 50, 47]),
        ("green", [60, 170, 70]),
        ("blue", [40, 110, 220]),
        ("yellow", [235, 200, 40]),
        ("orange", [240, 140, 30]),
        ("purple", [140, 80, 180]),
        ("pink", [240, 120, 170]),
        ("white", [235, 235, 235]),
        ("black", [40, 40, 40]),
        ("brown", [130, 90, 50]),
        ("grey", [140, 140, 140]),
        ("gray", [140, 140, 140]),
        ("table", [170, 140, 100]),
        ("banana", [240, 215, 60]),
        ("egg", [245, 235, 210]),
    ];
    let lower = name.to_lowercase();
    lower
        .split(|c: char| !c.is_alphanumeric())
        .find_map(|w| WORDS.iter().find(|(k, _)| *k == w).map(|(_, c)| *c))
        .unwrap_or([150, 160, 170])
}
