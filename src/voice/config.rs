//! Speech-to-text settings, layered like the language model's: built-in defaults, the
//! `[stt]` table of `betr.toml`, `BETR_STT*` environment variables, command-line flags.
//! As there, the API key is never configured: only the name of the variable holding it.

use std::time::Duration;

use serde::Deserialize;

use crate::http_retry::RetryPolicy;

use super::openai_stt::{OpenAiStt, OpenAiSttSettings, SttKey};
use super::whisper_local::{LocalSettings, LocalWhisper};
use super::{SpeechToText, VoiceError};

/// The default embedded model.
pub const DEFAULT_LOCAL_MODEL: &str = "whisper-tiny.en";
/// The default model name sent to an OpenAI-compatible server.
pub const DEFAULT_REMOTE_MODEL: &str = "whisper-1";

/// Which backend transcribes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SttBackend {
    /// Whisper embedded through CTranslate2.
    Local,
    /// `POST {base_url}/audio/transcriptions`.
    Openai,
}

/// A speech-to-text backend name that is none of the known ones.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown speech-to-text backend {name:?} (expected local or openai)")]
pub struct UnknownSttBackend {
    pub name: String,
}

impl std::str::FromStr for SttBackend {
    type Err = UnknownSttBackend;
    fn from_str(s: &str) -> Result<Self, UnknownSttBackend> {
        match s.trim().to_ascii_lowercase().as_str() {
            "local" => Ok(SttBackend::Local),
            "openai" => Ok(SttBackend::Openai),
            other => Err(UnknownSttBackend {
                name: other.to_string(),
            }),
        }
    }
}

/// One layer: every field optional; later layers win.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SttLayer {
    pub backend: Option<SttBackend>,
    /// Local: a model of `betr model list`; openai: the server's model name.
    pub model: Option<String>,
    pub base_url: Option<String>,
    pub api_key_env: Option<String>,
    /// The language spoken, for multilingual models (`en`, the default).
    pub language: Option<String>,
    pub beam_size: Option<usize>,
    pub threads: Option<usize>,
    pub timeout_secs: Option<f64>,
    pub max_retries: Option<u32>,
    /// Refused: keys belong in the environment.
    pub api_key: Option<toml::Value>,
}

macro_rules! merge_fields {
    ($self:ident, $other:ident, $($f:ident),*) => { $( if $other.$f.is_some() { $self.$f = $other.$f; } )* };
}

impl SttLayer {
    pub fn merge(&mut self, other: SttLayer) {
        merge_fields!(
            self,
            other,
            backend,
            model,
            base_url,
            api_key_env,
            language,
            beam_size,
            threads,
            timeout_secs,
            max_retries,
            api_key
        );
    }

    /// `BETR_STT` (backend), `BETR_STT_MODEL`, `BETR_STT_BASE_URL`, `BETR_STT_API_KEY_ENV`,
    /// `BETR_STT_LANGUAGE`, read through `var`.
    pub fn from_env(var: &dyn Fn(&str) -> Option<String>) -> Result<SttLayer, VoiceError> {
        let get = |k: &str| var(k).filter(|v| !v.trim().is_empty());
        Ok(SttLayer {
            backend: get("BETR_STT")
                .map(|b| {
                    b.parse()
                        .map_err(|e| VoiceError::Config(format!("BETR_STT: {e}")))
                })
                .transpose()?,
            model: get("BETR_STT_MODEL"),
            base_url: get("BETR_STT_BASE_URL"),
            api_key_env: get("BETR_STT_API_KEY_ENV"),
            language: get("BETR_STT_LANGUAGE"),
            ..SttLayer::default()
        })
    }
}

/// Resolved settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SttSettings {
    pub backend: SttBackend,
    pub model: String,
    /// Without the credentials a URL may carry (they are `url_key`).
    pub base_url: String,
    /// A key given inside the base URL (`http://user:KEY@host/v1`), taken out of it: sent
    /// and redacted like a key from the environment, which wins when both are given.
    pub url_key: Option<SttKey>,
    pub api_key_env: Option<String>,
    pub language: Option<String>,
    pub beam_size: usize,
    pub threads: usize,
    pub timeout: Duration,
    pub max_retries: u32,
}

/// The widest beam search a transcription may ask for.
const MAX_BEAM: usize = 64;

impl SttSettings {
    /// Defaults, then `file`, then `env`, then `flags`.
    pub fn resolve(
        file: Option<SttLayer>,
        env: SttLayer,
        flags: SttLayer,
    ) -> Result<SttSettings, VoiceError> {
        let mut layer = SttLayer::default();
        if let Some(file) = file {
            if file.api_key.is_some() {
                return Err(VoiceError::Config(
                    "`api_key` is not allowed under [stt]; put the key in an environment variable and name it with `api_key_env`".into(),
                ));
            }
            layer.merge(file);
        }
        layer.merge(env);
        layer.merge(flags);
        let backend = layer.backend.unwrap_or(SttBackend::Local);
        let range = |e: crate::bounds::OutOfRange| VoiceError::Config(e.to_string());
        let timeout = crate::bounds::seconds("timeout_secs", layer.timeout_secs.unwrap_or(120.0))
            .map_err(range)?;
        let defaults = LocalSettings::default();
        let beam_size = crate::bounds::within(
            "beam_size",
            layer.beam_size.unwrap_or(defaults.beam_size).max(1),
            1,
            MAX_BEAM,
        )
        .map_err(range)?;
        let max_retries =
            crate::bounds::within("max_retries", layer.max_retries.unwrap_or(3), 0, 20)
                .map_err(range)?;
        let (base_url, url_key) = crate::http_text::split_credentials(
            &layer
                .base_url
                .unwrap_or_else(|| "https://api.openai.com/v1".into()),
        );
        Ok(SttSettings {
            backend,
            base_url,
            url_key,
            model: layer.model.unwrap_or_else(|| {
                match backend {
                    SttBackend::Local => DEFAULT_LOCAL_MODEL,
                    SttBackend::Openai => DEFAULT_REMOTE_MODEL,
                }
                .to_string()
            }),
            api_key_env: match layer.api_key_env {
                Some(v) if v.is_empty() => None,
                Some(v) => Some(v),
                None => Some("OPENAI_API_KEY".into()),
            },
            language: match layer.language {
                Some(l) if l.is_empty() => None,
                Some(l) => Some(l.to_ascii_lowercase()),
                None => Some("en".into()),
            },
            beam_size,
            threads: layer
                .threads
                .map(|t| crate::bounds::within("threads", t, 1, 1024))
                .transpose()
                .map_err(range)?
                .unwrap_or(defaults.threads),
            timeout,
            max_retries,
        })
    }

