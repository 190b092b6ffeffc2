//! Settings of the language-model layer, from four layers, later ones overriding earlier
//! ones: built-in defaults, a TOML file (`betr.toml`; see `betr.example.toml`), `BETR_*`
//! environment variables, and command-line flags.
//!
//! The API key itself is never configured here: only the NAME of the environment variable
//! that holds it. A file that contains a key is refused.

use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::Deserialize;

use super::cassette::{Recorder, Replay};
use super::local::{EngineOptions, LocalModel};
use super::openai::{ApiKey, AuthHeader, OpenAiClient, OpenAiSettings, RetryPolicy};
use super::usage::{Ledger, Metered, PriceTable};
use super::{LanguageModel, LlmError};

/// Which backend answers (the embedded model unless a server is configured).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// An OpenAI-compatible HTTP server.
    Openai,
    /// The embedded model (llama.cpp in-process, a GGUF file fetched on first use).
    #[default]
    Local,
    /// Answers from a cassette only.
    Replay,
}

impl Backend {
    /// The name settings and flags use (`--backend local`).
    pub fn name(self) -> &'static str {
        match self {
            Backend::Openai => "openai",
            Backend::Local => "local",
            Backend::Replay => "replay",
        }
    }
}

/// A backend name that is none of the known ones.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown backend {name:?} (expected openai, local or replay)")]
pub struct UnknownBackend {
    pub name: String,
}

impl std::str::FromStr for Backend {
    type Err = UnknownBackend;
    fn from_str(s: &str) -> Result<Self, UnknownBackend> {
        match s.trim().to_ascii_lowercase().as_str() {
            "openai" => Ok(Backend::Openai),
            "local" => Ok(Backend::Local),
            "replay" => Ok(Backend::Replay),
            other => Err(UnknownBackend {
                name: other.to_string(),
            }),
        }
    }
}

/// One layer of settings: every field optional, `merge` lets a later layer win.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    pub backend: Option<Backend>,
    pub base_url: Option<String>,
    pub model: Option<String>,
    pub api_key_env: Option<String>,
    pub auth_header: Option<AuthHeader>,
    pub structured: Option<bool>,
    pub temperature: Option<f32>,
    pub max_tokens: Option<u32>,
    pub max_tokens_field: Option<String>,
    pub timeout_secs: Option<f64>,
    pub connect_timeout_secs: Option<f64>,
    pub max_retries: Option<u32>,
    pub initial_backoff_ms: Option<u64>,
    pub max_backoff_ms: Option<u64>,
    pub cassette: Option<PathBuf>,
    /// A live backend answers what the cassette already holds from it and records the rest.
    pub reuse_cassette: Option<bool>,
    pub usage_log: Option<PathBuf>,
    /// Local backend: a GGUF file to use instead of a fetched model.
    pub model_path: Option<PathBuf>,
    /// Local backend: CPU threads.
    pub threads: Option<u32>,
    /// Local backend: constrain replies with a grammar built from the vocabulary.
    pub grammar: Option<bool>,
    /// Local backend: context length in tokens.
    pub context: Option<u32>,
    /// The most bytes a server's reply may have; a longer one fails the call.
    pub max_reply_bytes: Option<u64>,
    /// Refused: keys belong in the environment.
    pub api_key: Option<toml::Value>,
}

macro_rules! merge_fields {
    ($self:ident, $other:ident, $($f:ident),*) => { $( if $other.$f.is_some() { $self.$f = $other.$f; } )* };
}

impl Layer {
    pub fn merge(&mut self, other: Layer) {
        merge_fields!(
            self,
            other,
            backend,
            base_url,
            model,
            api_key_env,
            auth_header,
            structured,
            temperature,
            max_tokens,
            max_tokens_field,
            timeout_secs,
            connect_timeout_secs,
            max_retries,
            initial_backoff_ms,
            max_backoff_ms,
            cassette,
            reuse_cassette,
            usage_log,
            model_path,
            threads,
            grammar,
            context,
            max_reply_bytes,
            api_key
        );
    }

