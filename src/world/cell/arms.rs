//! The real arms of the execution world: the robot read from its published description
//! (URDF and meshes in the cache), and for each skill's motion the arm that gets there —
//! inverse kinematics for the tool poses the skill needs (above the target and where the
//! fingers close or let go, the gripper pointing down with its fingers opening across y),
//! the straight approach between them followed pose by pose, and a collision-free path in
//! joint space from where the arm is to the start of the approach (RRT-Connect against
//! the scene's solids, the torso and the other arm, with what the hand holds).
//!
//! The description is read once per process and shared by every world that uses it. When
//! it is not in the cache, the cell keeps its reach spheres and gripper sweep
//! ([`ArmsAvailability::Abstract`]): nothing is fetched from here.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use super::robot::ArmsSpec;
use crate::motion::{ArmCheck, MotionError, PlanOptions, Solid, plan};
use crate::robot::{IkOptions, Model, Robot, RobotShapes, describe_pose, solve};

/// Longest step (metres) between two poses followed along a straight approach.
const APPROACH_STEP: f64 = 0.01;
/// Largest change of any joint (radians) between two poses of a straight approach: a
/// larger one is the arm flipping over, not following the line.
const APPROACH_JUMP: f64 = 0.35;
/// Inverse kinematics runs (from different starts) per arm and grip before giving up.
const IK_ATTEMPTS: u64 = 3;
/// Largest change of any joint (radians) between two configurations of the path kept
/// for display: fine enough that the arm is seen to move, not jump.
const DRAW_STEP: f64 = 0.05;

/// The robot's arms with their collision shapes and where the tool sits on each flange.
pub struct Arms {
    pub robot: Robot,
    /// The description as read (shared with the scene snapshots that draw it).
    pub model: Arc<Model>,
    pub shapes: RobotShapes,
    /// The tool centre point in each flange's frame.
    pub tool: Isometry3<f64>,
    pub rest: Vec<Vec<f64>>,
    pub plan: PlanOptions,
    pub ik: IkOptions,
    /// Every path query posed while recording is on (for the benchmark), else `None`.
    recorded: Mutex<Option<Vec<PathQuery>>>,
}

/// One collision-free path asked of the planner by a skill's motion: the arm, the joint
/// values from and to, and everything its check held (the robot's root, the other arms'
/// values, the scene's solids and what the hand carries, in the flange's frame).
#[derive(Debug, Clone)]
pub struct PathQuery {
    pub arm: usize,
    pub base: Isometry3<f64>,
    pub configs: Vec<Vec<f64>>,
    pub solids: Vec<Solid>,
    pub carried: Vec<Solid>,
    pub start: Vec<f64>,
    pub goal: Vec<f64>,
}

impl std::fmt::Debug for Arms {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Arms")
            .field("arms", &self.robot.arms.len())
            .finish_non_exhaustive()
    }
}

/// The descriptions read so far in this process, by name (or why one could not be read).
type ReadRobots = HashMap<&'static str, Result<Arc<Robot>, ArmsError>>;

/// Why a scenario's robot cannot move its real arms.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ArmsError {
    /// The description did not read (kept as text: it is remembered for the process).
    #[error("the robot description: {0}")]
    Description(String),
    /// The links' collision shapes could not be made from the meshes.
    #[error("{0}")]
    Shapes(String),
    #[error("[world.robot] rest gives {given} arm(s), the description has {has}")]
    RestCount { given: usize, has: usize },
    #[error("[world.robot] rest: the values for {arm} are not within its joint limits")]
    RestLimits { arm: String },
}

/// Whether a cell's execution world moves real arms.
#[derive(Debug, Clone)]
pub enum ArmsAvailability {
    /// The scenario names no robot description.
    NotAsked,
    Real(Arc<Arms>),
    /// The description is named but cannot be used; why, in a sentence.
    Abstract(String),
}

/// One motion of a skill, in the world's frame.
pub struct Reach<'a> {
    /// The robot's root.
    pub base: Isometry3<f64>,
    /// Every arm's joint values now.
    pub configs: &'a [Vec<f64>],
    pub solids: &'a [Solid],
    /// What the hand holds, in a frame at the tool centre point with the world's axes.
    pub carried: &'a [Solid],
    /// The tool where the straight approach starts, and where it ends.
    pub above: Isometry3<f64>,
    pub at: Isometry3<f64>,
    /// The one arm that may make it (the one holding what it carries).
    pub only: Option<usize>,
    /// The hand lets go at the end and the arm goes back to its rest values.
    pub lets_go: bool,
}