    /// The embedded model, loaded from the cache.
    pub fn load_local(&self) -> Result<LocalWhisper, VoiceError> {
        LocalWhisper::load_named(
            &self.model,
            LocalSettings {
                language: self.language.clone(),
                beam_size: self.beam_size,
                threads: self.threads,
            },
        )
    }

    /// The OpenAI-compatible client, with the key read through `var`.
    pub fn remote(&self, var: &dyn Fn(&str) -> Option<String>) -> Result<OpenAiStt, VoiceError> {
        let (api_key, api_key_env) =
            crate::http_text::chosen_key(self.api_key_env.as_deref(), var, self.url_key.as_ref());
        OpenAiStt::new(OpenAiSttSettings {
            base_url: self.base_url.clone(),
            model: self.model.clone(),
            language: self.language.clone(),
            api_key_env,
            api_key,
            timeout: self.timeout,
            connect_timeout: Duration::from_secs(10),
            retry: RetryPolicy {
                max_retries: self.max_retries,
                ..RetryPolicy::default()
            },
        })
    }

    /// The configured backend (the embedded model must be in the cache).
    pub fn build(
        &self,
        var: &dyn Fn(&str) -> Option<String>,
    ) -> Result<Box<dyn SpeechToText>, VoiceError> {
        Ok(match self.backend {
            SttBackend::Local => Box::new(self.load_local()?),
            SttBackend::Openai => Box::new(self.remote(var)?),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn later_layers_win_and_defaults_follow_the_backend() {
        let file: SttLayer = toml::from_str("backend = \"openai\"\nlanguage = \"de\"\n").unwrap();
        let env = SttLayer::from_env(&|k| {
            (k == "BETR_STT_BASE_URL").then(|| "http://127.0.0.1:9/v1".to_string())
        })
        .unwrap();
        let s = SttSettings::resolve(Some(file), env, SttLayer::default()).unwrap();
        assert_eq!(s.backend, SttBackend::Openai);
        assert_eq!(s.model, DEFAULT_REMOTE_MODEL);
        assert_eq!(s.base_url, "http://127.0.0.1:9/v1");
        assert_eq!(s.language.as_deref(), Some("de"));
        let flags = SttLayer {
            backend: Some(SttBackend::Local),
            language: Some(String::new()),
            ..SttLayer::default()
        };
        let s = SttSettings::resolve(None, SttLayer::default(), flags).unwrap();
        assert_eq!(s.model, DEFAULT_LOCAL_MODEL);
        assert_eq!(s.language, None);
        assert_eq!(s.api_key_env.as_deref(), Some("OPENAI_API_KEY"));
    }

    #[test]
    fn a_key_inside_the_base_url_is_taken_out_and_used_as_the_key() {
        let env = SttLayer::from_env(&|k| {
            (k == "BETR_STT_BASE_URL").then(|| "http://user:sk-URLKEY@127.0.0.1:9/v1".to_string())
        })
        .unwrap();
        let s = SttSettings::resolve(None, env, SttLayer::default()).unwrap();
        assert!(!s.base_url.contains("sk-URLKEY"), "{}", s.base_url);
        assert!(
            s.base_url.starts_with("http://127.0.0.1:9/v1"),
            "{}",
            s.base_url
        );
        assert_eq!(s.url_key.as_ref().map(SttKey::expose), Some("sk-URLKEY"));
        assert!(!format!("{s:?}").contains("sk-URLKEY"));
        // No key in the environment: the URL's is sent, and named as where it came from.
        let client = s.remote(&|_| None).unwrap();
        assert!(!client.describe().to_string().contains("sk-URLKEY"));
        // One in the environment wins.
        let s2 = s.clone();
        assert!(
            s2.remote(&|k| (k == "OPENAI_API_KEY").then(|| "sk-ENV".into()))
                .is_ok()
        );
    }

    #[test]
    fn keys_unknown_backends_and_models_are_refused() {
        let file = SttLayer {
            api_key: Some(toml::Value::String("sk-x".into())),
            ..SttLayer::default()
        };
        let e = SttSettings::resolve(Some(file), SttLayer::default(), SttLayer::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("api_key_env") && !e.contains("sk-x"), "{e}");
        assert!(SttLayer::from_env(&|k| (k == "BETR_STT").then(|| "cloud".into())).is_err());
        let flags = SttLayer {
            model: Some("whisper-huge".into()),
            ..SttLayer::default()
        };
        let s = SttSettings::resolve(None, SttLayer::default(), flags).unwrap();
        let e = s.build(&|_| None).err().unwrap().to_string();
        assert!(
            e.contains("whisper-huge") && e.contains("whisper-tiny.en"),
            "{e}"
        );
    }
}
