//! The tabletop cell: a world whose truth comes from geometry, not from a list of facts.
//!
//! Objects are solids with poses (see `geometry`); the robot is a YuMi with a reach and a
//! payload per arm and a gripper that is itself a solid (`robot`). Conditions are computed
//! from the solids every time they are asked: `"a" on "b"` when a's bottom rests on b's
//! top face above it, `"a" in "b"` when a's centre lies in b's cavity, `"b" open` when the
//! slab in front of b's opening is free of other solids (a closed lid or door, or the
//! table under an upside-down cup, is in it), `upright` from the pose's axis, `near robot`
//! from the reach spheres, `grasped`, `unlocked`, `location known` and `clean` from the
//! few states that are not geometric (what the gripper holds, locks, the robot's map, dirt).
//!
//! Skills are performed by name (`skills`), run for the number of ticks the scenario
//! declares, check everything (including collision along the approach path) on their
//! first tick, and teleport objects to consistent poses when they complete.

pub mod arms;
mod describe;
pub mod geometry;
mod motions;
mod observe;
pub mod robot;
pub mod scene;
pub mod skills;
pub mod snapshot;
#[cfg(test)]
mod tests;
pub mod values;

use std::any::Any;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;

use nalgebra::{Point3, Vector2};

use super::{Snapshot, Step, World, WorldError};
use crate::domain::{ANY_OBJECT, ActionCall, Atom, Condition, Domain};
use crate::scenario::{Scenario, ScenarioError};
use geometry::{Counter, Obstacle, Pose, REST_TOLERANCE, is_upright, overlaps_any};
use scene::Scene;

/// Footprints nearer than this (metres) stand beside each other.
const BESIDE_GAP: f32 = 0.05;

/// What the gripper holds: the object and where it sits relative to the tool centre point.
#[derive(Debug, Clone, PartialEq)]
struct Held {
    id: usize,
    grip: Pose,
    half_width: f32,
    /// Where it was picked up (a place to put it down near).
    from: Point3<f32>,
    /// The real arm that holds it (with real arms).
    arm: Option<usize>,
}

/// What a running action will do when it completes (decided on its first tick).
#[derive(Debug, Clone, PartialEq)]
enum Effect {
    Grasp(Held),
    /// Put the held object at this pose and let go.
    Release {
        id: usize,
        pose: Pose,
    },
    /// Move an object that is not held (flipping a cup, scooping sand).
    Move {
        id: usize,
        pose: Pose,
    },
    Open(usize),
    Unlock(usize),
    Know(usize),
    Clean(usize),
    Base(Vector2<f32>),
}

#[derive(Debug, Clone, PartialEq)]
struct Progress {
    done: u32,
    effect: Effect,
    /// The arm motion the action makes, with real arms.
    arm: Option<arms::ArmMove>,
}

#[derive(Debug, Clone, PartialEq)]
struct State {
    poses: Vec<Pose>,
    lid_open: Vec<bool>,
    locked: Vec<bool>,
    known: Vec<bool>,
    dirty: Vec<bool>,
    base: Vector2<f32>,
    held: Option<Held>,
    progress: HashMap<String, Progress>,
    /// Each real arm's joint values (empty without real arms).
    arms: Vec<Vec<f64>>,
}

#[derive(Clone)]
pub struct CellWorld {
    scene: Arc<Scene>,
    domain: Arc<Domain>,
    index: Arc<HashMap<String, usize>>,
    counter: Arc<Counter>,
    state: State,
    /// The last approach path a skill swept (for display only: no truth depends on it).
    approach: RefCell<Option<snapshot::SweptPath>>,
    /// The robot's real arms, when this world moves them (the execution world).
    arms: Option<Arc<arms::Arms>>,
    /// The arm motion of the action being started (taken into its progress).
    planned: RefCell<Option<arms::ArmMove>>,
    /// The last arm motion made or refused (for display only).
    last_motion: RefCell<Option<arms::LastMotion>>,
    /// What the arm motions of the action being started took so far.
    spent: RefCell<arms::Effort>,
}

