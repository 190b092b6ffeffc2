//! The tabletop cell with the YuMi's real arms in the execution world: every failure
//! scenario of BETR-XP-LLM fails at the paper's action with the arm's own reason (the
//! solid its motion collides with, the pose no joint values reach) where the failure is a
//! motion's, or with the paper's error where it is not (a locked door's torque, an object
//! the robot has never seen), is repaired by its expected fix planned in the planning
//! world, and the repaired tree then runs to success with every grasp, place and put-in
//! made by an arm (through the cupboard's front opening the hand comes in level), the
//! same way on every run. The parameter scenarios run with the arms too: the action that
//! needs a value fails for want of it, and with a good value the tree succeeds. The
//! planning world keeps the reach spheres and the gripper sweep.

use crate::support;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use betr::bt::{self, Tree};
use betr::domain::Condition;
use betr::model::{Pip, Progress, YUMI_DESCRIPTION, cache_dir, ensure_description};
use betr::planner::{Planner, RunEnd, run_tree};
use betr::scenario::Scenario;
use betr::world::{self, World};

struct Quiet;
impl Progress for Quiet {
    fn stage(&mut self, _: &str) {}
    fn bytes(&mut self, _: u64, _: u64) {}
}

/// The YuMi's description in the cache, fetched on first use like the robot's own tests.
fn description() {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        ensure_description(&YUMI_DESCRIPTION, &cache_dir(), Pip::DEFAULT, &mut Quiet)
            .unwrap_or_else(|e| panic!("fetching the YuMi's description: {e}"))
    });
}

fn load(rel: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/cell")
        .join(rel);
    Scenario::load(&path).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The execution world, which must move the real arms.
fn arms_world(scenario: &Scenario, variant: Option<&str>) -> Box<dyn World> {
    description();
    let e = world::load_execution(scenario, variant).expect("the execution world");
    assert_eq!(e.notice, None, "the arms are available");
    let cell = e
        .world
        .as_any()
        .and_then(|a| a.downcast_ref::<world::CellWorld>())
        .expect("a cell");
    assert!(cell.has_real_arms());
    e.world
}

/// Run `tree` in a fresh copy of `world`; how it ended.
fn run(tree: &Tree, scenario: &Scenario, world: &dyn World) -> (RunEnd, Box<dyn World>) {
    let mut w = world.fork();
    let report = run_tree(tree, w.as_mut(), &scenario.domain, 1000, |_, _| true);
    (report.end, w)
}

/// One expected failure in the execution world: the action, how the error begins, and a
/// part of it that says the arm's reason.
type Expected = (&'static str, &'static str, &'static str);

const FAILURES: &[(&str, &[Expected])] = &[
    (
        "red_on_blue.toml",
        &[(
            "grasp \"blue cube\"",
            "No collision free path found for yumi_link_7_l",
            "collides with red cube",
        )],
    ),
    (
        "blocked_both.toml",
        &[
            (
                "grasp \"blue cube\"",
                "No collision free path found for yumi_link_7_l",
                "collides with red cube",
            ),
            (
                "place \"blue cube\" \"green cube\"",
                "No collision free path found for yumi_link_7_l",
                "collides with yellow cube",
            ),
        ],
    ),
    (
        "flip_cup.toml",
        &[(
            "put_in \"green cube\" \"red cup\"",
            "No collision free path found for yumi_link_7_",
            "collides with red cup",
        )],
    ),
    (
        "centrifuge.toml",
        &[(
            "put_in \"test tube\" \"centrifuge\"",
            "No collision free path found for yumi_link_7_",
            "collides with centrifuge lid",
        )],
    ),
    (
        "cupboard.toml",
        &[(
            "open \"cupboard\"",
            "Torque limit exceeded",
            "Torque limit exceeded",
        )],
    ),
    (
        "banana_unknown.toml",
        &[(
            "grasp \"banana\"",
            "Object \"banana\" is not in the dictionary",
            "not in the dictionary",
        )],
    ),
    (
        "banana_far.toml",
        &[(
            "grasp \"banana\"",
            "Position out of reach: pose",
            "is out of reach of yumi_link_7_",
        )],
    ),
];

/// A test per failure scenario (so the harness runs them side by side), and one that
/// every scenario of [`FAILURES`] has its test.
macro_rules! failure_scenario_tests {
    ($($test:ident => $file:literal),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                fails_for_the_arms_reason_and_succeeds_after_its_fix($file);
            }
        )*

        #[test]
        fn every_failure_scenario_has_its_test() {
            let tested: Vec<&str> = vec![$($file),*];
            let listed: Vec<&str> = FAILURES.iter().map(|(rel, _)| *rel).collect();
            assert_eq!(tested, listed);
        }
    };
}

