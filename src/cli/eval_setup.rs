//! What the `betr eval` commands share: the prompt variant, the run flags, the model
//! and its settings (for the resume guard), and a progress bar that draws only on a
//! terminal.

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use betr::eval::run::Progress;
use betr::llm::LanguageModel;
use betr::llm::config::{Backend, Settings};
use betr::session::Options;

use super::lab_flags::LabFlags;
use super::llm_cmds::{self, CallFlags, LlmFlags};

/// The prompt ablations of the paper's Table III.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PromptVariant {
    Full,
    NoDescriptions,
    NoObjectRule,
    OriginalExamples,
    Cot,
}

impl PromptVariant {
    fn name(self) -> &'static str {
        match self {
            PromptVariant::Full => "full",
            PromptVariant::NoDescriptions => "no-descriptions",
            PromptVariant::NoObjectRule => "no-object-rule",
            PromptVariant::OriginalExamples => "original-examples",
            PromptVariant::Cot => "cot",
        }
    }
}

/// Flags every experiment that asks a model shares.
#[derive(Args, Debug, Clone)]
pub struct RunFlags {
    /// Prompt variant (ablations of the paper's Table III); original-examples needs --examples FILE.
    #[arg(long, value_enum, default_value = "full")]
    pub prompt: PromptVariant,
    /// Requests in flight at once (default: 4 for HTTP backends, 1 for the local model).
    #[arg(value_parser = super::ranged(1, 256), long, value_name = "K")]
    pub concurrency: Option<usize>,
    /// Where to write the results (default: a new directory under eval-results/). Pointing
    /// a run at an existing directory resumes it: cases already recorded are not asked again.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Stop after this many newly finished cases (for testing interruption).
    #[arg(value_parser = super::ranged(1, 100_000_000), long, hide = true)]
    pub limit: Option<usize>,
    #[command(flatten)]
    pub llm: LlmFlags,
    #[command(flatten)]
    pub call: CallFlags,
    #[command(flatten)]
    pub lab: LabFlags,
}

/// Draws a progress bar on stderr when it is a terminal; otherwise draws nothing.
pub(super) struct Bar(ProgressBar);

impl Bar {
    pub(super) fn new() -> Bar {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(None, target);
        if let Ok(style) = ProgressStyle::with_template(
            "{bar:40} {pos}/{len} [{elapsed_precise}, eta {eta}] {msg}",
        ) {
            bar.set_style(style);
        }
        Bar(bar)
    }
}

impl Progress for Bar {
    fn begin(&self, total: usize, done: usize) {
        self.0.set_length(total as u64);
        self.0.set_position(done as u64);
        if done > 0 {
            self.0.println(format!(
                "resuming: {done} of {total} case(s) already recorded"
            ));
        }
    }
    fn finished(&self, label: &str) {
        self.0.inc(1);
        self.0.set_message(label.to_string());
    }
    fn end(&self) {
        self.0.finish_and_clear();
    }
}

/// The model, its options with the prompt variant applied, and the run settings.
pub(super) struct Prepared {
    pub(super) llm: llm_cmds::Llm,
    pub(super) label: String,
    pub(super) settings: BTreeMap<String, String>,
    /// The model's settings (its prices among them).
    pub(super) model_settings: Settings,
    pub(super) concurrency: usize,
}

pub(super) fn prepare(flags: &RunFlags, extra: &[(&str, String)]) -> Result<Prepared> {
    let lab = with_prompt(&flags.lab, flags.prompt)?;
    let levers = lab.levers()?;
    let mut layer = llm_cmds::layer(&flags.llm, &flags.call)?;
    lab.layer(&mut layer);
    let (model_settings, mut options) = llm_cmds::settings_from(&flags.llm, layer)?;
    levers.apply(&mut options);
    let llm = llm_cmds::build(&model_settings, options)?;
    let backend = format!("{:?}", model_settings.backend).to_lowercase();
    let model = llm.model.model().to_string();
    let mut settings = run_settings(&llm.options, &model_settings, &lab);
    settings.insert("backend".into(), backend.clone());
    settings.insert("model".into(), model.clone());
    settings.insert("prompt".into(), flags.prompt.name().into());
    for (k, v) in extra {
        settings.insert((*k).into(), v.clone());
    }
    let concurrency = flags
        .concurrency
        .unwrap_or(if model_settings.backend == Backend::Local {
            1
        } else {
            4
        })
        .max(1);
    Ok(Prepared {
        label: format!(
            "{model} ({backend}), prompt {}, {}",
            flags.prompt.name(),
            reading_label(&llm.options)
        ),
        llm,
        settings,
        model_settings,
        concurrency,
    })
}

