//! The language-model flags every command that asks a model shares, and the settings
//! and model they make.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context as _, Result};
use clap::Args;

use betr::config_file::FileConfig;
use betr::llm::LanguageModel;
use betr::llm::config::{Backend, Layer, Settings};
use betr::llm::prompt::{DEFAULT_EXAMPLES_SHOWN, Templates, Variant};
use betr::llm::usage::{Ledger, Metered};
use betr::scenario::Example;
use betr::session::Options;
use betr::session::types::{Ablations, DEFAULT_CANDIDATES};

/// The help heading of the flags an evaluation turns parts off with
/// (`session::types::Ablations`).
const ABLATIONS: &str = "Ablations (what an evaluation turns off to measure each part)";

/// Flags shared by every command that asks a language model. Each overrides the
/// matching `BETR_*` variable, which overrides `betr.toml`.
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
    /// Cassette: replayed with --backend replay, else every exchange is recorded to it
    /// [env: BETR_CASSETTE].
    #[arg(long, value_name = "FILE")]
    pub cassette: Option<PathBuf>,
    /// With a live backend and --cassette: answer what the cassette already holds for the
    /// model from it, ask the model only the rest and record that (a run repeated with
    /// one setting changed asks only the questions that changed).
    #[arg(long, requires = "cassette")]
    pub reuse_cassette: bool,
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
    /// Ablation: leave the condition descriptions out of the prompt.
    #[arg(help_heading = ABLATIONS, long)]
    pub no_descriptions: bool,
    /// Ablation: leave out the rule that only listed objects may be used.
    #[arg(help_heading = ABLATIONS, long)]
    pub no_object_rule: bool,
    /// Ablation: ask for reasoning before the goal (chain of thought).
    #[arg(help_heading = ABLATIONS, long)]
    pub cot: bool,
    /// Ablation: examples from this TOML file ([[examples]] instruction, goal) instead of
    /// the scenario's, e.g. the original prompt's examples.
    #[arg(help_heading = ABLATIONS, long, value_name = "FILE")]
    pub examples: Option<PathBuf>,
    /// Worked examples per prompt, chosen from the scenario's pool as the most similar
    /// to the request (default 6; 0: none).
    #[arg(value_parser = super::ranged(0, 100), long, value_name = "K")]
    pub examples_shown: Option<usize>,
    /// Show only the pool's examples, without the up to three made from the scene's own
    /// words for the request (what it asks of one object in the words the scene lists for
    /// a condition or its opposite, said with the scene's phrase, with that condition).
    #[arg(long, help_heading = ABLATIONS)]
    pub no_scene_word_examples: bool,
    /// Candidates per question: drawn when a goal's first answer fails its checks, and
    /// for every failure, each tried in simulation before it is offered (default 4).
    #[arg(value_parser = super::ranged(1, 64), long, value_name = "N")]
    pub candidates: Option<usize>,
    /// Local backend: a goal's first answer is the most likely whole answer of N beams
    /// searched under the grammar, the runners-up candidates too (default 4; 1: one
    /// greedy answer).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=6))]
    pub beams: Option<u32>,
    /// Take the first usable goal as it is: no checks, no vote, no feedback (the paper's
    /// single call).
    #[arg(long, help_heading = ABLATIONS)]
    pub no_checks: bool,
    /// Times the model is told why its goals were refused and asked again (default 2).
    #[arg(value_parser = super::ranged(0, 10), long, value_name = "N")]
    pub feedback_rounds: Option<usize>,
    /// Read a request of several wishes whole, instead of one wish at a time with the
    /// goals joined as the request joins them.
    #[arg(long, help_heading = ABLATIONS)]
    pub whole_request: bool,
    /// Ask a numeric parameter's first value as a number, instead of as a level (very low
    /// … very high) of the range the robot can do that betr turns into a number.
    #[arg(long, help_heading = ABLATIONS)]
    pub value_as_number: bool,
    /// Let the model name a failure's missing condition out of the whole vocabulary,
    /// instead of choosing among the conditions over the action's objects that fix the
    /// failure when tried in simulation.
    #[arg(long, help_heading = ABLATIONS)]
    pub no_shortlist: bool,
    /// Read goal.md, resolve.md and value.md from this directory instead of the built-in prompts.
    #[arg(long, value_name = "DIR")]
    pub prompts: Option<PathBuf>,
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
    /// Local backend: let the model write freely instead of following a grammar built
    /// from the scenario's vocabulary [env: BETR_GRAMMAR=false].
    #[arg(long)]
    pub no_grammar: bool,
}

