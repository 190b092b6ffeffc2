//! Tower cells for planning at scale (`betr bench scale`, and the `cell_towers` and
//! `verify_goals` benchmarks): `n` cubes stacked in towers of three, cube A at the bottom
//! of one tower near the robot, the task "put cube A on cube B"; and the repair that
//! inserts `~"any object" on "X"` at each grasp that fails until the tree succeeds (the fix
//! a person approves in scenario 1, without the model).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::BenchError;
use crate::domain::Condition;
use crate::planner::{Outcome, Plan, Planner};
use crate::scenario::Scenario;
use crate::world::World;

pub const TOWER: usize = 3;

/// A scenario with `n` cubes (A, B and the rest) in `dir`, extending the cell's `base`
/// file (`scenarios/cell/cell.toml`) in place, so its example pool and conventions come
/// with it.
pub fn write_scenario(dir: &Path, n: usize, base: &Path) -> Result<PathBuf, BenchError> {
    write(dir, "towers.toml", &scenario_text(n, base, false)?)
}

/// The same cell with the YuMi's real arms in its execution world (the cell scenarios'
/// `[world.robot]`), and the fixes a person approves for the grasps that fail (nothing
/// on cube A, then nothing on cube 1) as its expected fixes (`n` ≥ 4).
pub fn write_arms_scenario(dir: &Path, n: usize, base: &Path) -> Result<PathBuf, BenchError> {
    write(dir, "towers-arms.toml", &scenario_text(n, base, true)?)
}

fn write(dir: &Path, name: &str, text: &str) -> Result<PathBuf, BenchError> {
    std::fs::create_dir_all(dir)?;
    let path = dir.join(name);
    std::fs::write(&path, text)?;
    Ok(path)
}

fn scenario_text(n: usize, base: &Path, arms: bool) -> Result<String, BenchError> {
    let base = std::path::absolute(base)?;
    let mut names = vec!["cube A".to_string(), "cube B".to_string()];
    names.extend((1..n.saturating_sub(1)).map(|i| format!("cube {i}")));
    let mut t = String::new();
    writeln!(
        t,
        "extends = '{}'\n[scenario]\nname = \"{n} cubes in towers\"",
        base.display()
    )?;
    writeln!(t, "goal = '\"cube A\" on \"cube B\"'")?;
    if arms {
        // The tower on cube A is cube 1 with cube 2 on it: grasping A fails for cube 1,
        // then grasping cube 1 for cube 2.
        writeln!(
            t,
            "expected_fix = ['~\"any object\" on \"cube A\"', '~\"any object\" on \"cube 1\"']"
        )?;
        let rest: Vec<String> = super::motion::CELL_REST_DEGREES
            .iter()
            .map(|a| format!("{a:?}"))
            .collect();
        writeln!(
            t,
            "[world.robot]\ndescription = \"yumi\"\nrest = [{}]\ntool = 0.143",
            rest.join(", ")
        )?;
    }
    writeln!(t, "[objects]")?;
    let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    writeln!(t, "item = [{}]", quoted.join(", "))?;
    // A big table: the towers stand beyond a free area in front of the robot.
    writeln!(
        t,
        "[world.solids.\"table\"]\nsize = [2.4, 3.2, 0.05]\nat = [1.2, 0.0, -0.05]"
    )?;
    let cube = |t: &mut String,
                name: &str,
                support: &str,
                xy: Option<(f32, f32)>|
     -> Result<(), BenchError> {
        writeln!(
            t,
            "[world.solids.\"{name}\"]\nshape = \"box\"\nsize = [0.04, 0.04, 0.04]\nmass = 0.05\non = \"{support}\""
        )?;
        if let Some((x, y)) = xy {
            writeln!(t, "xy = [{x}, {y}]")?;
        }
        Ok(())
    };
    cube(&mut t, "cube A", "table", Some((0.35, 0.12)))?;
    cube(&mut t, "cube B", "table", Some((0.35, -0.12)))?;
    // The first tower is on A; the rest stand on a grid at least 0.5 m out.
    let mut rest = names[2..].iter();
    let mut below = "cube A".to_string();
    for _ in 1..TOWER {
        if let Some(name) = rest.next() {
            cube(&mut t, name, &below, None)?;
            below = name.clone();
        }
    }
    let rest: Vec<&String> = rest.collect();
    for (slot, tower) in rest.chunks(TOWER).enumerate() {
        let (x, y) = (
            0.5 + 0.08 * (slot / 38) as f32,
            -1.48 + 0.08 * (slot % 38) as f32,
        );
        let mut support = "table".to_string();
        for (level, name) in tower.iter().enumerate() {
            cube(&mut t, name, &support, (level == 0).then_some((x, y)))?;
            support = (*name).clone();
        }
    }
    Ok(t)
}

/// The tree planned and repaired, with the plan time, the repair time and the repairs.
pub struct Repaired {
    pub plan: Plan,
    pub plan_time: Duration,
    pub repair_time: Duration,
    pub repairs: usize,
}

/// Plan the scenario's goal in `world`, then repair each grasp that fails by clearing what
/// lies on the grasped object, until the tree succeeds (at most `TOWER + 1` repairs).
pub fn plan_and_repair(scenario: &Scenario, world: &dyn World) -> Result<Repaired, BenchError> {
    let failed = |what: String| BenchError::Setup(format!("{}: {what}", scenario.name));
    let goal = scenario
        .goal
        .clone()
        .ok_or_else(|| failed("the scenario has no goal".into()))?
        .to_dnf();
    let planner = Planner::new(&scenario.domain);

    let started = Instant::now();
    let mut plan = planner
        .plan(&goal, world)
        .map_err(|e| failed(e.to_string()))?;
    let plan_time = started.elapsed();

    let started = Instant::now();
    let mut repairs = 0;
    while let Outcome::ActionFailed {
        node,
        action,
        error,
    } = &plan.outcome
    {
        let Some(object) = action.args.first().filter(|_| action.skill == "grasp") else {
            return Err(failed(format!("unexpected failure of {action}: {error}")));
        };
        if repairs > TOWER {
            return Err(failed(format!(
                "{action} still fails after {repairs} repairs"
            )));
        }
        let fix = Condition::parse(&format!("~\"any object\" on \"{object}\""))
            .map_err(|e| failed(e.to_string()))?;
        plan = planner
            .repair(plan.tree.clone(), *node, &[fix], world)
            .map_err(|e| failed(e.to_string()))?;
        repairs += 1;
    }
    let repair_time = started.elapsed();
    if plan.outcome != Outcome::Success {
        return Err(failed(format!(
            "the repaired tree does not succeed: {:?}",
            plan.outcome
        )));
    }
    Ok(Repaired {
        plan,
        plan_time,
        repair_time,
        repairs,
    })
}
