//! The session engine: one state machine that owns a task from instruction to saved
//! policy, headless. Front ends send [`Command`]s and render the [`Event`]s it emits; the
//! TUI, `betr resolve` and the tests drive the same code.
//!
//! The engine owns the scenario, the goal, the tree, a planning world (the planner ticks
//! the tree in forks of it), an execution world with its `Ticker` (what "tick" and "run"
//! advance), the language model, the pending proposal, the undo stack (the tree before
//! each applied change) and the policy store.
//!
//! Model calls run as tokio tasks whose results come back as internal messages: the engine
//! keeps answering commands (ticks included) while a call is under way, and a call whose
//! answer is no longer wanted (the tree was re-planned, undone or reset) is aborted and
//! its late answer ignored. Nothing a model proposes changes the tree until it is
//! approved (by a person, or by `auto_approve`).

mod changes;
mod checks;
mod debug;
mod flow;
mod learning;
mod policies;
mod requests;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};

use crate::bt::{Forced, NodeId, TickRecord, Ticker, Tree};
use crate::domain::Condition;
use crate::goal::Formula;
use crate::llm::LanguageModel;
use crate::llm::usage::{Ledger, UsageTotals};
use crate::scenario::Scenario;
use crate::world::{self, World};

use super::ask::Tried;
use super::policy::{Approval, PolicyStore};
use super::types::{Event, NoModel, Options, Proposal, SessionError};

use requests::Internal;

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
    /// Plan the current goal (the scenario's when none was submitted).
    Plan,
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
    /// Conditions (`A & ~B`) or a value (`5 N`) a person wrote for the pending proposal or
    /// the current failure, read by [`super::parse_edit`]; checked against what is pending,
    /// then applied.
    Edit(super::Edit),
    /// A value for every action using a skill with an object (`force of egg = 5 N`, read by
    /// [`super::values::parse_setting`]).
    SetValue(super::values::Setting),
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

/// An action that failed in the execution world.
use super::screen::FailureAt as Failure;

/// The goal being worked on, and the instruction it came from.
#[derive(Debug, Clone)]
struct Task {
    goal: Formula,
    instruction: Option<String>,
}

/// A proposal waiting for approval, with who made it.
#[derive(Debug, Clone)]
struct Pending {
    proposal: Proposal,
    /// Who answered (`model gpt-4o`, a fixture's label, or `a person`).
    author: String,
    failure: Option<Failure>,
}

/// A change that is in the tree, for the policy header.
#[derive(Debug, Clone)]
struct AppliedFix {
    change: String,
    /// The nodes it added (ids are stable; a later change may remove some).
    nodes: Vec<NodeId>,
    author: String,
    approval: Approval,
    at: String,
}

/// The tree before an applied change.
#[derive(Debug, Clone)]
struct UndoEntry {
    tree: Tree,
    fixes: usize,
    /// The change this entry undoes, when it was a proposal: undone, it is a candidate
    /// for its failure again, whatever was said of it before.
    proposal: Option<Proposal>,
}

/// A model call under way.
struct Request {
    id: u64,
    handle: tokio::task::JoinHandle<()>,
}

pub struct Engine {
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
    knowledge: Option<super::knowledge::Knowledge>,
    /// Fixes of the last applied change that may still be kept as rules.
    offers: Vec<learning::RuleOffer>,

