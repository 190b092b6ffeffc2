//! `betr bench` parts that need what only the slow tier has: ticks against py_trees (in a
//! virtual environment under target/) with planning at scale, the model and cold parts
//! beside llama-bench with the default model, and the embedded engine's saved prompt
//! state used by the next engine and refused when it is not whole.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::{Path, PathBuf};

use betr::llm::local::{Engine, EngineOptions, Generation};

use support::bench::{bench, rows_of};

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
