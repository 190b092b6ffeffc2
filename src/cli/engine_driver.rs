//! The command line's end of a session engine. The one-shot commands (`plan`, `run`,
//! `repair`, `export`) start the same engine the workbench drives, without a language
//! model, send it commands and print what it reports; every event also goes to the 3D
//! view when one is open.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Result, anyhow, bail};
use tokio::sync::mpsc::UnboundedReceiver;

use betr::bt::{NodeId, TickRecord, Tree};
use betr::domain::ActionCall;
use betr::goal::Formula;
use betr::record::SessionRecorder;
use betr::scenario::Scenario;
use betr::session::types::{VerifyRequest, VerifyScope};
use betr::session::{
    BreakReason, Command, Engine, EngineHandle, Event, NoModel, PlanSummary, RunLimits, Setup,
};
use betr::verify::Report;
use betr::viz::Viz;

/// A running engine and its events.
pub struct Driver {
    runtime: tokio::runtime::Runtime,
    handle: EngineHandle,
    events: UnboundedReceiver<Event>,
    viz: Option<Viz>,
    record: Option<SessionRecorder>,
    tree: Option<Arc<Tree>>,
}

/// What the engine did for a change: what the planner did (when it planned) and how many
/// nodes the change added or set a value on.
#[derive(Default)]
pub struct Change {
    pub summary: Option<PlanSummary>,
    pub added_nodes: usize,
    pub valued_nodes: usize,
}

/// What the engine is asked to start from.
pub struct Start<'a> {
    pub scenario: &'a Scenario,
    /// The scenario's file as the person named it (for a saved policy's header; none: the
    /// file it was loaded from).
    pub scenario_path: Option<&'a Path>,
    pub variant: Option<&'a str>,
    pub limits: RunLimits,
    pub viz: Option<Viz>,
    pub record: Option<SessionRecorder>,
    /// Whether the command runs the tree in the execution world, where a cell moves its
    /// robot's real arms: only then is a missing robot description fetched first
    /// (planning never moves the arms).
    pub runs_tree: bool,
    /// What performs the actions instead of the execution world (`--executor`).
    pub executor: Option<Box<dyn betr::executor::Executor>>,
}

impl<'a> Start<'a> {
    /// The scenario's own world, the default limits, no 3D view, a tree that is run.
    pub fn new(scenario: &'a Scenario) -> Start<'a> {
        Start {
            scenario,
            scenario_path: None,
            variant: None,
            limits: RunLimits::DEFAULT,
            viz: None,
            record: None,
            runs_tree: true,
            executor: None,
        }
    }
}

/// How a run of the tree in the execution world ended.
pub enum RunEnd {
    /// The goal was reached: in betr's world, or by `executor` (its name).
    Success { executor: Option<String> },
    ActionFailed {
        action: ActionCall,
        node_path: String,
        error: String,
    },
    /// The engine stopped running: the tree failed with no action failing, or the tick
    /// limit came (the last record still running).
    Stopped { reason: String },
    /// A breakpoint stopped the run: before tick `tick`, which would enter `node`, or
    /// after it, in which `node` failed.
    Break {
        node: NodeId,
        node_path: String,
        tick: u64,
        reason: BreakReason,
    },
}

/// A run: its end, how many ticks it took and every node's status at the last tick.
pub struct Run {
    pub end: RunEnd,
    pub ticks: u64,
    pub last: Option<Arc<TickRecord>>,
}

impl Run {
    /// Whether the last tick left the tree running (the tick limit stopped it).
    pub fn still_running(&self) -> bool {
        self.last
            .as_ref()
            .is_some_and(|r| r.root == betr::bt::Outcome::Running)
    }
}

impl Driver {
    pub fn start(start: Start) -> Result<Driver> {
        // The robot the scenario's cell moves, fetched on first use as the workbench does.
        if start.runs_tree {
            super::model_cmd::ensure_scenario_robot(start.scenario, super::offline())?;
        }
        let path = match start.scenario_path {
            Some(path) => path.to_path_buf(),
            None => start
                .scenario
                .files
                .last()
                .map(|f| f.path.clone())
                .unwrap_or_default(),
        };
        let mut setup = Setup::new(
            Arc::new(start.scenario.clone()),
            path,
            Err(NoModel::NotUsed("this command")),
        );
        setup.variant = start.variant.map(str::to_string);
        setup.limits = start.limits;
        setup.scenes = start.viz.is_some();
        setup.executor = start.executor;
        let runtime = super::runtime()?;
        let (handle, events) = {
            let _entered = runtime.enter();
            Engine::spawn(setup)?
        };
        Ok(Driver {
            runtime,
            handle,
            events,
            viz: start.viz,
            record: start.record,
            tree: None,
        })
    }