/// The arm that made a motion and where it ended: back at the start of the approach
/// holding what it grasped, or at its rest values after letting go.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmMove {
    pub arm: usize,
    pub q: Vec<f64>,
    /// Joint-space length (radians) of the paths, there and (after letting go) back.
    pub length: f64,
    pub samples: usize,
    pub checks: usize,
    /// The whole way the arm goes, from where it was to `q`: the planned path to above
    /// the target, down the approach and back up, and (after letting go) the path back
    /// to rest; no joint changes by more than `DRAW_STEP` between two of them.
    pub path: Vec<Vec<f64>>,
    /// The tool centre point (world) at each configuration of `path`.
    pub tool: Vec<[f32; 3]>,
    /// Where on `path` the fingers close or open (the bottom of the approach).
    pub acts_at: usize,
    pub effort: Effort,
}

/// What finding a motion took, made or refused.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Effort {
    /// The arm that made the motion, or whose refusal is reported.
    pub arm: usize,
    /// Arm, grip and inverse-kinematics start combinations tried.
    pub attempts: usize,
    /// Wall-clock seconds spent (inverse kinematics, collision tests, path search).
    pub seconds: f64,
}

/// The last motion asked of the arms (for display): made, or refused with what blocked it.
#[derive(Debug, Clone, PartialEq)]
pub enum LastMotion {
    Made(ArmMove),
    Refused {
        effort: Effort,
        /// The solid or link the motion collided with, when known.
        blocker: Option<String>,
    },
}

/// Why no arm made a motion.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    /// No joint values within the limits put the tool at the pose.
    OutOfReach(String),
    /// Every arm that reaches it collides on the way; the nearest arm's motion error.
    NoPath {
        message: String,
        blocker: Option<String>,
    },
}