failure_scenario_tests! {
    red_on_blue_fails_for_the_arms_reason_and_succeeds_after_its_fix => "red_on_blue.toml",
    blocked_both_fails_for_the_arms_reason_and_succeeds_after_its_fix => "blocked_both.toml",
    flip_cup_fails_for_the_arms_reason_and_succeeds_after_its_fix => "flip_cup.toml",
    centrifuge_fails_for_the_arms_reason_and_succeeds_after_its_fix => "centrifuge.toml",
    cupboard_fails_for_the_arms_reason_and_succeeds_after_its_fix => "cupboard.toml",
    banana_unknown_fails_for_the_arms_reason_and_succeeds_after_its_fix => "banana_unknown.toml",
    banana_far_fails_for_the_arms_reason_and_succeeds_after_its_fix => "banana_far.toml",
}

/// The failure scenario `rel` of [`FAILURES`] fails in the arms' world for each expected
/// reason in turn, is repaired with its expected fix each time, and then succeeds.
fn fails_for_the_arms_reason_and_succeeds_after_its_fix(rel: &str) {
    let (rel, steps) = FAILURES
        .iter()
        .find(|(r, _)| *r == rel)
        .unwrap_or_else(|| panic!("{rel} is not in FAILURES"));
    let scenario = load(rel);
    let exec = arms_world(&scenario, None);
    let planning = world::load(&scenario).expect("the planning world");
    let planner = Planner::new(&scenario.domain);
    let goal = scenario.goal.clone().expect("the scenario's goal");
    let mut tree = planner
        .plan(&goal.to_dnf(), planning.as_ref())
        .expect("a plan")
        .tree;
    assert_eq!(scenario.expected_fix.len(), steps.len(), "{rel}");
    for ((action, begins, reason), fix) in steps.iter().zip(&scenario.expected_fix) {
        let (end, _) = run(&tree, &scenario, exec.as_ref());
        let RunEnd::Failure {
            action: Some((node, error)),
        } = end
        else {
            panic!(
                "{rel}: expected {action} to fail, got {end:?}\n{}",
                bt::to_text(&tree)
            );
        };
        let failed = tree
            .kind(node)
            .ok()
            .and_then(|k| k.as_action())
            .expect("the failing node is an action")
            .to_string();
        assert_eq!(failed, *action, "{rel}: the failing action ({error})");
        assert!(error.starts_with(begins), "{rel}: {error}");
        assert!(error.contains(reason), "{rel}: {error}");
        // The planning world's sweep agrees here: no disagreement is reported.
        assert!(!error.contains(world::DISAGREEMENT_NOTE), "{rel}: {error}");
        let fix = Condition::parse(fix).expect("the expected fix parses");
        tree = planner
            .repair(tree, node, &[fix], planning.as_ref())
            .expect("a repair")
            .tree;
    }
    succeeds_twice(rel, &tree, &scenario, exec.as_ref(), true);
}

/// `tree` runs to success in `exec` and the scenario's goal holds; a second run from the
/// same world does the same; and an arm moved, or not, as `moves` says.
fn succeeds_twice(rel: &str, tree: &Tree, scenario: &Scenario, exec: &dyn World, moves: bool) {
    let goal = scenario.goal.clone().expect("the scenario's goal");
    let (end, after) = run(tree, scenario, exec);
    assert_eq!(
        end,
        RunEnd::Success,
        "{rel}: {end:?}\n{}",
        bt::to_text(tree)
    );
    assert!(
        goal.eval(&|a| after.check(&Condition::pos(a.clone()))),
        "{rel}: the goal holds"
    );
    // The same arms, the same run.
    let (again, _) = run(tree, scenario, exec);
    assert_eq!(again, RunEnd::Success, "{rel}");
    let cell = after
        .as_any()
        .and_then(|a| a.downcast_ref::<world::CellWorld>())
        .expect("a cell");
    assert_eq!(cell.last_motion().is_some(), moves, "{rel}: an arm moved");
}

/// Scenarios whose failure only the real arms produce: the planning world's gripper sweep
/// finds the way clear, the arm does not, and the failure says both.
const ARMS_ONLY: &[(&str, &str, &str)] = &[
    (
        "shelf_over.toml",
        "grasp \"blue cube\"",
        "collides with shelf",
    ),
    (
        "vase_beside.toml",
        "place \"blue cube\" \"green cube\"",
        "collides with vase",
    ),
];

