//! Plans all 100 gold goals of the LLM-OBTEA dataset from the shared cafe state and prints
//! the median and maximum planning time per goal (each goal timed as the median of
//! several repetitions, so one noisy run does not decide it).
//!
//! Run: `cargo bench --bench plan_goals`

use std::path::Path;
use std::time::{Duration, Instant};

use betr::dataset::{self, Difficulty};
use betr::goal::Formula;
use betr::planner::{Outcome, Planner};
use betr::scenario::Scenario;
use betr::world;

const REPETITIONS: usize = 7;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenario = Scenario::load(&root.join("scenarios/cafe/cafe.toml"))?;
    let world = world::load(&scenario)?;
    let planner = Planner::new(&scenario.domain);
    let cases = dataset::load(&root.join("../shared/datasets/llm-obtea"))?;

    let mut rows: Vec<(Difficulty, String, Duration, usize, bool)> = Vec::new();
    for case in &cases {
        let dnf = Formula::parse(&case.gold)?.to_dnf();
        let mut times = Vec::with_capacity(REPETITIONS);
        let mut last = None;
        for _ in 0..REPETITIONS {
            let started = Instant::now();
            let plan = planner.plan(&dnf, world.as_ref())?;
            times.push(started.elapsed());
            last = Some(plan);
        }
        times.sort();
        let plan = last.ok_or("no repetition ran")?;
        rows.push((
            case.difficulty,
            case.gold.clone(),
            times[times.len() / 2],
            plan.tree.len(),
            plan.outcome == Outcome::Success,
        ));
    }

    println!(
        "planning time per goal (median of {REPETITIONS} runs each), {} goals",
        rows.len()
    );
    println!(
        "{:<8} {:>6} {:>12} {:>12} {:>10}",
        "set", "goals", "median", "max", "succeeded"
    );
    for d in Difficulty::ALL.iter().copied().map(Some).chain([None]) {
        let mut times: Vec<Duration> = rows
            .iter()
            .filter(|r| d.is_none_or(|d| r.0 == d))
            .map(|r| r.2)
            .collect();
        times.sort();
        let ok = rows
            .iter()
            .filter(|r| d.is_none_or(|d| r.0 == d) && r.4)
            .count();
        let (Some(max), Some(median)) = (times.last(), times.get(times.len() / 2)) else {
            continue;
        };
        println!(
            "{:<8} {:>6} {:>9.3} ms {:>9.3} ms {:>10}",
            d.map_or("all", |d| d.as_str()),
            times.len(),
            median.as_secs_f64() * 1e3,
            max.as_secs_f64() * 1e3,
            ok
        );
    }
    rows.sort_by_key(|r| std::cmp::Reverse(r.2));
    println!("\nslowest goals:");
    for (d, gold, t, nodes, _) in rows.iter().take(5) {
        println!(
            "  {:>8.3} ms  {:>3} nodes  [{}] {gold}",
            t.as_secs_f64() * 1e3,
            nodes,
            d.as_str()
        );
    }
    Ok(())
}
