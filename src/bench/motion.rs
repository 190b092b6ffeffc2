//! Arm motions against the tools a robotics engineer reaches for, on the same URDF:
//! forward kinematics per second against Pinocchio, and collision-free paths in joint
//! space (time per query, median and 95th percentile, and how many are found) against
//! OMPL's RRTConnect with PyBullet's contact test as its validity checker, among the same
//! boxes. `scripts/bench_motion.py` is the anchors' side, run in a virtual environment
//! under `target/` with the wheels pinned below.
//!
//! The queries: from each arm's rest values to joint values drawn within the limits that
//! are free among the boxes (so the target is reachable by construction), in a cell
//! cluttered with boxes in front of the robot. Both check the same thing: the cell's check
//! (the arm against the boxes, the torso, the other arm and itself, with betr's collision
//! shapes of the links), which PyBullet is given as a URDF with those shapes and the
//! pairs to test (`super::pybullet`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use parry3d::shape::SharedShape;

use super::pybullet::{collision_model, pybullet_solid, tested_pairs_json};
use super::{BenchError, Better, Row};
use crate::model::DescriptionSpec;
use crate::motion::{ArmCheck, PlanOptions, Solid, plan};
use crate::robot::{Robot, RobotShapes, SplitMix};

/// The anchors' wheels.
pub const ANCHORS: &[&str] = &["pin==4.1.0", "ompl==2.0.1", "pybullet==3.2.7"];

/// A box of the cluttered cell: centre and half sizes (metres, world frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clutter {
    pub center: [f32; 3],
    pub half: [f32; 3],
}

/// The random targets' cell: the robot, its links' collision shapes, every arm's rest
/// values (where each query starts and the other arm stays) and the boxes.
#[derive(Clone, Copy)]
pub struct ClutteredCell<'a> {
    pub robot: &'a Robot,
    pub shapes: &'a RobotShapes,
    pub rest: &'a [Vec<f64>],
    pub boxes: &'a [Clutter],
}

impl ClutteredCell<'_> {
    /// The check of arm `arm` among the boxes, the other arm at its rest values.
    fn check<'c>(&'c self, solids: &'c [Solid], arm: usize) -> Result<ArmCheck<'c>, BenchError> {
        Ok(ArmCheck::new(
            self.robot,
            self.shapes,
            Isometry3::identity(),
            arm,
            self.rest,
            solids,
        )?)
    }
}

/// How the anchors' side is run: the venv's Python, the script, the robot description
/// and its folder, the seconds each query may take, and the folder the script's input
/// is written to.
#[derive(Clone, Copy)]
pub struct AnchorRun<'a> {
    pub python: &'a Path,
    pub script: &'a Path,
    pub spec: &'a DescriptionSpec,
    pub dir: &'a Path,
    pub budget_s: f64,
    pub scratch: &'a Path,
}

/// One query: arm `arm` from `start` to `goal`, the other arms at their rest values.
#[derive(Debug, Clone, PartialEq)]
pub struct Query {
    pub arm: usize,
    pub start: Vec<f64>,
    pub goal: Vec<f64>,
}

/// Time per query (seconds) and how many were solved.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanTimes {
    pub seconds: Vec<f64>,
    pub solved: usize,
}

impl PlanTimes {
    /// `solve` on each of `queries`, timed one by one (true: a path was found).
    pub fn measure<Q>(
        queries: &[Q],
        mut solve: impl FnMut(&Q) -> Result<bool, BenchError>,
    ) -> Result<PlanTimes, BenchError> {
        let mut times = PlanTimes {
            seconds: Vec::with_capacity(queries.len()),
            solved: 0,
        };
        for q in queries {
            let started = Instant::now();
            let found = solve(q)?;
            times.seconds.push(started.elapsed().as_secs_f64());
            times.solved += usize::from(found);
        }
        Ok(times)
    }

    /// The `q` quantile (0–1) of the times, in milliseconds.
    pub fn quantile_ms(&self, q: f64) -> f64 {
        let mut s = self.seconds.clone();
        s.sort_by(f64::total_cmp);
        if s.is_empty() {
            return f64::NAN;
        }
        let i = ((s.len() - 1) as f64 * q).round() as usize;
        s[i.min(s.len() - 1)] * 1000.0
    }

    pub fn success(&self) -> f64 {
        self.solved as f64 / self.seconds.len().max(1) as f64
    }
}

/// A Python with the anchors in a virtual environment under `venv` (made the first time).
pub fn anchor_python(venv: &Path) -> Result<PathBuf, BenchError> {
    super::anchor_venv(
        venv,
        ANCHORS,
        &["--only-binary=:all:"],
        "import pinocchio, ompl, pybullet",
    )
}

