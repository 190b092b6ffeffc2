//! Planning and repair at scale: scenario 1 end to end (plan, fail, repair, re-plan, run to
//! success; the model's part left out: the fix is the one a person approves) and tower
//! cells of up to 10,000 cubes.

use std::path::Path;
use std::time::{Duration, Instant};

use super::towers::{self, Repaired};
use super::{BenchError, Better, Row, Target};
use crate::planner::{RunEnd, run_tree};
use crate::scenario::Scenario;
use crate::world::{self, World};

/// The reference Python planner's time for scenario 1 on this machine kind, as measured
/// when it could be run (its path planner is ABB-internal, so it cannot run here).
pub const PAPER_PLANNER_MS: (f64, f64) = (2.3, 4.4);
/// Ticks allowed when running the repaired tree to success.
const RUN_TICKS: u64 = 10_000;

/// Scenario 1 end to end, repeated for at least `time`; the mean per run.
pub fn scenario_one(path: &Path, time: Duration) -> Result<Row, BenchError> {
    let scenario = Scenario::load(path)?;
    let world = world::load(&scenario)?;
    let mut runs = 0u32;
    let started = Instant::now();
    let mut repairs = 0;
    while runs == 0 || started.elapsed() < time {
        repairs = end_to_end(&scenario, world.as_ref())?;
        runs += 1;
    }
    let ms = started.elapsed().as_secs_f64() * 1e3 / f64::from(runs);
    let (low, high) = PAPER_PLANNER_MS;
    Ok(Row {
        part: "scale".into(),
        measure: "scenario 1: plan, fail, repair, re-plan, run to success".into(),
        unit: "ms".into(),
        better: Better::Lower,
        betr: ms,
        anchor: None,
        target: Some(Target::AtMost(0.25)),
        note: format!(
            "mean of {runs} runs, {repairs} repair(s); the paper's Python planner needs {low}–{high} ms for the same work on this machine kind (not run here: its path planner is ABB-internal)"
        ),
    })
}

/// Scenario 1 end to end with the real arms, repeated for at least `time`: planned in the
/// planning world, run in the execution world (whose arms plan every motion), repaired
/// with the scenario's expected fix after the arm's failure, run again to success. The
/// mean per run.
pub fn scenario_one_arms(path: &Path, time: Duration) -> Result<Row, BenchError> {
    let scenario = Scenario::load(path)?;
    let exec = world::load_execution(&scenario, None)?;
    if let Some(why) = exec.notice {
        return Err(BenchError::Setup(why));
    }
    let planning = world::load(&scenario)?;
    let mut runs = 0u32;
    let started = Instant::now();
    let mut repairs = 0;
    while runs == 0 || started.elapsed() < time {
        (repairs, _) =
            super::cell_motion::gold_runs(&scenario, exec.world.as_ref(), planning.as_ref(), None)?;
        runs += 1;
    }
    let ms = started.elapsed().as_secs_f64() * 1e3 / f64::from(runs);
    Ok(Row {
        part: "motion".into(),
        measure: "scenario 1 with the real arms: plan, fail, repair, run to success".into(),
        unit: "ms".into(),
        better: Better::Lower,
        betr: ms,
        anchor: None,
        target: Some(Target::AtMost(50.0)),
        note: format!(
            "mean of {runs} runs, {repairs} repair(s) with the expected fix; every grasp and place an arm's inverse kinematics and collision-free path"
        ),
    })
}

/// The tower cell of `n` cubes with the YuMi's real arms (`base`: the cell's cell.toml):
/// planned in the planning world, run in the execution world (every grasp and place an
/// arm's inverse kinematics and collision-free path among the `n` cubes), repaired with
/// the expected fixes after each failure, run again to success; once.
pub fn towers_arms(n: usize, base: &Path) -> Result<Row, BenchError> {
    let dir = std::env::temp_dir().join(format!("betr-bench-arms-{}", std::process::id()));
    let row = towers_arms_in(n, base, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    row
}

fn towers_arms_in(n: usize, base: &Path, dir: &Path) -> Result<Row, BenchError> {
    let path = towers::write_arms_scenario(dir, n, base)?;
    let started = Instant::now();
    let scenario = Scenario::load(&path)?;
    let exec = world::load_execution(&scenario, None)?;
    if let Some(why) = exec.notice {
        return Err(BenchError::Setup(why));
    }
    let planning = world::load(&scenario)?;
    let loaded = started.elapsed();
    let started = Instant::now();
    let (repairs, _) =
        super::cell_motion::gold_runs(&scenario, exec.world.as_ref(), planning.as_ref(), None)?;
    let ms = started.elapsed().as_secs_f64() * 1e3;
    Ok(Row {
        part: "motion".into(),
        measure: format!(
            "{n} cubes in towers with the real arms: plan, fail, repair, run to success"
        ),
        unit: "ms".into(),
        better: Better::Lower,
        betr: ms,
        anchor: None,
        target: None,
        note: format!(
            "once; {repairs} repair(s) with the expected fixes; every grasp and place an arm's inverse kinematics and collision-free path among the {n} cubes; reading the scenario and building both worlds before it {:.0} ms",
            loaded.as_secs_f64() * 1e3
        ),
    })
}

/// One run: plan, repair each failing grasp, then tick the repaired tree in a fresh copy
/// of the world until it succeeds. The number of repairs.
fn end_to_end(scenario: &Scenario, world: &dyn World) -> Result<usize, BenchError> {
    let Repaired { plan, repairs, .. } = towers::plan_and_repair(scenario, world)?;
    let mut run = world.fork();
    let report = run_tree(
        &plan.tree,
        run.as_mut(),
        &scenario.domain,
        RUN_TICKS,
        |_, _| true,
    );
    if report.end != RunEnd::Success {
        return Err(BenchError::Setup(format!(
            "{}: the repaired tree ended {:?} after {} ticks",
            scenario.name, report.end, report.ticks
        )));
    }
    Ok(repairs)
}

/// The tower cells of each size, extending `base` (the cell's cell.toml): plan and repair
/// times, against the targets for 1000 and 10,000 cubes. The scenarios are written to a
/// directory of their own and removed afterwards.
pub fn towers(sizes: &[usize], base: &Path) -> Result<Vec<Row>, BenchError> {
    let dir = std::env::temp_dir().join(format!("betr-bench-towers-{}", std::process::id()));
    let rows = tower_rows(sizes, base, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    rows
}

fn tower_rows(sizes: &[usize], base: &Path, dir: &Path) -> Result<Vec<Row>, BenchError> {
    let mut rows = Vec::new();
    for &n in sizes {
        let path = towers::write_scenario(dir, n, base)?;
        let scenario = Scenario::load(&path)?;
        let world = world::load(&scenario)?;
        let r = towers::plan_and_repair(&scenario, world.as_ref())?;
        let target = match n {
            1000 => Some(Target::AtMost(20.0)),
            10_000 => Some(Target::AtMost(200.0)),
            _ => None,
        };
        rows.push(Row {
            part: "scale".into(),
            measure: format!("repair, {n} cubes in towers"),
            unit: "ms".into(),
            better: Better::Lower,
            betr: r.repair_time.as_secs_f64() * 1e3,
            anchor: None,
            target,
            note: format!(
                "{} repairs, {} nodes; planning before it {:.2} ms",
                r.repairs,
                r.plan.tree.len(),
                r.plan_time.as_secs_f64() * 1e3
            ),
        });
    }
    Ok(rows)
}
