//! The session engine: one state machine that owns a task from instruction to saved
//! policy, headless. Front ends send [`Command`]s and render the [`Event`]s it emits; the
//! TUI, `betr resolve` and the tests drive the same code.
//!
//! What the engine is doing is one [`phase::Phase`] (idle, reading an instruction,
//! choosing a reading, ready, running, failed, asking about a failure, a proposal waiting,
//! a change being checked, a change that fails its check), holding the data of that phase
//! alone; `handle` says what each command does in each phase. Beside the phase: the task
//! (goal, tree, undo history, fixes), the run (planning and execution worlds, ticker,
//! debugger, facts), the settings, and the knowledge kept from approved fixes.
//!
//! Model calls run as tokio tasks whose results come back as internal messages: the engine
//! keeps answering commands while a call is under way, and leaving the phase that started
//! a call aborts it, so its late answer finds no phase waiting for it. Reading an
//! instruction (`session::interpret`) and asking about a failure (`session::repair`) run
//! there; the engine only starts them and takes their answers. Nothing a model proposes
//! changes the tree until it is approved (by a person, or by `auto_approve`).

mod changes;
mod checks;
mod debug;
mod flow;
mod learning;
mod phase;
mod policies;
mod requests;
mod run;
mod task;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};

use crate::bt::{Forced, NodeId, Tree};
use crate::domain::Condition;
use crate::llm::LanguageModel;
use crate::llm::usage::{Ledger, UsageTotals};
use crate::scenario::Scenario;
use crate::world;

use super::policy::{Approval, PolicyStore};
use super::types::{Event, NoModel, Options, PhaseKind, SessionError};

use phase::Phase;
use requests::Internal;
use run::Run;
use task::Task;

/// What the engine is given.
pub struct Setup {
    pub scenario: Arc<Scenario>,
    /// The scenario's file (policies are keyed by its stem).
    pub scenario_path: PathBuf,
    /// The scenario's `[world.variants.NAME]` to run in.
    pub variant: Option<String>,
    /// The model, or why there is none (the session still plans, ticks and takes
    /// conditions a person types).
    pub model: Result<Arc<dyn LanguageModel>, NoModel>,
    /// The ledger the model is metered into, for usage totals (none: counted here).
    pub ledger: Option<Ledger>,
    pub options: Options,
    /// Apply every proposal without asking (shown by front ends).
    pub auto_approve: bool,
    /// Where policies are saved and looked up (none: not saved, not loaded).
    pub policies: Option<PolicyStore>,
    /// Time between ticks when running (zero: as fast as possible).
    pub tick_interval: Duration,
    /// Running stops after `limits.run_ticks` ticks of one run.
    pub limits: crate::planner::RunLimits,
    /// Emit `Event::Scene` after every tick and reset of a cell world (for a 3D view).
    pub scenes: bool,
    /// The learned knowledge: approved fixes of conditions are offered as rules and kept
    /// here (none: nothing is offered).
    pub knowledge: Option<super::knowledge::Knowledge>,
    /// What performs the actions instead of the execution world, which then becomes its
    /// twin (none: the execution world performs them).
    pub executor: Option<Box<dyn crate::executor::Executor>>,
}

impl Setup {
    /// A setup with default options, no policy store and no pause between ticks.
    pub fn new(
        scenario: Arc<Scenario>,
        scenario_path: impl Into<PathBuf>,
        model: Result<Arc<dyn LanguageModel>, NoModel>,
    ) -> Setup {
        Setup {
            scenario,
            scenario_path: scenario_path.into(),
            variant: None,
            model,
            ledger: None,
            options: Options::default(),
            auto_approve: false,
            policies: None,
            tick_interval: Duration::ZERO,
            limits: crate::planner::RunLimits::DEFAULT,
            scenes: false,
            knowledge: None,
            executor: None,
        }
    }
}

