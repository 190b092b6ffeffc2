//! The embedded backend (`--backend local`): a GGUF model run in-process by llama.cpp,
//! with grammar-constrained decoding so replies can only use the scenario's vocabulary.

mod beam;
pub mod engine;
pub mod prompt_state;
pub mod threads;

use std::sync::Arc;
use std::time::Instant;

pub use engine::{Engine, EngineError, EngineOptions, Generated, Generation};

use super::{
    ChatFuture, ChatReply, ChatRequest, LanguageModel, LlmError, OutputConstraint, ReplySource,
    TokenUsage,
};

/// A loaded local model behind the `LanguageModel` trait.
pub struct LocalModel {
    engine: Arc<Engine>,
    name: String,
}

impl LocalModel {
    /// Load the model file (about a second for the 1.5B default, from the page cache).
    pub fn load(name: &str, options: EngineOptions) -> Result<LocalModel, LlmError> {
        let engine = Engine::load(options).map_err(|e| LlmError::Local(e.to_string()))?;
        Ok(LocalModel {
            engine: Arc::new(engine),
            name: name.to_string(),
        })
    }

    pub fn engine(&self) -> &Engine {
        &self.engine
    }
}

impl LanguageModel for LocalModel {
    fn model(&self) -> &str {
        &self.name
    }

    fn supports_grammar(&self) -> bool {
        true
    }

    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        Box::pin(async move {
            let grammar = match &request.constraint {
                Some(OutputConstraint::Grammar { gbnf, .. }) => Some(gbnf.clone()),
                // JSON schemas are for HTTP backends; the local model is constrained by
                // grammars only, so it answers in plain text here.
                Some(OutputConstraint::JsonSchema { .. }) | None => None,
            };
            let generation = Generation {
                messages: request
                    .messages
                    .iter()
                    .map(|m| (m.role.name().to_string(), m.content.clone()))
                    .collect(),
                max_tokens: request.max_tokens,
                temperature: request.temperature,
                // llama.cpp takes a 32-bit seed; evaluation seeds are small run numbers.
                seed: request.seed.map_or(0, |s| (s % u64::from(u32::MAX)) as u32),
                stop: request.stop.clone(),
                beams: if grammar.is_some() {
                    request.beams.unwrap_or(1)
                } else {
                    1
                },
                grammar,
                prefill: request.prefill.clone().unwrap_or_default(),
            };
            let started = Instant::now();
            let out = self
                .engine
                .generate(generation)
                .await
                .map_err(|e| match e {
                    EngineError::PromptTooLong { tokens, context } => {
                        LlmError::TooLong { tokens, context }
                    }
                    e => LlmError::Local(e.to_string()),
                })?;
            tracing::debug!(
                prompt_tokens = out.prompt_tokens,
                cached_tokens = out.cached_tokens,
                completion_tokens = out.completion_tokens,
                prompt_ms = out.prompt_time.as_millis(),
                generation_ms = out.generation_time.as_millis(),
                "local model answered"
            );
            Ok(ChatReply {
                text: out.text,
                model: self.name.clone(),
                usage: TokenUsage {
                    prompt_tokens: u64::from(out.prompt_tokens),
                    completion_tokens: u64::from(out.completion_tokens),
                },
                latency: started.elapsed(),
                source: ReplySource::Model,
                ranked: out.ranked,
            })
        })
    }
}
