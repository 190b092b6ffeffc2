//! An in-process language model for engine and screen tests: answers with the first
//! hand-written fixture whose `when` strings all occur in the prompt, optionally after a
//! delay, and counts its calls. Its replies are labelled as fixtures, never as a model's.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use betr::llm::{
    ChatFuture, ChatReply, ChatRequest, LanguageModel, LlmError, ReplySource, TokenUsage,
};

use super::fixtures::FixtureReply;

pub struct FixtureModel {
    replies: Vec<FixtureReply>,
    /// Delay before answering a failure question (goal questions answer at once).
    pub delay: Duration,
    pub calls: Arc<AtomicUsize>,
}

impl FixtureModel {
    pub fn new(replies: Vec<FixtureReply>) -> FixtureModel {
        FixtureModel {
            replies,
            delay: Duration::ZERO,
            calls: Arc::default(),
        }
    }

    pub fn calls(&self) -> Arc<AtomicUsize> {
        self.calls.clone()
    }
}

impl LanguageModel for FixtureModel {
    fn model(&self) -> &str {
        "fixture-model"
    }

    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        Box::pin(async move {
            self.calls.fetch_add(1, Ordering::SeqCst);
            let prompt: String = request
                .messages
                .iter()
                .map(|m| m.content.as_str())
                .collect::<Vec<_>>()
                .join("\n");
            if prompt.contains("# Task: failure resolution") && !self.delay.is_zero() {
                tokio::time::sleep(self.delay).await;
            }
            let Some(f) = self
                .replies
                .iter()
                .find(|f| f.answers(&prompt, request.seed))
            else {
                return Err(LlmError::MalformedReply {
                    url: "fixture-model".into(),
                    detail: "no fixture reply for this prompt".into(),
                });
            };
            Ok(ChatReply {
                ranked: Vec::new(),
                text: f.text.clone(),
                model: "fixture-model".into(),
                usage: TokenUsage {
                    prompt_tokens: 100,
                    completion_tokens: 20,
                },
                latency: Duration::ZERO,
                source: ReplySource::HandWritten {
                    note: "tests/fixtures/replies".into(),
                },
            })
        })
    }
}

/// A reply a test wrote, labelled as such (`note`: where), never as a model's.
pub fn scripted(text: String, note: &str) -> ChatReply {
    ChatReply {
        ranked: Vec::new(),
        text,
        model: "scripted".into(),
        usage: TokenUsage {
            prompt_tokens: 10,
            completion_tokens: 5,
        },
        latency: Duration::ZERO,
        source: ReplySource::HandWritten { note: note.into() },
    }
}

/// A grammar-following model that answers each request as `answer` says, keeping every
/// request seen.
pub struct AnswersBy<F> {
    answer: F,
    /// Every request seen, for checking what was asked and how it was constrained.
    pub seen: Mutex<Vec<ChatRequest>>,
}

impl<F: Fn(&ChatRequest) -> String + Send + Sync> AnswersBy<F> {
    pub fn new(answer: F) -> Self {
        AnswersBy {
            answer,
            seen: Mutex::default(),
        }
    }
}

impl<F: Fn(&ChatRequest) -> String + Send + Sync> LanguageModel for AnswersBy<F> {
    fn model(&self) -> &str {
        "scripted"
    }

    fn supports_grammar(&self) -> bool {
        true
    }

    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        Box::pin(async move {
            self.seen.lock().unwrap().push(request.clone());
            Ok(scripted((self.answer)(request), "a test's scripted answer"))
        })
    }
}
