//! The cell scenarios' own arm motions: every collision-free path the real arms are asked
//! for while a scenario's tree runs in the execution world, failing first and then
//! repaired with the scenario's expected fixes until it succeeds. The queries are kept as
//! the arms posed them (start and goal joint values, the scene's solids, the other arm,
//! what the hand carries), so betr and OMPL + PyBullet can plan the very same ones.

use std::path::Path;
use std::sync::Arc;

use super::BenchError;
use super::motion::{AnchorRun, PlanTimes};
use super::pybullet::{collision_model, pybullet_solid, tested_pairs_json};
use crate::domain::Condition;
use crate::model::DescriptionSpec;
use crate::motion::{Solid, plan};
use crate::planner::{Planner, RunEnd, run_tree};
use crate::scenario::Scenario;
use crate::world::cell::arms::{Arms, PathQuery};
use crate::world::{self, CellWorld, World};

/// Ticks a scenario's tree may take per run.
const RUN_TICKS: u64 = 1000;

/// The path queries of one scenario's runs.
pub struct ScenarioQueries {
    pub scenario: String,
    pub arms: Arc<Arms>,
    pub queries: Vec<PathQuery>,
}

/// The path queries posed while `path`'s tree runs with the real arms until it succeeds
/// (each failing run, then the run after each expected fix), each query once; `None` when
/// the scenario's world moves no real arms.
pub fn scenario_queries(path: &Path) -> Result<Option<ScenarioQueries>, BenchError> {
    let setup = |what: String| BenchError::Setup(format!("{}: {what}", path.display()));
    let scenario = Scenario::load(path).map_err(|e| setup(e.to_string()))?;
    if scenario.world_kind != "cell" {
        return Ok(None);
    }
    let exec = world::load_execution(&scenario, None).map_err(|e| setup(e.to_string()))?;
    let Some(arms) = CellWorld::of(exec.world.as_ref()).and_then(|c| c.arms().cloned()) else {
        return Ok(None);
    };
    if scenario.goal.is_none() {
        return Ok(None);
    }
    let planning = world::load(&scenario).map_err(|e| setup(e.to_string()))?;
    let (_, queries) = gold_runs(
        &scenario,
        exec.world.as_ref(),
        planning.as_ref(),
        Some(&arms),
    )?;
    Ok(Some(ScenarioQueries {
        scenario: scenario.name.clone(),
        arms,
        queries,
    }))
}

/// Plan the scenario's goal in `planning`, run the tree in a fresh copy of `exec`, and
/// after each failure repair it with the next expected fix (the one a person approves),
/// until a run succeeds. The repairs made, and with `arms` the path queries posed during
/// the runs, each once.
pub fn gold_runs(
    scenario: &Scenario,
    exec: &dyn World,
    planning: &dyn World,
    arms: Option<&Arms>,
) -> Result<(usize, Vec<PathQuery>), BenchError> {
    let setup = |what: String| BenchError::Setup(format!("{}: {what}", scenario.name));
    let goal = scenario
        .goal
        .clone()
        .ok_or_else(|| setup("the scenario has no goal".into()))?;
    let planner = Planner::new(&scenario.domain);
    let mut tree = planner
        .plan(&goal.to_dnf(), planning)
        .map_err(|e| setup(e.to_string()))?
        .tree;
    let mut fixes = scenario.expected_fix.iter();
    let mut queries: Vec<PathQuery> = Vec::new();
    let mut repairs = 0;
    loop {
        let mut run = exec.fork();
        if let Some(arms) = arms {
            arms.record_queries();
        }
        let report = run_tree(&tree, run.as_mut(), &scenario.domain, RUN_TICKS, |_, _| {
            true
        });
        for q in arms.map(Arms::take_queries).unwrap_or_default() {
            if !queries.iter().any(|kept| same_query(kept, &q)) {
                queries.push(q);
            }
        }
        let (node, error) = match report.end {
            RunEnd::Success => return Ok((repairs, queries)),
            RunEnd::Failure {
                action: Some(failed),
            } => failed,
            other => return Err(setup(format!("the tree ended {other:?}"))),
        };
        let Some(fix) = fixes.next() else {
            return Err(setup(format!("{error} with no expected fix left")));
        };
        let fix = Condition::parse(fix).map_err(|e| setup(e.to_string()))?;
        // Repaired in the planning world, or where the planning world predicted the
        // failed motion's success, in the execution world, as the engine does.
        let repair_in = if error.ends_with(world::DISAGREEMENT_NOTE) {
            exec
        } else {
            planning
        };
        tree = planner
            .repair(tree, node, &[fix], repair_in)
            .map_err(|e| setup(e.to_string()))?
            .tree;
        repairs += 1;
    }
}

