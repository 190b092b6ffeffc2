//! Language models: the [`LanguageModel`] trait, an OpenAI-compatible HTTP backend,
//! record/replay cassettes, usage accounting, configuration, prompts and the tolerant
//! reading of replies.
//!
//! This module knows the scenario's vocabulary (to write prompts and validate replies) but
//! nothing of trees, worlds or user interfaces. Backends compose: a live backend may be
//! wrapped by a [`cassette::Recorder`], and anything by a [`usage::Metered`] model that
//! accounts every call.

pub mod arriving;
pub mod cassette;
pub mod config;
pub mod examples;
pub mod grammar;
pub mod local;
pub mod openai;
pub mod printable;
pub mod prompt;
pub mod reply;
pub mod scene_text;
pub mod schema;
pub mod usage;

use std::future::Future;
use std::pin::Pin;
use std::time::Duration;

use serde::{Deserialize, Serialize};

/// Who speaks a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    System,
    User,
    Assistant,
}

impl Role {
    /// The role's name in chat templates and on the wire.
    pub fn name(self) -> &'static str {
        match self {
            Role::System => "system",
            Role::User => "user",
            Role::Assistant => "assistant",
        }
    }
}

#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Message {
    pub role: Role,
    pub content: String,
}

impl Message {
    pub fn system(content: impl Into<String>) -> Self {
        Message {
            role: Role::System,
            content: content.into(),
        }
    }

    pub fn user(content: impl Into<String>) -> Self {
        Message {
            role: Role::User,
            content: content.into(),
        }
    }
}

/// A constraint on the shape of the reply, for backends that can enforce one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum OutputConstraint {
    /// The reply is JSON matching this schema (OpenAI `response_format: json_schema`).
    JsonSchema {
        name: String,
        schema: serde_json::Value,
    },
    /// The reply follows this GBNF grammar (llama.cpp), token by token.
    Grammar { name: String, gbnf: String },
}

/// One chat request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChatRequest {
    pub messages: Vec<Message>,
    pub temperature: f32,
    pub max_tokens: u32,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stop: Vec<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constraint: Option<OutputConstraint>,
    /// Sampling seed, for backends that take one (OpenAI `seed`); repeated evaluation runs
    /// use run k → seed k. `None` leaves the choice to the backend.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// With a grammar and temperature 0, a backend that can search for the answers the
    /// model finds most likely as a whole returns up to this many, ranked (the embedded
    /// model); others answer once.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beams: Option<u32>,
    /// The reply's first words, written by the caller: a backend that can continue an
    /// answer begun for it (the embedded model) has them after the assistant's header,
    /// goes on from there and returns them with the rest; others ignore them (the prompt
    /// asks the model to begin that way).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prefill: Option<String>,
}

impl ChatRequest {
    pub fn new(messages: Vec<Message>) -> Self {
        ChatRequest {
            messages,
            temperature: 0.0,
            max_tokens: 800,
            stop: Vec::new(),
            constraint: None,
            seed: None,
            beams: None,
            prefill: None,
        }
    }
}

/// Tokens a call consumed, as the backend reported them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct TokenUsage {
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
}

/// Where a reply's text came from. Only `Model` is what a model just answered; a replayed
/// reply names the model that once produced it; a hand-written one is test plumbing and
/// must never be presented as a model's answer.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum ReplySource {
    /// Answered now by the backend.
    Model,
    /// Replayed from a cassette recorded from `model`.
    Recorded,
    /// Replayed from a hand-written fixture; `note` says what it is.
    HandWritten { note: String },
}

/// A reply with its accounting.
#[derive(Debug, Clone, PartialEq)]
pub struct ChatReply {
    pub text: String,
    /// The model that produced the text (as the backend or the cassette names it).
    pub model: String,
    pub usage: TokenUsage,
    pub latency: Duration,
    pub source: ReplySource,
    /// When beams were searched: every answer found with its log-probability under the
    /// model, best first (`text` is the first); empty otherwise.
    pub ranked: Vec<(String, f64)>,
}

impl ChatReply {
    /// A short label for showing who answered: never claims a model for a fixture.
    pub fn attribution(&self) -> String {
        match &self.source {
            ReplySource::Model => format!("model {}", self.model),
            ReplySource::Recorded => format!("model {} (replayed from a cassette)", self.model),
            ReplySource::HandWritten { note } => {
                format!("hand-written fixture, not a model's answer ({note})")
            }
        }
    }
}

