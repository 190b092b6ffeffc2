//! LLM cassettes (`llm::cassette::read_entries`, `Replay::from_text`).
//!
//! Properties: every entry read is written back (as the recorder writes it) to a line
//! that reads as the same entry; a replay answers each request of its model with the
//! reply of the last entry for that request; an error names a line of the input.

use crate::fuzz::Material;
use std::future::Future;
use std::path::Path;
use std::pin::pin;
use std::task::{Context, Poll, Waker};

use super::{Rng, Target, Violation, ensure, strings, text_of};
use crate::fuzz::mutate::random_char;
use crate::llm::cassette::{Entry, Replay, prompt_hash, read_entries};
use crate::llm::{ChatRequest, LanguageModel, Message, OutputConstraint, ReplySource, TokenUsage};

pub struct CassetteTarget {
    material: Material,
}

impl CassetteTarget {
    pub fn new() -> CassetteTarget {
        let mut seeds = Vec::new();
        for k in 0..12 {
            let mut rng = Rng::new(k);
            let lines: Vec<String> = (0..1 + rng.small(4))
                .map(|_| serde_json::to_string(&entry(&mut rng)).unwrap_or_default())
                .collect();
            seeds.push(format!("{}\n", lines.join("\n")).into_bytes());
        }
        CassetteTarget {
            material: Material {
                seeds,
                tokens: strings(&[
                    "\"model\":",
                    "\"reply_model\":",
                    "\"prompt_hash\":",
                    "\"request\":",
                    "\"messages\":",
                    "\"role\":\"user\"",
                    "\"role\":\"system\"",
                    "\"content\":",
                    "\"temperature\":",
                    "\"max_tokens\":",
                    "\"stop\":",
                    "\"constraint\":",
                    "\"seed\":",
                    "\"reply\":",
                    "\"usage\":",
                    "\"latency_ms\":",
                    "\"source\":",
                    "{\"kind\":\"hand-written\",\"note\":\"n\"}",
                    "\"recorded_unix\":",
                    "null",
                    "true",
                    "\\u0000",
                    "\\ud800",
                    "\\\"",
                    "1e38",
                    "3.4028236e38",
                    "-0.0",
                    "1.00000000000000000001",
                ]),
                brackets: super::pairs(&[("[", "]"), ("{\"a\":", "}")]),
            },
        }
    }
}

/// A random cassette entry: one of a few models, a request with or without a schema or a
/// grammar, and awkward text.
fn entry(rng: &mut Rng) -> Entry {
    let constraint = match rng.below(3) {
        0 => None,
        1 => Some(OutputConstraint::JsonSchema {
            name: "goal".into(),
            schema: serde_json::json!({"type": "object", "properties": {"goal": {"type": "string"}}, "x": 0.1}),
        }),
        _ => Some(OutputConstraint::Grammar {
            name: "g".into(),
            gbnf: "root ::= \"a\" | [^\\n]{0,8}".into(),
        }),
    };
    let request = ChatRequest {
        beams: None,
        messages: vec![Message::system(text(rng)), Message::user(text(rng))],
        temperature: *rng.pick(&[0.0f32, 0.7, 1.0, 0.1]).unwrap_or(&0.0),
        max_tokens: rng.below(2000) as u32,
        stop: if rng.chance(30) {
            vec![text(rng)]
        } else {
            Vec::new()
        },
        constraint,
        seed: rng.chance(50).then(|| rng.next_u64()),
        prefill: rng.chance(20).then(|| text(rng)),
    };
    let model = rng
        .pick(&["gpt-x", "qwen2.5-coder-1.5b", ""])
        .copied()
        .unwrap_or("m");
    Entry {
        ranked: Vec::new(),
        model: model.into(),
        reply_model: if rng.chance(50) {
            model.into()
        } else {
            String::new()
        },
        prompt_hash: if rng.chance(90) {
            prompt_hash(&request)
        } else {
            "0".repeat(64)
        },
        request,
        reply: text(rng),
        usage: TokenUsage {
            prompt_tokens: rng.next_u64() >> rng.below(64),
            completion_tokens: rng.below(500) as u64,
        },
        latency_ms: rng.next_u64() >> rng.below(64),
        source: match rng.below(3) {
            0 => ReplySource::Model,
            1 => ReplySource::Recorded,
            _ => ReplySource::HandWritten { note: text(rng) },
        },
        recorded_unix: rng.next_u64() >> 30,
    }
}

/// Text of a request or reply: a label a prompt or reply starts with, then random
/// characters.
fn text(rng: &mut Rng) -> String {
    let labels = [
        "Goal: ",
        "Conditions:\n",
        "# Task: goal interpretation\n",
        "",
    ];
    let mut s = String::from(*rng.pick(&labels).unwrap_or(&""));
    for _ in 0..rng.small(30) {
        s.push(random_char(rng));
    }
    s
}

/// The output of a future that is ready at once (a replay's answer), if it is.
fn ready<F: Future>(future: F) -> Option<F::Output> {
    let mut future = pin!(future);
    match future
        .as_mut()
        .poll(&mut Context::from_waker(Waker::noop()))
    {
        Poll::Ready(out) => Some(out),
        Poll::Pending => None,
    }
}

impl Target for CassetteTarget {
    fn name(&self) -> &'static str {
        "cassette"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        let lines: Vec<String> = (0..1 + rng.small(6))
            .map(|_| serde_json::to_string(&entry(rng)).unwrap_or_default())
            .collect();
        lines.join("\n").into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        let entries = match read_entries(&text) {
            Ok(read) => read.entries,
            Err(e) => {
                let lines = text.lines().count();
                return ensure(
                    (1..=lines).contains(&e.line),
                    "a cassette error names a line of the input",
                    || format!("line {} of {lines}: {e}", e.line),
                );
            }
        };
        for e in &entries {
            let line = serde_json::to_string(e);
            let back = line.as_ref().ok().map(|l| serde_json::from_str::<Entry>(l));
            ensure(
                matches!(&back, Some(Ok(b)) if b == e),
                "a cassette entry written again reads back the same",
                || format!("{e:?} wrote {line:?}, read back as {back:?}"),
            )?;
        }
        let Ok(replay) = Replay::from_text(Path::new("fuzz.jsonl"), &text, None, false) else {
            return Ok(());
        };
        for e in entries.iter().filter(|e| e.model == replay.model()) {
            let hash = prompt_hash(&e.request);
            if e.prompt_hash != hash {
                continue;
            }
            let expected = entries
                .iter()
                .rev()
                .find(|x| x.model == e.model && x.prompt_hash == hash)
                .map(|x| x.reply.as_str());
            let answer = ready(replay.chat(&e.request));
            let got = match &answer {
                Some(Ok(reply)) => Some(reply.text.as_str()),
                _ => None,
            };
            ensure(
                got == expected,
                "a replay answers a recorded request with its reply",
                || format!("{:?}: expected {expected:?}, got {answer:?}", e.request),
            )?;
        }
        Ok(())
    }
}
