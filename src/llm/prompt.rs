//! Prompts: the three templates of `prompts/` (goal interpretation, failure resolution,
//! parameter value) filled from a scenario, the facts true in the world now, and the
//! failure being resolved.
//!
//! Every template has the same parts, following the BETR-XP-LLM paper's findings: a short
//! role statement, the condition vocabulary with one-line descriptions, the objects and the
//! rule that only listed objects may be used, a few examples, the scene as text and a strict
//! answer format. [`Variant`] switches parts off for the ablations of the paper's Table III.

use std::path::Path;

use super::scene_text::{objects_text, scene_text, vocabulary_text};
use super::{ChatRequest, Message};
use crate::domain::{ActionCall, Condition, ValueParam, Vocabulary};
use crate::scenario::{Example, Scenario};

/// How many worked examples a prompt shows when it chooses them per request.
pub const DEFAULT_EXAMPLES_SHOWN: usize = 6;

/// The most examples made from the scene's own words one prompt shows.
const SCENE_WORD_EXAMPLES: usize = 3;

/// Which ablation of the prompt to write.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Leave out the one-line descriptions of the conditions.
    pub no_descriptions: bool,
    /// Leave out the rule that only listed objects may be used.
    pub no_object_rule: bool,
    /// Ask for reasoning before the goal (the resolution and value prompts always do).
    pub chain_of_thought: bool,
    /// Examples to use instead of the scenario's (e.g. the original prompt's examples).
    pub examples: Option<Vec<Example>>,
    /// How many examples to show, chosen from the pool by similarity to the request
    /// (`None`: every example of the pool, in pool order).
    pub examples_shown: Option<usize>,
    /// Also show examples made from the scene's own words for the request
    /// (`examples::from_scene_words`, after the pool's): what the request asks of one
    /// object in the words the scene lists, said with the scene's phrase, with the
    /// condition; off: the pool's examples alone.
    pub scene_word_examples: bool,
}

impl Default for Variant {
    fn default() -> Self {
        Variant {
            no_descriptions: false,
            no_object_rule: false,
            chain_of_thought: false,
            examples: None,
            examples_shown: Some(DEFAULT_EXAMPLES_SHOWN),
            scene_word_examples: true,
        }
    }
}

impl Variant {
    /// The examples a prompt about `request` shows, from `pool`.
    pub fn choose<'a>(&self, pool: &'a [Example], request: &str) -> Vec<&'a Example> {
        match self.examples_shown {
            None => pool.iter().collect(),
            Some(k) => super::examples::nearest(pool, request, k),
        }
    }
}

/// The three templates.
#[derive(Debug, Clone, PartialEq)]
pub struct Templates {
    pub goal: String,
    pub resolve: String,
    pub value: String,
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PromptError {
    #[error("cannot read prompt template {path}: {detail}")]
    Read { path: String, detail: String },
    #[error("template {template}: unknown placeholder {{{{{name}}}}}")]
    UnknownPlaceholder { template: String, name: String },
    #[error("template {template}: unclosed {{{{ at byte {at}")]
    Unclosed { template: String, at: usize },
}

impl Templates {
    /// The templates shipped in `prompts/`, built into the program.
    pub fn builtin() -> Templates {
        Templates {
            goal: include_str!("../../prompts/goal.md").to_string(),
            resolve: include_str!("../../prompts/resolve.md").to_string(),
            value: include_str!("../../prompts/value.md").to_string(),
        }
    }

    /// `goal.md`, `resolve.md` and `value.md` from a directory (to edit prompts without
    /// rebuilding).
    pub fn from_dir(dir: &Path) -> Result<Templates, PromptError> {
        let read = |name: &str| {
            let path = dir.join(name);
            crate::store::read_text(&path, crate::store::SMALL_FILE_BYTES).map_err(|e| {
                PromptError::Read {
                    path: path.display().to_string(),
                    detail: e.to_string(),
                }
            })
        };
        Ok(Templates {
            goal: read("goal.md")?,
            resolve: read("resolve.md")?,
            value: read("value.md")?,
        })
    }
}

/// What every prompt is written from.
pub struct Context<'a> {
    pub scenario: &'a Scenario,
    /// The conditions true in the world now.
    pub facts: &'a [Condition],
    pub instruction: &'a str,
    pub variant: &'a Variant,
}

/// The role statement shared by all prompts (the system message).
pub const ROLE: &str = "You are the reasoning part of a robot that plans with behavior trees. You answer in the exact format asked for, using only the conditions and objects you are given.";