    planning: Box<dyn World>,
    exec: Box<dyn World>,
    ticker: Ticker,
    /// Forced statuses and breakpoints.
    debug: debug::Debugger,
    /// Ticks since the last Run command (for the limit).
    run_ticks: u64,
    facts: Vec<Condition>,
    /// The last arm motion told (`Event::ArmMotion`).
    motion: Option<crate::world::cell::snapshot::MotionView>,
    task: Option<Task>,
    tree: Option<Tree>,
    last: Option<Arc<TickRecord>>,
    failure: Option<Failure>,
    pending: Option<Pending>,
    /// Changes tried for a failure that did not fix it, told to the model when it is asked
    /// about the same failure again.
    tried: Vec<(Failure, Tried)>,
    request: Option<Request>,
    next_id: u64,
    undo: Vec<UndoEntry>,
    fixes: Vec<AppliedFix>,
    rounds: usize,
    running: bool,
    usage: UsageTotals,
    verifications: usize,
    /// The check of the last applied change, while it is under way or failed.
    gate: Option<checks::Gate>,
    /// The last proposal applied and the failure it was for, so a change that fails
    /// verification and is rejected is told to the model as tried.
    last_change: Option<(Option<Failure>, Proposal)>,
    /// What the last failed check found, in one line.
    violation: Option<String>,
    /// The file the tree was loaded from, until the next plan.
    loaded_from: Option<PathBuf>,
    /// Whether the tree was planned in the planner's model (by `Verify` before the first
    /// tick) rather than in simulation.
    planned_in_model: bool,
    /// The readings of an instruction offered for the person to choose among, with it.
    choosing: Option<(String, Vec<super::readings::Reading>)>,

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
        let planning = world::load_variant(&setup.scenario, setup.variant.as_deref())?;
        let execution = world::load_execution(&setup.scenario, setup.variant.as_deref())?;
        let exec = execution.world;
        let facts = exec.facts();
        let (events, events_rx) = unbounded_channel();
        let (internal_tx, internal_rx) = unbounded_channel();
        let engine = Engine {
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
            knowledge: setup.knowledge,
            offers: Vec::new(),
            planning,
            exec,
            ticker: Ticker::new(),
            debug: debug::Debugger::default(),
            run_ticks: 0,
            motion: None,
            facts,
            task: None,
            tree: None,
            last: None,
            failure: None,
            pending: None,
            tried: Vec::new(),
            request: None,
            next_id: 0,
            undo: Vec::new(),
            fixes: Vec::new(),
            rounds: 0,
            running: false,
            usage: UsageTotals::default(),
            verifications: 0,
            gate: None,
            loaded_from: None,
            last_change: None,
            violation: None,
            planned_in_model: false,
            choosing: None,
            events,
            internal_tx,
            internal_rx,
        };
        if let Some(why) = execution.notice {
            engine.notice(why);
        }
        engine.emit(Event::WorldChanged {
            facts: engine.facts.clone(),
            reset: true,
        });
        engine.emit_scene();
        Ok((engine, events_rx))
    }

    /// Start the engine as a tokio task; commands go through the handle.
    pub fn spawn(setup: Setup) -> Result<(EngineHandle, UnboundedReceiver<Event>), SessionError> {
        let (engine, events) = Engine::new(setup)?;
        let (tx, rx) = unbounded_channel();
        tokio::spawn(engine.run(rx));
        Ok((EngineHandle { commands: tx }, events))
    }

    /// The engine's loop: commands, answers of model calls, and ticks while running.
    pub async fn run(mut self, mut commands: UnboundedReceiver<Command>) {
        loop {
            let running = self.running;
            let interval = self.tick_interval;
            tokio::select! {
                biased;
                command = commands.recv() => match command {
                    None | Some(Command::Shutdown) => break,
                    Some(c) => self.handle(c),
                },
                Some(message) = self.internal_rx.recv() => self.on_internal(message),
                () = pace(interval), if running => self.run_step(),
            }
        }
        if let Some(r) = self.request.take() {
            r.handle.abort();
        }
    }

    /// Carry out one command (model calls it starts run on the current tokio runtime).
    pub fn handle(&mut self, command: Command) {
        match command {
            Command::Submit(text) => self.submit(&text),
            Command::SubmitGoal { goal, instruction } => self.submit_goal(goal, instruction),
            Command::Plan => self.plan(),
            Command::Run if matches!(self.gate, Some(checks::Gate::Checking { .. })) => {
                if let Some(checks::Gate::Checking { run_after, .. }) = &mut self.gate {
                    *run_after = true;
                }
                self.notice("the changed tree is being verified; it runs when the check passes");
            }
            Command::Tick | Command::Run if self.awaiting().is_some() => {
                let what = self.awaiting().unwrap_or_default();
                let message = if self.gate.is_some() {
                    format!("not ticked: the changed tree waits for {what}")
                } else {
                    format!(
                        "not ticked: the failure waits for {what}; the failed tree would only fail again"
                    )
                };
                self.emit(Event::Notice { message });
            }
            Command::Tick => {
                if self.running {
                    self.set_running(false);
                }
                self.tick();
            }
            Command::Run => self.start_running(),
            Command::Pause => self.set_running(false),
            Command::Force { node, status } => self.force(node, status),
            Command::CycleForce(node) => self.cycle_force(node),
            Command::ToggleBreakpoint(node) => self.toggle_breakpoint(node),
            Command::BreakOnFailure(on) => self.break_on_failure(on),
            Command::Approve => self.approve(),
            Command::Reject => self.reject(),
            Command::Edit(edit) => self.edit(edit),
            Command::SetValue(setting) => self.set_value(&setting),
            Command::Undo => self.undo(),
            Command::Verify => self.verify(super::types::VerifyRequest::default()),
            Command::VerifyWith(request) => self.verify(request),
            Command::SavePolicy => self.save_policy_to(None),
            Command::Export => self.export(),
            Command::LoadPolicy(path) => self.load_policy(path, true),
            Command::LoadTree { path, grow } => self.load_policy(Some(path), grow),
            Command::Insert {
                conditions,
                before,
                author,
            } => self.insert(&conditions, before.as_ref(), author),
            Command::SavePolicyTo(path) => self.save_policy_to(Some(path)),
            Command::ResetWorld => self.reset_world(true),
            Command::RobotArrived => self.robot_arrived(),
            Command::KeepRule { only } => self.keep_rule(only),
            Command::DeclineRule => self.decline_rule(),
            Command::ShowKnowledge => self.show_knowledge(),
            Command::ChooseReading(index) => self.choose_reading(index),
            Command::Shutdown => self.set_running(false),
        }
    }

    /// Wait for the next answer of a model call (or verification) and take it in; false
    /// when nothing is under way. For drivers that run the engine in their own task.
    pub async fn next_internal(&mut self) -> bool {
        if self.request.is_none() && self.verifications == 0 {
            return false;
        }
        match self.internal_rx.recv().await {
            Some(m) => {
                self.on_internal(m);
                true
            }
            None => false,
        }
    }

    /// What a failure waits for before the tree can change: a person's approval of the
    /// pending proposal, or the model's proposal. Ticking the failed tree meanwhile would
    /// only fail again.
    fn awaiting(&self) -> Option<&'static str> {
        if let Some(gate) = self.gate {
            return Some(match gate {
                checks::Gate::Checking { .. } => "the verification of the change",
                checks::Gate::Violated => {
                    "approval of the change that fails verification (approve again, reject, or undo)"
                }
            });
        }
        if self.pending.is_some() {
            Some("approval of the proposal")
        } else if self.request.is_some() && self.failure.is_some() {
            Some("the model's proposal")
        } else {
            None
        }
    }

    /// Whether the engine is ticking on its own.
    pub fn is_running(&self) -> bool {
        self.running
    }

    /// Whether a model call is under way.
    pub fn is_asking(&self) -> bool {
        self.request.is_some()
    }

    /// The current tree.
    pub fn tree(&self) -> Option<&Tree> {
        self.tree.as_ref()
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

    fn set_running(&mut self, running: bool) {
        if self.running != running {
            self.running = running;
            self.emit(Event::RunState { running });
        }
    }
}

async fn pace(interval: Duration) {
    if interval.is_zero() {
        tokio::task::yield_now().await;
    } else {
        tokio::time::sleep(interval).await;
    }
}