    /// The `BETR_*` variables, read through `var`.
    pub fn from_env(var: &dyn Fn(&str) -> Option<String>) -> Result<Layer, LlmError> {
        let get = |k: &str| var(k).filter(|v| !v.trim().is_empty());
        let bool_var = |k: &str| -> Result<Option<bool>, LlmError> {
            get(k)
                .map(|v| {
                    crate::bounds::switch_value(&v)
                        .ok_or_else(|| LlmError::Config(format!("{k}={v:?} is not true or false")))
                })
                .transpose()
        };
        Ok(Layer {
            backend: get("BETR_BACKEND")
                .map(|b| {
                    b.parse()
                        .map_err(|e| LlmError::Config(format!("BETR_BACKEND: {e}")))
                })
                .transpose()?,
            base_url: get("BETR_BASE_URL"),
            model: get("BETR_MODEL"),
            api_key_env: get("BETR_API_KEY_ENV"),
            structured: bool_var("BETR_STRUCTURED")?,
            cassette: get("BETR_CASSETTE").map(PathBuf::from),
            usage_log: get("BETR_USAGE_LOG").map(PathBuf::from),
            model_path: get("BETR_MODEL_PATH").map(PathBuf::from),
            threads: get("BETR_THREADS")
                .map(|t| {
                    t.trim()
                        .parse::<u32>()
                        .ok()
                        .filter(|n| *n > 0)
                        .ok_or_else(|| {
                            LlmError::Config(format!(
                                "BETR_THREADS={t:?} is not a positive whole number"
                            ))
                        })
                })
                .transpose()?,
            grammar: bool_var("BETR_GRAMMAR")?,
            ..Layer::default()
        })
    }
}

/// Resolved settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub backend: Backend,
    /// Without the credentials a URL may carry (they are `url_key`).
    pub base_url: String,
    /// A key given inside the base URL (`http://user:KEY@host/v1`), taken out of it: sent
    /// and redacted like a key from the environment, which wins when both are given.
    pub url_key: Option<ApiKey>,
    pub model: Option<String>,
    pub api_key_env: Option<String>,
    pub auth_header: AuthHeader,
    pub structured: bool,
    pub temperature: f32,
    pub max_tokens: u32,
    pub max_tokens_field: String,
    pub timeout: Duration,
    pub connect_timeout: Duration,
    pub retry: RetryPolicy,
    pub cassette: Option<PathBuf>,
    /// A live backend answers what the cassette already holds from it and records the rest.
    pub reuse_cassette: bool,
    pub usage_log: Option<PathBuf>,
    pub prices: PriceTable,
    /// The file the settings came from, if any.
    pub file: Option<PathBuf>,
    /// Local backend: the GGUF file (`None`: the fetched default model).
    pub model_path: Option<PathBuf>,
    /// Local backend: CPU threads (`None`: the cores idle when the model loads).
    pub threads: Option<u32>,
    pub grammar: bool,
    pub context: u32,
    /// The most bytes a server's reply may have.
    pub max_reply_bytes: usize,
}

/// The ranges of the numbers settings take (inclusive).
pub mod limits {
    /// A server's reply: 256 KiB by default (a goal or a fix is a few hundred bytes).
    pub const DEFAULT_REPLY_BYTES: u64 = 256 * 1024;
    pub const REPLY_BYTES: (u64, u64) = (1024, 64 * 1024 * 1024);
    pub const TEMPERATURE: (f32, f32) = (0.0, 2.0);
    pub const MAX_TOKENS: (u32, u32) = (1, 131_072);
    pub const RETRIES: (u32, u32) = (0, 20);
    /// Backoff between retries, in milliseconds (an hour at most).
    pub const BACKOFF_MS: (u64, u64) = (0, 3_600_000);
    pub const THREADS: (u32, u32) = (1, 1024);
    pub const CONTEXT: (u32, u32) = (512, 1_048_576);
}