#[test]
fn real_arm_scenarios_fail_only_with_the_arms_and_succeed_after_their_fix() {
    for (rel, action, reason) in ARMS_ONLY {
        let scenario = load(rel);
        let exec = arms_world(&scenario, None);
        let planning = world::load(&scenario).unwrap();
        let goal = scenario.goal.clone().unwrap();
        // The planning world predicts success.
        let plan = Planner::new(&scenario.domain)
            .plan(&goal.to_dnf(), planning.as_ref())
            .expect("a plan");
        assert_eq!(plan.outcome, betr::planner::Outcome::Success, "{rel}");
        let (end, _) = run(&plan.tree, &scenario, exec.as_ref());
        let RunEnd::Failure {
            action: Some((node, error)),
        } = end
        else {
            panic!("{rel}: expected {action} to fail, got {end:?}");
        };
        let failed = plan
            .tree
            .kind(node)
            .unwrap()
            .as_action()
            .unwrap()
            .to_string();
        assert_eq!(failed, *action, "{rel}: {error}");
        assert!(
            error.starts_with("No collision free path found for yumi_link_7_"),
            "{rel}: {error}"
        );
        assert!(error.contains(reason), "{rel}: {error}");
        assert!(error.ends_with(world::DISAGREEMENT_NOTE), "{rel}: {error}");
        // Repaired in a planning world that moves the arms too, as the engine does once
        // planning and execution disagree.
        let fix = Condition::parse(&scenario.expected_fix[0]).unwrap();
        let repaired = Planner::new(&scenario.domain)
            .repair(plan.tree.clone(), node, &[fix], exec.as_ref())
            .expect("a repair");
        assert_eq!(repaired.outcome, betr::planner::Outcome::Success, "{rel}");
        let (end, after) = run(&repaired.tree, &scenario, exec.as_ref());
        assert_eq!(
            end,
            RunEnd::Success,
            "{rel}:\n{}",
            bt::to_text(&repaired.tree)
        );
        assert!(
            goal.eval(&|a| after.check(&Condition::pos(a.clone()))),
            "{rel}"
        );
        // Without the obstacle the first tree already runs with the arms.
        let clear = arms_world(&scenario, Some("clear"));
        let (end, _) = run(&plan.tree, &scenario, clear.as_ref());
        assert_eq!(end, RunEnd::Success, "{rel}: the clear variant");
    }
}

/// In the workbench's engine: the arm's failure says planning and execution disagree, the
/// engine says so, asks the model, and the approved fix runs to success with the arms.
#[test]
fn the_engine_reports_the_disagreement_and_repairs_it_through_the_usual_loop() {
    use betr::session::{Command, Event, Setup};
    use std::sync::Arc;
    description();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/shelf_over.toml");
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    let model = support::engine::model(std::time::Duration::ZERO);
    let setup = Setup::new(scenario, path, Ok(Arc::new(model)));
    support::repo::runtime().block_on(async {
        let mut s = support::engine::Session::start(setup);
        s.send(Command::Submit("\"blue cube\" on \"green cube\"".into()));
        s.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Run);
        s.until("a proposal", |e| matches!(e, Event::Proposal { .. }))
            .await;
        let error = s
            .seen
            .iter()
            .find_map(|e| match e {
                Event::ActionFailed { error, .. } => Some(error.clone()),
                _ => None,
            })
            .expect("an action failed");
        assert!(error.contains("collides with shelf"), "{error}");
        assert!(error.ends_with(world::DISAGREEMENT_NOTE), "{error}");
        assert!(s.seen.iter().any(|e| matches!(
            e,
            Event::Notice { message } if message.starts_with("planning and execution disagree")
        )));
        let proposed = s.seen.iter().find_map(|e| match e {
            Event::Proposal { proposal, .. } => Some(proposal.to_string()),
            _ => None,
        });
        assert!(
            proposed
                .as_deref()
                .is_some_and(|p| p.starts_with("insert ~\"any object\" over \"blue cube\"")),
            "{proposed:?}"
        );
        s.send(Command::Approve);
        s.until("the repaired tree", |e| {
            matches!(e, Event::TreeChanged { .. })
        })
        .await;
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
    });
}

