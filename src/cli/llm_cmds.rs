//! The language-model flags of the product's commands, and the settings and model they
//! make. The lab's flags (`betr eval`) are its own (`lab_flags`).

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Result;
use clap::Args;

use betr::config_file::FileConfig;
use betr::llm::LanguageModel;
use betr::llm::config::{Backend, Layer, Settings};
use betr::llm::usage::{Ledger, Metered};
use betr::session::Options;

/// Which model answers: the flags every command that asks a model takes, the workbench
/// included. Each overrides the matching `BETR_*` variable, which overrides `betr.toml`.
#[derive(Args, Debug, Clone, Default)]
pub struct LlmFlags {
    /// Settings file (default: $BETR_CONFIG, ./betr.toml, ~/.config/betr/betr.toml).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Which model answers: openai (any OpenAI-compatible server), local (the embedded model, the default), replay
    /// [env: BETR_BACKEND].
    #[arg(long, value_name = "openai|local|replay")]
    pub backend: Option<String>,
    /// Server base URL including /v1, e.g. http://127.0.0.1:8080/v1 [env: BETR_BASE_URL].
    #[arg(long, value_name = "URL")]
    pub base_url: Option<String>,
    /// Model name [env: BETR_MODEL].
    #[arg(long, value_name = "NAME")]
    pub model: Option<String>,
    /// NAME of the environment variable holding the API key (default OPENAI_API_KEY)
    /// [env: BETR_API_KEY_ENV].
    #[arg(long, value_name = "VAR")]
    pub api_key_env: Option<String>,
}

/// How a one-shot command (`interpret`, `resolve`, and the lab's commands) calls the
/// model. The workbench keeps its command line short and takes these from `betr.toml`
/// and the `BETR_*` variables.
#[derive(Args, Debug, Clone, Default)]
pub struct CallFlags {
    /// Cassette: replayed with --backend replay, else every exchange is recorded to it
    /// [env: BETR_CASSETTE].
    #[arg(long, value_name = "FILE")]
    pub cassette: Option<PathBuf>,
    /// Constrain replies to the vocabulary with a JSON schema (servers with response_format)
    /// [env: BETR_STRUCTURED].
    #[arg(long)]
    pub structured: bool,
    /// Append usage records here instead of $XDG_STATE_HOME/betr/usage.jsonl [env: BETR_USAGE_LOG].
    #[arg(long, value_name = "FILE")]
    pub usage_log: Option<PathBuf>,
    /// Request timeout in seconds.
    #[arg(long, value_name = "SECS")]
    pub timeout: Option<f64>,
    /// Retries of HTTP 429 / 5xx replies.
    #[arg(long, value_name = "N")]
    pub max_retries: Option<u32>,
    /// Sampling temperature.
    #[arg(long)]
    pub temperature: Option<f32>,
    /// Print each reply's raw text too.
    #[arg(long)]
    pub show_replies: bool,
    /// Local backend: use this GGUF file instead of the fetched default model
    /// [env: BETR_MODEL_PATH].
    #[arg(long, value_name = "FILE")]
    pub model_path: Option<PathBuf>,
    /// Local backend: CPU threads (default: the cores idle when the model loads)
    /// [env: BETR_THREADS].
    #[arg(long, value_name = "N")]
    pub threads: Option<u32>,
}

/// The configured model and its ledger, and the session options for it.
pub(super) struct Llm {
    pub(super) model: Arc<Metered<Box<dyn LanguageModel>>>,
    pub(super) options: Options,
}

pub(super) fn setup(flags: &LlmFlags, call: &CallFlags) -> Result<Llm> {
    let (settings, options) = settings_from(flags, layer(flags, call)?)?;
    build(&settings, options)
}

/// The model the settings ask for, fetched first when it is the embedded one and missing.
pub(super) fn build(settings: &Settings, options: Options) -> Result<Llm> {
    ensure_local_model(settings)?;
    let ledger = Ledger::new(settings.usage_log.clone());
    let model = settings.build(ledger, &|k: &str| std::env::var(k).ok())?;
    Ok(Llm {
        model: Arc::new(model),
        options,
    })
}

/// The local model is fetched on first use (with a progress bar) before it is loaded.
pub fn ensure_local_model(settings: &Settings) -> Result<()> {
    if settings.backend == Backend::Local && settings.model_path.is_none() {
        super::model_cmd::ensure(settings.model.as_deref())?;
    }
    Ok(())
}

/// The embedded model the settings ask for when it is not in the cache yet (none for a
/// server, a model file given by path, or a model name betr does not know).
pub fn local_model_to_fetch(settings: &Settings) -> Option<&'static betr::model::ModelSpec> {
    if settings.backend != Backend::Local || settings.model_path.is_some() {
        return None;
    }
    let spec = match settings.model.as_deref() {
        None => betr::model::DEFAULT_MODEL,
        Some(name) => betr::model::find(name)?,
    };
    (!spec.is_present()).then_some(spec)
}

/// The resolved settings and the session options the workbench's flags ask for (no model
/// built yet).
pub fn settings(flags: &LlmFlags) -> Result<(Settings, Options)> {
    settings_from(flags, layer(flags, &CallFlags::default())?)
}

/// The settings the flags give, over the environment's and the settings file's.
pub(super) fn layer(flags: &LlmFlags, call: &CallFlags) -> Result<Layer> {
    Ok(Layer {
        backend: flags
            .backend
            .as_deref()
            .map(str::parse::<Backend>)
            .transpose()
            .map_err(|e| anyhow::anyhow!("--backend: {e}"))?,
        base_url: flags.base_url.clone(),
        model: flags.model.clone(),
        api_key_env: flags.api_key_env.clone(),
        structured: call.structured.then_some(true),
        temperature: call.temperature,
        timeout_secs: call.timeout,
        max_retries: call.max_retries,
        cassette: call.cassette.clone(),
        usage_log: call.usage_log.clone(),
        model_path: call.model_path.clone(),
        threads: call.threads,
        ..Layer::default()
    })
}

/// `flag_layer` over the `BETR_*` variables over the settings file (`--config` or the
/// usual places), and the product's session options for those settings.
pub(super) fn settings_from(flags: &LlmFlags, flag_layer: Layer) -> Result<(Settings, Options)> {
    let var = |k: &str| std::env::var(k).ok();
    let file = match FileConfig::locate(flags.config.as_deref(), &var) {
        Some(path) => Some((FileConfig::read(&path)?, path)),
        None => None,
    };
    let settings = Settings::resolve(
        file.as_ref()
            .map(|(f, p)| (p.as_path(), f.llm.clone(), f.prices.clone())),
        Layer::from_env(&var)?,
        flag_layer,
    )?;
    let options = Options {
        temperature: settings.temperature,
        max_tokens: settings.max_tokens,
        structured: settings.structured,
        grammar: settings.grammar,
        ..Options::default()
    };
    Ok((settings, options))
}
