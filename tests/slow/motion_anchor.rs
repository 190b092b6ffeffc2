//! The anchor of `betr bench motion` (OMPL with PyBullet's contact test) solves the same
//! problem betr does: PyBullet, given the URDF with betr's collision shapes and the pairs
//! betr's check tests (`betr::bench::pybullet`), calls the same configurations free as
//! betr's own check, on the cell scenarios' motions (with their solids, the other arm and
//! what the hand carries) and among the random targets' boxes. The anchors' venv under
//! target/ is made when missing, as the benchmark makes it.

#![allow(clippy::unwrap_used)] // tests may panic on what they check

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use betr::bench::{cell_motion, motion};
use betr::model::{Pip, Progress, YUMI_DESCRIPTION, cache_dir, ensure_description};
use betr::motion::ArmCheck;
use betr::robot::{Chain, Robot, RobotShapes, SplitMix};
use nalgebra::Isometry3;

struct Quiet;
impl Progress for Quiet {
    fn stage(&mut self, _: &str) {}
    fn bytes(&mut self, _: u64, _: u64) {}
}

fn description() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        ensure_description(&YUMI_DESCRIPTION, &cache_dir(), Pip::DEFAULT, &mut Quiet)
            .unwrap_or_else(|e| panic!("fetching the YuMi's description: {e}"))
    })
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The anchors' python, installed into the benchmark's venv when missing.
fn anchor_python() -> PathBuf {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().unwrap();
    motion::anchor_python(&target.join("motion-bench-venv")).unwrap()
}

/// `count` joint values of `chain` drawn within its limits.
fn drawn(chain: &Chain, rng: &mut SplitMix, count: usize) -> Vec<Vec<f64>> {
    (0..count)
        .map(|_| {
            chain
                .joints
                .iter()
                .map(|j| j.lower + rng.unit() * (j.upper - j.lower))
                .collect()
        })
        .collect()
}

/// PyBullet's verdicts (true: free) on each query's `states` of `input`.
fn pybullet_verdicts(input: &serde_json::Value, name: &str) -> Vec<Vec<bool>> {
    let file = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("anchor-{name}.json"));
    std::fs::write(&file, input.to_string()).unwrap();
    let out = Command::new(anchor_python())
        .arg(root().join("scripts/bench_motion.py"))
        .arg("check")
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().find_map(|f| f.strip_prefix("free=")))
        .map(|v| v.chars().map(|c| c == '1').collect())
        .collect()
}

/// Both checkers agree on every state, and the states are not all of one kind.
fn assert_same_verdicts(betr: &[Vec<bool>], pybullet: &[Vec<bool>]) {
    assert_eq!(betr.len(), pybullet.len(), "one line per query");
    let mut free = 0;
    let mut total = 0;
    for (i, (b, p)) in betr.iter().zip(pybullet).enumerate() {
        let differ: Vec<usize> = (0..b.len()).filter(|&k| p.get(k) != Some(&b[k])).collect();
        assert!(
            differ.is_empty(),
            "query {i}: betr and PyBullet disagree on states {differ:?} (betr {b:?}, PyBullet {p:?})"
        );
        free += b.iter().filter(|&&f| f).count();
        total += b.len();
    }
    assert!(
        free > total / 10 && free < total * 9 / 10,
        "{free} of {total} states free: too few of one kind to compare"
    );
}

#[test]
fn pybullet_calls_the_cell_motions_states_free_where_betr_does() {
    let dir = description();
    let path = root().join("scenarios/cell/red_on_blue.toml");
    let found = cell_motion::scenario_queries(&path)
        .unwrap()
        .expect("scenario 1 moves the real arms");
    let arms = &found.arms;
    let mut rng = SplitMix::new(7);
    let mut betr = Vec::new();
    let (mut input, skipped) =
        cell_motion::anchor_input(&YUMI_DESCRIPTION, dir, arms, &found.queries, 1.0).unwrap();
    assert!(
        skipped.is_empty(),
        "every solid has a PyBullet shape: {skipped:?}"
    );
    let exported = input["queries"].as_array_mut().unwrap();
    assert_eq!(exported.len(), found.queries.len());
    assert!(found.queries.iter().any(|q| !q.carried.is_empty()));
    for (q, json) in found.queries.iter().zip(exported) {
        let check = arms.check_of(q).unwrap();
        // The motions the arms made start and end where betr's own check is free.
        assert!(check.is_free(&q.start) && check.is_free(&q.goal), "{q:?}");
        // And states around the way, near the solids and the other arm.
        let mut states = vec![q.start.clone(), q.goal.clone()];
        for _ in 0..40 {
            let t = rng.unit();
            let noise = 2.5;
            states.push(
                q.start
                    .iter()
                    .zip(&q.goal)
                    .map(|(a, b)| a + (b - a) * t + noise * (rng.unit() - 0.5))
                    .collect(),
            );
        }
        states.retain(|s| check.chain().within_limits(s));
        betr.push(
            states
                .iter()
                .map(|s| check.blocker(s).is_none())
                .collect::<Vec<_>>(),
        );
        json["states"] = serde_json::json!(states);
    }
    let pybullet = pybullet_verdicts(&input, "cell");
    // The start and goal of each query: PyBullet accepts them as betr does.
    for (i, p) in pybullet.iter().enumerate() {
        assert!(
            p[0] && p[1],
            "query {i}: PyBullet refuses its start or goal"
        );
    }
    assert_same_verdicts(&betr, &pybullet);
}

#[test]
fn pybullet_calls_states_among_the_random_targets_boxes_free_where_betr_does() {
    let dir = description();
    let robot = Robot::read(&YUMI_DESCRIPTION, dir).unwrap();
    let shapes = RobotShapes::new(&robot.model, &robot.arms).unwrap();
    let rest = motion::cell_rest();
    let boxes = motion::clutter(&robot, &shapes, &rest, 12, 39).unwrap();
    let solids = motion::solids(&boxes);
    let mut rng = SplitMix::new(11);
    // One query per arm, whose states are drawn anywhere within the limits.
    let queries: Vec<motion::Query> = (0..robot.arms.len())
        .map(|arm| motion::Query {
            arm,
            start: rest[arm].clone(),
            goal: rest[arm].clone(),
        })
        .collect();
    let cell = motion::ClutteredCell {
        robot: &robot,
        shapes: &shapes,
        rest: &rest,
        boxes: &boxes,
    };
    let mut input = motion::anchor_input(&YUMI_DESCRIPTION, dir, &cell, &queries, 1.0).unwrap();
    let mut betr = Vec::new();
    for (q, json) in queries.iter().zip(input["queries"].as_array_mut().unwrap()) {
        let check = ArmCheck::new(
            &robot,
            &shapes,
            Isometry3::identity(),
            q.arm,
            &rest,
            &solids,
        )
        .unwrap();
        let states = drawn(&robot.arms[q.arm], &mut rng, 150);
        betr.push(
            states
                .iter()
                .map(|s| check.blocker(s).is_none())
                .collect::<Vec<_>>(),
        );
        json["states"] = serde_json::json!(states);
    }
    assert_same_verdicts(&betr, &pybullet_verdicts(&input, "boxes"));
}