/// The parameter scenarios with the real arms: the action that needs a value fails at
/// once for want of it, and with a good value the tree runs to success, its motions made
/// by an arm (scooping and wiping move no arm).
const VALUES: &[(&str, &str, &str, &str, f64, bool)] = &[
    ("params/egg.toml", "grasp \"egg\"", "force", "N", 5.3, true),
    (
        "params/hammer.toml",
        "grasp \"hammer\"",
        "force",
        "N",
        37.2,
        true,
    ),
    (
        "params/pillow.toml",
        "place \"pillow\" \"tray\"",
        "speed",
        "m/s",
        0.6,
        true,
    ),
    (
        "params/first_aid.toml",
        "place \"first aid kit\" \"tray\"",
        "speed",
        "m/s",
        1.5,
        true,
    ),
    (
        "params/baby.toml",
        "put_in \"baby doll\" \"crib\"",
        "speed",
        "m/s",
        0.1,
        true,
    ),
];

/// The tool scenarios: the category a good answer names.
const TOOLS: &[(&str, &str, &str)] = &[
    ("params/sand.toml", "scoop \"sand\" \"bucket\"", "shovel"),
    ("params/plate.toml", "wipe \"plate\"", "sponge"),
];

#[test]
fn parameter_scenarios_run_with_the_arms_once_given_a_good_value() {
    use betr::domain::{ActionCall, Value};
    let cases = VALUES
        .iter()
        .map(|(file, action, name, unit, amount, moves)| {
            let value = Value::Number {
                value: *amount,
                unit: (*unit).to_string(),
            };
            (*file, *action, *name, value, *moves)
        })
        .chain(TOOLS.iter().map(|(file, action, tool)| {
            (
                *file,
                *action,
                "tool",
                Value::Category((*tool).into()),
                false,
            )
        }));
    for (rel, action, name, value, moves) in cases {
        let scenario = load(rel);
        let exec = arms_world(&scenario, None);
        let planning = world::load(&scenario).unwrap();
        let goal = scenario.goal.clone().unwrap();
        let mut tree = Planner::new(&scenario.domain)
            .plan(&goal.to_dnf(), planning.as_ref())
            .expect("a plan")
            .tree;
        let (end, _) = run(&tree, &scenario, exec.as_ref());
        let RunEnd::Failure {
            action: Some((node, error)),
        } = end
        else {
            panic!("{rel}: expected {action} to fail, got {end:?}");
        };
        let failed = tree.kind(node).unwrap().as_action().unwrap().to_string();
        assert_eq!(failed, action, "{rel}: {error}");
        assert!(error.contains("not defined"), "{rel}: {error}");
        let target = ActionCall::parse(action).unwrap();
        let changed =
            betr::planner::set_value(&mut tree, &target.skill, &target.args[0], name, &value);
        assert!(changed >= 1, "{rel}");
        succeeds_twice(rel, &tree, &scenario, exec.as_ref(), moves);
    }
}

/// A tower cell of many cubes plans with the real arms too: the first run fails at the
/// grasp of cube A for the arm's reason (cube 1 lies on it), the expected fixes (nothing on
/// cube A, then nothing on cube 1) repair it, and the repaired tree runs to success with
/// every motion an arm's path among all the cubes.
#[test]
fn a_tower_cell_of_a_hundred_cubes_plans_and_runs_with_the_arms() {
    description();
    let dir = support::cli::tmp("towers-arms");
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/cell.toml");
    let path = betr::bench::towers::write_arms_scenario(&dir, 100, &base).unwrap();
    let scenario = Scenario::load(&path).unwrap();
    let exec = arms_world(&scenario, None);
    let planning = world::load(&scenario).unwrap();
    let goal = scenario.goal.clone().unwrap().to_dnf();
    let tree = Planner::new(&scenario.domain)
        .plan(&goal, planning.as_ref())
        .unwrap()
        .tree;
    let (end, _) = run(&tree, &scenario, exec.as_ref());
    let RunEnd::Failure {
        action: Some((_, error)),
    } = end
    else {
        panic!("the unrepaired tree ends {end:?}");
    };
    assert!(
        error.starts_with("No collision free path found for yumi_link_7_")
            && error.contains("cube 1"),
        "{error}"
    );
    let arms = exec
        .as_any()
        .and_then(|a| a.downcast_ref::<world::CellWorld>())
        .and_then(|c| c.arms().cloned())
        .unwrap();
    let (repairs, queries) = betr::bench::cell_motion::gold_runs(
        &scenario,
        exec.as_ref(),
        planning.as_ref(),
        Some(&arms),
    )
    .unwrap();
    assert_eq!(repairs, 2);
    // Among the solids of every path: the 100 cubes (less one in the hand) and the table.
    assert!(queries.len() >= 6, "{}", queries.len());
    assert!(
        queries.iter().all(|q| q.solids.len() >= 100),
        "{:?}",
        queries.iter().map(|q| q.solids.len()).collect::<Vec<_>>()
    );
}