    pub fn send(&mut self, command: Command) {
        if let Some(r) = self.record.as_mut() {
            r.command(&command);
        }
        self.handle.send(command);
    }

    /// The next event; an error the engine reports ends the command with it.
    fn next(&mut self) -> Result<Event> {
        let event = self
            .runtime
            .block_on(self.events.recv())
            .ok_or_else(|| anyhow!("the session stopped unexpectedly"))?;
        betr::record::trace(&event);
        if let Some(v) = self.viz.as_mut() {
            v.on_event(&event);
        }
        if let Some(r) = self.record.as_mut() {
            r.event(&event);
            // A recording asked for and not made is a failed command, not a note.
            if let Some(why) = r.stopped() {
                bail!("--record: {why}");
            }
        }
        if let Event::TreeChanged { tree, .. } = &event {
            self.tree = Some(tree.clone());
        }
        match event {
            Event::Error { message } => bail!(message),
            Event::Failed { error } => Err(error.into()),
            event => Ok(event),
        }
    }

    /// Plan `goal` (none: the scenario's); what the planner did.
    pub fn plan(&mut self, goal: Option<Formula>) -> Result<PlanSummary> {
        self.send(match goal {
            Some(goal) => Command::SubmitGoal {
                goal,
                instruction: String::new(),
            },
            None => Command::Plan,
        });
        self.until_changed()?
            .summary
            .ok_or_else(|| anyhow!("the tree changed without a plan"))
    }

    /// Events until the tree changes: what the planner did and what the change added.
    fn until_changed(&mut self) -> Result<Change> {
        let mut change = Change::default();
        loop {
            match self.next()? {
                Event::Planned { summary } => change.summary = Some(summary),
                Event::Repaired {
                    added_nodes,
                    valued_nodes,
                } => {
                    change.added_nodes = added_nodes;
                    change.valued_nodes = valued_nodes;
                }
                Event::TreeChanged { .. } => return Ok(change),
                _ => {}
            }
        }
    }

    /// Make a tree file the tree (`grow`: expanded in this world); its notes go to
    /// stderr, and what the planner did when it grew the tree is returned.
    pub fn load(&mut self, path: PathBuf, grow: bool) -> Result<Option<PlanSummary>> {
        self.send(Command::LoadTree { path, grow });
        let mut summary = None;
        let mut loaded = false;
        loop {
            match self.next()? {
                // Before the tree is loaded, notices are the file's notes.
                Event::Notice { message } if !loaded => errln!("note: {message}"),
                Event::PolicyLoaded { .. } => loaded = true,
                Event::Planned { summary: s } => summary = Some(s),
                Event::TreeChanged { .. } => return Ok(summary),
                _ => {}
            }
        }
    }