/// What a front end asks of the engine.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// An instruction, or a goal formula over the scenario's vocabulary; then plan.
    Submit(String),
    /// Work on `goal` for `instruction` as if the instruction had been read as it (no
    /// model call); the instruction still reaches the questions about failures.
    SubmitGoal {
        goal: crate::goal::Formula,
        instruction: String,
    },
    /// Plan the current goal afresh (the scenario's when none was submitted): the tree's
    /// changes and every refused fix forgotten.
    Plan,
    /// Plan the current goal afresh, keeping the fixes refused for its failures (by a
    /// person, the simulation or verification): the model is told them again and they are
    /// not offered again.
    PlanKeepingRefused,
    /// One tick of the tree in the execution world.
    Tick,
    /// Tick on their own until success, failure, a pause, a breakpoint or the tick limit.
    Run,
    Pause,
    /// Force `node`'s status in every tick of the execution world (`None` clears it):
    /// the node returns it without checking, stepping or ticking below it. Kept until
    /// cleared or the tree is replaced (`Event::Forced`).
    Force {
        node: NodeId,
        status: Option<Forced>,
    },
    /// Force `node` to the next status of the cycle failure → success → running → none,
    /// from the status the engine holds: a front end that cycled from the status it last
    /// heard of would skip a step when keys come faster than events.
    CycleForce(NodeId),
    /// Set or clear a breakpoint on `node`: running stops before a tick that would enter
    /// it (`Event::Breakpoints`, `Event::BreakpointHit`).
    ToggleBreakpoint(NodeId),
    /// Stop running after a tick in which a node that succeeded or ran fails, or an action
    /// fails.
    BreakOnFailure(bool),
    /// Apply the pending proposal.
    Approve,
    /// Drop the pending proposal.
    Reject,
    /// Stop the model call under way: a question about a failure leaves the failure to
    /// the person (write the fix, or tick to ask again); a reading leaves the tree as it
    /// was.
    Cancel,
    /// Conditions (`A & ~B`) or a value (`5 N`) a person wrote for the pending proposal or
    /// the current failure, read by [`super::parse_edit`]; checked against what is pending,
    /// then applied.
    Edit(super::Edit),
    /// A value for every action using a skill with an object (`force of egg = 5 N`, read by
    /// [`super::repair::values::parse_setting`]).
    SetValue(super::repair::values::Setting),
    /// Restore the tree from before the last applied change.
    Undo,
    Verify,
    /// Verify with more properties, other bounds or a Promela file.
    VerifyWith(super::types::VerifyRequest),
    SavePolicy,
    /// Write the tree beside its policy as BT.CPP XML and Graphviz DOT.
    Export,
    /// Load a policy file (none: the saved policy of the current task).
    LoadPolicy(Option<PathBuf>),
    /// Make a tree file (a policy, betr tree text or BT.CPP XML) the tree; `grow`: expand
    /// what it leaves unachieved in this world, else run it as written.
    LoadTree {
        path: PathBuf,
        grow: bool,
    },
    /// Insert `conditions` as a person wrote them: before the action `before`, or as the
    /// first preconditions of the action that failed; kept whether or not it helps (the
    /// next run shows that).
    Insert {
        conditions: Vec<Condition>,
        before: Option<crate::domain::ActionCall>,
        author: String,
    },
    /// Save the tree as a policy at this path, whatever the policy directory.
    SavePolicyTo(PathBuf),
    /// A fresh execution world and ticker.
    ResetWorld,
    /// The robot description the cell's arms need has arrived in the cache: the
    /// execution world moves the real arms from now on if nothing has run yet, else from
    /// its next reset.
    RobotArrived,
    /// Keep the offered fix as a rule of its skill (`only`: for the fix's objects alone).
    KeepRule {
        only: bool,
    },
    /// Keep nothing of the offered fix.
    DeclineRule,
    /// The kept rules of the scenario's domain (`Event::Knowledge`).
    ShowKnowledge,
    /// Work on reading N (from 0) of those `Event::Readings` offered.
    ChooseReading(usize),
    /// Stop the engine's loop.
    Shutdown,
}

