//! `betr bench llm`: how fast the embedded model answers the goal prompt of scenario 1.

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context as _, Result};

use betr::domain::Scenario;
use betr::llm::grammar;
use betr::llm::local::{Engine, EngineOptions, Generated, Generation};
use betr::llm::prompt::{Context, Templates, Variant};
use betr::llm::{Message, Role};
use betr::world;

/// Load the model, then time a cold call, warm calls that share the cached prompt prefix,
/// with and without the grammar, and print one table.
pub fn llm(
    scenario: &Path,
    (model_path, model): (Option<&Path>, Option<&str>),
    threads: Option<u32>,
    repeats: usize,
) -> Result<ExitCode> {
    let threads = threads.map_or_else(betr::llm::local::threads::idle_threads, |t| t.max(1));
    let path = match model_path {
        Some(p) => p.to_path_buf(),
        None => super::model_cmd::ensure(model)?,
    };
    println!("model: {}", path.display());
    let scenario = Scenario::load(scenario)?;
    let facts = world::load(&scenario)?.facts();
    let instruction = scenario
        .instruction
        .clone()
        .context("the scenario has no instruction")?;
    let variant = Variant::default();
    let prompt = |instruction: &str| -> Result<Vec<(String, String)>> {
        let ctx = Context {
            scenario: &scenario,
            facts: &facts,
            instruction,
            variant: &variant,
        };
        Ok(ctx
            .goal(&Templates::builtin())?
            .into_iter()
            .map(chat_pair)
            .collect())
    };
    let gbnf = grammar::goal_grammar(&scenario.domain.vocabulary, true, false);
    let generation = |messages, grammar: Option<String>| Generation {
        messages,
        max_tokens: 60,
        temperature: 0.0,
        seed: 0,
        stop: vec!["\n".into()],
        grammar,
    };

    let started = Instant::now();
    let engine = Engine::load(EngineOptions {
        model_path: path,
        threads,
        context: 4096,
    })?;
    let load = started.elapsed();
    println!(
        "model load: {:.2} s ({threads} thread(s))",
        load.as_secs_f64()
    );
    println!(
        "{:<34} {:>9} {:>8} {:>8} {:>11} {:>10}  answer",
        "call", "latency", "prompt", "cached", "prompt t/s", "gen t/s"
    );
    let cold = timed(
        &engine,
        generation(prompt(&instruction)?, Some(gbnf.clone())),
    )?;
    report("cold (grammar)", &cold);
    // The same prompt prefix (role, vocabulary, objects, examples, scene) with other
    // instructions: only the request's own tokens are evaluated.
    let others = [
        "Put the red cube on the table",
        "Stack the green cube on the blue cube",
        "Hold the red cube",
    ];
    for (label, grammar) in [
        ("warm (grammar)", Some(gbnf.clone())),
        ("warm (no grammar)", None),
    ] {
        for i in 0..repeats.max(1) {
            let g = timed(
                &engine,
                generation(prompt(others[i % others.len()])?, grammar.clone()),
            )?;
            report(label, &g);
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn chat_pair(m: Message) -> (String, String) {
    let role = match m.role {
        Role::System => "system",
        Role::User => "user",
        Role::Assistant => "assistant",
    };
    (role.to_string(), m.content)
}

fn timed(engine: &Engine, generation: Generation) -> Result<(Generated, f64)> {
    let started = Instant::now();
    let g = engine.generate_blocking(generation)?;
    Ok((g, started.elapsed().as_secs_f64()))
}

fn report(label: &str, (g, seconds): &(Generated, f64)) {
    let evaluated = g.prompt_tokens.saturating_sub(g.cached_tokens);
    let rate = |n: u32, d: std::time::Duration| {
        if d.as_secs_f64() > 0.0 {
            n as f64 / d.as_secs_f64()
        } else {
            0.0
        }
    };
    println!(
        "{:<34} {:>7.2} s {:>8} {:>8} {:>11.0} {:>10.1}  {}",
        label,
        seconds,
        g.prompt_tokens,
        g.cached_tokens,
        rate(evaluated, g.prompt_time),
        rate(g.completion_tokens, g.generation_time),
        g.text.trim()
    );
}