impl CellWorld {
    /// Build the cell a scenario describes; `variant` applies a `[world.variants.NAME]`.
    pub fn from_scenario(
        scenario: &Scenario,
        variant: Option<&str>,
    ) -> Result<Self, ScenarioError> {
        let scene = scene::read(scenario, variant)?;
        let i = scene.initial.clone();
        let index = scene
            .solids
            .iter()
            .enumerate()
            .map(|(n, s)| (s.name.clone(), n))
            .collect();
        Ok(CellWorld {
            state: State {
                poses: i.poses,
                lid_open: i.lid_open,
                locked: i.locked,
                known: i.known,
                dirty: i.dirty,
                base: Vector2::from(i.base),
                held: None,
                progress: HashMap::new(),
                arms: Vec::new(),
            },
            scene: Arc::new(scene),
            domain: Arc::new(scenario.domain.clone()),
            index: Arc::new(index),
            counter: Arc::new(Counter::default()),
            approach: RefCell::new(None),
            arms: None,
            planned: RefCell::new(None),
            last_motion: RefCell::new(None),
            spent: RefCell::new(arms::Effort::default()),
        })
    }

    /// Whether the scenario's robot has real arms this machine can move.
    pub fn arms_availability(&self) -> arms::ArmsAvailability {
        match &self.scene.robot.arms {
            None => arms::ArmsAvailability::NotAsked,
            Some(spec) => arms::Arms::available(spec),
        }
    }

    /// This world with its robot's real arms: every grasp, place, put-in and flip then
    /// moves an arm along a collision-free path, starting from the arms' rest values.
    pub fn moving_arms(mut self, arms: Arc<arms::Arms>) -> Self {
        self.state.arms = arms.rest.clone();
        self.arms = Some(arms);
        self
    }

    /// Whether this world moves real arms.
    pub fn has_real_arms(&self) -> bool {
        self.arms.is_some()
    }

    /// The real arms this world moves, if it moves them.
    pub fn arms(&self) -> Option<&Arc<arms::Arms>> {
        self.arms.as_ref()
    }

    /// Where the robot's root stands (x, y).
    pub fn base(&self) -> [f32; 2] {
        [self.state.base.x, self.state.base.y]
    }

    /// Each real arm's joint values now (empty without real arms).
    pub fn arm_configs(&self) -> &[Vec<f64>] {
        &self.state.arms
    }

    /// The last arm motion a skill made (none when the last one was refused), and the
    /// arm's name.
    pub fn last_motion(&self) -> Option<(String, arms::ArmMove)> {
        let arms = self.arms.as_ref()?;
        match self.last_motion.borrow().clone()? {
            arms::LastMotion::Made(m) => Some((arms.arm_name(m.arm).to_string(), m)),
            arms::LastMotion::Refused { .. } => None,
        }
    }

    /// Exact collision tests (of two convex parts) made so far by this world and all
    /// its forks.
    pub fn collision_checks(&self) -> u64 {
        self.counter.get()
    }

    /// Box tests of whole solids made so far (the broad phase before the exact tests).
    pub fn broad_checks(&self) -> u64 {
        self.counter.broad()
    }

    /// Collision questions answered so far (is this path free, is this opening clear),
    /// and the seconds spent answering them.
    pub fn collision_queries(&self) -> (u64, f64) {
        (self.counter.queries(), self.counter.seconds())
    }

    /// The pose of a solid by name (for tests and display).
    pub fn pose_of(&self, name: &str) -> Option<Pose> {
        self.index.get(name).map(|i| self.state.poses[*i])
    }

    fn id(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    fn name(&self, id: usize) -> &str {
        &self.scene.solids[id].name
    }

    fn is_held(&self, id: usize) -> bool {
        self.state.held.as_ref().is_some_and(|h| h.id == id)
    }

    fn aabb(&self, id: usize) -> geometry::Aabb {
        self.scene.solids[id].body.aabb(&self.state.poses[id])
    }

    /// Every solid (and lid) except `exclude` and the held object, at its pose.
    fn obstacles(&self, exclude: &[usize]) -> Vec<Obstacle<'_>> {
        let mut out = Vec::with_capacity(self.scene.solids.len() + 2);
        for (i, s) in self.scene.solids.iter().enumerate() {
            if let Some(lid) = &s.lid {
                let rel = if self.state.lid_open[i] {
                    lid.open
                } else {
                    lid.closed
                };
                out.push(Obstacle {
                    pose: self.state.poses[i] * rel,
                    body: &lid.body,
                });
            }
            if exclude.contains(&i) || self.is_held(i) {
                continue;
            }
            out.push(Obstacle {
                pose: self.state.poses[i],
                body: &s.body,
            });
        }
        out
    }

