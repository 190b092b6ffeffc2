//! What carries out a running tree's actions, and betr's world as the twin that predicts.
//!
//! By default the execution world performs the actions itself: the cell moves its arms and
//! its solids, and what it computes is what happens. An [`Executor`] is anything else that
//! performs them — another simulator, a robot — behind one interface that names no
//! transport: betr sends an [`ActionOrder`] (the action, and the joint path it planned for
//! the arm when there is one), the executor reports progress tick by tick (`Running`,
//! `Success`, or `Failure` with its own error text) and, when asked, an [`Observation`]
//! (the objects' poses, what the gripper holds).
//!
//! With an executor, betr's execution world becomes the twin ([`Reality`]): before an
//! action is sent, a copy of the twin performs it to predict it (an action the twin
//! refuses — no collision-free path — is never sent, as a robot's own motion planner
//! refuses before moving); the order carries the twin's planned path. When the executor
//! reports the action's end, the twin takes the predicted state and then what the executor
//! observed, so every condition is computed from reality's poses by the twin's geometry.
//! An action the twin predicted to succeed that fails in reality, or completes without its
//! declared effects, is a [`Divergence`], told to the person beside the failure.
//!
//! Writing an executor for a new simulator or robot: implement the five methods; an action
//! that takes time returns `Running` until it ends (a real arm does); `Failure` text is
//! what the person and the model read ("No collision free path found", "the grasp closed
//! on nothing"); an `Err` means the executor itself broke (stopped answering, crashed), and
//! stops the run instead of being repaired.

use std::collections::{BTreeSet, HashMap};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::bt::{ActionStep, Leaves, NodeId};
use crate::domain::{ActionCall, Condition, Domain};
use crate::planner::postcondition_failure;
use crate::world::cell::snapshot::SceneSnapshot;
use crate::world::observation::ObservedObject;
use crate::world::{CellWorld, Observation, ObservationError, SceneDescription, Step, World};

pub mod mujoco;
pub mod process;
pub use process::ProcessExecutor;

/// Performs actions somewhere other than betr's own world.
pub trait Executor: Send {
    /// A short name for messages (`mujoco`, `robot`, a process's name).
    fn name(&self) -> &str;
    /// Start (`started`) or continue the action `order` describes; called once per tick
    /// while the tree runs it.
    fn perform(&mut self, order: &ActionOrder, started: bool) -> Result<Step, ExecutorError>;
    /// Stop the action, which the tree no longer runs.
    fn halt(&mut self, action: &ActionCall) -> Result<(), ExecutorError>;
    /// What it sees now.
    fn observe(&mut self) -> Result<Observation, ExecutorError>;
    /// Back to the scenario's first state (a simulator), or refuse (a robot cannot).
    fn reset(&mut self) -> Result<(), ExecutorError>;
    /// The scene to simulate, once before the first action: a simulator builds its world
    /// from it. A robot, or a simulator with its own world, takes it as it is.
    fn load(&mut self, scene: &SceneDescription) -> Result<(), ExecutorError> {
        let _ = scene;
        Ok(())
    }
}

/// One action sent to an executor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ActionOrder {
    /// The skill, its objects and its parameter values (`place "blue cube" "green cube"`).
    pub action: ActionCall,
    /// The joint path the twin planned for the arm, when the action moves one.
    pub path: Option<ArmPath>,
    /// What the twin expects to observe once the action has ended (where a place puts
    /// the object: the target a robot's skill takes), when the twin has geometry.
    pub expected: Option<Observation>,
}

/// An arm's planned way: joint values (radians) from where the arm is to where it ends.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArmPath {
    /// The arm's name in the robot description (its flange link).
    pub arm: String,
    /// Where the robot's root stands while the arm moves (x, y in metres).
    pub base: [f32; 2],
    pub joints: Vec<Vec<f64>>,
    /// The index in `joints` where the fingers close or open.
    pub acts_at: usize,
}

