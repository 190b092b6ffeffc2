//! The executor seam through the engine: scenario 1's actions performed by a small
//! executor that is not the cell (`SlowArm`: cubes as points with a 4 cm height, each
//! action taking four ticks), with betr's cell as the twin. An action runs across ticks
//! and then ends; a grasp reality refuses where the twin predicted it free reaches the
//! question and the proposal, the scene takes in where the object in the way really lay,
//! and the approved change clears it in reality; an executor that stops answering stops
//! the run without a repair. The same through a process speaking the JSON-lines protocol
//! (tests/fixtures/executor/follower.py), and that process's faults named.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use betr::bt::{self, NodeKind, Status};
use betr::domain::{ActionCall, Condition};
use betr::executor::{ActionOrder, ArmPath, Executor, ExecutorError, ProcessExecutor};
use betr::session::{Command, Event, Setup};
use betr::world::Observation;
use betr::world::Step;
use betr::world::observation::ObservedObject;
use support::engine::{INSTRUCTION, Session, fix_inserted, model, setup, tree_of};
use support::repo::runtime as rt;

const CUBE: f32 = 0.04;
const TICKS: u32 = 4;

/// Reality as the executor keeps it: each cube's footprint centre, what the gripper holds.
#[derive(Clone, Default)]
struct Cubes {
    at: BTreeMap<String, [f32; 3]>,
    held: Option<String>,
}

impl Cubes {
    /// Scenario 1's cubes, the red one on the blue one (`red_on_blue`) or on the table.
    fn scenario_1(red_on_blue: bool) -> Cubes {
        let red = if red_on_blue {
            [0.35, 0.12, CUBE]
        } else {
            [0.45, 0.0, 0.0]
        };
        Cubes {
            at: [
                ("blue cube".to_string(), [0.35, 0.12, 0.0]),
                ("green cube".to_string(), [0.35, -0.12, 0.0]),
                ("red cube".to_string(), red),
            ]
            .into(),
            held: None,
        }
    }

    /// Whether another cube rests on `name`.
    fn covered(&self, name: &str) -> bool {
        let Some(p) = self.at.get(name) else {
            return false;
        };
        self.at.iter().any(|(other, q)| {
            other != name
                && self.held.as_deref() != Some(other)
                && (q[0] - p[0]).hypot(q[1] - p[1]) < CUBE / 2.0
                && (q[2] - p[2] - CUBE).abs() < 0.005
        })
    }

    fn observation(&self) -> Observation {
        Observation {
            objects: self
                .at
                .iter()
                .map(|(name, position)| ObservedObject {
                    name: name.clone(),
                    position: *position,
                    rotation: [0.0, 0.0, 0.0, 1.0],
                })
                .collect(),
            held: self.held.clone(),
        }
    }
}

/// A small arm that takes `TICKS` ticks per action, grasps what nothing lies on, and puts
/// down where the twin's order expects the object.
struct SlowArm {
    start: Cubes,
    now: Cubes,
    done: u32,
    answers: bool,
    orders: Arc<Mutex<Vec<ActionCall>>>,
}

impl SlowArm {
    fn new(start: Cubes) -> SlowArm {
        SlowArm {
            now: start.clone(),
            start,
            done: 0,
            answers: true,
            orders: Arc::default(),
        }
    }

    /// The action's end in this reality.
    fn end(&mut self, order: &ActionOrder) -> Step {
        let action = &order.action;
        let object = action.args.first().cloned().unwrap_or_default();
        match action.skill.as_str() {
            "grasp" if self.now.covered(&object) => {
                Step::Failure("No collision free path found".into())
            }
            "grasp" => {
                self.now.held = Some(object);
                Step::Success
            }
            "place" => {
                let target = order
                    .expected
                    .as_ref()
                    .and_then(|e| e.objects.iter().find(|o| o.name == object));
                match target {
                    Some(t) => {
                        self.now.at.insert(object, t.position);
                        self.now.held = None;
                        Step::Success
                    }
                    None => Step::Failure(format!("no place given for {object}")),
                }
            }
            other => Step::Failure(format!("this arm cannot {other}")),
        }
    }
}

