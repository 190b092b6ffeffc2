//! `betr bench` runs each part and prints its table (tiny sizes: nothing here is timed;
//! replay's seeks are measured, not judged);
//! planning at scale keeps its plans; the embedded engine's saved prompt state is used by
//! the next engine and refused when it is not whole.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

mod support;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use betr::bench::towers;
use betr::bt::NodeKind;
use betr::llm::local::{Engine, EngineOptions, Generation};
use betr::scenario::Scenario;
use betr::world;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `betr bench PARTS --quick` in the repository (it reads scenarios/ and ../shared), the
/// JSON written to a scratch file.
fn bench(parts: &[&str], extra: &[&str]) -> (Output, serde_json::Value) {
    let scratch = support::cli::tmp(&format!("bench-{}", parts.join("-")));
    let json = scratch.join("bench.json");
    let out = Command::new(env!("CARGO_BIN_EXE_betr"))
        .arg("bench")
        .args(parts)
        .arg("--quick")
        .arg("--json")
        .arg(&json)
        .args(extra)
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", support::cli::text(&out));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    (out, report)
}

fn rows_of<'a>(report: &'a serde_json::Value, part: &str) -> Vec<&'a serde_json::Value> {
    report["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["part"] == part)
        .collect()
}

#[test]
fn ticks_and_scale_print_their_rows_against_py_trees_and_the_targets() {
    let (out, report) = bench(&["ticks", "scale"], &[]);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("load average"), "{table}");
    assert!(
        table.contains("| ticks | ticks of a 1021-node planned-BT-shaped tree (ticks/s) |"),
        "{table}"
    );
    assert!(table.contains("| py_trees 2.6.0 |"), "{table}");
    assert!(
        table.contains("scenario 1: plan, fail, repair, re-plan, run to success"),
        "{table}"
    );
    assert!(table.contains("repair, 100 cubes in towers"), "{table}");
    let ticks = rows_of(&report, "ticks");
    assert_eq!(ticks.len(), 1);
    assert!(ticks[0]["anchor"][1].as_f64().unwrap() > 0.0);
    assert!(ticks[0]["betr"].as_f64().unwrap() > 0.0);
    assert_eq!(rows_of(&report, "scale").len(), 3);
    assert!(report["machine"]["cores"].as_u64().unwrap() >= 1);
}

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

/// The model and cold parts with the default model: llama-bench is built against the
/// test binary's llama.cpp and both rows have an anchor value.
#[test]
fn model_and_cold_parts_measure_betr_beside_llama_bench_and_the_unsaved_state() {
    support::embedded::default_model_file();
    let (out, report) = bench(
        &["model", "cold"],
        &["--model", betr::model::DEFAULT_MODEL.name, "--threads", "2"],
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("| llama-bench |"), "{table}");
    assert!(
        table.contains("first answer of a one-shot command"),
        "{table}"
    );
    let model = rows_of(&report, "model");
    assert_eq!(model.len(), 2, "prompt and generation: {report}");
    for row in model.iter().chain(rows_of(&report, "cold").iter().take(1)) {
        assert!(row["betr"].as_f64().unwrap() > 0.0, "{row}");
        assert!(row["anchor"][1].as_f64().unwrap() > 0.0, "{row}");
    }
}

fn engine(states: &Path) -> Engine {
    Engine::load(EngineOptions {
        model_path: support::embedded::default_model_file(),
        threads: 2,
        context: 2048,
        prompt_states: Some(states.to_path_buf()),
    })
    .unwrap()
}

fn ask(engine: &Engine, question: &str) -> betr::llm::local::Generated {
    // A long fixed part, so the prompt is worth a saved state, then the question.
    let system = format!(
        "You answer questions about a robot cell in one short line. {}",
        "The cell has a table, a blue cube, a green cube and a red cube. ".repeat(30)
    );
    engine
        .generate_blocking(Generation {
            beams: 1,
            messages: vec![("system".into(), system), ("user".into(), question.into())],
            max_tokens: 8,
            temperature: 0.0,
            seed: 0,
            stop: vec!["\n".into()],
            grammar: None,
            prefill: String::new(),
        })
        .unwrap()
}

fn state_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(Result::ok).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    files
}

/// A new engine starts from the state the first saved; a state file cut short is not used
/// (the whole prompt is evaluated again, giving the first answer) and is saved again whole.
#[test]
fn the_next_engine_starts_from_the_saved_prompt_state() {
    let dir = support::cli::tmp("prompt-state");
    let first = ask(&engine(&dir), "Which cube is red?");
    assert_eq!(first.cached_tokens, 0);
    let files = state_files(&dir);
    assert_eq!(files.len(), 2, "a state and its metadata: {files:?}");

    let second = ask(&engine(&dir), "Which cube is red?");
    assert!(
        second.cached_tokens > first.prompt_tokens / 2,
        "{} of {} tokens reused",
        second.cached_tokens,
        second.prompt_tokens
    );
    // (Not compared with the first answer word for word: its last prompt token is
    // evaluated alone here, in a batch there, and the sums may round differently.)
    assert!(!second.text.trim().is_empty());

    let state = files
        .iter()
        .find(|f| f.extension().unwrap() == "state")
        .unwrap();
    let bytes = std::fs::read(state).unwrap();
    std::fs::write(state, &bytes[..bytes.len() / 2]).unwrap();
    let third = ask(&engine(&dir), "Which cube is red?");
    assert_eq!(third.cached_tokens, 0, "a half-written state is not used");
    assert_eq!(third.text, first.text);
    // Saved again, whole.
    assert_eq!(std::fs::read(state).unwrap().len(), bytes.len());
}