/// The executor itself failed; no action result can be trusted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExecutorError {
    #[error("the {executor} executor stopped: {detail}")]
    Stopped { executor: String, detail: String },
    #[error("the {executor} executor cannot build the scene: {detail}")]
    Load { executor: String, detail: String },
    #[error("the {executor} executor's observation was refused: {source}")]
    Observation {
        executor: String,
        source: ObservationError,
    },
}

/// What the twin predicted and reality did otherwise.
#[derive(Debug, Clone, PartialEq)]
pub struct Divergence {
    pub action: ActionCall,
    /// What reality reported instead of the predicted success.
    pub reality: String,
    /// The twin's scene as it predicted the action would leave it (a cell twin).
    pub predicted: Option<Arc<SceneSnapshot>>,
}

/// A divergence in words, naming the executor that reported it (as an event carries it).
pub fn describe_divergence(action: &ActionCall, executor: &str, reality: &str) -> String {
    format!(
        "the twin predicted {action}! would succeed; the {executor} executor reports: {reality}"
    )
}

/// What one tick over an executor found besides the tick's own record.
#[derive(Debug, Default)]
pub struct Findings {
    /// Actions the twin predicted to succeed that reality did not.
    pub diverged: Vec<Divergence>,
    /// The executor broke during the tick (every later action of the tick fails with it).
    pub broken: Option<ExecutorError>,
    /// Objects whose first-state pose reality showed otherwise than the scene.
    pub learned: Vec<String>,
}

/// An executor with what the twin predicted of each action it is performing, and what
/// reality has shown of the scene's first state.
pub struct Reality {
    executor: Box<dyn Executor>,
    pending: HashMap<NodeId, Pending>,
    /// The objects the robot may have moved since the first state: those it has held and
    /// those of the actions that succeeded. A grasp that closed on nothing moved nothing
    /// (where reality shows that object is where it was from the start).
    touched: BTreeSet<String>,
    /// Poses reality showed of objects the robot had not moved: where they were in the first
    /// state, unlike what the scenario's scene says. The twin starts from these after a
    /// reset, and the planning world takes them in, so repairs are screened in them.
    learned: Observation,
}

struct Pending {
    order: ActionOrder,
    /// The twin as it will be when the action has ended as predicted.
    prediction: Box<dyn World>,
}

impl Reality {
    /// `executor` as reality beside `twin`: a twin with geometry gives it its scene, as
    /// `[world.reality]` says reality differs from it.
    pub fn start(
        mut executor: Box<dyn Executor>,
        twin: &dyn World,
    ) -> Result<Reality, ExecutorError> {
        if let Some(cell) = CellWorld::of(twin) {
            let scene = cell
                .reality_description()
                .map_err(|detail| ExecutorError::Load {
                    executor: executor.name().to_string(),
                    detail: detail.to_string(),
                })?;
            executor.load(&scene)?;
        }
        Ok(Reality::new(executor))
    }

    pub fn new(executor: Box<dyn Executor>) -> Reality {
        Reality {
            executor,
            pending: HashMap::new(),
            touched: BTreeSet::new(),
            learned: Observation::default(),
        }
    }

    /// Poses reality showed of objects the robot had not touched: the first state as it
    /// really was, where betr's scene had it otherwise.
    pub fn learned(&self) -> &Observation {
        &self.learned
    }

    /// Keep the poses of `observation`'s untouched objects that differ from `before`'s
    /// (the twin's before it took the observation in); their names.
    fn learn(&mut self, observation: &Observation, before: &Observation) -> Vec<String> {
        // What the gripper holds may have been moved by it from now on.
        self.touched.extend(observation.held.iter().cloned());
        let mut names = Vec::new();
        for seen in &observation.objects {
            if self.touched.contains(&seen.name) {
                continue;
            }
            let moved = before
                .objects
                .iter()
                .find(|b| b.name == seen.name)
                .is_none_or(|b| !near(b, seen));
            if !moved {
                continue;
            }
            self.learned.objects.retain(|l| l.name != seen.name);
            self.learned.objects.push(seen.clone());
            names.push(seen.name.clone());
        }
        names
    }

