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
use crate::goal::Formula;
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
    let mut followed = Followed::default();
    let ending = loop {
        let Some(event) = events.recv().await else {
            return Err(SessionError::Stopped);
        };
        emit(&event);
        if let Some(ending) = followed.take(event, &engine, (&mut *approve, &mut *choose), emit)? {
            break ending;
        }
    };
    let saved = match (&ending, &options.policy_dir, &followed.goal) {
        (Ending::Success { .. }, Some(dir), Some(goal)) => {
            let to = PolicyStore::new(dir).path_for(&path, goal);
            Some(save_policy(&engine, &mut events, to, emit).await?)
        }
        _ => None,
    };
    engine.send(Command::Shutdown);
    let Followed {
        goal: Some(goal),
        tree: Some(tree),
        rounds,
        repairs,
        kept,
        ..
    } = followed
    else {
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

/// What the loop has followed of the engine's events so far.
#[derive(Default)]
struct Followed {
    goal: Option<Formula>,
    tree: Option<Arc<Tree>>,
    rounds: usize,
    repairs: usize,
    /// The approved proposal the engine is applying, until it reports the repair.
    offered: Option<(Proposal, String)>,
    kept: Vec<(Proposal, String)>,
}

impl Followed {
    /// Take in one event and answer the engine where it waits (a reading to choose, a
    /// proposal to approve, a changed tree to run); how the loop ended, once it has.
    fn take(
        &mut self,
        event: Event,
        engine: &EngineHandle,
        (approve, choose): (Approver<'_>, ReadingChooser<'_>),
        emit: &mut dyn FnMut(&Event),
    ) -> Result<Option<Ending>, SessionError> {
        match event {
            Event::Goal { goal, .. } => self.goal = Some(goal),
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
            Event::Asking { .. } if self.goal.is_some() => self.rounds += 1,
            Event::TreeChanged { tree, .. } => {
                self.tree = Some(tree);
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
                    return Ok(Some(Ending::Rejected));
                }
                self.offered = Some((proposal, author));
                engine.send(Command::Approve);
            }
            Event::Repaired { .. } => {
                self.repairs += 1;
                self.kept.extend(self.offered.take());
            }
            Event::Rejected => return Ok(Some(Ending::Rejected)),
            // Never approved past a failed check, not even under --yes: the change is
            // rejected, undone, and the model is asked again knowing why.
            Event::ChangeViolates { .. } => {
                self.repairs = self.repairs.saturating_sub(1);
                self.kept.pop();
                engine.send(Command::Reject);
            }
            Event::Success { ticks, .. } => return Ok(Some(Ending::Success { ticks })),
            Event::GaveUp { reason } => return Ok(Some(Ending::GaveUp { reason })),
            Event::Failed { error } => {
                engine.send(Command::Shutdown);
                return Err(error);
            }
            Event::Error { message } => return Ok(Some(Ending::GaveUp { reason: message })),
            _ => {}
        }
        Ok(None)
    }
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