impl Context<'_> {
    /// The values every prompt fills in. `goal_question`: the prompt asks about a goal, so
    /// its examples include those made from the scene's own words for the request (when
    /// the variant shows them); a failure's or a value's prompt shows the pool's alone.
    fn common(&self, goal_question: bool) -> Vec<(&'static str, String)> {
        let vocabulary = &self.scenario.domain.vocabulary;
        let examples = self
            .variant
            .examples
            .as_deref()
            .unwrap_or(&self.scenario.examples);
        vec![
            (
                "vocabulary",
                vocabulary_text(vocabulary, !self.variant.no_descriptions),
            ),
            ("objects", objects_text(vocabulary)),
            (
                "object_rule",
                if self.variant.no_object_rule {
                    String::new()
                } else {
                    OBJECT_RULE.to_string()
                },
            ),
            ("examples", {
                let derived = if goal_question && self.variant.scene_word_examples {
                    let lexicon = crate::reading::Lexicon::new(vocabulary, examples);
                    let request =
                        crate::reading::Request::new(self.instruction, self.scenario, &lexicon);
                    super::examples::from_scene_words(&request, SCENE_WORD_EXAMPLES)
                } else {
                    Vec::new()
                };
                let mut shown = self.variant.choose(examples, self.instruction);
                // Last, next to the request: they are about its own words and objects.
                shown.extend(&derived);
                examples_text(&shown)
            }),
            ("scene", scene_text(self.facts)),
            ("instruction", self.instruction.trim().to_string()),
        ]
    }

    /// The goal-interpretation request. `prompts/goal.md` puts everything that is the same
    /// for every request of a scene before the examples, which change with the request:
    /// the embedded model keeps that beginning in its cache. The answer format stays after
    /// the request although it is the same every time: moved before the examples (about
    /// 20 tokens, 0.3 s a call) it read the request of a failure scenario wrong.
    pub fn goal(&self, templates: &Templates) -> Result<Vec<Message>, PromptError> {
        let mut values = self.common(true);
        values.push(("conventions", self.conventions_text()));
        values.push((
            "answer_format",
            if self.variant.chain_of_thought {
                "First think about what the person wants, then give the goal, exactly like this:\nReasoning: <a few sentences>\nGoal: <formula>".into()
            } else {
                "Answer with exactly one line and nothing else:\nGoal: <formula>".into()
            },
        ));
        Ok(messages(fill("goal.md", &templates.goal, &values)?))
    }

    /// The failure-resolution request for `action`, which failed with `error`.
    /// `tried`: proposals for this same failure that did not fix it (reflective feedback,
    /// so a repeated question does not get the same answer). `shortlist`: conditions that
    /// fixed the failure when tried in simulation, for the model to choose from (empty:
    /// the model names the condition itself).
    pub fn resolve(
        &self,
        templates: &Templates,
        action: &ActionCall,
        error: &str,
        tried: &[String],
        shortlist: &[Condition],
    ) -> Result<Vec<Message>, PromptError> {
        let mut values = self.common(false);
        values.push(("tried", tried_text(tried)));
        values.push((
            "shortlist",
            shortlist_text(shortlist, &self.scenario.domain.vocabulary),
        ));
        let pre: Vec<String> = self
            .scenario
            .domain
            .resolve(action)
            .map(|g| g.pre.iter().map(ToString::to_string).collect())
            .unwrap_or_default();
        values.push(("action", action.to_string()));
        values.push((
            "action_preconditions",
            if pre.is_empty() {
                ", which the robot believed needs no preconditions".into()
            } else {
                format!(", which the robot believed needs only: {}", pre.join(", "))
            },
        ));
        values.push(("error", error.trim().to_string()));
        // The facts that name the action's objects: a small model finds the cause among
        // a handful of lines far more often than in the whole scene.
        let about: Vec<String> = self
            .facts
            .iter()
            .filter(|f| f.atom.args.iter().any(|a| action.args.contains(a)))
            .map(|f| format!("- {f}"))
            .collect();
        values.push((
            "action_facts",
            if about.is_empty() {
                "(none)".into()
            } else {
                about.join("\n")
            },
        ));
        values.push((
            "answer_format",
            "Explain the cause first, then list the missing conditions, one per line, exactly like this:\nReasoning: <a few sentences>\nConditions:\n<condition>\n<condition, only if more than one is needed>".into(),
        ));
        Ok(messages(fill("resolve.md", &templates.resolve, &values)?))
    }

    /// The parameter-value request for `param` of `action` (`error`: what it reported).
    /// `tried`: values already tried for this failure, each with what the world did;
    /// `bounds`: what those answers leave, in one sentence, if they say anything.
    pub fn value(
        &self,
        templates: &Templates,
        action: &ActionCall,
        param: &ValueParam,
        error: &str,
        (tried, bounds): (&[String], Option<&str>),
    ) -> Result<Vec<Message>, PromptError> {
        let mut values = self.common(false);
        let mut tried = tried_text(tried);
        if let Some(bounds) = bounds {
            tried.push_str(bounds);
            tried.push('\n');
        }
        values.push(("tried", tried));
        values.push(("action", action.to_string()));
        values.push((
            "error_line",
            if error.trim().is_empty() {
                String::new()
            } else {
                format!("It reported: \"{}\"", error.trim())
            },
        ));
        values.push(("parameter", parameter_text(param)));
        values.push((
            "value_examples",
            if param.unit.is_some() {
                NUMBER_EXAMPLES
            } else {
                CHOICE_EXAMPLES
            }
            .to_string(),
        ));
        let format = match &param.unit {
            Some(unit) => format!(
                "Explain your choice first, then give one number in {unit}, exactly like this:\nReasoning: <a few sentences>\nParameter value: <number> {unit}"
            ),
            None => format!(
                "Explain your choice first, then give one of: {}, exactly like this:\nReasoning: <a few sentences>\nParameter value: <choice>",
                param.categories.join(", ")
            ),
        };
        values.push(("answer_format", format));
        Ok(messages(fill("value.md", &templates.value, &values)?))
    }
}

