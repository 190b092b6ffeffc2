//! The question about a failed action, whole: what the model is told (the scene, the
//! instruction, what was tried), which question it is (a missing value or missing
//! conditions), the candidates screened in a copy of the tree and the planning world, and
//! the evidence of the proposal chosen. The engine builds a [`Question`] from its state,
//! runs [`Question::answer`] off its thread and takes the [`Answer`].

use crate::bt::Tree;
use crate::domain::Condition;
use crate::llm::LanguageModel;
use crate::llm::prompt::Context;
use crate::scenario::Scenario;
use crate::world::World;

use super::super::types::{Event, Evidence, Options, SessionError};
use super::ask::{Asked, FailedAction, Tried, ask_conditions, ask_value, missing_value};
use super::evidence::Found;
use super::screen::{FailureAt, Screen};

/// Everything the question about one failure needs, owned, so it can be asked off the
/// engine's thread.
pub(crate) struct Question {
    pub scenario: std::sync::Arc<Scenario>,
    pub failure: FailureAt,
    /// The execution world's facts when the action failed.
    pub facts: Vec<Condition>,
    /// The instruction, else the goal in words.
    pub instruction: String,
    /// Changes tried for this failure before that did not fix it.
    pub tried: Vec<Tried>,
    /// The tree that failed; candidates are tried in a copy of it.
    pub tree: Tree,
    /// A fork of the planning world, for trying candidates.
    pub world: Box<dyn World>,
}

/// What asking produced: the model's answer and, for the proposal chosen, what betr found.
pub(crate) struct Answer {
    pub result: Result<Asked, SessionError>,
    pub evidence: Option<Box<Evidence>>,
}

impl Question {
    /// Ask `model`, emitting what was asked and who answered.
    pub(crate) async fn answer(
        self,
        model: &dyn LanguageModel,
        options: &Options,
        emit: &mut (dyn FnMut(&Event) + Send),
    ) -> Answer {
        let Question {
            scenario,
            failure,
            facts,
            instruction,
            tried,
            tree,
            world,
        } = self;
        let mut screen = Screen {
            scenario: scenario.clone(),
            tree,
            world,
            failure: failure.clone(),
        };
        let ctx = Context {
            scenario: &scenario,
            facts: &facts,
            instruction: &instruction,
            variant: &options.steps.prompt,
        };
        let failed = FailedAction {
            node: failure.node,
            action: &failure.action,
            error: &failure.error,
            tried: &tried,
        };
        let result = match missing_value(&scenario, &failure.action, &failure.error) {
            Some(param) => ask_value(&ctx, model, options, &failed, param, &mut screen, emit).await,
            None => ask_conditions(&ctx, model, options, &failed, &mut screen, emit).await,
        };
        let evidence = result.as_ref().ok().and_then(|asked| {
            let (proposal, reasoning) = asked.chosen.as_ref()?;
            let found = Found {
                failure: &failure,
                facts: &facts,
                shortlist: asked.shortlist.as_ref(),
                tried: &tried,
                proposal,
                verdict: asked.verdict,
            };
            Some(Box::new(Evidence::of(
                &found,
                reasoning.as_deref(),
                &scenario.domain.vocabulary,
            )))
        });
        Answer { result, evidence }
    }
}
