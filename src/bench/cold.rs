//! The first answer of a one-shot command against a warm answer.
//!
//! A one-shot command (`betr interpret`, `resolve`, a new workbench) starts with an empty
//! key-value cache. With the saved prompt state (`llm::local::prompt_state`) it evaluates
//! only the part of the goal prompt that differs from the last one; without it, the whole
//! prompt. Each is measured as a new engine would meet it: a fresh engine per first answer,
//! then warm answers on the last one. Prompt states go to a directory of their own.

use std::path::Path;
use std::time::{Duration, Instant};

use super::{BenchError, Better, Row, Target};
use crate::domain::Condition;
use crate::llm::grammar;
use crate::llm::local::{Engine, EngineOptions, Generation};
use crate::llm::prompt::{Context, Templates, Variant};
use crate::scenario::Scenario;
use crate::world;

/// Instructions for the first answers and the warm ones (the goal prompt of scenario 1's
/// cell with each).
const INSTRUCTIONS: [&str; 4] = [
    "Put the blue cube on the green cube",
    "Put the red cube on the table",
    "Stack the green cube on the blue cube",
    "Hold the red cube",
];

/// A scenario's goal prompt as the product sends it to the embedded model (the built-in
/// templates, the default variant, the scene's facts, the goal grammar), for timing.
pub struct GoalPrompt {
    pub scenario: Scenario,
    facts: Vec<Condition>,
    gbnf: String,
}

impl GoalPrompt {
    pub fn load(path: &Path) -> Result<GoalPrompt, BenchError> {
        let scenario = Scenario::load(path)?;
        let facts = world::load(&scenario)?.facts();
        let gbnf = grammar::goal_grammar(&scenario.domain.vocabulary, true, false);
        Ok(GoalPrompt {
            scenario,
            facts,
            gbnf,
        })
    }

    /// The generation for `instruction`: greedy, one line, with or without the grammar.
    pub fn generation(&self, instruction: &str, grammar: bool) -> Result<Generation, BenchError> {
        let ctx = Context {
            scenario: &self.scenario,
            facts: &self.facts,
            instruction,
            variant: &Variant::default(),
        };
        let messages = ctx
            .goal(&Templates::builtin())?
            .into_iter()
            .map(|m| (m.role.name().to_string(), m.content))
            .collect();
        Ok(Generation {
            messages,
            max_tokens: 60,
            temperature: 0.0,
            seed: 0,
            stop: vec!["\n".into()],
            grammar: grammar.then(|| self.gbnf.clone()),
            beams: 1,
            prefill: String::new(),
        })
    }
}

/// Latencies of one model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Latencies {
    /// First answer of a fresh engine with no saved prompt state.
    pub cold_unsaved: Duration,
    /// First answer of a fresh engine that finds the state saved by the one before.
    pub cold_saved: Duration,
    /// Later answers of the same engine (the median).
    pub warm: Duration,
    /// Prompt tokens of the first answer, and how many the saved state spared.
    pub prompt_tokens: u32,
    pub reused_tokens: u32,
    pub load: Duration,
}

/// Measure `model` on `scenario`'s goal prompt with `threads`; `states` is emptied first.
pub fn latencies(
    model: &Path,
    scenario: &Path,
    threads: u32,
    states: &Path,
    warm_calls: usize,
) -> Result<Latencies, BenchError> {
    let prompt = GoalPrompt::load(scenario)?;
    let job = |instruction: &str| prompt.generation(instruction, true);
    if states.exists() {
        std::fs::remove_dir_all(states)?;
    }
    let load = || -> Result<(Engine, Duration), BenchError> {
        let started = Instant::now();
        let engine = Engine::load(EngineOptions {
            model_path: model.to_path_buf(),
            threads,
            context: 4096,
            prompt_states: Some(states.to_path_buf()),
        })?;
        Ok((engine, started.elapsed()))
    };
    let timed = |engine: &Engine, g: Generation| {
        let started = Instant::now();
        let out = engine.generate_blocking(g)?;
        Ok::<_, BenchError>((started.elapsed(), out))
    };

    // A fresh engine, nothing saved: the whole prompt is evaluated (and its state saved).
    let (first, load_time) = load()?;
    let (cold_unsaved, _) = timed(&first, job(INSTRUCTIONS[0])?)?;
    drop(first);
    // Another fresh engine, as the next one-shot command, with another instruction.
    let (engine, _) = load()?;
    let (cold_saved, out) = timed(&engine, job(INSTRUCTIONS[1])?)?;
    let mut warm = Vec::new();
    for i in 0..warm_calls.max(1) {
        let instruction = INSTRUCTIONS[2 + i % 2];
        warm.push(timed(&engine, job(instruction)?)?.0);
    }
    warm.sort();
    Ok(Latencies {
        cold_unsaved,
        cold_saved,
        warm: warm[warm.len() / 2],
        prompt_tokens: out.prompt_tokens,
        reused_tokens: out.cached_tokens,
        load: load_time,
    })
}

/// The rows of one model: the first answer with the saved state against without it
/// (target: at most twice the warm answer), and the warm answer.
pub fn rows(name: &str, threads: u32, l: &Latencies) -> Vec<Row> {
    let warm = l.warm.as_secs_f64();
    vec![
        Row {
            part: "cold".into(),
            measure: format!("{name}: first answer of a one-shot command"),
            unit: "s".into(),
            better: Better::Lower,
            betr: l.cold_saved.as_secs_f64(),
            anchor: Some((
                "betr without the saved prompt state".into(),
                l.cold_unsaved.as_secs_f64(),
            )),
            target: Some(Target::AtMost(2.0 * warm)),
            note: format!(
                "{} of {} prompt tokens from the saved state; target 2 × warm; model load {:.2} s; {threads} thread(s)",
                l.reused_tokens,
                l.prompt_tokens,
                l.load.as_secs_f64()
            ),
        },
        Row {
            part: "cold".into(),
            measure: format!("{name}: warm answer"),
            unit: "s".into(),
            better: Better::Lower,
            betr: warm,
            anchor: None,
            target: None,
            note: format!("median; goal prompt of scenario 1, {threads} thread(s)"),
        },
    ]
}