/// `value` of the setting `what` when it lies in `range` (inclusive), else a
/// configuration error saying the range.
fn in_range<T: PartialOrd + std::fmt::Display>(
    what: &str,
    value: T,
    (min, max): (T, T),
) -> Result<T, LlmError> {
    crate::bounds::within(what, value, min, max).map_err(|e| LlmError::Config(e.to_string()))
}

/// Threads for the local model when the load cannot decide (tests, which share the
/// machine with other tests, use it too): one thread keeps generating at full speed when
/// another process is busy, where two threads stall waiting for each other; see
/// `betr bench llm` and `local::threads`.
pub const DEFAULT_THREADS: u32 = 1;

impl Settings {
    /// Defaults, then the settings file's (its path, its `[llm]` layer and its prices),
    /// then `env`, then `flags`.
    pub fn resolve(
        file: Option<(&Path, Layer, PriceTable)>,
        env: Layer,
        flags: Layer,
    ) -> Result<Settings, LlmError> {
        let mut layer = Layer::default();
        let (path, prices) = match file {
            Some((p, llm, prices)) => {
                layer.merge(llm);
                (Some(p.to_path_buf()), prices)
            }
            None => (None, PriceTable::default()),
        };
        layer.merge(env);
        layer.merge(flags);
        let secs = |v: Option<f64>, default: f64, what: &str| {
            crate::bounds::seconds(what, v.unwrap_or(default))
                .map_err(|e| LlmError::Config(e.to_string()))
        };
        let temperature = in_range(
            "temperature",
            layer.temperature.unwrap_or(0.0),
            limits::TEMPERATURE,
        )?;
        let max_tokens = in_range(
            "max_tokens",
            layer.max_tokens.unwrap_or(800),
            limits::MAX_TOKENS,
        )?;
        let retries = in_range(
            "max_retries",
            layer.max_retries.unwrap_or(3),
            limits::RETRIES,
        )?;
        let backoff = |what: &str, v: Option<u64>, default: u64| {
            in_range(what, v.unwrap_or(default), limits::BACKOFF_MS).map(Duration::from_millis)
        };
        let threads = layer
            .threads
            .map(|t| in_range("threads", t, limits::THREADS))
            .transpose()?;
        let context = in_range("context", layer.context.unwrap_or(4096), limits::CONTEXT)?;
        let reply_bytes = in_range(
            "max_reply_bytes",
            layer.max_reply_bytes.unwrap_or(limits::DEFAULT_REPLY_BYTES),
            limits::REPLY_BYTES,
        )?;
        let (base_url, url_key) = crate::http_text::split_credentials(
            layer
                .base_url
                .as_deref()
                .unwrap_or("https://api.openai.com/v1"),
        );
        Ok(Settings {
            // Offline by default: the embedded model needs no key and no network. A base
            // URL given without a backend can only mean an HTTP server.
            backend: layer.backend.unwrap_or(if layer.base_url.is_some() {
                Backend::Openai
            } else {
                Backend::Local
            }),
            base_url,
            url_key,
            model: layer.model,
            api_key_env: match layer.api_key_env {
                Some(v) if v.is_empty() => None,
                Some(v) => Some(v),
                None => Some("OPENAI_API_KEY".into()),
            },
            auth_header: layer.auth_header.unwrap_or(AuthHeader::Bearer),
            structured: layer.structured.unwrap_or(false),
            temperature,
            max_tokens,
            max_tokens_field: layer
                .max_tokens_field
                .unwrap_or_else(|| "max_tokens".into()),
            timeout: secs(layer.timeout_secs, 60.0, "timeout_secs")?,
            connect_timeout: secs(layer.connect_timeout_secs, 10.0, "connect_timeout_secs")?,
            retry: RetryPolicy {
                max_retries: retries,
                initial_backoff: backoff("initial_backoff_ms", layer.initial_backoff_ms, 500)?,
                max_backoff: backoff("max_backoff_ms", layer.max_backoff_ms, 20_000)?,
            },
            cassette: layer.cassette,
            reuse_cassette: layer.reuse_cassette.unwrap_or(false),
            usage_log: layer.usage_log.or_else(super::usage::default_log_path),
            prices,
            file: path,
            model_path: layer.model_path,
            threads,
            grammar: layer.grammar.unwrap_or(true),
            context,
            max_reply_bytes: usize::try_from(reply_bytes).unwrap_or(usize::MAX),
        })
    }

