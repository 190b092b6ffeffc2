//! `betr bench` runs each part and prints its table (tiny sizes: nothing here is timed;
//! replay's seeks are measured, not judged); planning at scale keeps its plans. The parts
//! that need the embedded model or the Python anchors: the slow tier's `bench_cmd`.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::process::Command;

use betr::bench::towers;
use betr::bt::NodeKind;
use betr::scenario::Scenario;
use betr::world;

use support::bench::{bench, repo, rows_of};

#[test]
fn replay_prints_its_seek_rows_against_the_target() {
    let (out, report) = bench(&["replay"], &[]);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("| replay | seek to a random step of a recording, mean (ms) |"),
        "{table}"
    );
    assert!(
        table.contains("| every step fed from the start |"),
        "{table}"
    );
    assert!(table.contains("≤ 50.0 ms"), "{table}");
    let rows = rows_of(&report, "replay");
    assert_eq!(rows.len(), 3, "{rows:?}");
    for row in rows {
        assert!(row["betr"].as_f64().unwrap() > 0.0, "{row}");
        assert_eq!(row["target"]["kind"], "at_most", "{row}");
        assert_eq!(row["target"]["value"], 50.0, "{row}");
    }
}

#[test]
fn an_unknown_part_is_refused_naming_the_parts() {
    let out = Command::new(env!("CARGO_BIN_EXE_betr"))
        .args(["bench", "tick"])
        .current_dir(repo())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("invalid value 'tick'") && err.contains("ticks"),
        "{err}"
    );
}

/// The repaired tree of 10,000 cubes is the 10-cube one: the same repairs, the same nodes
/// of the same kinds with the same conditions and actions (only the ids of the cubes lying
/// on cube A are the same too, as the towers are built alike).
#[test]
fn ten_thousand_cubes_are_repaired_into_the_tree_ten_cubes_get() {
    let dir = support::cli::tmp("towers-scale");
    let base = repo().join("scenarios/cell/cell.toml");
    let shape = |n: usize| {
        let scenario = Scenario::load(&towers::write_scenario(&dir, n, &base).unwrap()).unwrap();
        let world = world::load(&scenario).unwrap();
        let repaired = towers::plan_and_repair(&scenario, world.as_ref()).unwrap();
        let tree = &repaired.plan.tree;
        let mut nodes: Vec<String> = Vec::new();
        let mut stack = vec![(tree.root(), 0usize)];
        while let Some((id, depth)) = stack.pop() {
            let kind = match tree.kind(id).unwrap() {
                NodeKind::Condition(c) => format!("{c}?"),
                NodeKind::Action(a) => format!("{a}!"),
                other => format!("{other:?}"),
            };
            nodes.push(format!("{depth} {kind}"));
            for &child in tree.children(id).unwrap().iter().rev() {
                stack.push((child, depth + 1));
            }
        }
        (repaired.repairs, nodes)
    };
    let small = shape(10);
    let large = shape(10_000);
    assert_eq!(small.0, 2);
    assert_eq!(small, large);
}
