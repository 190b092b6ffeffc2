//! The only contact between the experiments and the session: one headless resolve with
//! every proposal approved, returning the events it emitted and how it ended.

use crate::scenario::Scenario;
use std::sync::Arc;

use crate::llm::LanguageModel;
use crate::session::{self, Ending, Event, Options, SessionError};

/// What one resolve did.
pub struct Trace {
    pub events: Vec<Event>,
    /// `Ok(ticks)`: the final tree succeeded in simulation; `Err`: why the loop stopped
    /// without success.
    pub ending: Result<u64, Unresolved>,
    pub rounds: usize,
    /// The approved proposals kept in the final tree, with who wrote each.
    pub kept: Vec<(session::Proposal, String)>,
}

/// Why a resolve ended without success.
#[derive(Debug, Clone, thiserror::Error)]
pub enum Unresolved {
    /// The loop gave up; its reason as the session gave it.
    #[error("{reason}")]
    GaveUp { reason: String },
    #[error("a proposal was rejected")]
    Rejected,
    /// The reply yielded no usable goal.
    #[error(transparent)]
    NoGoal(SessionError),
}

/// Resolve `scenario`'s instruction end to end, approving every proposal. A reply that
/// yields no usable goal ends the run as a failure; other errors (the model could not be
/// reached, a scenario that does not load) are returned.
pub async fn resolve_approving(
    scenario: &Scenario,
    model: Arc<dyn LanguageModel>,
    options: &Options,
    executor: Option<Box<dyn crate::executor::Executor>>,
) -> Result<Trace, SessionError> {
    let mut events = Vec::new();
    let mut approve = |_: &session::Proposal| true;
    let mut best = |_: &[session::Reading], _: Option<&str>| Some(0);
    let mut emit = |e: &Event| events.push(e.clone());
    let execution = session::Execution {
        scenes: false,
        executor,
    };
    let result = session::resolve_with_scenes(
        scenario,
        None,
        model,
        options,
        execution,
        (&mut approve, &mut best),
        &mut emit,
    )
    .await;
    let (ending, rounds, kept) = match result {
        Ok(r) => (
            match r.ending {
                Ending::Success { ticks } => Ok(ticks),
                Ending::GaveUp { reason } => Err(Unresolved::GaveUp { reason }),
                Ending::Rejected => Err(Unresolved::Rejected),
            },
            r.rounds,
            r.kept,
        ),
        Err(e @ SessionError::NoGoal { .. }) => (Err(Unresolved::NoGoal(e)), 0, Vec::new()),
        Err(e) => return Err(e),
    };
    Ok(Trace {
        events,
        ending,
        rounds,
        kept,
    })
}
