//! Cells with 10, 100 and 1000 cubes stacked in towers of three. Cube A is the bottom of
//! one tower near the robot; the task is "put cube A on cube B". Planning ends with
//! `grasp "cube A"` failing (the tower is in the gripper's way); the repair inserts
//! `~"any object" on "cube A"`, and since the cube taken off A has one on it in turn, the
//! same kind of fix is inserted at each grasp that fails until the tree succeeds.
//!
//! Prints plan time, repair time, the number of repairs, the collision questions asked
//! (is this path free, is this opening clear), the broad-phase box tests and exact tests
//! (convex part pairs: shape casts and intersection tests) they took, the time spent
//! answering them, and tests per second of that time. Run with
//! `cargo bench --bench cell_towers`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};

use betr::domain::{Condition, Scenario};
use betr::planner::{Outcome, Planner};
use betr::world::CellWorld;

const TOWER: usize = 3;

/// A scenario with `n` cubes (A, B and the rest), written next to a copy of cell.toml.
fn write_scenario(dir: &Path, n: usize) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/cell.toml");
    std::fs::copy(base, dir.join("cell.toml"))?;
    let mut names = vec!["cube A".to_string(), "cube B".to_string()];
    names.extend((1..n.saturating_sub(1)).map(|i| format!("cube {i}")));
    let mut t = String::new();
    writeln!(
        t,
        "extends = \"cell.toml\"\n[scenario]\nname = \"{n} cubes in towers\""
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

fn main() -> Result<()> {
    let dir = std::env::temp_dir().join(format!("betr-cell-towers-{}", std::process::id()));
    println!(
        "| cubes | plan (ms) | repair (ms) | repairs | queries | box tests | exact tests | collision (ms) | tests/s |"
    );
    println!(
        "|------:|----------:|------------:|--------:|--------:|----------:|------------:|---------------:|--------:|"
    );
    for n in [10, 100, 1000] {
        let scenario = Scenario::load(&write_scenario(&dir, n)?)?;
        let world = CellWorld::from_scenario(&scenario, None)?;
        let goal = scenario
            .goal
            .clone()
            .context("the scenario has a goal")?
            .to_dnf();
        let planner = Planner::new(&scenario.domain);

        let started = Instant::now();
        let mut plan = planner.plan(&goal, &world)?;
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
                bail!("{n} cubes: unexpected failure of {action}: {error}");
            }
            let fix = Condition::parse(&format!("~\"any object\" on \"{}\"", action.args[0]))?;
            plan = planner.repair(plan.tree.clone(), *node, &[fix], &world)?;
            repairs += 1;
        }
        let repair_time = started.elapsed();
        if plan.outcome != Outcome::Success {
            bail!(
                "{n} cubes: the repaired tree does not succeed: {:?}",
                plan.outcome
            );
        }
        let (queries, seconds) = world.collision_queries();
        let tests = world.collision_checks() + world.broad_checks();
        println!(
            "| {n:>5} | {:>9.2} | {:>11.1} | {repairs:>7} | {queries:>7} | {:>9} | {:>11} | {:>14.2} | {:>7.2e} |",
            plan_time.as_secs_f64() * 1e3,
            repair_time.as_secs_f64() * 1e3,
            world.broad_checks(),
            world.collision_checks(),
            seconds * 1e3,
            tests as f64 / seconds.max(1e-9),
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}
