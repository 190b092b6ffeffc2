//! The embedded model at the machine's limit: betr's prompt evaluation and generation
//! speed against llama.cpp's own `llama-bench`, linked against the same llama.cpp
//! libraries (`scripts/llama-bench.sh`), on the same model file and thread count, measured
//! back to back.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use serde::Deserialize;

use super::{BenchError, Better, Row, Target};
use crate::llm::local::{Engine, EngineOptions, Generation};

/// How much to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelSizes {
    /// Prompt tokens evaluated per run (llama-bench's `-p`).
    pub prompt: u32,
    /// Tokens generated per run (`-n`).
    pub generate: u32,
    /// Runs per measure (`-r`); the mean of their rates is reported.
    pub repeats: u32,
}

/// Prompt and generation tokens per second.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Speeds {
    pub prompt: f64,
    pub generation: f64,
}

/// Build (or find) llama-bench with `script`, against the llama.cpp built in the cargo
/// profile directory `profile`; its path. The script's progress goes to stderr.
pub fn llama_bench_binary(script: &Path, profile: &Path) -> Result<PathBuf, BenchError> {
    let out = super::run_anchor(
        "building llama-bench",
        Command::new("bash")
            .arg(script)
            .arg(std::path::absolute(profile)?)
            .stderr(Stdio::inherit()),
    )?;
    let path = PathBuf::from(out.trim());
    if !path.is_file() {
        return Err(anchor(format!(
            "{} named {}, which is not a file",
            script.display(),
            path.display()
        )));
    }
    Ok(path)
}

fn anchor(detail: String) -> BenchError {
    BenchError::Anchor {
        what: "llama-bench".into(),
        detail,
    }
}

/// One result of `llama-bench -o json`.
#[derive(Debug, Deserialize)]
struct BenchResult {
    n_prompt: u32,
    n_gen: u32,
    avg_ts: f64,
}

/// llama-bench's speeds for `model` with `threads`.
pub fn llama_bench(
    binary: &Path,
    model: &Path,
    threads: u32,
    sizes: ModelSizes,
) -> Result<Speeds, BenchError> {
    let out = super::run_anchor(
        "llama-bench",
        Command::new(binary)
            .arg("-m")
            .arg(model)
            .args(["-t", &threads.to_string()])
            .args(["-p", &sizes.prompt.to_string()])
            .args(["-n", &sizes.generate.to_string()])
            .args(["-r", &sizes.repeats.max(1).to_string()])
            .args(["-o", "json"]),
    )?;
    parse_llama_bench(&out)
}

fn parse_llama_bench(json: &str) -> Result<Speeds, BenchError> {
    let results: Vec<BenchResult> = serde_json::from_str(json).map_err(|e| {
        anchor(format!(
            "unexpected output ({e}): {}",
            json.chars().take(200).collect::<String>()
        ))
    })?;
    let find = |prompt: bool| {
        results
            .iter()
            .find(|r| {
                if prompt {
                    r.n_prompt > 0 && r.n_gen == 0
                } else {
                    r.n_gen > 0 && r.n_prompt == 0
                }
            })
            .map(|r| r.avg_ts)
            .ok_or_else(|| {
                anchor(format!(
                    "no {} result in its output",
                    if prompt { "prompt" } else { "generation" }
                ))
            })
    };
    Ok(Speeds {
        prompt: find(true)?,
        generation: find(false)?,
    })
}

/// betr's speeds: the model loaded by betr's engine with `threads`; each run evaluates a
/// fresh prompt of about `sizes.prompt` tokens (nothing of it cached) and generates
/// `sizes.generate` tokens greedily, as the product does (sampling included).
pub fn betr_speeds(model: &Path, threads: u32, sizes: ModelSizes) -> Result<Speeds, BenchError> {
    let engine = Engine::load(EngineOptions {
        model_path: model.to_path_buf(),
        threads,
        context: (sizes.prompt + sizes.generate + 64).max(512),
        prompt_states: None,
    })?;
    let (mut prompt, mut generation) = (Vec::new(), Vec::new());
    for run in 0..sizes.repeats.max(1) {
        // Each run's text starts differently, so no prompt token is reused from the last.
        let g = engine.generate_blocking(Generation {
            messages: vec![("user".into(), filler(run, sizes.prompt))],
            max_tokens: sizes.generate,
            temperature: 0.0,
            seed: 0,
            stop: Vec::new(),
            grammar: None,
            beams: 1,
            prefill: String::new(),
        })?;
        let evaluated = g.prompt_tokens.saturating_sub(g.cached_tokens);
        prompt.push(f64::from(evaluated) / g.prompt_time.as_secs_f64().max(1e-9));
        if g.completion_tokens > 1 {
            generation
                .push(f64::from(g.completion_tokens) / g.generation_time.as_secs_f64().max(1e-9));
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    Ok(Speeds {
        prompt: mean(&prompt),
        generation: mean(&generation),
    })
}

/// About `tokens` tokens of text asking for a long answer (so generation does not stop
/// early); `run` makes its first words differ from the last run's.
fn filler(run: u32, tokens: u32) -> String {
    let mut text = format!(
        "Run {run}. Count from {} upwards, one number per line, and keep going. Notes:",
        run * 1000 + 1
    );
    // About 12 tokens per sentence.
    for i in 0..tokens.saturating_sub(30) / 12 {
        text.push_str(&format!(
            " The robot puts cube {i} on the table beside the tower."
        ));
    }
    text
}

/// The rows for one model and thread count: prompt and generation, betr against llama-bench.
pub fn rows(name: &str, threads: u32, betr: Speeds, anchor: Speeds, sizes: ModelSizes) -> Vec<Row> {
    let row = |what: &str, n: u32, b: f64, a: f64| Row {
        part: "model".into(),
        measure: format!("{name}, {what}, {threads} thread(s)"),
        unit: "tokens/s".into(),
        better: Better::Higher,
        betr: b,
        anchor: Some(("llama-bench".into(), a)),
        target: Some(Target::RatioAtLeast(0.9)),
        note: format!("{n} tokens, mean of {} run(s)", sizes.repeats.max(1)),
    };
    vec![
        row("prompt", sizes.prompt, betr.prompt, anchor.prompt),
        row(
            "generation",
            sizes.generate,
            betr.generation,
            anchor.generation,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn llama_benchs_json_is_read() -> Result<(), BenchError> {
        let json = r#"[{"n_prompt": 512, "n_gen": 0, "avg_ts": 77.8, "n_threads": 2},
                      {"n_prompt": 0, "n_gen": 64, "avg_ts": 15.3, "n_threads": 2}]"#;
        let s = parse_llama_bench(json)?;
        assert_eq!((s.prompt, s.generation), (77.8, 15.3));
        assert!(parse_llama_bench("[]").is_err());
        assert!(parse_llama_bench("error: model not found").is_err());
        Ok(())
    }

    #[test]
    fn filler_text_grows_with_the_tokens_asked_and_differs_per_run() {
        assert!(filler(0, 512).len() > 4 * filler(0, 64).len());
        assert_ne!(filler(0, 64)[..12], filler(1, 64)[..12]);
    }
}