impl Context<'_> {
    /// The domain's conventions that apply to this scene (it has every object one names),
    /// as a section of the goal prompt; empty when none does.
    fn conventions_text(&self) -> String {
        let vocabulary = &self.scenario.domain.vocabulary;
        let lines: Vec<String> = self
            .scenario
            .conventions
            .iter()
            .filter(|c| c.objects.iter().all(|o| vocabulary.object(o).is_some()))
            .map(|c| format!("- {}", c.text))
            .collect();
        if lines.is_empty() {
            return String::new();
        }
        format!("\n## What requests mean here\n{}\n", lines.join("\n"))
    }
}

/// Changes already tried for this failure, with what happened after each: the model
/// learns from the world's verdict instead of repeating itself.
/// The refusals told back: the latest ones, each cut short, so five rounds of answers
/// and their reasons stay well inside a small model's context (an unbounded list passed
/// 23,000 tokens in a cafe with many objects).
const MAX_TRIED_LINES: usize = 12;
const MAX_TRIED_CHARS: usize = 600;

fn tried_text(tried: &[String]) -> String {
    if tried.is_empty() {
        return String::new();
    }
    let left_out = tried.len().saturating_sub(MAX_TRIED_LINES);
    let mut lines: Vec<String> = tried[left_out..]
        .iter()
        .map(|t| match t.char_indices().nth(MAX_TRIED_CHARS) {
            Some((cut, _)) => format!("- {}…", &t[..cut]),
            None => format!("- {t}"),
        })
        .collect();
    if left_out > 0 {
        lines.insert(0, format!("- ({left_out} earlier ones left out)"));
    }
    format!(
        "\nAlready proposed and refused (why is in parentheses: the action still failed when it was tried in simulation, or it was not tried because of what the world said before); learn from it and propose something else:\n{}\n",
        lines.join("\n")
    )
}

/// Worked value choices for a parameter asked as a number: one where too much is the
/// danger and one where too little is, so neither end of a range is taught as the answer.
const NUMBER_EXAMPLES: &str = "- Action `pour \"tea\" \"cup\"` needs the pour rate (a number in ml/s; the robot can do at most 100 ml/s). Reasoning: hot tea into a small cup: too fast overflows it and scalds the person; too slow only takes a little longer. Parameter value: 20 ml/s\n- Action `lift \"cement sack\"` needs the lifting force (a number in N; the robot can do at most 1000 N). Reasoning: a 25 kg sack is heavy and cannot be hurt: too little drops it on someone's feet; more than enough does no harm. Parameter value: 700 N";

/// The same two choices for a parameter asked as one of a few choices.
const CHOICE_EXAMPLES: &str = "- Action `pour \"tea\" \"cup\"` needs the pour rate (one of: slow, steady, fast). Reasoning: hot tea into a small cup: too fast overflows it and scalds the person; too slow only takes a little longer. Parameter value: slow\n- Action `lift \"cement sack\"` needs the lifting force (one of: light, firm, full). Reasoning: a 25 kg sack is heavy and cannot be hurt: too little drops it on someone's feet; more than enough does no harm. Parameter value: full";