impl Executor for SlowArm {
    fn name(&self) -> &str {
        "slow-arm"
    }

    fn perform(&mut self, order: &ActionOrder, started: bool) -> Result<Step, ExecutorError> {
        if !self.answers {
            return Err(ExecutorError::Stopped {
                executor: "slow-arm".into(),
                detail: "no answer in 2 s".into(),
            });
        }
        if started {
            self.done = 0;
            self.orders.lock().unwrap().push(order.action.clone());
        }
        self.done += 1;
        if self.done < TICKS {
            return Ok(Step::Running);
        }
        Ok(self.end(order))
    }

    fn halt(&mut self, _action: &ActionCall) -> Result<(), ExecutorError> {
        Ok(())
    }

    fn observe(&mut self) -> Result<Observation, ExecutorError> {
        Ok(self.now.observation())
    }

    fn reset(&mut self) -> Result<(), ExecutorError> {
        self.now = self.start.clone();
        self.done = 0;
        Ok(())
    }
}

/// The facts of the latest world change among `events`.
fn facts_now(events: &[Event]) -> Option<Vec<Condition>> {
    events.iter().rev().find_map(|e| match e {
        Event::WorldChanged { facts, .. } => Some(facts.clone()),
        _ => None,
    })
}

/// Submit scenario 1's instruction and run the tree once it is planned.
async fn submit_and_run(s: &mut Session) {
    s.send(Command::Submit(INSTRUCTION.into()));
    s.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
        .await;
    s.send(Command::Run);
}

/// Scenario 1 with the twin in the `clear` variant (the red cube on the table) and `arm`
/// performing the actions.
fn session(arm: SlowArm) -> Session {
    let setup = Setup {
        variant: Some("clear".into()),
        executor: Some(Box::new(arm)),
        ..setup(Ok(Arc::new(model(Duration::ZERO))), None)
    };
    Session::start(setup)
}

