//! The only contact between the experiments and the session: one headless resolve with
//! every proposal approved, returning the events it emitted and how it ended.

use crate::scenario::Scenario;
use std::sync::Arc;

use crate::llm::LanguageModel;
use crate::session::{self, Ending, Event, Options, SessionError};

/// What one resolve did.
pub struct Trace {
    pub events: Vec<Event>,
    /// `Ok(ticks)`: the final tree succeeded in simulation; `Err(reason)`: the loop
    /// stopped without success.
    pub ending: Result<u64, String>,
    pub rounds: usize,
    /// The approved proposals kept in the final tree, with who wrote each.
    pub kept: Vec<(session::Proposal, String)>,
}

/// Resolve `scenario`'s instruction end to end, approving every proposal. A reply that
/// yields no usable goal ends the run as a failure; other errors (the model could not be
/// reached, a scenario that does not load) are returned.
pub async fn resolve_approving(
    scenario: &Scenario,
    model: Arc<dyn LanguageModel>,
    options: &Options,
) -> Result<Trace, SessionError> {
    let mut events = Vec::new();
    let mut approve = |_: &session::Proposal| true;
    let mut emit = |e: &Event| events.push(e.clone());
    let result = session::resolve(scenario, None, model, options, &mut approve, &mut emit).await;
    let (ending, rounds, kept) = match result {
        Ok(r) => (
            match r.ending {
                Ending::Success { ticks } => Ok(ticks),
                Ending::GaveUp { reason } => Err(reason),
                Ending::Rejected => Err("a proposal was rejected".into()),
            },
            r.rounds,
            r.kept,
        ),
        Err(e @ SessionError::NoGoal { .. }) => (Err(e.to_string()), 0, Vec::new()),
        Err(e) => return Err(e),
    };
    Ok(Trace {
        events,
        ending,
        rounds,
        kept,
    })
}