impl Arms {
    /// The check `query` is planned against: its robot root, the other arms' values, the
    /// scene's solids and what the hand carries.
    pub fn check_of(&self, query: &PathQuery) -> Result<ArmCheck<'_>, MotionError> {
        Ok(ArmCheck::new(
            &self.robot,
            &self.shapes,
            query.base,
            query.arm,
            &query.configs,
            &query.solids,
        )?
        .carrying(query.carried.clone()))
    }

    /// The arms of `spec`'s description when it is in the cache, read once per process.
    pub fn available(spec: &ArmsSpec) -> ArmsAvailability {
        static READ: OnceLock<Mutex<ReadRobots>> = OnceLock::new();
        let description = spec.description;
        let dir = description.path();
        if !description.urdf_in(&dir).is_file() {
            return ArmsAvailability::Abstract(format!(
                "the robot description {:?} is not in the cache ({}): the cell checks its \
                 reach spheres and gripper sweep instead of moving the arms (`betr model \
                 fetch --robot {}` fetches it, as the workbench and the commands that run a \
                 scenario do on first use unless offline)",
                description.name,
                dir.display(),
                description.name,
            ));
        }
        let read = READ.get_or_init(|| Mutex::new(HashMap::new()));
        let robot = {
            let Ok(mut read) = read.lock() else {
                return ArmsAvailability::Abstract("the robot description is being read".into());
            };
            read.entry(description.name)
                .or_insert_with(|| {
                    Robot::read(description, &dir)
                        .map(Arc::new)
                        .map_err(|e| ArmsError::Description(e.to_string()))
                })
                .clone()
        };
        let robot = match robot {
            Ok(r) => r,
            Err(e) => return ArmsAvailability::Abstract(e.to_string()),
        };
        match Arms::new(robot.as_ref().clone(), spec) {
            Ok(arms) => ArmsAvailability::Real(Arc::new(arms)),
            Err(e) => ArmsAvailability::Abstract(e.to_string()),
        }
    }

    fn new(robot: Robot, spec: &ArmsSpec) -> Result<Arms, ArmsError> {
        let shapes = RobotShapes::new(&robot.model, &robot.arms)
            .map_err(|e| ArmsError::Shapes(e.to_string()))?;
        if spec.rest.len() != robot.arms.len() {
            return Err(ArmsError::RestCount {
                given: spec.rest.len(),
                has: robot.arms.len(),
            });
        }
        for (q, arm) in spec.rest.iter().zip(&robot.arms) {
            if !arm.within_limits(q) {
                return Err(ArmsError::RestLimits {
                    arm: arm.tip.clone(),
                });
            }
        }
        Ok(Arms {
            model: Arc::new(robot.model.clone()),
            robot,
            shapes,
            tool: Isometry3::translation(0.0, 0.0, spec.tool),
            rest: spec.rest.clone(),
            plan: PlanOptions::default(),
            ik: IkOptions::default(),
            recorded: Mutex::new(None),
        })
    }

    /// Start keeping every path query posed from now on (forgetting any kept before).
    pub fn record_queries(&self) {
        if let Ok(mut recorded) = self.recorded.lock() {
            *recorded = Some(Vec::new());
        }
    }

    /// The path queries kept since [`Arms::record_queries`]; recording stops.
    pub fn take_queries(&self) -> Vec<PathQuery> {
        self.recorded
            .lock()
            .ok()
            .and_then(|mut r| r.take())
            .unwrap_or_default()
    }

    /// A path for `check`'s arm, the query kept when recording.
    fn plan_path(
        &self,
        check: &ArmCheck<'_>,
        query: PathQuery,
    ) -> Result<crate::motion::JointPath, MotionError> {
        let found = plan(check, &query.start, &query.goal, &self.plan);
        if let Ok(mut recorded) = self.recorded.lock()
            && let Some(kept) = recorded.as_mut()
        {
            kept.push(query);
        }
        found
    }

    /// The arm's name as people read it.
    pub fn arm_name(&self, arm: usize) -> &str {
        self.robot.arms.get(arm).map_or("?", |a| a.tip.as_str())
    }

    /// Move an arm to `reach.above` and along the straight line to `reach.at`: the nearer
    /// arm first, each of the two grips that open across y; the first that gets there,
    /// else the refusal that tells the most, with what the search took either way.
    pub fn reach(&self, reach: &Reach<'_>) -> (Result<ArmMove, Refusal>, Effort) {
        let began = Instant::now();
        let mut effort = Effort {
            arm: 0,
            attempts: 0,
            seconds: 0.0,
        };
        let mut result = self.try_arms(reach, &mut effort);
        effort.seconds = began.elapsed().as_secs_f64();
        if let Ok(m) = &mut result {
            m.effort = effort;
        }
        (result, effort)
    }

    fn try_arms(&self, reach: &Reach<'_>, effort: &mut Effort) -> Result<ArmMove, Refusal> {
        let target = reach.at.translation.vector;
        let mut order: Vec<(usize, f64)> = self
            .robot
            .arms
            .iter()
            .enumerate()
            .filter(|(i, _)| reach.only.is_none_or(|only| only == *i))
            .filter_map(|(i, arm)| {
                let shoulder = (reach.base * arm.joints.first()?.before).translation.vector;
                Some((i, (target - shoulder).norm()))
            })
            .collect();
        order.sort_by(|a, b| a.1.total_cmp(&b.1));
        // The refusal that tells the most: a solid of the scene in the way, then a part of
        // the robot in the way, then a pose out of reach; the first of its kind.
        let rank = |r: &Refusal| match r {
            Refusal::NoPath {
                blocker: Some(b), ..
            } if reach.solids.iter().any(|s| s.name == *b) => 3,
            Refusal::NoPath { .. } => 2,
            Refusal::OutOfReach(_) => 1,
        };
        let mut refused: Option<Refusal> = None;
        for (arm, _) in order {
            for (turn, attempt) in [0.0, std::f64::consts::PI]
                .into_iter()
                .flat_map(|t| (0..IK_ATTEMPTS).map(move |a| (t, a)))
            {
                let spin = Isometry3::rotation(Vector3::z() * turn);
                effort.attempts += 1;
                match self.reach_with(arm, reach, spin, attempt) {
                    Ok(m) => {
                        effort.arm = arm;
                        return Ok(m);
                    }
                    Err(r) => {
                        if refused.as_ref().is_none_or(|old| rank(&r) > rank(old)) {
                            refused = Some(r);
                            effort.arm = arm;
                        }
                    }
                }
            }
        }
        Err(refused.unwrap_or_else(|| Refusal::OutOfReach(describe_pose(&reach.at))))
    }

    /// The flange pose (in the robot's root frame) that puts the tool at `tool` (world).
    fn flange_for(
        &self,
        reach: &Reach<'_>,
        tool: &Isometry3<f64>,
        spin: &Isometry3<f64>,
    ) -> Isometry3<f64> {
        reach.base.inverse() * tool * spin * self.tool.inverse()
    }

    /// Arm `arm` with the grip turned by `spin`; `attempt` chooses where the inverse
    /// kinematics starts (another elbow swivel when one cannot follow the approach).
    fn reach_with(
        &self,
        arm: usize,
        reach: &Reach<'_>,
        spin: Isometry3<f64>,
        attempt: u64,
    ) -> Result<ArmMove, Refusal> {
        let tip = &self.robot.arms[arm].tip;
        let start = reach
            .configs
            .get(arm)
            .cloned()
            .unwrap_or_else(|| self.rest[arm].clone());
        let from = self.ik_start(arm, &start, attempt);
        let line = self.approach_line(arm, reach, &spin, &from)?;
        let Some(above) = line.last().cloned() else {
            return Err(out_of_reach(&reach.above, tip));
        };
        let carried = self.carried_in_flange(reach, &spin);
        let check = ArmCheck::new(
            &self.robot,
            &self.shapes,
            reach.base,
            arm,
            reach.configs,
            reach.solids,
        )
        .map_err(|e| no_path(&e))?
        .carrying(carried.clone());
        approach_clear(&check, &line, reach, tip)?;
        let path = self
            .plan_path(&check, reach.query(arm, carried, &start, &above))
            .map_err(|e| no_path(&e))?;
        // There, down the approach (`line` runs up from the bottom) and back up.
        let mut way = path.waypoints.clone();
        way.extend(line.iter().rev().skip(1).cloned());
        way.extend(line.iter().skip(1).cloned());
        let mut done = ArmMove {
            arm,
            q: above.clone(),
            length: path.length(),
            samples: path.samples,
            checks: path.checks,
            path: Vec::new(),
            tool: Vec::new(),
            acts_at: 0,
            effort: Effort {
                arm,
                attempts: 0,
                seconds: 0.0,
            },
        };
        if reach.lets_go {
            let back = self.path_back_to_rest(arm, reach, &above)?;
            done.q.clone_from(&self.rest[arm]);
            done.length += back.length();
            done.samples += back.samples;
            done.checks += back.checks;
            way.extend(back.waypoints.into_iter().skip(1));
        }
        done.path = densify(&way, DRAW_STEP);
        // Densifying keeps every configuration of the way as it is: the bottom of the
        // approach is found again exactly.
        done.acts_at = line
            .first()
            .and_then(|bottom| done.path.iter().position(|q| q == bottom))
            .unwrap_or_default();
        done.tool = self.tool_along(arm, reach.base, &done.path);
        Ok(done)
    }

    /// Where the inverse kinematics starts on attempt `attempt`: from where the arm is
    /// (`start`), then from the middle of its ranges, then from its rest.
    fn ik_start(&self, arm: usize, start: &[f64], attempt: u64) -> Vec<f64> {
        match attempt {
            0 => start.to_vec(),
            1 => self.robot.arms[arm]
                .joints
                .iter()
                .map(|j| (j.lower + j.upper) / 2.0)
                .collect(),
            _ => self.rest[arm].clone(),
        }
    }

    /// The straight approach in joint values, from its bottom (`reach.at`) up to
    /// `reach.above`: the end of the approach (the harder pose, nearest the table) is
    /// solved first from `from`, then each pose of the line back up from the one below;
    /// refused when a pose is out of reach or the arm would flip over between two.
    fn approach_line(
        &self,
        arm: usize,
        reach: &Reach<'_>,
        spin: &Isometry3<f64>,
        from: &[f64],
    ) -> Result<Vec<Vec<f64>>, Refusal> {
        let chain = &self.robot.arms[arm];
        let at_flange = self.flange_for(reach, &reach.at, spin);
        let Some((at, _, _)) = solve(chain, &at_flange, from, &self.ik) else {
            return Err(out_of_reach(&reach.at, &chain.tip));
        };
        let travel = (reach.at.translation.vector - reach.above.translation.vector).norm();
        let steps = (travel / APPROACH_STEP).ceil().max(1.0) as usize;
        let follow = IkOptions {
            starts: 1,
            solutions: 1,
            ..self.ik
        };
        let mut line = vec![at];
        for k in 1..=steps {
            let t = k as f64 / steps as f64;
            let tool = Isometry3::from_parts(
                Translation3::from(
                    reach
                        .at
                        .translation
                        .vector
                        .lerp(&reach.above.translation.vector, t),
                ),
                reach.at.rotation.slerp(&reach.above.rotation, t),
            );
            let flange = self.flange_for(reach, &tool, spin);
            let Some(previous) = line.last().cloned() else {
                break;
            };
            let Some((q, _, _)) = solve(chain, &flange, &previous, &follow) else {
                return Err(out_of_reach(&tool, &chain.tip));
            };
            let jump = q
                .iter()
                .zip(&previous)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if jump > APPROACH_JUMP {
                return Err(out_of_reach(&tool, &chain.tip));
            }
            line.push(q);
        }
        Ok(line)
    }

    /// What the hand holds, from the tool's world-aligned frame into the flange's.
    fn carried_in_flange(&self, reach: &Reach<'_>, spin: &Isometry3<f64>) -> Vec<Solid> {
        let into_flange = (self.tool
            * spin.inverse()
            * Isometry3::from_parts(Translation3::identity(), reach.at.rotation.inverse()))
        .cast::<f32>();
        reach
            .carried
            .iter()
            .map(|p| Solid {
                name: p.name.clone(),
                pose: into_flange * p.pose,
                shape: p.shape.clone(),
            })
            .collect()
    }

    /// Empty-handed, from above the object let go back to rest (the object below the hand
    /// is out of the way going up).
    fn path_back_to_rest(
        &self,
        arm: usize,
        reach: &Reach<'_>,
        above: &[f64],
    ) -> Result<crate::motion::JointPath, Refusal> {
        let empty = ArmCheck::new(
            &self.robot,
            &self.shapes,
            reach.base,
            arm,
            reach.configs,
            reach.solids,
        )
        .map_err(|e| no_path(&e))?;
        self.plan_path(&empty, reach.query(arm, Vec::new(), above, &self.rest[arm]))
            .map_err(|e| no_path(&e))
    }

    /// The tool centre point (world) at each configuration of `path`.
    fn tool_along(&self, arm: usize, base: Isometry3<f64>, path: &[Vec<f64>]) -> Vec<[f32; 3]> {
        let chain = &self.robot.arms[arm];
        path.iter()
            .map(|q| {
                // The grip's turn about the tool's axis does not move its centre.
                let at = base * chain.fk(q) * self.tool;
                let p = at.translation.vector;
                [p.x as f32, p.y as f32, p.z as f32]
            })
            .collect()
    }
}