/// The joint values (degrees, right arm first) the cell's arms start from: the cell
/// scenarios' `[world.robot] rest`.
pub const CELL_REST_DEGREES: [[f64; 7]; 2] = [
    [2.9, -60.2, -62.7, 37.1, -68.2, 30.6, -92.5],
    [13.5, -34.1, 64.4, 34.3, -7.8, 16.8, -23.3],
];

/// [`CELL_REST_DEGREES`] in radians.
pub fn cell_rest() -> Vec<Vec<f64>> {
    CELL_REST_DEGREES
        .iter()
        .map(|a| a.iter().map(|d: &f64| d.to_radians()).collect())
        .collect()
}

/// Joint values of every arm drawn within the limits.
fn random_configuration(robot: &Robot, rng: &mut SplitMix) -> Vec<Vec<f64>> {
    robot
        .arms
        .iter()
        .map(|a| {
            a.joints
                .iter()
                .map(|j| j.lower + rng.unit() * (j.upper - j.lower))
                .collect()
        })
        .collect()
}

/// betr's forward kinematics of every arm's flange per second (one count per
/// configuration of the whole robot).
pub fn betr_fk_rate(robot: &Robot, seconds: f64) -> f64 {
    let mut rng = SplitMix::new(39);
    let configurations: Vec<Vec<Vec<f64>>> = (0..1000)
        .map(|_| random_configuration(robot, &mut rng))
        .collect();
    let started = Instant::now();
    let mut count = 0u64;
    while started.elapsed().as_secs_f64() < seconds {
        for q in &configurations {
            for (arm, values) in robot.arms.iter().zip(q) {
                std::hint::black_box(arm.fk(values));
            }
        }
        count += configurations.len() as u64;
    }
    count as f64 / started.elapsed().as_secs_f64()
}

/// Pinocchio's rate on the same URDF and flanges.
pub fn pin_fk_rate(
    python: &Path,
    script: &Path,
    urdf: &Path,
    dir: &Path,
    robot: &Robot,
    seconds: f64,
) -> Result<f64, BenchError> {
    let what = format!("pinocchio ({})", script.display());
    let out = super::run_anchor(
        &what,
        Command::new(python)
            .arg(script)
            .arg("fk")
            .arg(urdf)
            .arg(dir)
            .arg(format!("{seconds:.3}"))
            .args(robot.arms.iter().map(|a| a.tip.as_str())),
    )?;
    out.lines()
        .find(|l| l.starts_with("pinocchio "))
        .and_then(|l| {
            l.split_whitespace()
                .find_map(|f| f.strip_prefix("fk_per_s="))
        })
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| BenchError::Anchor {
            what,
            detail: format!("unexpected output: {}", out.trim()),
        })
}

/// `count` boxes 2–6 cm in half size, in front of the robot (x 0.3–0.7 m, y ±0.5 m,
/// z 0–0.4 m), placed by the seed, each clear of the arms at their rest values.
pub fn clutter(
    robot: &Robot,
    shapes: &RobotShapes,
    rest: &[Vec<f64>],
    count: usize,
    seed: u64,
) -> Result<Vec<Clutter>, BenchError> {
    let mut rng = SplitMix::new(seed);
    let mut out = Vec::with_capacity(count);
    for _ in 0..count * 100 {
        if out.len() == count {
            return Ok(out);
        }
        let mut r = |lo: f32, hi: f32| lo + rng.unit() as f32 * (hi - lo);
        let b = Clutter {
            center: [r(0.3, 0.7), r(-0.5, 0.5), r(0.0, 0.4)],
            half: [r(0.02, 0.06), r(0.02, 0.06), r(0.02, 0.06)],
        };
        let solid = solids(&[b]);
        let clear = (0..robot.arms.len()).all(|arm| {
            ArmCheck::new(robot, shapes, Isometry3::identity(), arm, rest, &solid)
                .is_ok_and(|c| c.is_free(&rest[arm]))
        });
        if clear {
            out.push(b);
        }
    }
    Err(BenchError::Setup(format!(
        "fewer than {count} boxes clear of the arms' rest values"
    )))
}

/// The boxes as the scene's solids (`box 0`, `box 1`, …).
pub fn solids(boxes: &[Clutter]) -> Vec<Solid> {
    boxes
        .iter()
        .enumerate()
        .map(|(i, b)| Solid {
            name: format!("box {i}"),
            pose: Isometry3::from_parts(
                Translation3::new(b.center[0], b.center[1], b.center[2]),
                UnitQuaternion::identity(),
            ),
            shape: SharedShape::cuboid(b.half[0], b.half[1], b.half[2]),
        })
        .collect()
}

