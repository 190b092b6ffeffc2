//! The resolve loop, headless, as a client of the session [`Engine`]: submit the
//! instruction (the model reads it as a goal), let the engine plan, run the tree in the
//! execution world; when an action fails the engine asks the model for the missing
//! preconditions (or parameter value), this loop asks `approve` and sends Approve (or
//! stops at a "no"), and runs again after each change, until the tree succeeds, the
//! rounds run out, or a proposal is rejected.
//!
//! Every event of the engine goes to `emit`; the loop never prints. A proposal that does
//! not change the failure is reported and undone by the engine, so the tree only ever
//! keeps changes that helped.

use std::sync::Arc;

use crate::bt::Tree;
use crate::llm::LanguageModel;
use crate::scenario::Scenario;

use tokio::sync::mpsc::UnboundedReceiver;

use super::engine::{Command, Engine, EngineHandle, Setup};
use super::policy::PolicyStore;
use super::types::{Ending, Event, Options, Proposal, Reading, Resolved, SessionError};

/// The whole loop for `scenario`: `instruction` (else the scenario's) → goal → tree → success.
pub async fn resolve(
    scenario: &Scenario,
    instruction: Option<&str>,
    model: Arc<dyn LanguageModel>,
    options: &Options,
    approve: &mut dyn FnMut(&Proposal) -> bool,
    emit: &mut dyn FnMut(&Event),
) -> Result<Resolved, SessionError> {
    // Only offered with `options.choose_reading`: the best reading, as without it.
    let mut best = |_: &[Reading], _: Option<&str>| Some(0);
    resolve_with_scenes(
        scenario,
        instruction,
        model,
        options,
        Execution::default(),
        (approve, &mut best),
        emit,
    )
    .await
}

/// Says whether a proposal is approved.
pub type Approver<'a> = &'a mut dyn FnMut(&Proposal) -> bool;
/// Picks the reading to work on among those offered, or none to stop.
/// Picks the reading to work on among those offered (with the doubt the checks raised
/// about a single one), or none to stop.
pub type ReadingChooser<'a> = &'a mut dyn FnMut(&[Reading], Option<&str>) -> Option<usize>;

/// Where a resolve loop's trees run: betr's own execution world, or an executor's with the
/// execution world as its twin; and whether the cell's scene is emitted after every tick.
#[derive(Default)]
pub struct Execution {
    pub scenes: bool,
    pub executor: Option<Box<dyn crate::executor::Executor>>,
}

/// [`resolve`] in `execution`: with `scenes` the engine also emits the cell's scene after every tick
/// (`Event::Scene`, for a 3D view). `choose` picks among the readings of the instruction
/// (with `options.choose_reading`): the index of one, or none to stop.
pub async fn resolve_with_scenes(
    scenario: &Scenario,
    instruction: Option<&str>,
    model: Arc<dyn LanguageModel>,
    options: &Options,
    execution: Execution,
    (approve, choose): (Approver<'_>, ReadingChooser<'_>),
    emit: &mut dyn FnMut(&Event),
) -> Result<Resolved, SessionError> {
    let (engine, mut events, path) = start(scenario, instruction, model, options, execution)?;

    let mut goal = None;
    let mut tree: Option<Arc<Tree>> = None;
    let mut rounds = 0;
    let mut repairs: usize = 0;
    let mut offered: Option<(Proposal, String)> = None;
    let mut kept: Vec<(Proposal, String)> = Vec::new();
    let ending = loop {
        let Some(event) = events.recv().await else {
            return Err(SessionError::Stopped);
        };
        emit(&event);
        match event {
            Event::Goal { goal: g, .. } => goal = Some(g),
            Event::Readings {
                readings, doubt, ..
            } => match choose(&readings, doubt.as_deref()) {
                Some(index) if index < readings.len() => {
                    engine.send(Command::ChooseReading(index));
                }
                _ => {
                    engine.send(Command::Shutdown);
                    return Err(SessionError::ReadingNotChosen {
                        count: readings.len(),
                        doubt,
                    });
                }
            },
            Event::Asking { .. } if goal.is_some() => rounds += 1,
            Event::TreeChanged { tree: t, .. } => {
                tree = Some(t);
                engine.send(Command::Run);
            }
            Event::DidNotHelp { .. } => {
                engine.send(Command::Run);
            }
            Event::Proposal {
                proposal, author, ..
            } => {
                if !approve(&proposal) {
                    // The loop ends at a "no" here, before the engine would put the
                    // question to the model again (as the workbench does after a
                    // rejection): no call is sent that nobody will read.
                    emit(&Event::Rejected);
                    break Ending::Rejected;
                }
                offered = Some((proposal.clone(), author.clone()));
                engine.send(Command::Approve);
            }
            Event::Repaired { .. } => {
                repairs += 1;
                kept.extend(offered.take());
            }
            Event::Rejected => break Ending::Rejected,
            // Never approved past a failed check, not even under --yes: the change is
            // rejected, undone, and the model is asked again knowing why.
            Event::ChangeViolates { .. } => {
                repairs = repairs.saturating_sub(1);
                kept.pop();
                engine.send(Command::Reject);
            }
            Event::Success { ticks, .. } => break Ending::Success { ticks },
            Event::GaveUp { reason } => break Ending::GaveUp { reason },
            Event::Failed { error } => {
                engine.send(Command::Shutdown);
                return Err(error);
            }
            Event::Error { message } => break Ending::GaveUp { reason: message },
            _ => {}
        }
    };
    let saved = match (&ending, &options.policy_dir, &goal) {
        (Ending::Success { .. }, Some(dir), Some(goal)) => {
            let to = PolicyStore::new(dir).path_for(&path, goal);
            Some(save_policy(&engine, &mut events, to, emit).await?)
        }
        _ => None,
    };
    engine.send(Command::Shutdown);
    let (Some(goal), Some(tree)) = (goal, tree) else {
        return Err(SessionError::Stopped);
    };
    Ok(Resolved {
        goal,
        tree: Arc::unwrap_or_clone(tree),
        ending,
        rounds,
        repairs,
        kept,
        saved,
    })
}

