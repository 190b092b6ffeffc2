//! The twin and an executor that is not the cell: actions that take several ticks, orders
//! that carry the twin's prediction, reality's poses taken into the twin's facts, and the
//! divergences and breakdowns a tick reports.

use std::path::Path;
use std::sync::{Arc, Mutex};

use super::*;
use crate::bt::{NodeKind, Outcome, Ticker, Tree};
use crate::scenario::Scenario;

fn scenario() -> Scenario {
    Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml"))
        .unwrap()
}

fn twin(variant: Option<&str>) -> Box<dyn World> {
    Box::new(CellWorld::from_scenario(&scenario(), variant).unwrap())
}

/// What the scripted executor was asked and how it answers.
#[derive(Default)]
struct Script {
    /// Ticks each action runs before it ends.
    ticks: u32,
    /// The error each skill fails with, instead of succeeding.
    fails: Vec<(String, String)>,
    /// What it reports seeing (empty objects: nothing moved as far as it knows).
    seen: Observation,
    orders: Vec<(ActionOrder, bool)>,
    halted: Vec<ActionCall>,
    broken: bool,
}

/// An executor that performs from a script: every action runs `ticks` ticks.
struct Scripted {
    script: Arc<Mutex<Script>>,
    done: u32,
}

impl Executor for Scripted {
    fn name(&self) -> &str {
        "scripted"
    }

    fn perform(&mut self, order: &ActionOrder, started: bool) -> Result<Step, ExecutorError> {
        let mut script = self.script.lock().unwrap();
        if script.broken {
            return Err(ExecutorError::Stopped {
                executor: "scripted".into(),
                detail: "no answer in 2 s".into(),
            });
        }
        script.orders.push((order.clone(), started));
        if started {
            self.done = 0;
        }
        self.done += 1;
        if self.done < script.ticks {
            return Ok(Step::Running);
        }
        Ok(
            match script.fails.iter().find(|(s, _)| *s == order.action.skill) {
                Some((_, error)) => Step::Failure(error.clone()),
                None => Step::Success,
            },
        )
    }

    fn halt(&mut self, action: &ActionCall) -> Result<(), ExecutorError> {
        self.script.lock().unwrap().halted.push(action.clone());
        Ok(())
    }

    fn observe(&mut self) -> Result<Observation, ExecutorError> {
        Ok(self.script.lock().unwrap().seen.clone())
    }

    fn reset(&mut self) -> Result<(), ExecutorError> {
        self.done = 0;
        Ok(())
    }
}

fn reality(script: &Arc<Mutex<Script>>) -> Reality {
    Reality::new(Box::new(Scripted {
        script: script.clone(),
        done: 0,
    }))
}

fn action(text: &str) -> ActionCall {
    ActionCall::parse(text).unwrap()
}

fn holds(world: &dyn World, condition: &str) -> bool {
    world.check(&Condition::parse(condition).unwrap())
}

/// A tree of one action.
fn one_action(text: &str) -> Tree {
    Tree::new(NodeKind::Action(action(text)))
}

/// A tree of one grasp (of the blue cube) ticked over `script`'s executor and a twin.
struct Grasping {
    reality: Reality,
    twin: Box<dyn World>,
    scenario: Scenario,
    tree: Tree,
    ticker: Ticker,
}

