//! The levers the lab pulls: each part of reading an instruction and asking about a
//! failure that an evaluation turns off, or sets otherwise, to measure what it earns. The
//! product always runs `session::Steps::default()` and the default counts of
//! `session::Options`; only the lab turns these into other steps (`betr eval`'s flags).

use crate::llm::prompt::{DEFAULT_EXAMPLES_SHOWN, Templates, Variant};
use crate::scenario::Example;
use crate::session::types::{DEFAULT_BEAMS, DEFAULT_CANDIDATES};
use crate::session::{Options, Steps};

/// The levers of one evaluation run; the default pulls none (the product's reading).
#[derive(Debug, Clone, Default)]
pub struct Levers {
    /// Leave the condition descriptions out of the prompt.
    pub no_descriptions: bool,
    /// Leave out the rule that only listed objects may be used.
    pub no_object_rule: bool,
    /// Ask for reasoning before the goal (chain of thought).
    pub chain_of_thought: bool,
    /// Examples instead of the scenario's (another prompt's), shown as they are, all of
    /// them, unless `examples_shown` says how many.
    pub examples: Option<Vec<Example>>,
    /// Worked examples per prompt (`None`: the product's count).
    pub examples_shown: Option<usize>,
    /// Show only the pool's examples, none made from the scene's own words.
    pub no_scene_word_examples: bool,
    /// Candidates per question (`None`: the product's count).
    pub candidates: Option<usize>,
    /// Beams for a goal's first answer (`None`: the product's count).
    pub beams: Option<u32>,
    /// Take the first usable goal: no checks, no vote, no feedback.
    pub no_checks: bool,
    /// Feedback rounds after refused goals (`None`: the product's count).
    pub feedback_rounds: Option<usize>,
    /// Read a request of several wishes whole.
    pub whole_request: bool,
    /// Ask a numeric parameter's first value as a number, not as a level of its range.
    pub value_as_number: bool,
    /// Let the model name a failure's condition out of the whole vocabulary.
    pub no_shortlist: bool,
    /// Propose the model's first usable answer for a failure without trying it first.
    pub no_screening: bool,
    /// Plan and screen without the symbolic worlds' hidden rules.
    pub twin_screening: bool,
    /// Detectors of plain misreadings left out, by name.
    pub without_misreadings: Vec<String>,
    /// Prompt templates instead of the built-in ones.
    pub templates: Option<Templates>,
}

impl Levers {
    /// The reading and asking steps these levers make.
    pub fn steps(&self) -> Steps {
        Steps {
            prompt: Variant {
                no_descriptions: self.no_descriptions,
                no_object_rule: self.no_object_rule,
                chain_of_thought: self.chain_of_thought,
                examples_shown: match (self.examples_shown, &self.examples) {
                    (Some(k), _) => Some(k),
                    (None, Some(_)) => None,
                    (None, None) => Some(DEFAULT_EXAMPLES_SHOWN),
                },
                scene_word_examples: !self.no_scene_word_examples,
                examples: self.examples.clone(),
            },
            check_goals: !self.no_checks,
            read_by_parts: !self.whole_request,
            value_levels: !self.value_as_number,
            shortlist: !self.no_shortlist,
            screen_proposals: !self.no_screening,
            planning_without_hidden_rules: self.twin_screening,
            without_misreadings: self.without_misreadings.clone(),
        }
    }

    /// `options` with these levers pulled.
    pub fn apply(&self, options: &mut Options) {
        options.steps = self.steps();
        options.candidates = self.candidates.unwrap_or(DEFAULT_CANDIDATES).max(1);
        options.beams = self.beams.unwrap_or(DEFAULT_BEAMS);
        if let Some(rounds) = self.feedback_rounds {
            options.goal_feedback_rounds = rounds;
        }
        if let Some(templates) = &self.templates {
            options.templates = templates.clone();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No lever pulled is the product's reading, so an evaluation without flags measures
    /// what the workbench runs.
    #[test]
    fn no_lever_pulled_is_the_product() {
        let mut options = Options::default();
        Levers::default().apply(&mut options);
        let product = Options::default();
        assert_eq!(options.steps.prompt, product.steps.prompt);
        assert_eq!(options.steps.check_goals, product.steps.check_goals);
        assert_eq!(options.steps.read_by_parts, product.steps.read_by_parts);
        assert_eq!(options.steps.value_levels, product.steps.value_levels);
        assert_eq!(options.steps.shortlist, product.steps.shortlist);
        assert_eq!(
            options.steps.screen_proposals,
            product.steps.screen_proposals
        );
        assert!(options.steps.without_misreadings.is_empty());
        assert_eq!(options.candidates, product.candidates);
        assert_eq!(options.beams, product.beams);
        assert_eq!(options.goal_feedback_rounds, product.goal_feedback_rounds);
        assert_eq!(options.templates, product.templates);
    }
}