/// `count` queries, arms taken in turn, from the rest values to free joint values.
pub fn random_queries(
    cell: &ClutteredCell<'_>,
    count: usize,
    seed: u64,
) -> Result<Vec<Query>, BenchError> {
    let (robot, rest) = (cell.robot, cell.rest);
    let solids = solids(cell.boxes);
    let checks: Vec<ArmCheck<'_>> = (0..robot.arms.len())
        .map(|arm| cell.check(&solids, arm))
        .collect::<Result<_, _>>()?;
    for (arm, check) in checks.iter().enumerate() {
        if !check.is_free(&rest[arm]) {
            return Err(BenchError::Setup(format!(
                "the rest values of {} are not free among the boxes",
                robot.arms[arm].tip
            )));
        }
    }
    let mut rng = SplitMix::new(seed);
    let mut out = Vec::with_capacity(count);
    let mut drawn = 0usize;
    while out.len() < count {
        drawn += 1;
        if drawn > count * 1000 {
            return Err(BenchError::Setup(
                "too few free joint values among the boxes".into(),
            ));
        }
        let arm = out.len() % robot.arms.len();
        let q = random_configuration(robot, &mut rng).swap_remove(arm);
        // A target over the table, in front of the body.
        let flange = robot.arms[arm].fk(&q).translation.vector;
        if flange.z < 0.05 || flange.x < 0.2 || !checks[arm].is_free(&q) {
            continue;
        }
        out.push(Query {
            arm,
            start: rest[arm].clone(),
            goal: q,
        });
    }
    Ok(out)
}

/// betr's planner on every query, timed one by one.
pub fn betr_plan(
    cell: &ClutteredCell<'_>,
    queries: &[Query],
    options: &PlanOptions,
) -> Result<PlanTimes, BenchError> {
    let solids = solids(cell.boxes);
    PlanTimes::measure(queries, |q| {
        let check = cell.check(&solids, q.arm)?;
        Ok(plan(&check, &q.start, &q.goal, options).is_ok())
    })
}

/// OMPL + PyBullet on the same queries, PyBullet checking what betr's check of each arm
/// checks (`super::pybullet`).
pub fn ompl_plan(
    anchor: &AnchorRun<'_>,
    cell: &ClutteredCell<'_>,
    queries: &[Query],
) -> Result<PlanTimes, BenchError> {
    let json = anchor_input(anchor.spec, anchor.dir, cell, queries, anchor.budget_s)?;
    run_ompl(anchor, &json, queries.len())
}

/// The anchor script's input for `queries` in `cell`, with `budget_s` seconds per query
/// (see `scripts/bench_motion.py`).
pub fn anchor_input(
    spec: &DescriptionSpec,
    dir: &Path,
    cell: &ClutteredCell<'_>,
    queries: &[Query],
    budget_s: f64,
) -> Result<serde_json::Value, BenchError> {
    let (robot, shapes) = (cell.robot, cell.shapes);
    let solids = solids(cell.boxes);
    let mut pairs = Vec::with_capacity(robot.arms.len());
    for arm in 0..robot.arms.len() {
        let check = cell.check(&solids, arm)?;
        pairs.push(tested_pairs_json(&check, robot, shapes));
    }
    let mut boxes_json = Vec::with_capacity(solids.len());
    for s in &solids {
        let mut converted = pybullet_solid(s)
            .ok_or_else(|| BenchError::Setup(format!("{} has no PyBullet shape", s.name)))?;
        if let serde_json::Value::Object(fields) = &mut converted {
            fields.insert("part".into(), format!("solid:{}", s.name).into());
        }
        boxes_json.push(converted);
    }
    Ok(serde_json::json!({
        "urdf": spec.urdf_in(dir),
        "package": spec.package,
        "package_dir": dir,
        "base": [0.0, 0.0, 0.0],
        "solids": boxes_json,
        "arms": arms_json(robot),
        "collision_model": collision_model(robot, shapes)?,
        "pairs_by_arm": pairs,
        "others": cell.rest,
        "queries": queries.iter().map(|q| serde_json::json!({"arm": q.arm, "start": q.start, "goal": q.goal})).collect::<Vec<_>>(),
        "resolution": PlanOptions::default().resolution,
        "budget_s": budget_s,
    }))
}

/// Each arm's joints, limits and flange, as the anchors' script reads them.
pub fn arms_json(robot: &Robot) -> serde_json::Value {
    robot
        .arms
        .iter()
        .map(|a| {
            serde_json::json!({
                "joints": a.joints.iter().map(|j| j.name.clone()).collect::<Vec<_>>(),
                "lower": a.joints.iter().map(|j| j.lower).collect::<Vec<_>>(),
                "upper": a.joints.iter().map(|j| j.upper).collect::<Vec<_>>(),
                "tip": a.tip,
            })
        })
        .collect()
}