/// The configured model and its ledger (also used by `betr eval`).
pub(super) struct Llm {
    pub(super) model: Arc<Metered<Box<dyn LanguageModel>>>,
    pub(super) options: Options,
    pub(super) settings: Settings,
}

pub(super) fn setup(flags: &LlmFlags) -> Result<Llm> {
    let (settings, options) = settings(flags)?;
    ensure_local_model(&settings)?;
    let ledger = Ledger::new(settings.usage_log.clone());
    let model = settings.build(ledger, &|k: &str| std::env::var(k).ok())?;
    Ok(Llm {
        model: Arc::new(model),
        options,
        settings,
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

/// The resolved settings and the session options the flags ask for (no model built yet).
pub fn settings(flags: &LlmFlags) -> Result<(Settings, Options)> {
    let var = |k: &str| std::env::var(k).ok();
    let file = match FileConfig::locate(flags.config.as_deref(), &var) {
        Some(path) => Some((FileConfig::read(&path)?, path)),
        None => None,
    };
    let flag_layer = Layer {
        backend: flags
            .backend
            .as_deref()
            .map(str::parse::<Backend>)
            .transpose()
            .map_err(|e| anyhow::anyhow!("--backend: {e}"))?,
        base_url: flags.base_url.clone(),
        model: flags.model.clone(),
        api_key_env: flags.api_key_env.clone(),
        structured: flags.structured.then_some(true),
        temperature: flags.temperature,
        timeout_secs: flags.timeout,
        max_retries: flags.max_retries,
        cassette: flags.cassette.clone(),
        reuse_cassette: flags.reuse_cassette.then_some(true),
        usage_log: flags.usage_log.clone(),
        model_path: flags.model_path.clone(),
        threads: flags.threads,
        grammar: flags.no_grammar.then_some(false),
        ..Layer::default()
    };
    let settings = Settings::resolve(
        file.as_ref()
            .map(|(f, p)| (p.as_path(), f.llm.clone(), f.prices.clone())),
        Layer::from_env(&var)?,
        flag_layer,
    )?;
    let examples = flags.examples.as_deref().map(read_examples).transpose()?;
    let templates = match &flags.prompts {
        Some(dir) => Templates::from_dir(dir)?,
        None => Templates::builtin(),
    };
    let options = Options {
        temperature: settings.temperature,
        max_tokens: settings.max_tokens,
        structured: settings.structured,
        grammar: settings.grammar,
        templates,
        variant: Variant {
            no_descriptions: flags.no_descriptions,
            no_object_rule: flags.no_object_rule,
            chain_of_thought: flags.cot,
            // Examples given in a file (another prompt's) are shown as they are, all of them.
            examples_shown: match (flags.examples_shown, &examples) {
                (Some(k), _) => Some(k),
                (None, Some(_)) => None,
                (None, None) => Some(DEFAULT_EXAMPLES_SHOWN),
            },
            scene_word_examples: !flags.no_scene_word_examples,
            examples,
        },
        candidates: flags.candidates.unwrap_or(DEFAULT_CANDIDATES).max(1),
        beams: flags.beams.unwrap_or(betr::session::types::DEFAULT_BEAMS),
        goal_feedback_rounds: flags.feedback_rounds.unwrap_or(2),
        ablations: Ablations {
            check_goals: !flags.no_checks,
            read_by_parts: !flags.whole_request,
            value_levels: !flags.value_as_number,
            shortlist: !flags.no_shortlist,
            without_misreadings: Vec::new(),
        },
        ..Options::default()
    };
    Ok((settings, options))
}

fn read_examples(path: &Path) -> Result<Vec<Example>> {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct File {
        examples: Vec<Raw>,
    }
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Raw {
        instruction: String,
        goal: String,
    }
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let file: File = toml::from_str(&text).with_context(|| format!("{}", path.display()))?;
    Ok(file
        .examples
        .into_iter()
        .map(|r| Example {
            instruction: r.instruction,
            goal: r.goal,
        })
        .collect())
}
