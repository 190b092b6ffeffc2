//! An OpenAI-compatible transcription backend: `POST {base_url}/audio/transcriptions` as a
//! multipart form with `model`, `file` (16 kHz mono 16-bit WAV), `response_format=json`
//! and an optional `language`, answered by `{"text": ...}`. OpenAI, whisper.cpp's server
//! and faster-whisper servers speak it.
//!
//! Like the chat client: HTTP 429 and 5xx are retried with exponential backoff (honouring
//! `Retry-After`), timeouts are not; the key is sent only in the authorization header and
//! removed from every error text.

use std::time::{Duration, Instant};

/// The most bytes a transcription reply may have (a transcript is a few kilobytes).
const MAX_REPLY_BYTES: usize = 1024 * 1024;

use reqwest::multipart::{Form, Part};
use serde_json::Value as Json;

use crate::http_retry::RetryPolicy;

use super::{Audio16k, SpeechToText, SttFuture, Transcript, VoiceError};

pub use crate::http_text::Secret as SttKey;

#[derive(Debug, Clone)]
pub struct OpenAiSttSettings {
    /// E.g. `https://api.openai.com/v1`, `http://127.0.0.1:8080/v1`.
    pub base_url: String,
    /// The server's model name (`whisper-1`; whisper.cpp ignores it).
    pub model: String,
    pub language: Option<String>,
    /// The variable the key came from, for error messages.
    pub api_key_env: Option<String>,
    pub api_key: Option<SttKey>,
    pub timeout: Duration,
    pub connect_timeout: Duration,
    /// Retries of 429 / 5xx.
    pub retry: RetryPolicy,
}

pub struct OpenAiStt {
    settings: OpenAiSttSettings,
    url: String,
    http: reqwest::Client,
}

impl OpenAiStt {
    pub fn new(settings: OpenAiSttSettings) -> Result<OpenAiStt, VoiceError> {
        // reqwest is built without a default crypto provider: use ring (an error only
        // means a provider is installed already).
        let _ = rustls::crypto::ring::default_provider().install_default();
        let base = settings.base_url.trim_end_matches('/');
        if !(base.starts_with("http://") || base.starts_with("https://")) {
            return Err(VoiceError::Config(format!(
                "base URL {base:?} must start with http:// or https:// (e.g. http://127.0.0.1:8080/v1)"
            )));
        }
        let http = reqwest::Client::builder()
            .timeout(settings.timeout)
            .connect_timeout(settings.connect_timeout)
            .build()
            .map_err(|e| VoiceError::Config(format!("cannot build the HTTP client: {e}")))?;
        let url = format!("{base}/audio/transcriptions");
        Ok(OpenAiStt {
            settings,
            url,
            http,
        })
    }

    pub fn url(&self) -> &str {
        &self.url
    }

    /// The form sent for `wav` (rebuilt for every attempt: a form is consumed by sending).
    fn form(&self, wav: &[u8]) -> Result<Form, VoiceError> {
        let file = Part::bytes(wav.to_vec())
            .file_name("speech.wav")
            .mime_str("audio/wav")
            .map_err(|e| VoiceError::Config(format!("multipart: {e}")))?;
        let mut form = Form::new()
            .text("model", self.settings.model.clone())
            .text("response_format", "json")
            .part("file", file);
        if let Some(language) = &self.settings.language {
            form = form.text("language", language.clone());
        }
        Ok(form)
    }

    async fn call(&self, audio: &Audio16k) -> Result<Transcript, VoiceError> {
        let wav = audio.to_wav_bytes();
        let started = Instant::now();
        let mut attempt: u32 = 0;
        loop {
            attempt += 1;
            let mut request = self.http.post(&self.url).multipart(self.form(&wav)?);
            if let Some(key) = self.settings.api_key.as_ref().map(SttKey::expose) {
                request = request.bearer_auth(key);
            }
            tracing::debug!(url = %self.url, attempt, bytes = wav.len(), "transcription request");
            let response = request.send().await.map_err(|e| self.transport_error(&e))?;
            let status = response.status().as_u16();
            let wait = crate::http_retry::retry_after(response.headers());
            let body = crate::http_text::read_body(response, MAX_REPLY_BYTES)
                .await
                .map_err(|e| match e {
                    crate::http_text::BodyError::TooLarge { limit } => VoiceError::MalformedReply {
                        url: self.url.clone(),
                        detail: format!(
                            "the reply is longer than {limit} bytes; it was not read further"
                        ),
                    },
                    crate::http_text::BodyError::Transport(e) => self.transport_error(&e),
                })?;
            match status {
                200..=299 => {
                    let text = self.parse(&body)?;
                    return Ok(Transcript {
                        text: super::stt::tidy(&text),
                        audio_seconds: audio.seconds(),
                        elapsed: started.elapsed(),
                        source: self.describe(),
                    });
                }
                401 | 403 => {
                    return Err(VoiceError::Unauthorized {
                        url: self.url.clone(),
                        status,
                        env_var: self
                            .settings
                            .api_key_env
                            .clone()
                            .unwrap_or_else(|| "(no key configured)".into()),
                        detail: self.detail(&body),
                    });
                }
                _ => {
                    if !self
                        .settings
                        .retry
                        .wait_before_retry(status, attempt, wait)
                        .await
                    {
                        return Err(VoiceError::Http {
                            url: self.url.clone(),
                            status,
                            attempts: attempt,
                            detail: self.detail(&body),
                        });
                    }
                }
            }
        }
    }

    fn parse(&self, body: &str) -> Result<String, VoiceError> {
        let malformed = |detail: String| VoiceError::MalformedReply {
            url: self.url.clone(),
            detail,
        };
        let json: Json = serde_json::from_str(body).map_err(|e| {
            malformed(format!(
                "{e} in {:?}",
                crate::http_text::excerpt(&self.redact(body))
            ))
        })?;
        json.get("text")
            .and_then(Json::as_str)
            .map(str::to_string)
            .ok_or_else(|| {
                malformed(format!(
                    "no `text` in {:?}",
                    crate::http_text::excerpt(&self.redact(body))
                ))
            })
    }

    fn transport_error(&self, e: &reqwest::Error) -> VoiceError {
        if e.is_timeout() {
            return VoiceError::Timeout {
                url: self.url.clone(),
                seconds: self.settings.timeout.as_secs_f64(),
            };
        }
        // The innermost cause says what happened ("Connection refused").
        let detail = crate::http_retry::innermost_cause(e);
        if e.is_connect() {
            VoiceError::Connect {
                url: self.url.clone(),
                detail: self.redact(&detail),
            }
        } else {
            VoiceError::MalformedReply {
                url: self.url.clone(),
                detail: self.redact(&detail),
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
        self.settings.api_key.as_ref().map(SttKey::expose)
    }
}

impl SpeechToText for OpenAiStt {
    fn describe(&self) -> String {
        format!("{} at {}", self.settings.model, self.settings.base_url)
    }

    fn transcribe<'a>(&'a self, audio: &'a Audio16k) -> SttFuture<'a> {
        Box::pin(self.call(audio))
    }
}