/// An engine for `scenario` in `execution`, given the instruction (or, with
/// `use_scenario_goal`, the scenario's stated goal) to work on; and the scenario's file.
fn start(
    scenario: &Scenario,
    instruction: Option<&str>,
    model: Arc<dyn LanguageModel>,
    options: &Options,
    execution: Execution,
) -> Result<(EngineHandle, UnboundedReceiver<Event>, std::path::PathBuf), SessionError> {
    let instruction = instruction
        .map(str::to_string)
        .or_else(|| scenario.instruction.clone())
        .ok_or_else(|| SessionError::NoInstruction(scenario.name.clone()))?;
    let path = scenario
        .files
        .last()
        .map(|f| f.path.clone())
        .unwrap_or_default();
    let mut setup = Setup::new(Arc::new(scenario.clone()), path.clone(), Ok(model));
    setup.options = options.clone();
    setup.scenes = execution.scenes;
    setup.executor = execution.executor;
    let (engine, events) = Engine::spawn(setup)?;
    match (&scenario.goal, options.use_scenario_goal) {
        (Some(goal), true) => {
            engine.send(Command::SubmitGoal {
                goal: goal.clone(),
                instruction,
            });
        }
        (None, true) => {
            engine.send(Command::Shutdown);
            return Err(SessionError::NoStatedGoal(scenario.name.clone()));
        }
        (_, false) => {
            engine.send(Command::Submit(instruction));
        }
    }
    Ok((engine, events, path))
}

/// Have the engine save the policy to `to`; where it saved it. The engine is shut down
/// when it cannot.
async fn save_policy(
    engine: &EngineHandle,
    events: &mut UnboundedReceiver<Event>,
    to: std::path::PathBuf,
    emit: &mut dyn FnMut(&Event),
) -> Result<std::path::PathBuf, SessionError> {
    engine.send(Command::SavePolicyTo(to));
    saved_policy(events, emit).await.inspect_err(|_| {
        engine.send(Command::Shutdown);
    })
}

/// The file the engine saved the policy to, once it says so.
async fn saved_policy(
    events: &mut tokio::sync::mpsc::UnboundedReceiver<Event>,
    emit: &mut dyn FnMut(&Event),
) -> Result<std::path::PathBuf, SessionError> {
    loop {
        let event = events.recv().await.ok_or(SessionError::Stopped)?;
        emit(&event);
        match event {
            Event::PolicySaved { path, .. } => return Ok(path),
            Event::Failed { error } => return Err(error),
            _ => {}
        }
    }
}