/// Why a call to a language model failed. Messages never contain the API key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LlmError {
    #[error("configuration: {0}")]
    Config(String),
    #[error(
        "the server at {url} rejected the credentials (HTTP {status}); check the key in ${env_var}: {detail}"
    )]
    Unauthorized {
        url: String,
        status: u16,
        env_var: String,
        detail: String,
    },
    #[error("model {model:?} not found at {url} (HTTP 404): {detail}")]
    ModelNotFound {
        model: String,
        url: String,
        detail: String,
    },
    #[error("cannot connect to {url}: {detail} (is the server running?)")]
    Connect { url: String, detail: String },
    #[error("no reply from {url} within {seconds:.1} s (timeout)")]
    Timeout { url: String, seconds: f64 },
    #[error("{url} answered HTTP {status} after {attempts} attempt(s): {detail}")]
    Http {
        url: String,
        status: u16,
        attempts: u32,
        detail: String,
    },
    #[error("{url} sent a reply that is not a chat completion: {detail}")]
    MalformedReply { url: String, detail: String },
    #[error("{url} sent a chat completion with no choices")]
    EmptyChoices { url: String },
    #[error(
        "{url} sent a reply longer than {limit} bytes, the most `max_reply_bytes` under [llm] allows; it was not read further"
    )]
    ReplyTooLarge { url: String, limit: usize },
    #[error(
        "cassette {path} has no reply for model {model:?} and prompt {hash} (replay never calls a model; record it first with a live backend and --cassette)"
    )]
    CassetteMiss {
        path: String,
        model: String,
        hash: String,
    },
    #[error("cassette {path}: {detail}")]
    Cassette { path: String, detail: String },
    #[error("local model: {0}")]
    Local(String),
    /// The model is not there yet (still being fetched or loaded), or will not come: what
    /// it waits for or why.
    #[error("{0}")]
    NotReady(String),
    /// The prompt and the reply it may take are longer than the model's context window:
    /// this question cannot be asked as it is, others can.
    #[error(
        "the prompt ({tokens} tokens with the reply's room) is past the model's context of {context} tokens"
    )]
    TooLong { tokens: usize, context: u32 },
}

/// The future a backend returns.
pub type ChatFuture<'a> = Pin<Box<dyn Future<Output = Result<ChatReply, LlmError>> + Send + 'a>>;

/// A chat model: messages in, text out, with token usage and latency.
///
/// Object safe, so a program can hold `Box<dyn LanguageModel>` and choose the backend at
/// run time.
pub trait LanguageModel: Send + Sync {
    /// The model name requests are made for (cassette keys use it).
    fn model(&self) -> &str;
    /// Whether the backend honours [`OutputConstraint::JsonSchema`].
    fn supports_constraint(&self) -> bool {
        false
    }
    /// Whether the backend honours [`OutputConstraint::Grammar`].
    fn supports_grammar(&self) -> bool {
        false
    }
    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a>;
}

/// `LanguageModel` for a model in front of another (a recorder, a meter, an evaluation
/// tap): `model` and the capability questions go to the field `inner`, `chat` to the
/// wrapper's own `async fn call(&self, &ChatRequest)`.
macro_rules! forwarding_model {
    (impl $(<$g:ident>)? for $ty:ty) => {
        impl$(<$g: $crate::llm::LanguageModel>)? $crate::llm::LanguageModel for $ty {
            fn model(&self) -> &str {
                self.inner.model()
            }
            fn supports_constraint(&self) -> bool {
                self.inner.supports_constraint()
            }
            fn supports_grammar(&self) -> bool {
                self.inner.supports_grammar()
            }
            fn chat<'a>(
                &'a self,
                request: &'a $crate::llm::ChatRequest,
            ) -> $crate::llm::ChatFuture<'a> {
                Box::pin(self.call(request))
            }
        }
    };
}
pub(crate) use forwarding_model;

impl<T: LanguageModel + ?Sized> LanguageModel for Box<T> {
    fn model(&self) -> &str {
        (**self).model()
    }
    fn supports_constraint(&self) -> bool {
        (**self).supports_constraint()
    }
    fn supports_grammar(&self) -> bool {
        (**self).supports_grammar()
    }
    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        (**self).chat(request)
    }
}

impl<T: LanguageModel + ?Sized> LanguageModel for std::sync::Arc<T> {
    fn model(&self) -> &str {
        (**self).model()
    }
    fn supports_constraint(&self) -> bool {
        (**self).supports_constraint()
    }
    fn supports_grammar(&self) -> bool {
        (**self).supports_grammar()
    }
    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        (**self).chat(request)
    }
}