impl Reach<'_> {
    /// The path query for `arm` in this motion's scene, carrying `carried`.
    fn query(&self, arm: usize, carried: Vec<Solid>, start: &[f64], goal: &[f64]) -> PathQuery {
        PathQuery {
            arm,
            base: self.base,
            configs: self.configs.to_vec(),
            solids: self.solids.to_vec(),
            carried,
            start: start.to_vec(),
            goal: goal.to_vec(),
        }
    }
}

/// The refusal for a tool pose no joint values within the limits of arm `tip` reach.
fn out_of_reach(pose: &Isometry3<f64>, tip: &str) -> Refusal {
    Refusal::OutOfReach(format!(
        "pose {} is out of reach of {} (no joint values within the limits reach it)",
        describe_pose(pose),
        tip
    ))
}

/// Every pose of the straight approach `line` free of collisions under `check`, else the
/// refusal naming what it hits first.
fn approach_clear(
    check: &ArmCheck<'_>,
    line: &[Vec<f64>],
    reach: &Reach<'_>,
    tip: &str,
) -> Result<(), Refusal> {
    for q in line {
        if let Some(blocker) = check.blocker(q) {
            return Err(Refusal::NoPath {
                message: format!(
                    "No collision free path found for {}: the straight approach to {} collides with {blocker}",
                    tip,
                    describe_pose(&reach.at)
                ),
                blocker: Some(blocker),
            });
        }
    }
    Ok(())
}