/// Says how to answer for a thing named otherwise than listed; its example names objects
/// of no scenario, so no domain's objects are suggested to another's requests.
const OBJECT_RULE: &str = "Use only the objects listed above, spelled exactly as listed. If the person names something that is not listed, use the listed object it most likely means (for example, if they ask for a sofa and only Couch is listed, use Couch).";

fn messages(user: String) -> Vec<Message> {
    vec![Message::system(ROLE), Message::user(user)]
}

/// A request for `messages` with the given sampling settings.
pub fn request(messages: Vec<Message>, temperature: f32, max_tokens: u32) -> ChatRequest {
    let mut r = ChatRequest::new(messages);
    r.temperature = temperature;
    r.max_tokens = max_tokens;
    r
}

/// Replace each `{{name}}` by its value; a name with no value is an error.
/// The conditions found to fix a failure in simulation, as the resolve prompt lists them,
/// each with what its predicate means (negated: "not: …"), so the choice is made on the
/// meaning beside it rather than on a name alone.
fn shortlist_text(shortlist: &[Condition], vocabulary: &Vocabulary) -> String {
    if shortlist.is_empty() {
        return String::new();
    }
    let lines: Vec<String> = shortlist
        .iter()
        .map(|c| {
            let meaning = vocabulary
                .predicate(&c.atom.predicate)
                .map(|p| p.description.trim())
                .filter(|d| !d.is_empty());
            match (meaning, c.negated) {
                (Some(m), false) => format!("- {c} ({m})"),
                (Some(m), true) => format!("- {c} (not: {m})"),
                (None, _) => format!("- {c}"),
            }
        })
        .collect();
    format!(
        "\n## Conditions that fix it in simulation\nEach of these, made true before the action starts, stopped the failure when the robot tried it in simulation. Choose the one that names the cause of the error (a condition about \"any object\" covers every object that could be in the way) and write only that one:\n{}\n",
        lines.join("\n")
    )
}

pub fn fill(
    template_name: &str,
    template: &str,
    values: &[(&str, String)],
) -> Result<String, PromptError> {
    let mut out = String::with_capacity(template.len() * 2);
    let mut rest = template;
    let mut offset = 0;
    while let Some(open) = rest.find("{{") {
        out.push_str(&rest[..open]);
        let Some(close) = rest[open..].find("}}") else {
            return Err(PromptError::Unclosed {
                template: template_name.into(),
                at: offset + open,
            });
        };
        let name = rest[open + 2..open + close].trim();
        let Some((_, value)) = values.iter().find(|(n, _)| *n == name) else {
            return Err(PromptError::UnknownPlaceholder {
                template: template_name.into(),
                name: name.into(),
            });
        };
        out.push_str(value);
        offset += open + close + 2;
        rest = &rest[open + close + 2..];
    }
    out.push_str(rest);
    // An empty optional part leaves a blank line; keep at most one in a row.
    let mut cleaned = String::with_capacity(out.len());
    let mut blank = false;
    for line in out.lines() {
        let is_blank = line.trim().is_empty();
        if !(is_blank && blank) {
            cleaned.push_str(line);
            cleaned.push('\n');
        }
        blank = is_blank;
    }
    Ok(cleaned)
}

fn examples_text(examples: &[&Example]) -> String {
    if examples.is_empty() {
        return "(none)".into();
    }
    examples
        .iter()
        .map(|e| format!("Instruction: {}\nGoal: {}", e.instruction, e.goal))
        .collect::<Vec<_>>()
        .join("\n\n")
}

fn parameter_text(param: &ValueParam) -> String {
    let mut s = format!("\"{}\"", param.name);
    if let Some(unit) = &param.unit {
        let range = match (param.min, param.max) {
            (Some(lo), Some(hi)) => format!("; the robot can do {lo} to {hi} {unit}"),
            (None, Some(hi)) => format!("; the robot can do at most {hi} {unit}"),
            (Some(lo), None) => format!("; the robot can do no less than {lo} {unit}"),
            (None, None) => String::new(),
        };
        s.push_str(&format!(" (a number in {unit}{range})"));
    } else if !param.categories.is_empty() {
        s.push_str(&format!(" (one of: {})", param.categories.join(", ")));
    }
    if !param.description.is_empty() {
        s.push_str(&format!(": {}", param.description));
    }
    s
}

#[cfg(test)]
#[path = "prompt_tests.rs"]
mod tests;
