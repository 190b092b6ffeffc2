//! Simulated worlds the planner ticks trees against, and that stand in for the robot.
//!
//! A world answers whether a condition holds, advances an action by one tick (Running,
//! Success, or Failure with the error text the skill reports), and can be copied so the
//! planner can try a tree without touching the world it will run in. It knows nothing of
//! behavior trees or language models.

pub mod cell;
pub mod description;
pub mod observation;
pub mod symbolic;

use std::any::Any;

use crate::domain::{ActionCall, Condition};
use crate::scenario::{Scenario, ScenarioError};

pub use cell::CellWorld;
pub use cell::skills::DISAGREEMENT_NOTE;
pub use description::{Perturbations, SceneDescription};
pub use observation::{Observation, ObservationError};
pub use symbolic::SymbolicWorld;

/// The result of advancing an action by one tick.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    /// The action needs more ticks.
    Running,
    /// The action completed.
    Success,
    /// The action failed; the text is what the skill reports ("No collision free path found").
    Failure(String),
}

/// An opaque copy of a world's state, for `World::restore`.
pub struct Snapshot(Box<dyn Any + Send>);

impl Snapshot {
    pub fn new<T: Any + Send>(state: T) -> Self {
        Snapshot(Box::new(state))
    }

    pub fn get<T: Any>(&self) -> Option<&T> {
        self.0.downcast_ref()
    }
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WorldError {
    #[error("this snapshot was taken from a different kind of world")]
    ForeignSnapshot,
}

pub trait World: Send {
    /// A short name of the simulator (`symbolic`, `cell`).
    fn kind(&self) -> &'static str;
    /// Whether the condition holds now (`"any object"`: for some object; negated: for none).
    fn check(&self, condition: &Condition) -> bool;
    /// Advance `action` by one tick. `started` is true on the first tick of a new run of it.
    fn step(&mut self, action: &ActionCall, started: bool) -> Step;
    /// Stop `action` if it is running; harmless otherwise.
    fn halt(&mut self, action: &ActionCall);
    /// An independent copy, for trying trees without side effects.
    fn fork(&self) -> Box<dyn World>;
    fn snapshot(&self) -> Snapshot;
    fn restore(&mut self, snapshot: &Snapshot) -> Result<(), WorldError>;
    /// The atoms true now, as conditions, in a stable order (for display and prompts).
    fn facts(&self) -> Vec<Condition>;
    /// Take in what an executor observed (objects' poses, what the gripper holds), all or
    /// nothing; the facts are then computed from it. Only a world with geometry can.
    fn take_observation(&mut self, _observation: &Observation) -> Result<(), ObservationError> {
        Err(ObservationError::NoGeometry(self.kind()))
    }
    /// The world itself, for front ends that draw one kind of world (the 3D view reads
    /// the cell's scene through it: `CellWorld::scene_of`). `None` unless a world opts in.
    fn as_any(&self) -> Option<&dyn Any> {
        None
    }
}

/// Build the world a scenario describes.
pub fn load(scenario: &Scenario) -> Result<Box<dyn World>, ScenarioError> {
    load_variant(scenario, None)
}

/// The world a tree runs in (the one a person steps), and what to tell them about it once.
pub struct Execution {
    pub world: Box<dyn World>,
    /// Why the cell moves its abstraction instead of the robot's real arms, when it does.
    pub notice: Option<String>,
}

/// Build the world a scenario's tree runs in: the cell moves its robot's real arms when
/// the scenario names a robot description that is in the cache (planning worlds keep the
/// reach spheres and the gripper sweep: [`load_variant`]); otherwise, with a notice, the
/// same world as [`load_variant`].
pub fn load_execution(
    scenario: &Scenario,
    variant: Option<&str>,
) -> Result<Execution, ScenarioError> {
    if scenario.world_kind != "cell" {
        return Ok(Execution {
            world: load_variant(scenario, variant)?,
            notice: None,
        });
    }
    let cell = CellWorld::from_scenario(scenario, variant)?;
    Ok(match cell.arms_availability() {
        cell::arms::ArmsAvailability::Real(arms) => Execution {
            world: Box::new(cell.moving_arms(arms)),
            notice: None,
        },
        cell::arms::ArmsAvailability::NotAsked => Execution {
            world: Box::new(cell),
            notice: None,
        },
        cell::arms::ArmsAvailability::Abstract(why) => {
            tracing::warn!("{why}");
            Execution {
                world: Box::new(cell),
                notice: Some(why),
            }
        }
    })
}

/// The robot description a scenario's cell moves its arms with, when the scenario names
/// one and it is not in the cache yet (a front end fetches it; the world meanwhile keeps
/// the reach spheres and gripper sweep). None for other worlds, and for a cell whose
/// scene cannot be read (loading it says why).
pub fn missing_description(scenario: &Scenario) -> Option<&'static crate::model::DescriptionSpec> {
    if scenario.world_kind != "cell" {
        return None;
    }
    let scene = cell::scene::read(scenario, None).ok()?;
    let description = scene.robot.arms.as_ref()?.description;
    (!description.urdf_in(&description.path()).is_file()).then_some(description)
}

/// Build the world a scenario describes, changed by its `[world.variants.NAME]` table when
/// `variant` names one (the same scene without an obstacle, say). Only the cell has
/// variants.
pub fn load_variant(
    scenario: &Scenario,
    variant: Option<&str>,
) -> Result<Box<dyn World>, ScenarioError> {
    let error = |message: String| ScenarioError {
        file: scenario
            .files
            .last()
            .map(|f| f.path.clone())
            .unwrap_or_default(),
        line: 0,
        column: 0,
        message,
    };
    match (scenario.world_kind.as_str(), variant) {
        ("symbolic", None) => Ok(Box::new(SymbolicWorld::from_scenario(scenario)?)),
        ("symbolic", Some(v)) => Err(error(format!(
            "the symbolic world has no variants (asked for {v:?})"
        ))),
        ("cell", v) => Ok(Box::new(CellWorld::from_scenario(scenario, v)?)),
        (other, _) => Err(error(format!(
            "unknown world kind {other:?} (known: symbolic, cell)"
        ))),
    }
}
