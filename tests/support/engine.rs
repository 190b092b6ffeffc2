//! Driving the session engine headless on scenario 1 (red cube on the blue cube) with an
//! in-process model answering from the hand-written fixtures: the setup, a `Session` that
//! sends commands and waits for events, and the tree of the last change.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use betr::bt;
use betr::llm::LanguageModel;
use betr::scenario::Scenario;
use betr::session::{
    Command, EditError, Engine, EngineHandle, Event, NoModel, PolicyStore, Setup, parse_edit,
};
use tokio::sync::mpsc::UnboundedReceiver;

use super::fake_model::FixtureModel;
use super::fixtures;

pub const INSTRUCTION: &str = "Put the blue cube on the green cube";
pub const FIX: &str = "~\"any object\" on \"blue cube\"";

pub fn scenario_path() -> PathBuf {
    fixtures::root().join("scenarios/cell/red_on_blue.toml")
}

/// The edit a person typed, read over scenario 1 as the workbench reads it.
pub fn edit(text: &str) -> Result<Command, EditError> {
    let scenario = Scenario::load(&scenario_path()).unwrap();
    parse_edit(&scenario, text).map(Command::Edit)
}

pub fn model(delay: Duration) -> FixtureModel {
    let mut m = FixtureModel::new(fixtures::every_reply());
    m.delay = delay;
    m
}

pub fn setup(model: Result<Arc<dyn LanguageModel>, NoModel>, policies: Option<PathBuf>) -> Setup {
    let path = scenario_path();
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    Setup {
        policies: policies.map(PolicyStore::new),
        ..Setup::new(scenario, path, model)
    }
}

pub struct Session {
    pub engine: EngineHandle,
    pub events: UnboundedReceiver<Event>,
    pub seen: Vec<Event>,
}

impl Session {
    pub fn start(setup: Setup) -> Session {
        let (engine, events) = Engine::spawn(setup).unwrap();
        Session {
            engine,
            events,
            seen: Vec::new(),
        }
    }

    /// A session keeping policies in `dir`, past scenario 1's first proposal, approved;
    /// with the events up to the repaired tree.
    pub async fn repaired(dir: &std::path::Path) -> (Session, Vec<Event>) {
        let mut s = Session::start(setup(
            Ok(Arc::new(model(Duration::ZERO))),
            Some(dir.to_path_buf()),
        ));
        s.run_to_proposal().await;
        s.send(Command::Approve);
        let got = s
            .until("repaired", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        (s, got)
    }

    /// Run to success, having asked the model nothing (`calls` counts its calls).
    pub async fn runs_to_success_without_a_call(&mut self, calls: &std::sync::atomic::AtomicUsize) {
        self.send(Command::Run);
        self.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        assert_eq!(calls.load(Ordering::SeqCst), 0, "no model call");
    }

    /// Approve the pending proposal; the events up to the changed tree.
    pub async fn approve(&mut self) -> Vec<Event> {
        self.send(Command::Approve);
        self.until("the repaired tree", |e| {
            matches!(e, Event::TreeChanged { .. })
        })
        .await
    }

    pub fn send(&self, c: Command) {
        assert!(self.engine.send(c));
    }

    /// Events up to and including the first that matches; panics after 20 s.
    pub async fn until(&mut self, what: &str, pred: impl Fn(&Event) -> bool) -> Vec<Event> {
        let mut got = Vec::new();
        let wait = async {
            loop {
                let e = self.events.recv().await.expect("the engine stopped");
                got.push(e.clone());
                self.seen.push(e.clone());
                if pred(&e) {
                    return;
                }
            }
        };
        if tokio::time::timeout(Duration::from_secs(120), wait)
            .await
            .is_err()
        {
            panic!("timed out waiting for {what}; got {got:#?}");
        }
        got
    }

    /// Submit the instruction and tick until the grasp fails and a proposal is pending.
    pub async fn run_to_proposal(&mut self) -> Vec<Event> {
        self.send(Command::Submit(INSTRUCTION.into()));
        self.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        let mut ticks = 0;
        loop {
            self.send(Command::Tick);
            let got = self
                .until("a tick", |e| matches!(e, Event::Ticked { .. }))
                .await;
            ticks += 1;
            // The tick's own record says whether an action failed (the failure event
            // follows it).
            if got
                .iter()
                .any(|e| matches!(e, Event::Ticked { record } if !record.failures.is_empty()))
            {
                break;
            }
            assert!(ticks < 20, "no failure after 20 ticks: {got:#?}");
        }
        if !self
            .seen
            .iter()
            .any(|e| matches!(e, Event::Proposal { .. }))
        {
            self.until("the proposal", |e| matches!(e, Event::Proposal { .. }))
                .await;
        }
        let failed_at = self
            .seen
            .iter()
            .position(|e| matches!(e, Event::ActionFailed { .. }))
            .unwrap_or(0);
        self.seen[failed_at..].to_vec()
    }
}

/// Whether the last change of the tree in `events` inserted scenario 1's fix.
pub fn fix_inserted(events: &[Event]) -> bool {
    let Some((tree, new_nodes)) = tree_of(events) else {
        return false;
    };
    new_nodes
        .iter()
        .any(|n| matches!(tree.kind(*n), Ok(bt::NodeKind::Condition(c)) if c.to_string() == FIX))
}

pub fn tree_of(events: &[Event]) -> Option<(Arc<bt::Tree>, Vec<bt::NodeId>)> {
    events.iter().rev().find_map(|e| match e {
        Event::TreeChanged {
            tree, new_nodes, ..
        } => Some((tree.clone(), new_nodes.clone())),
        _ => None,
    })
}