    /// The point an arm must reach to act on a solid: the top centre of a movable solid,
    /// the middle of a container's opening, else the solid's point nearest the robot.
    fn reach_point(&self, id: usize) -> Point3<f32> {
        let s = &self.scene.solids[id];
        let pose = &self.state.poses[id];
        let b = self.aabb(id);
        if !s.fixed {
            let c = b.center();
            return Point3::new(c.x, c.y, b.maxs.z);
        }
        if let Some(region) = s.body.opening_region(pose) {
            return Point3::from(region.local.translation.vector);
        }
        let (_, shoulder) = self
            .scene
            .robot
            .nearest_shoulder(self.state.base, &b.center());
        Point3::new(
            shoulder.x.clamp(b.mins.x, b.maxs.x),
            shoulder.y.clamp(b.mins.y, b.maxs.y),
            b.maxs.z,
        )
    }

    fn on(&self, a: usize, b: usize) -> bool {
        if a == b || self.is_held(a) || self.is_held(b) {
            return false;
        }
        let (x, y) = (self.aabb(a), self.aabb(b));
        let c = x.center();
        (x.mins.z - y.maxs.z).abs() <= REST_TOLERANCE
            && (y.mins.x..=y.maxs.x).contains(&c.x)
            && (y.mins.y..=y.maxs.y).contains(&c.y)
    }

    /// `a` over `b`: a is higher than b's top and their footprints overlap (a shelf over
    /// a cube, a cube lying on it).
    fn over(&self, a: usize, b: usize) -> bool {
        if a == b || self.is_held(a) || self.is_held(b) {
            return false;
        }
        let (x, y) = (self.aabb(a), self.aabb(b));
        x.mins.z >= y.maxs.z - REST_TOLERANCE
            && x.mins.x < y.maxs.x
            && y.mins.x < x.maxs.x
            && x.mins.y < y.maxs.y
            && y.mins.y < x.maxs.y
    }

    /// `a` beside `b`: side by side at the same height, their footprints less than
    /// `BESIDE_GAP` apart (a tall vase next to a cube), neither over the other.
    fn beside(&self, a: usize, b: usize) -> bool {
        if a == b || self.is_held(a) || self.is_held(b) || self.over(a, b) || self.over(b, a) {
            return false;
        }
        let (x, y) = (self.aabb(a), self.aabb(b));
        let gap_x = (x.mins.x - y.maxs.x).max(y.mins.x - x.maxs.x);
        let gap_y = (x.mins.y - y.maxs.y).max(y.mins.y - x.maxs.y);
        x.mins.z < y.maxs.z && y.mins.z < x.maxs.z && gap_x.max(gap_y) < BESIDE_GAP
    }

    fn inside(&self, a: usize, b: usize) -> bool {
        a != b
            && !self.is_held(a)
            && self.scene.solids[b]
                .body
                .cavity_contains(&self.state.poses[b], &self.aabb(a).center())
    }

    /// Open: the slab in front of the opening is free of every other solid and of the
    /// solid's own lid or door (things inside it do not count).
    fn open(&self, id: usize) -> bool {
        let Some(region) = self.scene.solids[id]
            .body
            .opening_region(&self.state.poses[id])
        else {
            return false;
        };
        let contents: Vec<usize> = (0..self.scene.solids.len())
            .filter(|o| self.inside(*o, id))
            .collect();
        let mut exclude = contents;
        exclude.push(id);
        !overlaps_any(&region, &self.obstacles(&exclude), &self.counter)
    }

    fn holds(&self, predicate: &str, args: &[usize]) -> bool {
        match (predicate, args) {
            ("on", [a, b]) => self.on(*a, *b),
            ("in", [a, b]) => self.inside(*a, *b),
            ("over", [a, b]) => self.over(*a, *b),
            ("beside", [a, b]) => self.beside(*a, *b),
            ("grasped", [a]) => self.is_held(*a),
            ("open", [a]) => self.open(*a),
            ("unlocked", [a]) => !self.state.locked[*a],
            ("upright", [a]) => is_upright(&self.state.poses[*a]),
            ("near robot", [a]) => {
                self.is_held(*a)
                    || self
                        .scene
                        .robot
                        .reaches(self.state.base, &self.reach_point(*a))
            }
            ("location known", [a]) => self.state.known[*a],
            ("clean", [a]) => !self.state.dirty[*a],
            _ => false,
        }
    }

    /// Whether the atom holds for some choice of the objects its wildcards stand for.
    fn holds_atom(&self, atom: &Atom) -> bool {
        let mut ids = Vec::with_capacity(atom.args.len());
        self.some_assignment(atom, &mut ids)
    }

