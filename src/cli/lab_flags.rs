//! The lab's flags: the levers `betr eval` pulls to measure what each part of reading and
//! asking earns (`betr::eval::levers`), and the settings of a run repeated with one lever
//! changed. No product command takes them.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use clap::Args;

use betr::eval::levers::Levers;
use betr::llm::config::Layer;
use betr::llm::prompt::Templates;
use betr::scenario::Example;

/// The help heading of the levers.
const LEVERS: &str = "Levers (what an evaluation turns off or sets to measure each part)";

#[derive(Args, Debug, Clone, Default)]
pub struct LabFlags {
    /// With a live backend and --cassette: answer what the cassette already holds for the
    /// model from it, ask the model only the rest and record that (a run repeated with
    /// one setting changed asks only the questions that changed).
    #[arg(long, requires = "cassette")]
    pub reuse_cassette: bool,
    /// Leave the condition descriptions out of the prompt.
    #[arg(help_heading = LEVERS, long)]
    pub no_descriptions: bool,
    /// Leave out the rule that only listed objects may be used.
    #[arg(help_heading = LEVERS, long)]
    pub no_object_rule: bool,
    /// Ask for reasoning before the goal (chain of thought).
    #[arg(help_heading = LEVERS, long)]
    pub cot: bool,
    /// Examples from this TOML file ([[examples]] instruction, goal) instead of the
    /// scenario's, e.g. the original prompt's examples.
    #[arg(help_heading = LEVERS, long, value_name = "FILE")]
    pub examples: Option<PathBuf>,
    /// Worked examples per prompt, chosen from the scenario's pool as the most similar
    /// to the request (default 6; 0: none).
    #[arg(help_heading = LEVERS, value_parser = super::ranged(0, 100), long, value_name = "K")]
    pub examples_shown: Option<usize>,
    /// Show only the pool's examples, without the up to three made from the scene's own
    /// words for the request (what it asks of one object in the words the scene lists for
    /// a condition or its opposite, said with the scene's phrase, with that condition).
    #[arg(help_heading = LEVERS, long)]
    pub no_scene_word_examples: bool,
    /// Candidates per question: drawn when a goal's first answer fails its checks, and
    /// for every failure, each tried in simulation before it is offered (default 4).
    #[arg(help_heading = LEVERS, value_parser = super::ranged(1, 64), long, value_name = "N")]
    pub candidates: Option<usize>,
    /// Local backend: a goal's first answer is the most likely whole answer of N beams
    /// searched under the grammar, the runners-up candidates too (default 4; 1: one
    /// greedy answer).
    #[arg(help_heading = LEVERS, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=6))]
    pub beams: Option<u32>,
    /// Take the first usable goal as it is: no checks, no vote, no feedback (the paper's
    /// single call).
    #[arg(help_heading = LEVERS, long)]
    pub no_checks: bool,
    /// Times the model is told why its goals were refused and asked again (default 2).
    #[arg(help_heading = LEVERS, value_parser = super::ranged(0, 10), long, value_name = "N")]
    pub feedback_rounds: Option<usize>,
    /// Read a request of several wishes whole, instead of one wish at a time with the
    /// goals joined as the request joins them.
    #[arg(help_heading = LEVERS, long)]
    pub whole_request: bool,
    /// Ask a numeric parameter's first value as a number, instead of as a level (very low
    /// … very high) of the range the robot can do that betr turns into a number.
    #[arg(help_heading = LEVERS, long)]
    pub value_as_number: bool,
    /// Let the model name a failure's missing condition out of the whole vocabulary,
    /// instead of choosing among the conditions over the action's objects that fix the
    /// failure when tried in simulation.
    #[arg(help_heading = LEVERS, long)]
    pub no_shortlist: bool,
    /// Propose the model's first usable answer about a failure as it is, without trying
    /// it in simulation first (with --no-shortlist: the model alone, as in the paper).
    #[arg(help_heading = LEVERS, long)]
    pub no_screening: bool,
    /// Plan and try fixes in the scenario's model only: a symbolic world's hidden rules
    /// (what its failures come from) are left out of the planning world, as a robot's
    /// planner knows only its model (the cell's model is its geometry: unchanged).
    #[arg(help_heading = LEVERS, long)]
    pub twin_screening: bool,
    /// Perform the actions of the cell scenarios in this executor (`mujoco`, or a program
    /// speaking the executor protocol), betr's cell as its twin; other scenarios run in
    /// betr's world.
    #[arg(help_heading = LEVERS, long, value_name = "COMMAND")]
    pub executor: Option<String>,
    /// Leave out a detector of plain misreadings when goals are judged, to measure what it
    /// earns (repeatable; the names are listed in docs/ARCHITECTURE.md and in the error
    /// for an unknown one).
    #[arg(help_heading = LEVERS, long, value_name = "NAME")]
    pub without_misreading: Vec<String>,
    /// Local backend: let the model write freely instead of following a grammar built
    /// from the scenario's vocabulary [env: BETR_GRAMMAR=false].
    #[arg(help_heading = LEVERS, long)]
    pub no_grammar: bool,
    /// Read goal.md, resolve.md and value.md from this directory instead of the built-in prompts.
    #[arg(help_heading = LEVERS, long, value_name = "DIR")]
    pub prompts: Option<PathBuf>,
}

impl LabFlags {
    /// The model settings these flags change, over the product's flags.
    pub fn layer(&self, layer: &mut Layer) {
        if self.reuse_cassette {
            layer.reuse_cassette = Some(true);
        }
        if self.no_grammar {
            layer.grammar = Some(false);
        }
    }

    /// The levers these flags pull (files read: the examples, the prompt templates).
    pub fn levers(&self) -> Result<Levers> {
        betr::reading::misreadings_without(&self.without_misreading)?;
        Ok(Levers {
            no_descriptions: self.no_descriptions,
            no_object_rule: self.no_object_rule,
            chain_of_thought: self.cot,
            examples: self.examples.as_deref().map(read_examples).transpose()?,
            examples_shown: self.examples_shown,
            no_scene_word_examples: self.no_scene_word_examples,
            candidates: self.candidates,
            beams: self.beams,
            no_checks: self.no_checks,
            feedback_rounds: self.feedback_rounds,
            whole_request: self.whole_request,
            value_as_number: self.value_as_number,
            no_shortlist: self.no_shortlist,
            no_screening: self.no_screening,
            twin_screening: self.twin_screening,
            without_misreadings: self.without_misreading.clone(),
            templates: self
                .prompts
                .as_deref()
                .map(Templates::from_dir)
                .transpose()?,
        })
    }
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
            source: Default::default(),
        })
        .collect())
}