fn same_query(a: &PathQuery, b: &PathQuery) -> bool {
    a.arm == b.arm
        && a.start == b.start
        && a.goal == b.goal
        && a.configs == b.configs
        && a.base == b.base
        && a.solids.len() == b.solids.len()
        && a.solids
            .iter()
            .zip(&b.solids)
            .all(|(x, y)| x.name == y.name && x.pose == y.pose)
        && a.carried.len() == b.carried.len()
}

/// betr's planner on each query (the check made and the path planned), timed one by one.
pub fn betr_plan(arms: &Arms, queries: &[PathQuery]) -> Result<PlanTimes, BenchError> {
    PlanTimes::measure(queries, |q| {
        let check = arms.check_of(q)?;
        Ok(plan(&check, &q.start, &q.goal, &arms.plan).is_ok())
    })
}

/// OMPL + PyBullet on the same queries, PyBullet checking what betr's check of each
/// query checks (`super::pybullet`), and the kinds of shape PyBullet was not given (none
/// when every solid converts).
pub fn ompl_plan(
    anchor: &AnchorRun<'_>,
    arms: &Arms,
    queries: &[PathQuery],
) -> Result<(PlanTimes, Vec<String>), BenchError> {
    let (json, skipped) = anchor_input(anchor.spec, anchor.dir, arms, queries, anchor.budget_s)?;
    let times = super::motion::run_ompl(anchor, &json, queries.len())?;
    Ok((times, skipped))
}

/// The anchor script's input for `queries` (see `scripts/bench_motion.py`), and the kinds
/// of shape PyBullet is not given.
pub fn anchor_input(
    spec: &DescriptionSpec,
    dir: &Path,
    arms: &Arms,
    queries: &[PathQuery],
    budget_s: f64,
) -> Result<(serde_json::Value, Vec<String>), BenchError> {
    let mut skipped: Vec<String> = Vec::new();
    // Each converted solid named as the tested pairs name it.
    let mut convert = |solids: &[Solid], part: &dyn Fn(usize, &Solid) -> String| {
        solids
            .iter()
            .enumerate()
            .filter_map(|(i, s)| {
                let mut converted = pybullet_solid(s);
                let kind = format!("{:?}", s.shape.shape_type());
                if converted.is_none() && !skipped.contains(&kind) {
                    skipped.push(kind);
                }
                if let Some(serde_json::Value::Object(fields)) = converted.as_mut() {
                    fields.insert("part".into(), part(i, s).into());
                }
                converted
            })
            .collect::<Vec<_>>()
    };
    let mut queries_json: Vec<serde_json::Value> = Vec::with_capacity(queries.len());
    for q in queries {
        let check = arms.check_of(q)?;
        let t = q.base.translation.vector;
        let r = q.base.rotation.coords;
        queries_json.push(serde_json::json!({
            "arm": q.arm,
            "start": q.start,
            "goal": q.goal,
            "others": q.configs,
            "base": [t.x, t.y, t.z],
            "base_orientation": [r.x, r.y, r.z, r.w],
            "solids": convert(&q.solids, &|_, s| format!("solid:{}", s.name)),
            "carried": convert(&q.carried, &|i, _| format!("carried:{i}")),
            "pairs": tested_pairs_json(&check, &arms.robot, &arms.shapes),
        }));
    }
    let model = collision_model(&arms.robot, &arms.shapes)?;
    let json = serde_json::json!({
        "urdf": spec.urdf_in(dir),
        "package": spec.package,
        "package_dir": dir,
        "base": [0.0, 0.0, 0.0],
        "arms": super::motion::arms_json(&arms.robot),
        "collision_model": model,
        "queries": queries_json,
        "resolution": arms.plan.resolution,
        "budget_s": budget_s,
    });
    Ok((json, skipped))
}

#[cfg(test)]
#[path = "cell_motion_tests.rs"]
mod tests;