fn grasp_node(tree: &bt::Tree) -> bt::NodeId {
    let grasp = ActionCall::parse(r#"grasp "blue cube""#).unwrap();
    tree.find(r#"grasp "blue cube""#)
        .unwrap()
        .into_iter()
        .find(|n| matches!(tree.kind(*n), Ok(NodeKind::Action(a)) if *a == grasp))
        .unwrap()
}

#[test]
fn an_action_runs_for_the_executors_ticks_and_the_run_succeeds() {
    rt().block_on(async {
        let arm = SlowArm::new(Cubes::scenario_1(false));
        let orders = arm.orders.clone();
        let mut s = session(arm);
        submit_and_run(&mut s).await;
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        let tree = tree_of(&s.seen).unwrap().0;
        let grasp = grasp_node(&tree);
        let statuses: Vec<Status> = s
            .seen
            .iter()
            .filter_map(|e| match e {
                Event::Ticked { record } => Some(record.status(grasp)),
                _ => None,
            })
            .filter(|s| *s != Status::Idle)
            .collect();
        // The twin's grasp takes 3 ticks; reality's takes 4, and reality decides.
        assert_eq!(
            statuses[..4],
            [
                Status::Running,
                Status::Running,
                Status::Running,
                Status::Success
            ]
        );
        let sent: Vec<String> = orders
            .lock()
            .unwrap()
            .iter()
            .map(|a| a.to_string())
            .collect();
        assert_eq!(
            sent,
            [r#"grasp "blue cube""#, r#"place "blue cube" "green cube""#]
        );
        let facts = facts_now(&s.seen);
        let on = Condition::parse(r#""blue cube" on "green cube""#).unwrap();
        assert!(
            facts.unwrap().contains(&on),
            "reality's poses, read by the twin"
        );
    });
}

#[test]
fn a_grasp_reality_refuses_is_repaired_in_the_scene_reality_showed_and_then_succeeds() {
    rt().block_on(async {
        // The camera's scene (the twin) has the red cube on the table; in reality it lies
        // on the blue cube.
        let arm = SlowArm::new(Cubes::scenario_1(true));
        let orders = arm.orders.clone();
        let mut s = session(arm);
        submit_and_run(&mut s).await;
        s.until("the proposal", |e| matches!(e, Event::Proposal { .. }))
            .await;
        let failed = s.seen.iter().find_map(|e| match e {
            Event::ActionFailed { action, error, .. } => Some(format!("{action}: {error}")),
            _ => None,
        });
        assert_eq!(
            failed.as_deref(),
            Some(r#"grasp "blue cube": No collision free path found"#)
        );
        let told: Vec<String> = s
            .seen
            .iter()
            .filter(|e| matches!(e, Event::Executor { .. } | Event::Diverged { .. }))
            .flat_map(betr::record::describe)
            .collect();
        assert_eq!(
            told,
            [
                "the slow-arm executor performs the actions; betr's world is its twin",
                r#"the twin predicted grasp "blue cube"! would succeed; the slow-arm executor reports: No collision free path found"#
            ],
        );
        // What reality showed is the twin's now: the red cube on the blue cube.
        let red_on_blue = Condition::parse(r#""red cube" on "blue cube""#).unwrap();
        let facts = facts_now(&s.seen);
        assert!(facts.unwrap().contains(&red_on_blue));
        // The robot never touched the red cube: it lay there from the start, and the
        // scene's first state takes that in, so the repair is tried where it is.
        let learned = s.seen.iter().any(|e| {
            matches!(e, Event::Notice { message } if message.starts_with(
                "reality showed red cube elsewhere than the scene said, untouched by the robot"
            ))
        });
        assert!(learned, "{:#?}", s.seen);
        let got = s.approve().await;
        assert!(fix_inserted(&got), "{got:#?}");
        // Run again from the first state: the twin starts from what reality showed, so the
        // tree clears the blue cube first, and reality lets it.
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        let sent: Vec<String> = orders.lock().unwrap().iter().map(|a| a.to_string()).collect();
        assert_eq!(
            sent[1..3],
            [r#"grasp "red cube""#.to_string(), r#"place "red cube" "table""#.to_string()],
            "{sent:?}"
        );
    });
}

#[test]
fn an_executor_that_stops_answering_stops_the_run_without_a_repair() {
    rt().block_on(async {
        let mut arm = SlowArm::new(Cubes::scenario_1(false));
        arm.answers = false;
        let mut s = session(arm);
        submit_and_run(&mut s).await;
        let got = s
            .until("the run given up", |e| matches!(e, Event::GaveUp { .. }))
            .await;
        let reason = got.iter().find_map(|e| match e {
            Event::GaveUp { reason } => Some(reason.clone()),
            _ => None,
        });
        assert_eq!(
            reason.as_deref(),
            Some(
                "the slow-arm executor stopped: no answer in 2 s; the run stops, and nothing this tick reported is taken as done"
            )
        );
        assert!(
            !s.seen
                .iter()
                .any(|e| matches!(e, Event::Success { .. } | Event::ActionFailed { .. } | Event::Proposal { .. })),
            "{:#?}",
            s.seen
        );
    });
}

/// The fixture executor process (tests/fixtures/executor/follower.py) with `args`.
fn follower(args: &[&str]) -> ProcessExecutor {
    let script = support::fixtures::root().join("tests/fixtures/executor/follower.py");
    let mut all = vec![script.display().to_string()];
    all.extend(args.iter().map(ToString::to_string));
    ProcessExecutor::spawn("python3", &all)
        .unwrap()
        .with_reply_limit(Duration::from_millis(1500))
}

fn order(text: &str) -> ActionOrder {
    ActionOrder {
        action: ActionCall::parse(text).unwrap(),
        path: None,
        expected: None,
    }
}

#[test]
fn a_process_executor_runs_scenario_1_to_success_over_json_lines() {
    rt().block_on(async {
        let setup = Setup {
            variant: Some("clear".into()),
            executor: Some(Box::new(follower(&["--ticks", "4"]))),
            ..setup(Ok(Arc::new(model(Duration::ZERO))), None)
        };
        let mut s = Session::start(setup);
        submit_and_run(&mut s).await;
        let got = s
            .until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        let ended = got.iter().find_map(|e| match e {
            Event::Success { ticks, executor } => Some((*ticks, executor.clone())),
            _ => None,
        });
        // Two actions of four ticks each, the place starting in the tick the grasp ends
        // (ticks 1-4 and 4-7), and the tick that finds the goal reached; the success is
        // the executor's, not the simulation's.
        let (ticks, executor) = ended.expect("a success");
        assert_eq!(ticks, 8);
        let executor = executor.expect("the executor named");
        assert!(executor.contains("follower"), "{executor}");
        let said = betr::record::describe::describe(&Event::Success {
            ticks,
            executor: Some(executor),
        })
        .join("\n");
        assert!(
            said.contains("SUCCESS in the python3 follower.py executor"),
            "{said}"
        );
    });
}

#[test]
fn a_process_that_misbehaves_is_reported_by_what_it_did() {
    let grasp = order(r#"grasp "blue cube""#);
    let err = |args: &[&str]| {
        follower(args)
            .perform(&grasp, true)
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        err(&["--fault", "hang"]),
        "the python3 follower.py executor stopped: no reply to perform within 1.5 s"
    );
    let exited = err(&["--fault", "exit"]);
    assert!(
        exited.starts_with(
            "the python3 follower.py executor stopped: its output closed before it replied to perform"
        ) && exited.contains("exit status: 3")
            && exited.ends_with(
                "its standard error ends: follower: the simulated controller lost power"
            ),
        "{exited}"
    );
    assert!(
        err(&["--fault", "garbage"]).starts_with(
            "the python3 follower.py executor stopped: it replied to perform with `this is not json`, which is not a reply"
        )
    );
    // A process that never reads: an order larger than its input pipe holds (a long arm
    // path) still ends in the reply's time limit, not in a write that never returns.
    let mut long = grasp.clone();
    long.path = Some(ArmPath {
        arm: "yumi_r".into(),
        base: [0.0, 0.0],
        joints: vec![vec![0.123_456_789; 7]; 4000],
        acts_at: 2000,
    });
    let deaf = follower(&["--fault", "deaf"])
        .perform(&long, true)
        .unwrap_err();
    assert_eq!(
        deaf.to_string(),
        "the python3 follower.py executor stopped: no reply to perform within 1.5 s"
    );
    let mut arm = follower(&["--fault", "refuse-reset"]);
    assert_eq!(
        arm.reset().unwrap_err().to_string(),
        "the python3 follower.py executor stopped: it cannot go back to the first state: a real arm is not put back by software"
    );
    let missing = ProcessExecutor::spawn("/nonexistent/simulator", &[])
        .err()
        .unwrap();
    assert!(
        missing
            .to_string()
            .starts_with("the simulator executor stopped: cannot start /nonexistent/simulator:"),
        "{missing}"
    );
}

#[test]
fn betr_run_performs_the_tree_in_the_program_named_by_executor() {
    let dir = support::cli::tmp("executor-run");
    let root = support::fixtures::root();
    let scenario = root.join("scenarios/cell/red_on_blue.toml");
    let follower = root.join("tests/fixtures/executor/follower.py");
    let command = format!("python3 '{}' --ticks 2", follower.display());
    let scenario = scenario.display().to_string();
    let args = [
        "run",
        &scenario,
        "--variant",
        "clear",
        "--executor",
        &command,
    ];
    let out = support::cli::betr(&dir, &args);
    let text = support::cli::text(&out);
    assert!(out.status.success(), "{text}");
    // Two ticks per action in the follower: the grasp in ticks 1-2, the place in 2-3.
    assert!(
        text.contains("SUCCESS in the python3 follower.py executor after 4 tick(s)"),
        "{text}"
    );
    // A command line that cannot be split, and a program that does not start, are named.
    let out = support::cli::betr(&dir, &["run", &scenario, "--executor", "python3 'sim.py"]);
    let text = support::cli::text(&out);
    assert!(!out.status.success());
    assert!(
        text.contains("--executor \"python3 'sim.py\": an unclosed quote or escape"),
        "{text}"
    );
    let out = support::cli::betr(&dir, &["run", &scenario, "--executor", "/nonexistent/sim"]);
    let text = support::cli::text(&out);
    assert!(!out.status.success());
    assert!(
        text.contains("the sim executor stopped: cannot start /nonexistent/sim"),
        "{text}"
    );
}
