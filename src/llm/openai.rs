//! An OpenAI-compatible chat backend (`POST {base_url}/chat/completions`), as spoken by
//! OpenAI, Azure OpenAI's v1 endpoint, Ollama, vLLM, llama.cpp's server and LM Studio.
//!
//! Transient failures (HTTP 429 and 5xx) are retried with exponential backoff, waiting as
//! long as the server's `Retry-After` (or `retry-after-ms`) asks, capped by the policy.
//! Timeouts are not retried: a model too slow once is usually too slow again. The API key
//! is read from an environment variable whose name is configured; it is sent only in the
//! authorization header and removed from every error text and every reply.

use std::time::{Duration, Instant};

use serde_json::{Value as Json, json};

use super::{ChatFuture, ChatReply, ChatRequest, LanguageModel, LlmError, OutputConstraint};
use super::{ReplySource, TokenUsage};

pub use crate::http_text::Secret as ApiKey;

/// How the key is sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AuthHeader {
    /// `Authorization: Bearer KEY` (OpenAI, Azure v1, vLLM, LM Studio, ...).
    Bearer,
    /// `api-key: KEY` (Azure OpenAI keys).
    ApiKey,
}

pub use crate::http_retry::RetryPolicy;

/// Everything the backend needs.
#[derive(Debug, Clone)]
pub struct OpenAiSettings {
    /// E.g. `https://api.openai.com/v1`, `http://127.0.0.1:11434/v1`.
    pub base_url: String,
    pub model: String,
    /// The name of the variable the key came from (for error messages), if any.
    pub api_key_env: Option<String>,
    pub api_key: Option<ApiKey>,
    pub auth_header: AuthHeader,
    pub timeout: Duration,
    pub connect_timeout: Duration,
    pub retry: RetryPolicy,
    /// Send `response_format: json_schema` when a request carries a constraint.
    pub structured: bool,
    /// `max_tokens` for most servers; newer OpenAI models want `max_completion_tokens`.
    pub max_tokens_field: String,
    /// The most bytes a reply's body may have: it is read in chunks and the call fails
    /// as soon as it passes them.
    pub max_reply_bytes: usize,
}

pub struct OpenAiClient {
    settings: OpenAiSettings,
    url: String,
    http: reqwest::Client,
}

impl OpenAiClient {
    pub fn new(settings: OpenAiSettings) -> Result<Self, LlmError> {
        // reqwest is built without a default crypto provider (no aws-lc): use ring. An
        // error only means a provider is already installed.
        let _ = rustls::crypto::ring::default_provider().install_default();
        let http = reqwest::Client::builder()
            .timeout(settings.timeout)
            .connect_timeout(settings.connect_timeout)
            .build()
            .map_err(|e| LlmError::Config(format!("cannot build the HTTP client: {e}")))?;
        let base = settings.base_url.trim_end_matches('/');
        if !(base.starts_with("http://") || base.starts_with("https://")) {
            return Err(LlmError::Config(format!(
                "base URL {base:?} must start with http:// or https:// (e.g. http://127.0.0.1:8080/v1)"
            )));
        }
        let url = format!("{base}/chat/completions");
        Ok(OpenAiClient {
            settings,
            url,
            http,
        })
    }

    /// The JSON body sent for `request`.
    pub fn body(&self, request: &ChatRequest) -> Json {
        let mut body = json!({
            "model": self.settings.model,
            "messages": request.messages,
            "temperature": request.temperature,
        });
        body[self.settings.max_tokens_field.as_str()] = json!(request.max_tokens);
        if !request.stop.is_empty() {
            body["stop"] = json!(request.stop);
        }
        if let Some(seed) = request.seed {
            body["seed"] = json!(seed);
        }
        if self.settings.structured
            && let Some(OutputConstraint::JsonSchema { name, schema }) = &request.constraint
        {
            body["response_format"] = json!({
                "type": "json_schema",
                "json_schema": { "name": name, "schema": schema, "strict": true },
            });
        }
        body
    }