/// The lab's flags with the prompt variant's levers pulled too.
fn with_prompt(lab: &LabFlags, prompt: PromptVariant) -> Result<LabFlags> {
    let mut lab = lab.clone();
    match prompt {
        PromptVariant::Full => {}
        PromptVariant::NoDescriptions => lab.no_descriptions = true,
        PromptVariant::NoObjectRule => lab.no_object_rule = true,
        PromptVariant::Cot => lab.cot = true,
        PromptVariant::OriginalExamples => {
            if lab.examples.is_none() {
                bail!(
                    "--prompt original-examples: the examples of the original LLM-OBTEA prompt are not shipped with betr; give them with --examples FILE (TOML: [[examples]] with instruction and goal)"
                );
            }
            // The original prompt's examples alone, as that prompt showed them.
            lab.no_scene_word_examples = true;
        }
    }
    Ok(lab)
}

/// The settings a run's journal is made with, besides the model and the prompt variant:
/// a run resumed with others is refused.
fn run_settings(
    options: &Options,
    model_settings: &Settings,
    lab: &LabFlags,
) -> BTreeMap<String, String> {
    let steps = &options.steps;
    let mut settings: BTreeMap<String, String> = BTreeMap::new();
    for (k, v) in [
        ("temperature", model_settings.temperature.to_string()),
        ("structured", model_settings.structured.to_string()),
        (
            "examples_shown",
            steps
                .prompt
                .examples_shown
                .map_or("all".into(), |k| k.to_string()),
        ),
        ("checks", steps.check_goals.to_string()),
        ("candidates", options.candidates.to_string()),
        ("beams", options.beams.to_string()),
        ("feedback_rounds", options.goal_feedback_rounds.to_string()),
        ("shortlist", steps.shortlist.to_string()),
        ("screen_proposals", steps.screen_proposals.to_string()),
        ("read_by_parts", steps.read_by_parts.to_string()),
        (
            "scene_word_examples",
            steps.prompt.scene_word_examples.to_string(),
        ),
        ("value_levels", steps.value_levels.to_string()),
        ("grammar", model_settings.grammar.to_string()),
    ] {
        settings.insert(k.into(), v);
    }
    if steps.planning_without_hidden_rules {
        settings.insert("planning_without_hidden_rules".into(), "true".into());
    }
    if let Some(executor) = &lab.executor {
        settings.insert("executor".into(), executor.clone());
    }
    if !steps.without_misreadings.is_empty() {
        settings.insert(
            "without_misreadings".into(),
            steps.without_misreadings.join(" "),
        );
    }
    let optional = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
    for (k, v) in [
        ("examples", optional(&lab.examples)),
        ("prompts", optional(&lab.prompts)),
    ] {
        if let Some(v) = v {
            settings.insert(k.into(), v);
        }
    }
    settings
}

/// How the run reads, for the table's label: the examples shown, and the checks.
fn reading_label(options: &Options) -> String {
    let examples = match options.steps.prompt.examples_shown {
        None => "all examples".to_string(),
        Some(k) => format!("{k} retrieved examples"),
    };
    let checks = if options.steps.check_goals {
        format!(
            "checked ({} candidates, {} feedback rounds{})",
            options.candidates,
            options.goal_feedback_rounds,
            if options.steps.read_by_parts {
                ", a wish at a time"
            } else {
                ", whole request"
            }
        )
    } else {
        "unchecked".to_string()
    };
    let failures = match (options.steps.shortlist, options.steps.screen_proposals) {
        (true, true) => "",
        (false, true) => ", failures without a shortlist",
        (true, false) => ", failures' proposals untried",
        (false, false) => ", failures asked of the model alone (no shortlist, untried)",
    };
    format!("{examples}, {checks}{failures}")
}