    pub fn name(&self) -> &str {
        self.executor.name()
    }

    /// Back to the first state: nothing pending or touched, the executor reset, and
    /// `twin` (reloaded from the scenario) given the poses reality showed of it.
    pub fn reset(&mut self, twin: &mut dyn World) -> Result<(), ExecutorError> {
        self.pending.clear();
        self.touched.clear();
        self.executor.reset()?;
        if self.learned.objects.is_empty() {
            return Ok(());
        }
        twin.take_observation(&self.learned)
            .map_err(|source| ExecutorError::Observation {
                executor: self.executor.name().to_string(),
                source,
            })
    }

    /// The leaves a tick runs against: conditions asked of `twin`, actions performed here.
    pub fn leaves<'a>(
        &'a mut self,
        twin: &'a mut Box<dyn World>,
        domain: &'a Domain,
    ) -> RealityLeaves<'a> {
        RealityLeaves {
            reality: self,
            twin,
            domain,
            found: Findings::default(),
        }
    }
}

/// One tick's leaves over a twin and an executor, with what the tick found.
pub struct RealityLeaves<'a> {
    reality: &'a mut Reality,
    twin: &'a mut Box<dyn World>,
    domain: &'a Domain,
    /// What the tick found so far.
    pub found: Findings,
}

impl RealityLeaves<'_> {
    fn broke(&mut self, error: ExecutorError) -> ActionStep {
        let text = error.to_string();
        self.found.broken = Some(error);
        ActionStep::Failure(text)
    }

    /// What `observation` shows of the first state where the twin had it otherwise
    /// (`before`: the twin's own view, none for a world without geometry).
    fn learn(&mut self, observation: &Observation, before: Option<Observation>) {
        if let Some(before) = before {
            let learned = self.reality.learn(observation, &before);
            self.found.learned.extend(learned);
        }
    }

    /// The action has ended in reality, in success or with the executor's error; the
    /// twin takes in what happened.
    fn ended(&mut self, node: NodeId, action: &ActionCall, failed: Option<String>) -> ActionStep {
        let Some(pending) = self.reality.pending.remove(&node) else {
            return ActionStep::Failure(format!("{action}! ended without being started"));
        };
        let executor = self.reality.executor.as_mut();
        // The scene the twin predicted, drawn beside reality's when they differ.
        let predicted = CellWorld::scene_of(pending.prediction.as_ref()).map(Arc::new);
        let reality = match failed {
            None => {
                // What the twin expected afterwards is what it sent with the order.
                let (mut prediction, before) = (pending.prediction, pending.order.expected);
                let observation = match take_in(executor, prediction.as_mut()) {
                    Ok(observation) => observation,
                    Err(e) => return self.broke(e),
                };
                // An action that did what it should may have moved its objects.
                self.reality.touched.extend(action.args.iter().cloned());
                self.learn(&observation, before);
                *self.twin = prediction;
                match postcondition_failure(self.domain, self.twin.as_ref(), action) {
                    Some(error) => error,
                    None => return ActionStep::Success,
                }
            }
            Some(error) => {
                let before = CellWorld::of(self.twin.as_ref()).map(CellWorld::observation);
                let observation = match take_in(executor, self.twin.as_mut()) {
                    Ok(observation) => observation,
                    Err(e) => return self.broke(e),
                };
                self.learn(&observation, before);
                error
            }
        };
        self.found.diverged.push(Divergence {
            action: action.clone(),
            reality: reality.clone(),
            predicted,
        });
        ActionStep::Failure(reality)
    }
}