/// What the engine works with and never changes on its own (but the scenario's domain,
/// which learns the rules a person keeps).
struct Settings {
    scenario: Arc<Scenario>,
    scenario_path: PathBuf,
    variant: Option<String>,
    model: Result<Arc<dyn LanguageModel>, NoModel>,
    ledger: Option<Ledger>,
    options: Options,
    auto_approve: bool,
    policies: Option<PolicyStore>,
    tick_interval: Duration,
    max_ticks: u64,
    scenes: bool,
}

/// Model calls and verifications: their ids, how many reports are awaited, and what the
/// replies cost.
#[derive(Default)]
struct Calls {
    next_id: u64,
    /// Verifications a person asked for whose reports are still to come.
    verifications: usize,
    usage: UsageTotals,
}

impl Calls {
    fn next_id(&mut self) -> u64 {
        self.next_id += 1;
        self.next_id
    }
}

pub struct Engine {
    settings: Settings,
    /// What the engine is doing, with the data of that alone.
    phase: Phase,
    /// The phase front ends were last told (`Event::Phase`).
    told_phase: PhaseKind,
    /// The goal, the tree and how it came to be.
    task: Task,
    /// The planning and execution worlds and what ticking them showed.
    run: Run,
    /// The knowledge file and the fixes of the last change that may be kept as rules.
    learning: learning::Learning,
    calls: Calls,
    events: UnboundedSender<Event>,
    internal_tx: UnboundedSender<Internal>,
    internal_rx: UnboundedReceiver<Internal>,
}

/// A front end's end of a running engine.
#[derive(Clone)]
pub struct EngineHandle {
    commands: UnboundedSender<Command>,
}

impl EngineHandle {
    /// Send a command; false when the engine has stopped.
    pub fn send(&self, command: Command) -> bool {
        self.commands.send(command).is_ok()
    }
}

impl Engine {
    /// An engine for `setup`, and the receiver of its events.
    pub fn new(setup: Setup) -> Result<(Engine, UnboundedReceiver<Event>), SessionError> {
        let mut planning = world::load_variant(&setup.scenario, setup.variant.as_deref())?;
        if setup.options.steps.planning_without_hidden_rules
            && let Some(symbolic) = planning
                .as_any()
                .and_then(|a| a.downcast_ref::<crate::world::SymbolicWorld>())
        {
            planning = Box::new(symbolic.clone().without_rules());
        }
        let execution = world::load_execution(&setup.scenario, setup.variant.as_deref())?;
        let reality = match setup.executor {
            Some(executor) => Some(crate::executor::Reality::start(
                executor,
                execution.world.as_ref(),
            )?),
            None => None,
        };
        let (events, events_rx) = unbounded_channel();
        let (internal_tx, internal_rx) = unbounded_channel();
        let engine = Engine {
            settings: Settings {
                scenario: setup.scenario,
                scenario_path: setup.scenario_path,
                variant: setup.variant,
                model: setup.model,
                ledger: setup.ledger,
                options: setup.options,
                auto_approve: setup.auto_approve,
                policies: setup.policies,
                tick_interval: setup.tick_interval,
                max_ticks: setup.limits.run_ticks,
                scenes: setup.scenes,
            },
            phase: Phase::Idle,
            told_phase: PhaseKind::Idle,
            task: Task::default(),
            run: Run::new(planning, execution.world, reality),
            learning: learning::Learning::new(setup.knowledge),
            calls: Calls::default(),
            events,
            internal_tx,
            internal_rx,
        };
        if let Some(why) = execution.notice {
            engine.notice(why);
        }
        if let Some(reality) = &engine.run.reality {
            engine.emit(Event::Executor {
                name: reality.name().to_string(),
            });
        }
        engine.emit(Event::WorldChanged {
            facts: engine.run.facts.clone(),
            reset: true,
        });
        engine.emit_scene();
        Ok((engine, events_rx))
    }

