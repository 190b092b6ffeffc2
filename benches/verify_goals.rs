//! Verifies the trees of all 100 gold goals of the LLM-OBTEA dataset, planned in the
//! planner's model from the shared cafe state as `betr verify` plans them: structural
//! checks plus model checking, once with nothing but the tree's own runs and once with
//! action failures and the cafe's declared disturbances.
//! Prints median and maximum verification time (each the median of several runs) and
//! the states explored, and how many trees pass.
//!
//! Then the tabletop cell with 10, 100 and 1000 cubes in towers (built, planned and
//! repaired as in `cell_towers`): the time to read the initial facts from the geometry,
//! and verification time, states and transitions, with and without action failures.
//!
//! Run: `cargo bench --bench verify_goals`

use std::path::Path;
use std::time::{Duration, Instant};

use betr::dataset;
use betr::goal::Formula;
use betr::scenario::Scenario;
use betr::verify::{self, Limits, Report, VerifyConfig, VerifyInput};
use betr::world::{self, CellWorld, World};

use betr::bench::towers;

const REPETITIONS: usize = 5;

struct Row {
    gold: String,
    time: Duration,
    states: usize,
    transitions: usize,
    holds: bool,
    findings: usize,
    /// The first finding or violated property, for trees that do not verify.
    why: String,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenario = Scenario::load(&root.join("scenarios/cafe/cafe.toml"))?;
    let config = VerifyConfig::from_scenario(&scenario)?;
    let world = world::load(&scenario)?;
    let initial = world.facts();
    let cases = dataset::load(&root.join("../shared/datasets/llm-obtea"))?;
    // The trees `betr verify` checks: planned in the planner's model.
    let trees = cases
        .iter()
        .map(|c| {
            let dnf = Formula::parse(&c.gold)?.to_dnf();
            let planned = verify::plan_in_model(
                &scenario.domain,
                &initial,
                &dnf,
                &config.properties,
                &config.disturbances,
            )?;
            Ok((c.gold.clone(), planned.plan.tree))
        })
        .collect::<Result<Vec<_>, Box<dyn std::error::Error>>>()?;

    for (label, disturbed) in [
        ("the tree's own runs", false),
        ("with action failures and disturbances", true),
    ] {
        let mut rows = Vec::new();
        for (gold, tree) in &trees {
            let input = VerifyInput {
                domain: &scenario.domain,
                tree,
                initial: &initial,
                disturbances: if disturbed { &config.disturbances } else { &[] },
                properties: &[],
                limits: Limits {
                    action_failures: disturbed,
                    ..Limits::default()
                },
            };
            let mut times = Vec::with_capacity(REPETITIONS);
            let mut last: Option<Report> = None;
            for _ in 0..REPETITIONS {
                let started = Instant::now();
                let report = verify::verify(&input);
                times.push(started.elapsed());
                last = Some(report);
            }
            times.sort();
            let report = last.ok_or("no repetition ran")?;
            let (states, transitions) = report
                .model
                .as_ref()
                .map_or((0, 0), |m| (m.states, m.transitions));
            let why = report
                .findings
                .first()
                .map(ToString::to_string)
                .or_else(|| {
                    let m = report.model.as_ref().ok()?;
                    let p = m.properties.iter().find(|p| !p.verdict.holds())?;
                    Some(match &p.verdict {
                        verify::Verdict::Violated(cx) => format!("{}: {}", p.name, cx.violation),
                        other => format!("{}: {other:?}", p.name),
                    })
                })
                .unwrap_or_default();
            rows.push(Row {
                why,
                gold: gold.clone(),
                time: times[times.len() / 2],
                states,
                transitions,
                holds: report.holds(),
                findings: report.findings.len(),
            });
        }
        summarize(label, &mut rows);
    }
    cell_towers()
}