impl Grasping {
    /// The twin of the scenario's `variant`.
    fn new(script: &Arc<Mutex<Script>>, variant: Option<&str>) -> Grasping {
        Grasping {
            reality: reality(script),
            twin: twin(variant),
            scenario: scenario(),
            tree: one_action(r#"grasp "blue cube""#),
            ticker: Ticker::new(),
        }
    }

    /// One tick: its record, and what it found.
    fn tick(&mut self) -> (crate::bt::TickRecord, Findings) {
        let mut leaves = self.reality.leaves(&mut self.twin, &self.scenario.domain);
        let record = self.ticker.tick(&self.tree, &mut leaves);
        (record, leaves.found)
    }

    fn holds(&self, condition: &str) -> bool {
        holds(self.twin.as_ref(), condition)
    }
}

#[test]
fn an_action_runs_for_the_executors_ticks_then_the_twin_takes_its_result() {
    // It sees the cube in the gripper afterwards (and reports no poses: none moved).
    let script = Arc::new(Mutex::new(Script {
        ticks: 5,
        seen: Observation {
            objects: Vec::new(),
            held: Some("blue cube".into()),
        },
        ..Script::default()
    }));
    let mut grasping = Grasping::new(&script, Some("clear"));
    let mut roots = Vec::new();
    for _ in 0..5 {
        let (record, found) = grasping.tick();
        roots.push(record.root);
        assert!(found.diverged.is_empty() && found.broken.is_none());
        if roots.last() == Some(&Outcome::Running) {
            assert!(
                !grasping.holds(r#""blue cube" grasped"#),
                "not before it ends"
            );
        }
    }
    assert_eq!(roots[..4], [Outcome::Running; 4]);
    assert_eq!(roots[4], Outcome::Success);
    assert!(grasping.holds(r#""blue cube" grasped"#));
    let script = script.lock().unwrap();
    let started: Vec<bool> = script.orders.iter().map(|(_, s)| *s).collect();
    assert_eq!(started, [true, false, false, false, false]);
    assert_eq!(script.orders[0].0.action, action(r#"grasp "blue cube""#));
}

#[test]
fn an_action_the_twin_refuses_is_never_sent() {
    let script = Arc::new(Mutex::new(Script {
        ticks: 1,
        ..Script::default()
    }));
    // The red cube lies on the blue cube: the gripper's way down is blocked in the twin.
    let (record, found) = Grasping::new(&script, None).tick();
    assert_eq!(record.root, Outcome::Failure);
    assert!(found.diverged.is_empty(), "the twin itself predicted it");
    assert!(script.lock().unwrap().orders.is_empty());
}

#[test]
fn reality_failing_what_the_twin_predicted_is_a_divergence_and_its_poses_become_facts() {
    // Reality: the red cube lies on the blue cube, where the twin (the camera's scene)
    // has it on the table; the grasp fails and the executor sees the red cube on top.
    let truth = CellWorld::from_scenario(&scenario(), None).unwrap();
    let script = Arc::new(Mutex::new(Script {
        ticks: 2,
        fails: vec![("grasp".into(), "No collision free path found".into())],
        seen: truth.observation(),
        ..Script::default()
    }));
    let mut grasping = Grasping::new(&script, Some("clear"));
    assert!(!grasping.holds(r#""red cube" on "blue cube""#));
    assert_eq!(grasping.tick().0.root, Outcome::Running);
    let (record, found) = grasping.tick();
    assert_eq!(record.root, Outcome::Failure);
    assert_eq!(record.failures[0].1, "No collision free path found");
    let divergence = &found.diverged[0];
    assert_eq!(
        describe_divergence(&divergence.action, "scripted", &divergence.reality),
        "the twin predicted grasp \"blue cube\"! would succeed; the scripted executor reports: No collision free path found"
    );
    assert!(grasping.holds(r#""red cube" on "blue cube""#));
}

#[test]
fn an_action_that_ends_without_its_effects_fails_by_its_postcondition() {
    // The executor reports success but sees the blue cube still on the table, not held.
    let start = CellWorld::from_scenario(&scenario(), Some("clear")).unwrap();
    let script = Arc::new(Mutex::new(Script {
        ticks: 1,
        seen: start.observation(),
        ..Script::default()
    }));
    let (record, found) = Grasping::new(&script, Some("clear")).tick();
    assert_eq!(
        record.failures[0].1,
        "Postcondition \"blue cube\" grasped not met after grasp action completion"
    );
    assert_eq!(found.diverged.len(), 1);
}

#[test]
fn an_executor_that_breaks_stops_the_tick_without_a_result() {
    let script = Arc::new(Mutex::new(Script {
        ticks: 1,
        broken: true,
        ..Script::default()
    }));
    let mut grasping = Grasping::new(&script, Some("clear"));
    let (record, found) = grasping.tick();
    assert_eq!(record.root, Outcome::Failure);
    assert!(record.completed.is_empty());
    assert_eq!(
        found.broken.as_ref().map(ToString::to_string).as_deref(),
        Some("the scripted executor stopped: no answer in 2 s")
    );
    assert!(!grasping.holds(r#""blue cube" grasped"#));
}

#[test]
fn an_observation_naming_an_unknown_object_changes_nothing() {
    let script = Arc::new(Mutex::new(Script {
        ticks: 1,
        seen: Observation {
            objects: vec![ObservedObject {
                name: "purple cube".into(),
                position: [0.0; 3],
                rotation: [0.0, 0.0, 0.0, 1.0],
            }],
            held: None,
        },
        ..Script::default()
    }));
    let mut grasping = Grasping::new(&script, Some("clear"));
    let before = grasping.twin.facts();
    let (_, found) = grasping.tick();
    assert_eq!(
        found.broken.as_ref().map(ToString::to_string).as_deref(),
        Some(
            "the scripted executor's observation was refused: the observation names \"purple cube\", which is not an object of this scene"
        )
    );
    // Neither the prediction nor the refused observation was taken.
    assert_eq!(grasping.twin.facts(), before);
}

#[test]
fn a_halted_action_is_halted_in_reality() {
    let script = Arc::new(Mutex::new(Script {
        ticks: 5,
        ..Script::default()
    }));
    let mut grasping = Grasping::new(&script, Some("clear"));
    grasping.tick();
    let Grasping {
        reality,
        twin,
        scenario,
        tree,
        ticker,
    } = &mut grasping;
    ticker.halt_all(tree, &mut reality.leaves(twin, &scenario.domain));
    assert_eq!(
        script.lock().unwrap().halted,
        [action(r#"grasp "blue cube""#)]
    );
}