    /// Start the engine as a task of the current tokio runtime; commands go through the
    /// handle.
    pub fn spawn(setup: Setup) -> Result<(EngineHandle, UnboundedReceiver<Event>), SessionError> {
        Engine::spawn_on(setup, &tokio::runtime::Handle::current())
    }

    /// Start the engine as a task of `runtime`: the model calls it starts run there too.
    pub fn spawn_on(
        setup: Setup,
        runtime: &tokio::runtime::Handle,
    ) -> Result<(EngineHandle, UnboundedReceiver<Event>), SessionError> {
        let (engine, events) = Engine::new(setup)?;
        let (tx, rx) = unbounded_channel();
        runtime.spawn(engine.run(rx));
        Ok((EngineHandle { commands: tx }, events))
    }

    /// The engine's loop: commands, answers of model calls, and ticks while running.
    pub async fn run(mut self, mut commands: UnboundedReceiver<Command>) {
        loop {
            let running = self.is_running();
            let interval = self.settings.tick_interval;
            tokio::select! {
                biased;
                command = commands.recv() => match command {
                    None | Some(Command::Shutdown) => break,
                    Some(c) => self.handle(c),
                },
                Some(message) = self.internal_rx.recv() => {
                    self.on_internal(message);
                    self.tell_state();
                }
                () = pace(interval), if running => {
                    self.run_step();
                    self.tell_state();
                }
            }
        }
        self.phase.abort_call();
    }

    /// Carry out one command (model calls it starts run on the current tokio runtime).
    pub fn handle(&mut self, command: Command) {
        self.carry_out(command);
        self.tell_state();
    }