/// Verification of the repaired tower-cell trees.
fn cell_towers() -> Result<(), Box<dyn std::error::Error>> {
    let base = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/cell.toml");
    let dir = std::env::temp_dir().join(format!("betr-verify-towers-{}", std::process::id()));
    println!("\nTower cells (median of {REPETITIONS} verifications each):");
    println!(
        "| cubes | facts | facts (ms) | repairs | tree nodes | failures | verify (ms) | states | transitions | atoms | verified |"
    );
    println!(
        "|------:|------:|-----------:|--------:|-----------:|---------:|------------:|-------:|------------:|------:|---------:|"
    );
    for n in [10, 100, 1000] {
        let scenario = Scenario::load(&towers::write_scenario(&dir, n, &base)?)?;
        let world = CellWorld::from_scenario(&scenario, None)?;
        let repaired = towers::plan_and_repair(&scenario, &world)?;
        let started = Instant::now();
        let initial = world.facts();
        let facts_time = started.elapsed();
        for failures in [false, true] {
            let input = VerifyInput {
                domain: &scenario.domain,
                tree: &repaired.plan.tree,
                initial: &initial,
                disturbances: &[],
                properties: &[],
                limits: Limits {
                    action_failures: failures,
                    ..Limits::default()
                },
            };
            let mut times = Vec::with_capacity(REPETITIONS);
            let mut last = None;
            for _ in 0..REPETITIONS {
                let started = Instant::now();
                last = Some(verify::verify(&input));
                times.push(started.elapsed());
            }
            times.sort();
            let report = last.ok_or("no repetition ran")?;
            let m = report.model.as_ref().map_err(|e| e.to_string())?;
            println!(
                "| {n:>5} | {:>5} | {:>10.1} | {:>7} | {:>10} | {:>8} | {:>11.3} | {:>6} | {:>11} | {:>5} | {:>8} |",
                initial.len(),
                facts_time.as_secs_f64() * 1e3,
                repaired.repairs,
                repaired.plan.tree.len(),
                if failures { "on" } else { "off" },
                times[times.len() / 2].as_secs_f64() * 1e3,
                m.states,
                m.transitions,
                m.atoms,
                if report.holds() { "yes" } else { "NO" },
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

fn summarize(label: &str, rows: &mut [Row]) {
    let mut times: Vec<Duration> = rows.iter().map(|r| r.time).collect();
    times.sort();
    let mut states: Vec<usize> = rows.iter().map(|r| r.states).collect();
    states.sort();
    let median = |v: &[Duration]| v.get(v.len() / 2).copied().unwrap_or_default();
    println!(
        "\n{} gold-goal trees, {label} (median of {REPETITIONS} runs each):",
        rows.len()
    );
    println!(
        "  time   median {:>8.3} ms   max {:>8.3} ms",
        median(&times).as_secs_f64() * 1e3,
        times.last().copied().unwrap_or_default().as_secs_f64() * 1e3
    );
    println!(
        "  states median {:>8}      max {:>8}   (transitions max {})",
        states.get(states.len() / 2).copied().unwrap_or_default(),
        states.last().copied().unwrap_or_default(),
        rows.iter().map(|r| r.transitions).max().unwrap_or_default()
    );
    println!(
        "  verified: {} of {}; trees with structural findings: {}",
        rows.iter().filter(|r| r.holds).count(),
        rows.len(),
        rows.iter().filter(|r| r.findings > 0).count()
    );
    rows.sort_by_key(|r| std::cmp::Reverse(r.time));
    println!("  slowest:");
    for r in rows.iter().take(3) {
        println!(
            "    {:>8.3} ms {:>6} states  {}",
            r.time.as_secs_f64() * 1e3,
            r.states,
            r.gold
        );
    }
    let failing: Vec<&Row> = rows.iter().filter(|r| !r.holds).collect();
    if !failing.is_empty() {
        println!("  not verified:");
        for r in failing.iter().take(10) {
            println!("    {}\n      {}", r.gold, r.why);
        }
    }
}
