//! The tower cells shared by the benchmarks (`cell_towers`, `verify_goals`): `n` cubes
//! stacked in towers of three, cube A at the bottom of one tower near the robot, the task
//! "put cube A on cube B"; and the repair that inserts `~"any object" on "X"` at each
//! grasp that fails until the tree succeeds.
#![allow(dead_code)] // each benchmark uses a part of it

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

use betr::domain::{Condition, Scenario};
use betr::planner::{Outcome, Plan, Planner};
use betr::world::CellWorld;

pub const TOWER: usize = 3;

/// A scenario with `n` cubes (A, B and the rest), extending the cell's cell.toml.
pub fn write_scenario(dir: &Path, n: usize) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    // Extends the cell in place, so its example pool and conventions come with it.
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/cell.toml");
    let mut names = vec!["cube A".to_string(), "cube B".to_string()];
    names.extend((1..n.saturating_sub(1)).map(|i| format!("cube {i}")));
    let mut t = String::new();
    writeln!(
        t,
        "extends = '{}'\n[scenario]\nname = \"{n} cubes in towers\"",
        base.display()
    )?;
    writeln!(t, "goal = '\"cube A\" on \"cube B\"'\n[objects]")?;
    let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    writeln!(t, "item = [{}]", quoted.join(", "))?;
    // A big table: the towers stand beyond a free area in front of the robot.
    writeln!(
        t,
        "[world.solids.\"table\"]\nsize = [2.4, 3.2, 0.05]\nat = [1.2, 0.0, -0.05]"
    )?;
    let cube = |t: &mut String, name: &str, support: &str, xy: Option<(f32, f32)>| -> Result<()> {
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
    let path = dir.join("towers.toml");
    std::fs::write(&path, t)?;
    Ok(path)
}

/// The tree planned and repaired, with the plan time, the repair time and the repairs.
pub struct Repaired {
    pub plan: Plan,
    pub plan_time: Duration,
    pub repair_time: Duration,
    pub repairs: usize,
}

/// Plan the scenario's goal in `world`, then repair each failing grasp.
pub fn plan_and_repair(scenario: &Scenario, world: &CellWorld) -> Result<Repaired> {
    let goal = scenario
        .goal
        .clone()
        .context("the scenario has a goal")?
        .to_dnf();
    let planner = Planner::new(&scenario.domain);

    let started = Instant::now();
    let mut plan = planner.plan(&goal, world)?;
    let plan_time = started.elapsed();

    let started = Instant::now();
    let mut repairs = 0;
    while let Outcome::ActionFailed {
        node,
        action,
        error,
    } = &plan.outcome
    {
        if action.skill != "grasp" || repairs > TOWER {
            bail!("{}: unexpected failure of {action}: {error}", scenario.name);
        }
        let fix = Condition::parse(&format!("~\"any object\" on \"{}\"", action.args[0]))?;
        plan = planner.repair(plan.tree.clone(), *node, &[fix], world)?;
        repairs += 1;
    }
    let repair_time = started.elapsed();
    if plan.outcome != Outcome::Success {
        bail!(
            "{}: the repaired tree does not succeed: {:?}",
            scenario.name,
            plan.outcome
        );
    }
    Ok(Repaired {
        plan,
        plan_time,
        repair_time,
        repairs,
    })
}