    /// Run the tree from the scenario's first state until it succeeds, an action fails,
    /// or the engine stops it; `on_tick` sees every tick.
    pub fn run(&mut self, mut on_tick: impl FnMut(&TickRecord)) -> Result<Run> {
        self.send(Command::ResetWorld);
        self.send(Command::Run);
        let mut last: Option<Arc<TickRecord>> = None;
        let end = loop {
            match self.next()? {
                Event::Ticked { record } => {
                    on_tick(&record);
                    last = Some(record);
                }
                Event::Success { executor, .. } => break RunEnd::Success { executor },
                Event::ActionFailed {
                    action,
                    node_path,
                    error,
                    ..
                } => {
                    break RunEnd::ActionFailed {
                        action,
                        node_path: betr::bt::path_text(&node_path),
                        error,
                    };
                }
                Event::GaveUp { reason } => break RunEnd::Stopped { reason },
                // Where reality did otherwise than the twin predicted, before the failure.
                e @ Event::Diverged { .. } => {
                    for line in betr::record::describe(&e) {
                        errln!("note: {line}");
                    }
                }
                Event::BreakpointHit {
                    node,
                    node_path,
                    tick,
                    reason,
                } => {
                    break RunEnd::Break {
                        node,
                        node_path: betr::bt::path_text(&node_path),
                        tick,
                        reason,
                    };
                }
                Event::ChangeViolates { report, inherited } => {
                    // A change written on the command line is the person's own: it is run
                    // with the finding in view rather than refused.
                    errln!(
                        "note: the changed tree fails verification in the model; it runs as written"
                    );
                    if !inherited.is_empty() {
                        errln!(
                            "note: {}",
                            betr::record::describe::not_the_change(&inherited)
                        );
                    }
                    let mut err = std::io::stderr();
                    if let Err(e) = super::verify_cmd::write_report(&mut err, &report, false) {
                        tracing::warn!("cannot write the report to stderr: {e}");
                    }
                    self.send(Command::Approve);
                    self.send(Command::Run);
                }
                _ => {}
            }
        };
        Ok(Run {
            ticks: last.as_ref().map_or(0, |r| r.tick),
            end,
            last,
        })
    }

    /// Put a breakpoint on each of `nodes` and, when asked, stop on failures; kept for
    /// every later run.
    pub fn set_breakpoints(&mut self, nodes: &[NodeId], on_failure: bool) -> Result<()> {
        // Each command toggles: a node named twice gets one breakpoint.
        let nodes: std::collections::BTreeSet<NodeId> = nodes.iter().copied().collect();
        for node in &nodes {
            self.send(Command::ToggleBreakpoint(*node));
        }
        if on_failure {
            self.send(Command::BreakOnFailure(true));
        }
        let mut awaited = nodes.len() + usize::from(on_failure);
        while awaited > 0 {
            if let Event::Breakpoints { .. } = self.next()? {
                awaited -= 1;
            }
        }
        Ok(())
    }

    /// Send a change and wait until the engine has made it.
    pub fn change(&mut self, command: Command) -> Result<Change> {
        self.send(command);
        self.until_changed()
    }

    /// Verify the tree; what was checked and the report.
    pub fn verify(&mut self, request: VerifyRequest) -> Result<(Arc<VerifyScope>, Arc<Report>)> {
        self.send(Command::VerifyWith(request));
        let mut scope = None;
        loop {
            match self.next()? {
                Event::Verifying { scope: s } => scope = Some(s),
                Event::Verified { report, .. } => {
                    let scope =
                        scope.ok_or_else(|| anyhow!("a report came without what it checked"))?;
                    return Ok((scope, report));
                }
                _ => {}
            }
        }
    }

    /// Save the tree as a policy at `path`.
    pub fn save(&mut self, path: PathBuf) -> Result<()> {
        self.send(Command::SavePolicyTo(path));
        loop {
            if let Event::PolicySaved { .. } = self.next()? {
                return Ok(());
            }
        }
    }

    /// The tree as the engine last told it.
    pub fn tree(&self) -> Result<Arc<Tree>> {
        self.tree
            .clone()
            .ok_or_else(|| anyhow!("no tree: nothing was planned or loaded"))
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        self.handle.send(Command::Shutdown);
    }
}