    /// What a command does depends on the phase; commands that mean the same in every
    /// phase come last.
    fn carry_out(&mut self, command: Command) {
        match (&mut self.phase, command) {
            (Phase::Idle, Command::Tick) => {
                self.error("nothing to tick: submit an instruction or plan first");
            }
            (Phase::Idle, Command::Run) => {
                self.error("nothing to run: submit an instruction or plan first");
            }
            (Phase::Checking { run_after, .. }, Command::Run) => {
                *run_after = true;
                self.notice("the changed tree is being verified; it runs when the check passes");
            }
            (
                phase @ (Phase::Checking { .. }
                | Phase::Violated { .. }
                | Phase::Asking { .. }
                | Phase::Proposed(_)),
                Command::Tick | Command::Run,
            ) => {
                if let Some(message) = phase.why_not_ticked() {
                    self.notice(message);
                }
            }
            (Phase::Reading { .. } | Phase::Choosing { .. }, Command::Run) => self.notice(
                "not run: the tree is replaced when the instruction is read; step it with a tick meanwhile",
            ),
            (Phase::Running, Command::Tick) => {
                self.stop_running();
                self.tick();
            }
            (_, Command::Tick) => self.tick(),
            (_, Command::Run) => self.start_running(),
            (Phase::Running, Command::Pause) => self.stop_running(),
            (_, Command::Pause) => {}
            (Phase::Proposed(_), Command::Approve) => self.apply_pending(Approval::Person),
            (Phase::Violated { .. }, Command::Approve) => self.approve_violation(),
            (_, Command::Approve) => self.error("no proposal to approve"),
            (Phase::Proposed(_), Command::Reject) => self.reject(),
            (Phase::Violated { .. }, Command::Reject) => self.reject_violation(),
            (_, Command::Reject) => self.error("no proposal to reject"),
            (Phase::Asking { failure, .. }, Command::Cancel) => {
                let failure = failure.clone();
                self.enter(Phase::Failed {
                    failure: failure.clone(),
                });
                self.emit(Event::CallCancelled);
                self.wait_for_person(
                    failure,
                    "the question was cancelled (the log says what fixes the failure in simulation)"
                        .into(),
                );
            }
            (Phase::Reading { .. }, Command::Cancel) => {
                let settled = self.settled();
                self.enter(settled);
                self.emit(Event::CallCancelled);
                self.notice("the reading was cancelled: the tree is as it was");
            }
            (_, Command::Cancel) => self.error("nothing to cancel: no model call is under way"),
            (Phase::Proposed(_) | Phase::Failed { .. } | Phase::Asking { .. }, Command::Edit(e)) => {
                self.edit(e);
            }
            (_, Command::Edit(_)) => {
                self.error("nothing to edit: no action has failed and nothing is proposed");
            }
            (Phase::Choosing { .. }, Command::ChooseReading(index)) => self.choose_reading(index),
            (_, Command::ChooseReading(_)) => {
                self.error("no readings to choose among: type an instruction first (i)");
            }
            (_, Command::Submit(text)) => self.submit(&text),
            (_, Command::SubmitGoal { goal, instruction }) => self.submit_goal(goal, instruction),
            (_, Command::Plan) => self.plan(),
            (_, Command::PlanKeepingRefused) => self.plan_keeping_refused(),
            (_, Command::Force { node, status }) => self.force(node, status),
            (_, Command::CycleForce(node)) => self.cycle_force(node),
            (_, Command::ToggleBreakpoint(node)) => self.toggle_breakpoint(node),
            (_, Command::BreakOnFailure(on)) => self.break_on_failure(on),
            (_, Command::SetValue(setting)) => self.set_value(&setting),
            (_, Command::Undo) => self.undo(),
            (_, Command::Verify) => self.verify(super::types::VerifyRequest::default()),
            (_, Command::VerifyWith(request)) => self.verify(request),
            (_, Command::SavePolicy) => self.save_policy_to(None),
            (_, Command::SavePolicyTo(path)) => self.save_policy_to(Some(path)),
            (_, Command::Export) => self.export(),
            (_, Command::LoadPolicy(path)) => self.load_policy(path, true),
            (_, Command::LoadTree { path, grow }) => self.load_policy(Some(path), grow),
            (_, Command::Insert { conditions, before, author }) => {
                self.insert(&conditions, before.as_ref(), author);
            }
            (_, Command::ResetWorld) => self.reset_world(true),
            (_, Command::RobotArrived) => self.robot_arrived(),
            (_, Command::KeepRule { only }) => self.keep_rule(only),
            (_, Command::DeclineRule) => self.decline_rule(),
            (_, Command::ShowKnowledge) => self.show_knowledge(),
            (_, Command::Shutdown) => self.stop_running(),
        }
    }

    /// Wait for the next answer of a model call (or verification) and take it in; false
    /// when nothing is under way. For drivers that run the engine in their own task.
    pub async fn next_internal(&mut self) -> bool {
        if !self.phase.has_call() && self.calls.verifications == 0 {
            return false;
        }
        match self.internal_rx.recv().await {
            Some(m) => {
                self.on_internal(m);
                self.tell_state();
                true
            }
            None => false,
        }
    }

    /// Whether the engine is ticking on its own.
    pub fn is_running(&self) -> bool {
        matches!(self.phase, Phase::Running)
    }

    /// Whether a model call is under way.
    pub fn is_asking(&self) -> bool {
        self.phase.has_call()
    }

    /// The current tree.
    pub fn tree(&self) -> Option<&Tree> {
        self.task.tree.as_ref()
    }

    fn emit(&self, event: Event) {
        // A front end that stopped listening is not an error of the session.
        let _ = self.events.send(event);
    }

    fn error(&self, message: impl Into<String>) {
        self.emit(Event::Error {
            message: message.into(),
        });
    }

    fn notice(&self, message: impl Into<String>) {
        self.emit(Event::Notice {
            message: message.into(),
        });
    }
}

async fn pace(interval: Duration) {
    if interval.is_zero() {
        tokio::task::yield_now().await;
    } else {
        tokio::time::sleep(interval).await;
    }
}