    /// The local model's name and file: `--model-path`, else the known model `--model`
    /// names (the default one without it).
    pub fn local_model(&self) -> Result<(String, PathBuf), LlmError> {
        if let Some(path) = &self.model_path {
            let name = self.model.clone().unwrap_or_else(|| {
                path.file_stem()
                    .map_or("local".into(), |s| s.to_string_lossy().into_owned())
            });
            return Ok((name, path.clone()));
        }
        let spec = match &self.model {
            None => crate::model::DEFAULT_MODEL,
            Some(name) => crate::model::find(name).ok_or_else(|| {
                let known: Vec<&str> = crate::model::MODELS.iter().map(|m| m.name).collect();
                LlmError::Config(format!(
                    "unknown local model {name:?} (known: {}; or pass --model-path FILE.gguf)",
                    known.join(", ")
                ))
            })?,
        };
        Ok((spec.name.to_string(), spec.path()))
    }

    /// A live backend as configured: recording to the cassette when one is set, and
    /// answering from it what it holds when reusing.
    fn recording<M: LanguageModel + 'static>(
        &self,
        live: M,
    ) -> Result<Box<dyn LanguageModel>, LlmError> {
        Ok(match &self.cassette {
            Some(path) if self.reuse_cassette => Box::new(Recorder::reusing(live, path)?),
            Some(path) => Box::new(Recorder::new(live, path)?),
            None => Box::new(live),
        })
    }

    /// Build the configured model, metered into `ledger`: a live backend records to the
    /// cassette when one is set; replay answers only from it.
    pub fn build(
        &self,
        ledger: Ledger,
        var: &dyn Fn(&str) -> Option<String>,
    ) -> Result<Metered<Box<dyn LanguageModel>>, LlmError> {
        let model: Box<dyn LanguageModel> = match self.backend {
            Backend::Local => {
                let (name, path) = self.local_model()?;
                let local = LocalModel::load(
                    &name,
                    EngineOptions {
                        model_path: path,
                        threads: self
                            .threads
                            .unwrap_or_else(super::local::threads::idle_threads),
                        context: self.context,
                        prompt_states: Some(crate::model::cache_dir().join("prompt-state")),
                    },
                )?;
                self.recording(local)?
            }
            Backend::Replay => {
                let Some(cassette) = &self.cassette else {
                    return Err(LlmError::Config(
                        "--backend replay needs --cassette FILE (or BETR_CASSETTE)".into(),
                    ));
                };
                Box::new(Replay::open(
                    cassette,
                    self.model.as_deref(),
                    self.structured,
                )?)
            }
            Backend::Openai => {
                let Some(model) = self.model.clone() else {
                    return Err(LlmError::Config(
                        "no model configured: pass --model NAME, set BETR_MODEL, or set `model` under [llm] in betr.toml".into(),
                    ));
                };
                let (api_key, api_key_env) = crate::http_text::chosen_key(
                    self.api_key_env.as_deref(),
                    var,
                    self.url_key.as_ref(),
                );
                let client = OpenAiClient::new(OpenAiSettings {
                    base_url: self.base_url.clone(),
                    model,
                    api_key_env,
                    api_key,
                    auth_header: self.auth_header,
                    timeout: self.timeout,
                    connect_timeout: self.connect_timeout,
                    retry: self.retry,
                    structured: self.structured,
                    max_tokens_field: self.max_tokens_field.clone(),
                    max_reply_bytes: self.max_reply_bytes,
                })?;
                self.recording(client)?
            }
        };
        // Every reply is made printable before anything shows or reads it.
        let model: Box<dyn LanguageModel> = Box::new(super::printable::Printable::new(model));
        Ok(Metered::new(model, ledger, self.prices.clone()))
    }
}

#[cfg(test)]
#[path = "config_tests.rs"]
mod tests;