    async fn call(&self, request: &ChatRequest) -> Result<ChatReply, LlmError> {
        let body = self.body(request);
        let started = Instant::now();
        let retry = self.settings.retry;
        let mut attempt: u32 = 0;
        loop {
            attempt += 1;
            let mut req = self.http.post(&self.url).json(&body);
            if let Some(key) = self.settings.api_key.as_ref().map(ApiKey::expose) {
                req = match self.settings.auth_header {
                    AuthHeader::Bearer => req.bearer_auth(key),
                    AuthHeader::ApiKey => req.header("api-key", key),
                };
            }
            tracing::debug!(url = %self.url, model = %self.settings.model, attempt, "chat request");
            let response = req.send().await.map_err(|e| self.transport_error(&e))?;
            let status = response.status().as_u16();
            let wait = crate::http_retry::retry_after(response.headers());
            let fixture = fixture_note(response.headers());
            let text = crate::http_text::read_body(response, self.settings.max_reply_bytes)
                .await
                .map_err(|e| match e {
                    crate::http_text::BodyError::TooLarge { limit } => LlmError::ReplyTooLarge {
                        url: self.url.clone(),
                        limit,
                    },
                    crate::http_text::BodyError::Transport(e) => self.transport_error(&e),
                })?;
            match status {
                200..=299 => {
                    let mut reply = self.parse_reply(&text, started.elapsed())?;
                    if let Some(note) = fixture {
                        reply.source = ReplySource::HandWritten { note };
                    }
                    return Ok(reply);
                }
                401 | 403 => {
                    return Err(LlmError::Unauthorized {
                        url: self.url.clone(),
                        status,
                        env_var: self
                            .settings
                            .api_key_env
                            .clone()
                            .unwrap_or_else(|| "(no key configured)".into()),
                        detail: self.detail(&text),
                    });
                }
                404 => {
                    return Err(LlmError::ModelNotFound {
                        model: self.settings.model.clone(),
                        url: self.url.clone(),
                        detail: self.detail(&text),
                    });
                }
                _ => {
                    if !retry.wait_before_retry(status, attempt, wait).await {
                        return Err(LlmError::Http {
                            url: self.url.clone(),
                            status,
                            attempts: attempt,
                            detail: self.detail(&text),
                        });
                    }
                }
            }
        }
    }

    fn parse_reply(&self, text: &str, latency: Duration) -> Result<ChatReply, LlmError> {
        let malformed = |detail: String| LlmError::MalformedReply {
            url: self.url.clone(),
            detail,
        };
        let json: Json = serde_json::from_str(text).map_err(|e| {
            malformed(format!(
                "{e} in {:?}",
                crate::http_text::excerpt(&self.redact(text))
            ))
        })?;
        let choices = json
            .get("choices")
            .and_then(Json::as_array)
            .ok_or_else(|| malformed("no `choices` array".into()))?;
        let Some(first) = choices.first() else {
            return Err(LlmError::EmptyChoices {
                url: self.url.clone(),
            });
        };
        let content = first
            .pointer("/message/content")
            .and_then(Json::as_str)
            .ok_or_else(|| {
                let refusal = first.pointer("/message/refusal").and_then(Json::as_str);
                malformed(match refusal {
                    Some(r) => format!("the model refused: {r}"),
                    None => "the first choice has no message content".into(),
                })
            })?;
        let count = |k: &str| json.pointer(&format!("/usage/{k}")).and_then(Json::as_u64);
        Ok(ChatReply {
            ranked: Vec::new(),
            // The reply as the model wrote it: what betr reads is never redacted (a key
            // like "test" would take the word out of "test tube"); the key is kept out of
            // the error messages betr writes.
            text: content.to_string(),
            model: json
                .get("model")
                .and_then(Json::as_str)
                .unwrap_or(&self.settings.model)
                .to_string(),
            usage: TokenUsage {
                prompt_tokens: count("prompt_tokens").unwrap_or(0),
                completion_tokens: count("completion_tokens").unwrap_or(0),
            },
            latency,
            source: ReplySource::Model,
        })
    }

    fn transport_error(&self, e: &reqwest::Error) -> LlmError {
        if e.is_timeout() {
            LlmError::Timeout {
                url: self.url.clone(),
                seconds: self.settings.timeout.as_secs_f64(),
            }
        } else if e.is_connect() {
            LlmError::Connect {
                url: self.url.clone(),
                detail: self.redact(&crate::http_retry::innermost_cause(e)),
            }
        } else {
            LlmError::MalformedReply {
                url: self.url.clone(),
                detail: self.redact(&e.to_string()),
            }
        }
    }

    /// The server's error message, shortened and without the key.
    fn detail(&self, body: &str) -> String {
        crate::http_text::server_message(body, self.key())
    }

    fn redact(&self, text: &str) -> String {
        crate::http_text::redact(text, self.key())
    }

    fn key(&self) -> Option<&str> {
        self.settings.api_key.as_ref().map(ApiKey::expose)
    }
}

impl LanguageModel for OpenAiClient {
    fn model(&self) -> &str {
        &self.settings.model
    }

    fn supports_constraint(&self) -> bool {
        self.settings.structured
    }

    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        Box::pin(self.call(request))
    }
}

/// A test server that answers with hand-written replies says so in the header
/// `x-betr-fixture`, so such a reply is never shown as a model's answer.
fn fixture_note(headers: &reqwest::header::HeaderMap) -> Option<String> {
    let note = headers.get("x-betr-fixture")?.to_str().ok()?.trim();
    Some(if note.is_empty() {
        "hand-written".to_string()
    } else {
        note.to_string()
    })
}

#[cfg(test)]
#[path = "openai_tests.rs"]
mod tests;