/// OMPL + PyBullet on the `count` queries of `json` (the script's `plan` input).
pub fn run_ompl(
    anchor: &AnchorRun<'_>,
    json: &serde_json::Value,
    count: usize,
) -> Result<PlanTimes, BenchError> {
    let (python, script) = (anchor.python, anchor.script);
    std::fs::create_dir_all(anchor.scratch)?;
    let file = anchor.scratch.join("motion-queries.json");
    crate::store::write_atomic(&file, json.to_string().as_bytes())?;
    let what = format!("OMPL + PyBullet ({})", script.display());
    let out = super::run_anchor(
        &what,
        Command::new(python).arg(script).arg("plan").arg(&file),
    )?;
    let mut times = PlanTimes {
        seconds: Vec::new(),
        solved: 0,
    };
    for line in out.lines().filter(|l| l.starts_with("ompl ")) {
        let field = |name: &str| {
            line.split_whitespace()
                .find_map(|f| f.strip_prefix(name)?.strip_prefix('='))
        };
        let (Some(solved), Some(seconds)) = (field("solved"), field("seconds")) else {
            continue;
        };
        times.solved += usize::from(solved == "1");
        times
            .seconds
            .push(seconds.parse().map_err(|_| BenchError::Anchor {
                what: what.clone(),
                detail: format!("unreadable line: {line}"),
            })?);
    }
    if times.seconds.len() != count {
        return Err(BenchError::Anchor {
            what,
            detail: format!(
                "{} answers for {} queries: {}",
                times.seconds.len(),
                count,
                out.trim()
            ),
        });
    }
    Ok(times)
}

/// The table rows of one comparison of path planning.
pub fn plan_rows(label: &str, betr: &PlanTimes, ompl: &PlanTimes, note: &str) -> Vec<Row> {
    let anchor = "OMPL 2.0.1 RRTConnect + PyBullet 3.2.7".to_string();
    let mut how = String::new();
    let _ = write!(
        how,
        "{note}; solved: betr {}/{}, OMPL {}/{}",
        betr.solved,
        betr.seconds.len(),
        ompl.solved,
        ompl.seconds.len()
    );
    // An anchor that solved none of the queries timed only its failures: its times and
    // its success rate say nothing about planning these motions, so nothing is compared.
    let compared = ompl.solved > 0;
    if !compared {
        how.push_str(
            "; OMPL + PyBullet solved none of these queries, so its times are those of \
             failed attempts and are not compared",
        );
    }
    let time_anchor = |value: f64| compared.then(|| (anchor.clone(), value));
    vec![
        Row {
            part: "motion".into(),
            measure: format!("{label}: median time per query"),
            unit: "ms".into(),
            better: Better::Lower,
            betr: betr.quantile_ms(0.5),
            anchor: time_anchor(ompl.quantile_ms(0.5)),
            target: Some(super::Target::AtMost(1.0)),
            note: how.clone(),
        },
        Row {
            part: "motion".into(),
            measure: format!("{label}: 95th percentile time per query"),
            unit: "ms".into(),
            better: Better::Lower,
            betr: betr.quantile_ms(0.95),
            anchor: time_anchor(ompl.quantile_ms(0.95)),
            target: None,
            note: how.clone(),
        },
        Row {
            part: "motion".into(),
            measure: format!("{label}: queries solved"),
            unit: "fraction".into(),
            better: Better::Higher,
            betr: betr.success(),
            anchor: Some((anchor.clone(), ompl.success())),
            target: compared.then_some(super::Target::RatioAtLeast(1.0)),
            note: how,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(seconds: &[f64], solved: usize) -> PlanTimes {
        PlanTimes {
            seconds: seconds.to_vec(),
            solved,
        }
    }

    #[test]
    fn an_anchor_that_solved_nothing_is_not_compared() {
        let betr = times(&[0.001, 0.002, 0.003], 3);
        let rows = plan_rows("q", &betr, &times(&[2.0, 2.0, 2.0], 0), "n");
        assert!(rows[0].anchor.is_none() && rows[1].anchor.is_none());
        assert!(rows[2].target.is_none());
        assert!(rows.iter().all(|r| r.note.contains("solved none")));
        // The median's own target (betr's time) still stands.
        assert!(rows[0].target.is_some());
    }

    #[test]
    fn an_anchor_that_solved_some_is_compared() {
        let betr = times(&[0.001, 0.002, 0.003], 3);
        let rows = plan_rows("q", &betr, &times(&[0.1, 0.2, 2.0], 2), "n");
        assert!(rows.iter().all(|r| r.anchor.is_some()));
        assert!(rows[2].target.is_some());
        assert!(rows.iter().all(|r| !r.note.contains("solved none")));
    }
}