/// `way` with configurations put in between so that no joint changes by more than `step`
/// from one to the next.
fn densify(way: &[Vec<f64>], step: f64) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = way.first().cloned().into_iter().collect();
    for pair in way.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let widest = a
            .iter()
            .zip(b)
            .map(|(x, y)| (y - x).abs())
            .fold(0.0, f64::max);
        let n = (widest / step).ceil().max(1.0) as usize;
        for k in 1..n {
            let t = k as f64 / n as f64;
            out.push(a.iter().zip(b).map(|(x, y)| x + (y - x) * t).collect());
        }
        out.push(b.clone());
    }
    out
}

fn no_path(e: &MotionError) -> Refusal {
    let blocker = match e {
        MotionError::NoPath { blocker, .. } => blocker.clone(),
        _ => None,
    };
    Refusal::NoPath {
        message: e.to_string(),
        blocker,
    }
}

/// The tool pose of a grip from above at `point` with the whole hand turned by `turn` (in
/// the world's axes) about the tool centre point; unturned, pointing down with the fingers
/// opening across y.
pub fn turned_from_above(point: &Point3<f32>, turn: &UnitQuaternion<f32>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(f64::from(point.x), f64::from(point.y), f64::from(point.z)),
        // Tool x along world y, tool z down.
        turn.cast::<f64>()
            * UnitQuaternion::from_basis_unchecked(&[Vector3::y(), Vector3::x(), -Vector3::z()]),
    )
}
