//! The cell's conditions and skills against the scenario files: truth computed from
//! poses, paths blocked by where solids are, reach, and located errors in scene tables.

use std::path::{Path, PathBuf};

use super::CellWorld;
use super::skills::SkillFailure;
use crate::domain::{ActionCall, Condition};
use crate::scenario::Scenario;
use crate::world::{Step, World};

fn scenario(rel: &str) -> Scenario {
    Scenario::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/cell")
            .join(rel),
    )
    .unwrap()
}

fn cell(rel: &str, variant: Option<&str>) -> CellWorld {
    CellWorld::from_scenario(&scenario(rel), variant).unwrap()
}

fn holds(w: &CellWorld, c: &str) -> bool {
    w.check(&Condition::parse(c).unwrap())
}

/// Run an action to completion (or its first failure).
fn act(w: &mut CellWorld, a: &str) -> Step {
    let call = ActionCall::parse(a).unwrap();
    let mut started = true;
    loop {
        match w.step(&call, started) {
            Step::Running => started = false,
            done => return done,
        }
    }
}

#[test]
fn on_and_grasped_follow_the_poses() {
    let mut w = cell("red_on_blue.toml", None);
    assert!(holds(&w, r#""red cube" on "blue cube""#));
    assert!(holds(&w, r#""blue cube" on "table""#));
    assert!(holds(&w, r#""any object" on "blue cube""#));
    assert!(!holds(&w, r#""any object" on "red cube""#));
    assert!(holds(&w, r#"~"any object" grasped"#));
    assert_eq!(act(&mut w, r#"grasp "red cube""#), Step::Success);
    assert!(holds(&w, r#""red cube" grasped"#));
    assert!(holds(&w, r#"~"any object" on "blue cube""#));
    assert!(!holds(&w, r#""red cube" on "any object""#));
    assert_eq!(act(&mut w, r#"place "red cube" "table""#), Step::Success);
    assert!(holds(&w, r#""red cube" on "table""#));
    // Put down clear of the cubes, so grasping the blue cube is free now.
    assert_eq!(act(&mut w, r#"grasp "blue cube""#), Step::Success);
    assert_eq!(
        act(&mut w, r#"place "blue cube" "green cube""#),
        Step::Success
    );
    assert!(holds(&w, r#""blue cube" on "green cube""#));
    // It rests on the green cube's top face.
    let (blue, green) = (
        w.pose_of("blue cube").unwrap(),
        w.pose_of("green cube").unwrap(),
    );
    assert!((blue.translation.vector.z - green.translation.vector.z - 0.04).abs() < 1e-5);
    assert!(w.broad_checks() > 0);
}

#[test]
fn a_cube_on_top_blocks_the_way_down() {
    let mut w = cell("red_on_blue.toml", None);
    assert_eq!(
        act(&mut w, r#"grasp "blue cube""#),
        Step::Failure(SkillFailure::NoPath.to_string())
    );
    let mut clear = cell("red_on_blue.toml", Some("clear"));
    assert_eq!(act(&mut clear, r#"grasp "blue cube""#), Step::Success);
    // Stacking on a cube that carries another is blocked by where that one is.
    let mut both = cell("blocked_both.toml", None);
    assert_eq!(act(&mut both, r#"grasp "red cube""#), Step::Success);
    assert_eq!(act(&mut both, r#"place "red cube" "table""#), Step::Success);
    assert_eq!(act(&mut both, r#"grasp "blue cube""#), Step::Success);
    assert_eq!(
        act(&mut both, r#"place "blue cube" "green cube""#),
        Step::Failure(SkillFailure::NoPath.to_string())
    );
}

#[test]
fn an_upside_down_cup_closes_its_opening() {
    let mut w = cell("flip_cup.toml", None);
    assert!(!holds(&w, r#""red cup" upright"#));
    assert!(!holds(&w, r#""red cup" open"#));
    assert_eq!(act(&mut w, r#"grasp "green cube""#), Step::Success);
    assert_eq!(
        act(&mut w, r#"put_in "green cube" "red cup""#),
        Step::Failure(SkillFailure::NoPath.to_string())
    );
    let mut w = cell("flip_cup.toml", None);
    assert_eq!(act(&mut w, r#"flip "red cup""#), Step::Success);
    assert!(holds(&w, r#""red cup" upright"#));
    assert!(holds(&w, r#""red cup" open"#));
    assert_eq!(act(&mut w, r#"grasp "green cube""#), Step::Success);
    assert_eq!(
        act(&mut w, r#"put_in "green cube" "red cup""#),
        Step::Success
    );
    assert!(holds(&w, r#""green cube" in "red cup""#));
    assert!(!holds(&w, r#""green cube" on "table""#));
}

#[test]
fn a_closed_lid_blocks_and_an_open_one_does_not() {
    let mut w = cell("centrifuge.toml", None);
    assert!(!holds(&w, r#""centrifuge" open"#));
    assert_eq!(act(&mut w, r#"grasp "test tube""#), Step::Success);
    assert_eq!(
        act(&mut w, r#"put_in "test tube" "centrifuge""#),
        Step::Failure(SkillFailure::NoPath.to_string())
    );
    let mut w = cell("centrifuge.toml", None);
    assert_eq!(act(&mut w, r#"open "centrifuge""#), Step::Success);
    assert!(holds(&w, r#""centrifuge" open"#));
    assert_eq!(act(&mut w, r#"grasp "test tube""#), Step::Success);
    assert_eq!(
        act(&mut w, r#"put_in "test tube" "centrifuge""#),
        Step::Success
    );
    assert!(holds(&w, r#""test tube" in "centrifuge""#));
}

#[test]
fn a_locked_door_does_not_open_and_a_closed_one_blocks() {
    let mut w = cell("cupboard.toml", None);
    assert!(!holds(&w, r#""cupboard" unlocked"#));
    assert_eq!(
        act(&mut w, r#"open "cupboard""#),
        Step::Failure(SkillFailure::Torque.to_string())
    );
    let mut w = cell("cupboard.toml", Some("clear"));
    assert_eq!(act(&mut w, r#"grasp "plate""#), Step::Success);
    assert_eq!(
        act(&mut w, r#"put_in "plate" "cupboard""#),
        Step::Failure(SkillFailure::NoPath.to_string())
    );
    let mut w = cell("cupboard.toml", Some("clear"));
    assert_eq!(act(&mut w, r#"open "cupboard""#), Step::Success);
    assert!(holds(&w, r#""cupboard" open"#));
    assert_eq!(act(&mut w, r#"grasp "plate""#), Step::Success);
    assert_eq!(act(&mut w, r#"put_in "plate" "cupboard""#), Step::Success);
    assert!(holds(&w, r#""plate" in "cupboard""#));
}

#[test]
fn reach_and_driving_and_the_robots_map() {
    let mut w = cell("banana_far.toml", None);
    assert!(!holds(&w, r#""banana" near robot"#));
    assert!(holds(&w, r#""tray" near robot"#));
    assert_eq!(
        act(&mut w, r#"grasp "banana""#),
        Step::Failure(SkillFailure::OutOfReach.to_string())
    );
    assert_eq!(act(&mut w, r#"move_base "banana""#), Step::Success);
    assert!(holds(&w, r#""banana" near robot"#));
    assert_eq!(act(&mut w, r#"grasp "banana""#), Step::Success);

    let mut w = cell("banana_unknown.toml", None);
    assert!(!holds(&w, r#""banana" location known"#));
    let lost = Step::Failure(r#"Object "banana" is not in the dictionary"#.into());
    assert_eq!(act(&mut w, r#"grasp "banana""#), lost);
    assert_eq!(act(&mut w, r#"look_for "banana""#), Step::Success);
    assert_eq!(act(&mut w, r#"grasp "banana""#), Step::Success);
}

#[test]
fn snapshots_restore_and_forks_share_the_check_count() {
    let mut w = cell("red_on_blue.toml", None);
    let snap = w.snapshot();
    assert_eq!(act(&mut w, r#"grasp "red cube""#), Step::Success);
    w.restore(&snap).unwrap();
    assert!(holds(&w, r#""red cube" on "blue cube""#));
    let before = w.collision_checks();
    let mut f = w.fork();
    let _ = f.step(&ActionCall::parse(r#"grasp "blue cube""#).unwrap(), true);
    assert!(w.collision_checks() > before);
    let facts: Vec<String> = w.facts().iter().map(ToString::to_string).collect();
    assert!(
        facts.contains(&r#""red cube" on "blue cube""#.to_string()),
        "{facts:?}"
    );
}

fn scratch(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("betr-cell-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The base file names its example pool beside it, so both are copied.
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell");
    for file in ["cell.toml", "examples.toml"] {
        std::fs::copy(base.join(file), dir.join(file)).unwrap();
    }
    let p = dir.join("s.toml");
    std::fs::write(&p, text).unwrap();
    p
}

const HEAD: &str =
    "extends = \"cell.toml\"\n[scenario]\nname = \"x\"\n[objects]\nitem = [\"cube\"]\n";

#[test]
fn scene_errors_name_file_line_and_column() {
    let p = scratch(
        "shape",
        &format!("{HEAD}[world.solids.\"cube\"]\nshape = \"blob\"\non = \"table\"\n"),
    );
    let e = CellWorld::from_scenario(&Scenario::load(&p).unwrap(), None)
        .err()
        .unwrap();
    assert_eq!((e.line, e.column), (7, 10), "{e}");
    assert!(e.message.contains("unknown shape \"blob\""), "{e}");

    let p = scratch(
        "support",
        &format!(
            "{HEAD}[world.solids.\"cube\"]\nshape = \"box\"\nsize = [0.04, 0.04, 0.04]\non = \"shelf\"\n"
        ),
    );
    let e = CellWorld::from_scenario(&Scenario::load(&p).unwrap(), None)
        .err()
        .unwrap();
    assert_eq!((e.line, e.column), (9, 7), "{e}");

    let p = scratch(
        "skill",
        &format!(
            "{HEAD}[[skills]]\nname = \"juggle\"\nparams = [\"x: item\"]\n[world.solids.\"cube\"]\nshape = \"box\"\nsize = [0.04, 0.04, 0.04]\non = \"table\"\n"
        ),
    );
    let e = CellWorld::from_scenario(&Scenario::load(&p).unwrap(), None)
        .err()
        .unwrap();
    assert_eq!(e.line, 7, "{e}");
    assert!(
        e.message
            .contains("cannot perform a skill named \"juggle\""),
        "{e}"
    );

    let p = scratch("nosolid", HEAD);
    let e = CellWorld::from_scenario(&Scenario::load(&p).unwrap(), None)
        .err()
        .unwrap();
    assert_eq!(e.line, 5, "{e}");
    assert!(e.message.contains("\"cube\" has no solid"), "{e}");
}

#[test]
fn numbers_that_are_not_finite_or_too_large_are_refused_where_they_are_written() {
    // 0.1e308 reads as an infinite f32, whose bounding box made reach_point clamp NaN.
    for (value, column) in [
        ("[0.2, 0.1e308, 0.01]", 8),
        ("[0.2, nan, 0.01]", 8),
        ("[0.2, 20000.0, 0.01]", 8),
    ] {
        let p = scratch(
            "finite",
            &format!(
                "{HEAD}[world.solids.\"cube\"]\nshape = \"box\"\nsize = {value}\non = \"table\"\nfixed = true\n"
            ),
        );
        let e = CellWorld::from_scenario(&Scenario::load(&p).unwrap(), None)
            .err()
            .unwrap();
        assert_eq!((e.line, e.column), (8, column), "{value}: {e}");
        assert!(e.message.contains("finite numbers"), "{e}");
    }
    let p = scratch(
        "finite-robot",
        &format!(
            "{HEAD}[world.robot]\nreach = inf\n[world.solids.\"cube\"]\nshape = \"box\"\nsize = [0.04, 0.04, 0.04]\non = \"table\"\n"
        ),
    );
    let e = CellWorld::from_scenario(&Scenario::load(&p).unwrap(), None)
        .err()
        .unwrap();
    assert_eq!(e.line, 7, "{e}");
}