    fn some_assignment(&self, atom: &Atom, ids: &mut Vec<usize>) -> bool {
        let Some(arg) = atom.args.get(ids.len()) else {
            return self.holds(&atom.predicate, ids);
        };
        if arg == ANY_OBJECT {
            for o in 0..self.scene.solids.len() {
                if ids.contains(&o) {
                    continue;
                }
                ids.push(o);
                let found = self.some_assignment(atom, ids);
                ids.pop();
                if found {
                    return true;
                }
            }
            return false;
        }
        let Some(id) = self.id(arg) else { return false };
        ids.push(id);
        let found = self.some_assignment(atom, ids);
        ids.pop();
        found
    }

    fn apply(&mut self, effect: Effect) {
        match effect {
            Effect::Grasp(held) => self.state.held = Some(held),
            Effect::Release { id, pose } => {
                self.state.poses[id] = pose;
                self.state.held = None;
            }
            Effect::Move { id, pose } => self.state.poses[id] = pose,
            Effect::Open(id) => self.state.lid_open[id] = true,
            Effect::Unlock(id) => self.state.locked[id] = false,
            Effect::Know(id) => self.state.known[id] = true,
            Effect::Clean(id) => self.state.dirty[id] = false,
            Effect::Base(b) => self.state.base = b,
        }
    }
}

impl World for CellWorld {
    fn kind(&self) -> &'static str {
        "cell"
    }

    fn check(&self, condition: &Condition) -> bool {
        self.holds_atom(&condition.atom) != condition.negated
    }

    fn step(&mut self, action: &ActionCall, started: bool) -> Step {
        let key = format!("{} {:?}", action.skill, action.args);
        if started || !self.state.progress.contains_key(&key) {
            self.planned.replace(None);
            self.spent.replace(arms::Effort::default());
            let before = self.last_motion.borrow().clone();
            match self.start(action) {
                Ok(effect) => {
                    // Spots refused on the way to the one the action takes are not its
                    // motion: that is recorded when the action completes.
                    self.last_motion.replace(before);
                    let arm = self.planned.take();
                    self.state.progress.insert(
                        key.clone(),
                        Progress {
                            done: 0,
                            effect,
                            arm,
                        },
                    );
                }
                Err(error) => {
                    self.planned.replace(None);
                    self.state.progress.remove(&key);
                    return Step::Failure(error.to_string());
                }
            }
        }
        let ticks = self.domain.resolve(action).map_or(1, |g| g.ticks);
        let Some(p) = self.state.progress.get_mut(&key) else {
            return Step::Failure(format!("Unknown action {action}"));
        };
        p.done += 1;
        if p.done < ticks {
            return Step::Running;
        }
        if let Some(p) = self.state.progress.remove(&key) {
            self.apply(p.effect);
            if let Some(m) = p.arm {
                if let Some(q) = self.state.arms.get_mut(m.arm) {
                    q.clone_from(&m.q);
                }
                self.last_motion.replace(Some(arms::LastMotion::Made(m)));
            }
        }
        Step::Success
    }

    fn halt(&mut self, action: &ActionCall) {
        self.state
            .progress
            .remove(&format!("{} {:?}", action.skill, action.args));
    }

    fn fork(&self) -> Box<dyn World> {
        Box::new(self.clone())
    }

    fn snapshot(&self) -> Snapshot {
        Snapshot::new(self.state.clone())
    }

    fn restore(&mut self, snapshot: &Snapshot) -> Result<(), WorldError> {
        let state = snapshot.get::<State>().ok_or(WorldError::ForeignSnapshot)?;
        self.state = state.clone();
        Ok(())
    }

    fn as_any(&self) -> Option<&dyn Any> {
        Some(self)
    }

    fn take_observation(
        &mut self,
        observation: &super::Observation,
    ) -> Result<(), super::ObservationError> {
        self.take(observation)
    }

    fn facts(&self) -> Vec<Condition> {
        let n = self.scene.solids.len();
        let mut out = Vec::new();
        let known = |p: &str| self.domain.vocabulary.predicate(p).is_some();
        for p in ["on", "in", "over", "beside"]
            .into_iter()
            .filter(|p| known(p))
        {
            for a in 0..n {
                for b in 0..n {
                    if self.holds(p, &[a, b]) {
                        out.push(Atom::new(p, [self.name(a), self.name(b)]));
                    }
                }
            }
        }
        for p in [
            "grasped",
            "open",
            "unlocked",
            "upright",
            "near robot",
            "location known",
            "clean",
        ]
        .into_iter()
        .filter(|p| known(p))
        {
            for a in 0..n {
                if self.holds(p, &[a]) {
                    out.push(Atom::new(p, [self.name(a)]));
                }
            }
        }
        out.sort();
        out.into_iter().map(Condition::pos).collect()
    }
}
