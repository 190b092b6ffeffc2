//! One call of the model, for reading an instruction and for repairing a failure alike:
//! the reply constrained the way the backend can, and who answered told as an event.

use crate::llm::prompt;
use crate::llm::{ChatReply, LanguageModel, Message, OutputConstraint};

use super::types::{Event, Options, SessionError};

/// Ask, constraining the reply the way the backend can: a grammar for the local model
/// (built only when used), a JSON schema for servers that take one, else plain text.
/// `seed`: for a sampled draw (a backend's own seed, as an evaluation run's, wins).
pub(crate) async fn ask(
    model: &dyn LanguageModel,
    messages: Vec<Message>,
    (schema, grammar): (OutputConstraint, &(dyn Fn() -> String + Sync)),
    options: &Options,
    seed: Option<u64>,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<ChatReply, SessionError> {
    let mut request = prompt::request(messages, options.temperature, options.max_tokens);
    request.seed = seed;
    if options.grammar && model.supports_grammar() {
        request.constraint = Some(OutputConstraint::Grammar {
            name: "answer".into(),
            gbnf: grammar(),
        });
        // Beams search for the most likely whole answer: only for a greedy answer, and
        // only when the caller asks for them (`options.beams`).
        if seed.is_none() && options.temperature <= 0.0 && options.beams > 1 {
            request.beams = Some(options.beams);
        }
    } else if options.structured && model.supports_constraint() {
        request.constraint = Some(schema);
    }
    let r = model.chat(&request).await?;
    emit(&Event::Replied {
        attribution: r.attribution(),
        prompt_tokens: r.usage.prompt_tokens,
        completion_tokens: r.usage.completion_tokens,
        latency_ms: u64::try_from(r.latency.as_millis()).unwrap_or(u64::MAX),
        text: r.text.clone(),
    });
    Ok(r)
}