impl Leaves for RealityLeaves<'_> {
    fn check(&mut self, condition: &Condition) -> bool {
        self.twin.check(condition)
    }

    fn step(&mut self, node: NodeId, action: &ActionCall, started: bool) -> ActionStep {
        if let Some(error) = &self.found.broken {
            return ActionStep::Failure(error.to_string());
        }
        let fresh = started || !self.reality.pending.contains_key(&node);
        if fresh {
            match predict(self.twin.as_ref(), action, self.domain) {
                Prediction::Succeeds(prediction) => {
                    let order = ActionOrder {
                        action: action.clone(),
                        path: planned_path(self.twin.as_ref(), prediction.as_ref()),
                        expected: CellWorld::of(prediction.as_ref()).map(CellWorld::observation),
                    };
                    self.reality
                        .pending
                        .insert(node, Pending { order, prediction });
                }
                Prediction::Refused(refusal) => {
                    self.reality.pending.remove(&node);
                    return ActionStep::Failure(refusal);
                }
            }
        }
        let Some(pending) = self.reality.pending.get(&node) else {
            return ActionStep::Failure(format!("{action}! was not predicted"));
        };
        match self.reality.executor.perform(&pending.order, fresh) {
            Err(e) => {
                self.reality.pending.remove(&node);
                self.broke(e)
            }
            Ok(Step::Running) => ActionStep::Running,
            Ok(Step::Success) => self.ended(node, action, None),
            Ok(Step::Failure(error)) => self.ended(node, action, Some(error)),
        }
    }

    fn halt(&mut self, node: NodeId, action: &ActionCall) {
        if self.reality.pending.remove(&node).is_none() {
            return;
        }
        if let Err(e) = self.reality.executor.halt(action) {
            self.found.broken.get_or_insert(e);
        }
    }
}

/// `world` takes in what the executor sees now (and it is returned), or is left as it was.
fn take_in(
    executor: &mut dyn Executor,
    world: &mut dyn World,
) -> Result<Observation, ExecutorError> {
    let observation = executor.observe()?;
    world
        .take_observation(&observation)
        .map_err(|source| ExecutorError::Observation {
            executor: executor.name().to_string(),
            source,
        })?;
    Ok(observation)
}

/// Positions this close (metres) are the same place: reality's poses are measured.
const SAME_PLACE: f32 = 0.005;

fn near(a: &ObservedObject, b: &ObservedObject) -> bool {
    let d2: f32 = a
        .position
        .iter()
        .zip(&b.position)
        .map(|(x, y)| (x - y) * (x - y))
        .sum();
    d2.sqrt() <= SAME_PLACE
}

/// What the twin says of an action before it is sent.
enum Prediction {
    /// The twin as it will be when the action has ended.
    Succeeds(Box<dyn World>),
    /// The error the twin refuses it with (no path, a postcondition it would not meet).
    Refused(String),
}

/// The twin's prediction of `action`, performed to its end in a copy of it.
fn predict(twin: &dyn World, action: &ActionCall, domain: &Domain) -> Prediction {
    let mut prediction = twin.fork();
    let ticks = domain.resolve(action).map_or(1, |g| g.ticks.max(1));
    for tick in 0..ticks {
        match prediction.step(action, tick == 0) {
            Step::Running => continue,
            Step::Failure(error) => return Prediction::Refused(error),
            Step::Success => {
                return match postcondition_failure(domain, prediction.as_ref(), action) {
                    Some(error) => Prediction::Refused(error),
                    None => Prediction::Succeeds(prediction),
                };
            }
        }
    }
    Prediction::Refused(format!(
        "{action}! did not end in the twin after {ticks} ticks"
    ))
}

/// The arm motion the prediction made, when the action moved an arm (a cell with real
/// arms whose last motion changed).
fn planned_path(twin: &dyn World, prediction: &dyn World) -> Option<ArmPath> {
    let motion = |w: &dyn World| CellWorld::of(w)?.last_motion();
    let (arm, made) = motion(prediction)?;
    if motion(twin).is_some_and(|(_, before)| before == made) {
        return None;
    }
    Some(ArmPath {
        arm,
        base: CellWorld::of(prediction)?.base(),
        joints: made.path,
        acts_at: made.acts_at,
    })
}

#[cfg(test)]
mod tests;
