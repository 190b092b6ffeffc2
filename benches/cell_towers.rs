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

use anyhow::Result;

use betr::scenario::Scenario;
use betr::world::CellWorld;

use betr::bench::towers::{Repaired, plan_and_repair, write_scenario};

fn main() -> Result<()> {
    let base = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/cell.toml");
    let dir = std::env::temp_dir().join(format!("betr-cell-towers-{}", std::process::id()));
    println!(
        "| cubes | plan (ms) | repair (ms) | repairs | queries | box tests | exact tests | collision (ms) | tests/s |"
    );
    println!(
        "|------:|----------:|------------:|--------:|--------:|----------:|------------:|---------------:|--------:|"
    );
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![10, 100, 1000]
    } else {
        sizes
    };
    for n in sizes {
        let scenario = Scenario::load(&write_scenario(&dir, n, &base)?)?;
        let world = CellWorld::from_scenario(&scenario, None)?;
        let Repaired {
            plan_time,
            repair_time,
            repairs,
            ..
        } = plan_and_repair(&scenario, &world)?;
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
