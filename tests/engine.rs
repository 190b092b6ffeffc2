//! The session engine, headless, on scenario 1 (red cube on the blue cube) with an
//! in-process model answering from the hand-written fixtures: submit → plan → tick to the
//! failure → proposal pending (tree untouched) → approve → tree changed with new nodes →
//! run → success; reject; an invalid edit; undo; a slow model call that does not block
//! ticks; a saved policy that makes the next session need no model call; no model at all.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

mod support;

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use betr::bt::{self, NodeKind};
use betr::llm::LanguageModel;
use betr::scenario::Scenario;
use betr::session::{Command, Engine, EngineHandle, Event, PolicyStore, Setup};
use support::fake_model::FixtureModel;
use support::fixtures;
use tokio::sync::mpsc::UnboundedReceiver;

const INSTRUCTION: &str = "Put the blue cube on the green cube";
const FIX: &str = "~\"any object\" on \"blue cube\"";

fn scenario_path() -> PathBuf {
    fixtures::root().join("scenarios/cell/red_on_blue.toml")
}

fn model(delay: Duration) -> FixtureModel {
    let mut m = FixtureModel::new(fixtures::every_reply());
    m.delay = delay;
    m
}

fn setup(model: Result<Arc<dyn LanguageModel>, String>, policies: Option<PathBuf>) -> Setup {
    let path = scenario_path();
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    Setup {
        policies: policies.map(PolicyStore::new),
        ..Setup::new(scenario, path, model)
    }
}

struct Session {
    engine: EngineHandle,
    events: UnboundedReceiver<Event>,
    seen: Vec<Event>,
}

impl Session {
    fn start(setup: Setup) -> Session {
        let (engine, events) = Engine::spawn(setup).unwrap();
        Session {
            engine,
            events,
            seen: Vec::new(),
        }
    }

    /// A session keeping policies in `dir`, past scenario 1's first proposal, approved;
    /// with the events up to the repaired tree.
    async fn repaired(dir: &std::path::Path) -> (Session, Vec<Event>) {
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
    async fn runs_to_success_without_a_call(&mut self, calls: &std::sync::atomic::AtomicUsize) {
        self.send(Command::Run);
        self.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        assert_eq!(calls.load(Ordering::SeqCst), 0, "no model call");
    }

    fn send(&self, c: Command) {
        assert!(self.engine.send(c));
    }

    /// Events up to and including the first that matches; panics after 20 s.
    async fn until(&mut self, what: &str, pred: impl Fn(&Event) -> bool) -> Vec<Event> {
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
        if tokio::time::timeout(Duration::from_secs(20), wait)
            .await
            .is_err()
        {
            panic!("timed out waiting for {what}; got {got:#?}");
        }
        got
    }

    /// Submit the instruction and tick until the grasp fails and a proposal is pending.
    async fn run_to_proposal(&mut self) -> Vec<Event> {
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

use support::repo::runtime as rt;

fn tree_of(events: &[Event]) -> Option<(Arc<bt::Tree>, Vec<bt::NodeId>)> {
    events.iter().rev().find_map(|e| match e {
        Event::TreeChanged {
            tree, new_nodes, ..
        } => Some((tree.clone(), new_nodes.clone())),
        _ => None,
    })
}

#[test]
fn submit_plan_fail_propose_approve_run_to_success() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        let got = s.run_to_proposal().await;
        let failed = s.seen.iter().find_map(|e| match e {
            Event::ActionFailed { action, error, .. } => Some((action.to_string(), error.clone())),
            _ => None,
        });
        assert_eq!(
            failed,
            Some((
                "grasp \"blue cube\"".to_string(),
                "No collision free path found".to_string()
            ))
        );
        // Nothing proposed changes the tree before approval.
        assert!(!got.iter().any(|e| matches!(e, Event::TreeChanged { .. })));
        let planned = tree_of(&s.seen).unwrap().0;
        s.send(Command::Approve);
        let got = s
            .until("the repaired tree", |e| {
                matches!(e, Event::TreeChanged { .. })
            })
            .await;
        let (tree, new_nodes) = tree_of(&got).unwrap();
        assert!(tree.len() > planned.len());
        assert!(!new_nodes.is_empty());
        let inserted = new_nodes
            .iter()
            .any(|n| matches!(tree.kind(*n), Ok(NodeKind::Condition(c)) if c.to_string() == FIX));
        assert!(inserted, "{}", bt::to_text(&tree));
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        let usage = s.seen.iter().rev().find_map(|e| match e {
            Event::Usage { totals } => Some(*totals),
            _ => None,
        });
        assert_eq!(usage.map(|u| u.calls), Some(2), "goal + failure question");
    });
}

#[test]
fn reject_leaves_the_tree_and_an_invalid_edit_is_refused() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        s.run_to_proposal().await;
        s.send(Command::Reject);
        s.until("rejected", |e| matches!(e, Event::Rejected)).await;
        s.send(Command::Edit("\"purple cube\" on \"blue cube\"".into()));
        let got = s
            .until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(format!("{got:?}").contains("purple cube"), "{got:?}");
        s.send(Command::Edit("~\"blue cube\" on \"blue cube\" | ".into()));
        s.until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        // Neither the rejection nor the bad edits changed the tree.
        let changes = s
            .seen
            .iter()
            .filter(|e| matches!(e, Event::TreeChanged { .. }))
            .count();
        assert_eq!(changes, 1, "only the planned tree");
        // A valid edit is applied like an approved proposal.
        s.send(Command::Edit(FIX.into()));
        let got = s
            .until("the edited tree", |e| {
                matches!(e, Event::TreeChanged { .. })
            })
            .await;
        assert!(!tree_of(&got).unwrap().1.is_empty());
    });
}

#[test]
fn a_pending_proposal_is_not_ticked_past() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        s.run_to_proposal().await;
        s.send(Command::Tick);
        s.send(Command::Run);
        for _ in 0..2 {
            s.until("the answer", |e| {
                matches!(e, Event::Notice { message }
                    if message.contains("not ticked: the failure waits for approval"))
            })
            .await;
        }
        // After approval the repaired tree is verified in the model, then ticks again.
        s.send(Command::Approve);
        s.until("repaired", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.until(
            "the check",
            |e| matches!(e, Event::Notice { message } if message.contains("verifies in the model")),
        )
        .await;
        s.send(Command::Tick);
        s.until("a tick", |e| matches!(e, Event::Ticked { .. }))
            .await;
    });
}

#[test]
fn undo_restores_the_tree_before_the_last_expansion() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        s.run_to_proposal().await;
        let planned = bt::to_text(&tree_of(&s.seen).unwrap().0);
        s.send(Command::Approve);
        s.until("repaired", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Undo);
        let got = s
            .until("undone", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        assert_eq!(bt::to_text(&tree_of(&got).unwrap().0), planned);
        s.send(Command::Undo);
        s.until("nothing to undo", |e| matches!(e, Event::Error { .. }))
            .await;
    });
}

#[test]
fn a_slow_model_call_does_not_block_ticks() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::from_secs(30)))), None));
        s.send(Command::Submit(INSTRUCTION.into()));
        s.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        for _ in 0..10 {
            s.send(Command::Tick);
            let got = s
                .until("a tick", |e| matches!(e, Event::Ticked { .. }))
                .await;
            if got
                .iter()
                .any(|e| matches!(e, Event::Ticked { record } if !record.failures.is_empty()))
            {
                break;
            }
        }
        s.until(
            "the question",
            |e| matches!(e, Event::Asking { what } if what.contains("preconditions")),
        )
        .await;
        // The failure question is under way for 30 s; a tick is answered at once, and
        // the failed tree is not ticked again while the proposal is awaited.
        let start = std::time::Instant::now();
        for _ in 0..5 {
            s.send(Command::Tick);
            s.until(
                "the answer to a tick",
                |e| matches!(e, Event::Notice { message } if message.contains("not ticked")),
            )
            .await;
        }
        let failures = s
            .seen
            .iter()
            .filter(|e| matches!(e, Event::ActionFailed { .. }))
            .count();
        assert_eq!(failures, 1, "the failed tree was ticked again");
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "{:?}",
            start.elapsed()
        );
        assert!(!s.seen.iter().any(|e| matches!(e, Event::Proposal { .. })));
        // Re-planning cancels the call.
        s.send(Command::Plan);
        s.until("re-planned", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        assert!(
            s.seen
                .iter()
                .any(|e| matches!(e, Event::Notice { message } if message.contains("cancelled")))
        );
    });
}

#[test]
fn a_saved_policy_needs_no_model_call_next_time() {
    let dir = std::env::temp_dir().join(format!("betr-engine-policy-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    rt().block_on(async {
        let (mut s, _) = Session::repaired(&dir).await;
        s.send(Command::SavePolicy);
        let got = s
            .until("saved", |e| matches!(e, Event::PolicySaved { .. }))
            .await;
        let Some(Event::PolicySaved { path, fixes }) = got.last() else {
            unreachable!()
        };
        assert_eq!(*fixes, 1);
        let text = std::fs::read_to_string(path).unwrap();
        assert!(
            text.contains("# instruction: Put the blue cube on the green cube"),
            "{text}"
        );
        assert!(text.contains(&format!("# fix 1: insert {FIX}")), "{text}");
        assert!(text.contains("hand-written fixture"), "{text}");
        assert!(text.contains("approved by a person"), "{text}");

        let fresh = model(Duration::ZERO);
        let calls = fresh.calls();
        let mut again = Session::start(setup(Ok(Arc::new(fresh)), Some(dir.clone())));
        again.send(Command::Submit(INSTRUCTION.into()));
        let got = again
            .until("loaded", |e| matches!(e, Event::PolicyLoaded { .. }))
            .await;
        assert!(matches!(
            got.last(),
            Some(Event::PolicyLoaded { fixes: 1, .. })
        ));
        again.runs_to_success_without_a_call(&calls).await;
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_repaired_tree_is_exported_and_a_fresh_engine_runs_the_btcpp_file() {
    let dir = std::env::temp_dir().join(format!("betr-engine-export-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    rt().block_on(async {
        let (mut s, got) = Session::repaired(&dir).await;
        let (repaired, _) = tree_of(&got).unwrap();
        s.send(Command::Export);
        let got = s
            .until("exported", |e| matches!(e, Event::Exported { .. }))
            .await;
        let Some(Event::Exported { paths }) = got.last() else {
            unreachable!()
        };
        let names: Vec<String> = paths
            .iter()
            .map(|p| p.extension().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["xml", "dot"]);
        let dot = std::fs::read_to_string(&paths[1]).unwrap();
        assert!(
            dot.contains("penwidth=3"),
            "the fix's nodes are marked:\n{dot}"
        );

        let fresh = model(Duration::ZERO);
        let calls = fresh.calls();
        let mut again = Session::start(setup(Ok(Arc::new(fresh)), None));
        again.send(Command::LoadPolicy(Some(paths[0].clone())));
        let got = again
            .until("loaded", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        let (loaded, _) = tree_of(&got).unwrap();
        assert_eq!(bt::to_text(&loaded), bt::to_text(&repaired));
        again.runs_to_success_without_a_call(&calls).await;
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn without_a_model_a_person_can_still_resolve() {
    rt().block_on(async {
        let mut s = Session::start(setup(
            Err("the local backend is not built yet".into()),
            None,
        ));
        s.send(Command::Submit(INSTRUCTION.into()));
        let got = s
            .until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(format!("{got:?}").contains("not built yet"), "{got:?}");
        s.send(Command::Submit("\"blue cube\" on \"green cube\"".into()));
        s.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Run);
        s.until("the failure", |e| matches!(e, Event::ActionFailed { .. }))
            .await;
        s.send(Command::Edit(FIX.into()));
        s.until("repaired", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
    });
}

/// Scenario 1 with the red cube fragile (`never "red cube" grasped`): the fix the model
/// proposes clears the blue cube by grasping the red one.
fn fragile_setup() -> Setup {
    let path = fixtures::root().join("tests/fixtures/scenarios/fragile_red.toml");
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    Setup::new(scenario, path, Ok(Arc::new(model(Duration::ZERO))))
}

#[test]
fn a_harmful_change_is_refused_with_a_counterexample_before_any_tick() {
    rt().block_on(async {
        let mut s = Session::start(fragile_setup());
        s.run_to_proposal().await;
        s.send(Command::Approve);
        let got = s
            .until("the verdict on the change", |e| {
                matches!(e, Event::ChangeViolates { .. })
            })
            .await;
        assert!(
            !got.iter().any(|e| matches!(e, Event::Ticked { .. })),
            "the changed tree ticked before its check: {got:#?}"
        );
        let Some(Event::ChangeViolates { report }) = got.last() else {
            unreachable!()
        };
        let violated: Vec<String> = report
            .model
            .as_ref()
            .unwrap()
            .properties
            .iter()
            .filter_map(|p| match &p.verdict {
                betr::verify::Verdict::Violated(cx) => {
                    Some(format!("{}: {cx}", p.name))
                }
                _ => None,
            })
            .collect();
        assert_eq!(violated.len(), 1, "{violated:?}");
        assert!(violated[0].starts_with("never \"red cube\" grasped"), "{violated:?}");
        assert!(violated[0].contains("grasp \"red cube\""), "{violated:?}");

        // Not ticked, not run, until the person decides.
        s.send(Command::Tick);
        s.send(Command::Run);
        for _ in 0..2 {
            s.until("the refusal", |e| {
                matches!(e, Event::Notice { message }
                    if message.contains("not ticked: the changed tree waits for approval of the change that fails verification"))
            })
            .await;
        }
        // Undone: the planned tree is back and may tick.
        s.send(Command::Undo);
        s.until("undone", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Tick);
        s.until("a tick", |e| matches!(e, Event::Ticked { .. }))
            .await;
    });
}

#[test]
fn a_change_approved_again_with_the_counterexample_in_view_runs() {
    rt().block_on(async {
        let mut s = Session::start(fragile_setup());
        s.run_to_proposal().await;
        s.send(Command::Approve);
        s.until("the verdict", |e| matches!(e, Event::ChangeViolates { .. }))
            .await;
        s.send(Command::Approve);
        s.until(
            "approved again",
            |e| matches!(e, Event::Notice { message } if message.contains("approved again")),
        )
        .await;
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
    });
}

#[test]
fn an_unattended_loop_rejects_a_change_that_fails_its_check_and_asks_again() {
    rt().block_on(async {
        let setup = fragile_setup();
        let scenario = (*setup.scenario).clone();
        let mut approve = |_: &betr::session::Proposal| true;
        let mut events = Vec::new();
        let resolved = betr::session::resolve(
            &scenario,
            None,
            Arc::new(model(Duration::ZERO)),
            &betr::session::Options::default(),
            &mut approve,
            &mut |e: &Event| events.push(e.clone()),
        )
        .await
        .unwrap();
        // The fixture model proposes the same fix every time; each is refused by the check,
        // undone, and told to the next question, until the rounds run out.
        assert!(
            matches!(resolved.ending, betr::session::Ending::GaveUp { .. }),
            "{:?}",
            resolved.ending
        );
        assert_eq!(resolved.repairs, 0);
        assert!(!events.iter().any(|e| matches!(e, Event::Success { .. })));
        let refused = events
            .iter()
            .filter(|e| matches!(e, Event::ChangeViolates { .. }))
            .count();
        assert!(refused >= 2, "asked again after the first refusal: {refused}");
        assert!(events.iter().any(|e| matches!(e, Event::DidNotHelp { reason }
            if reason.contains("fails verification in the model: never \"red cube\" grasped is violated"))));
    });
}

#[test]
fn verify_before_the_first_tick_plans_the_whole_tree_in_the_model() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        s.send(Command::Submit(INSTRUCTION.into()));
        s.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Verify);
        let got = s
            .until("the report", |e| matches!(e, Event::Verified { .. }))
            .await;
        // The property of scenario 1 asked for the precondition the failure would teach.
        let (tree, _) = tree_of(&got).expect("the tree planned in the model is shown");
        assert!(
            bt::to_text(&tree).contains(&format!("{FIX}?")),
            "{}",
            bt::to_text(&tree)
        );
        let Some(Event::Verified { report, origin }) = got.last() else {
            unreachable!()
        };
        assert!(report.holds(), "{report:#?}");
        assert!(
            origin.starts_with("planned in the planner's model"),
            "{origin}"
        );
        assert!(origin.contains(FIX), "{origin}");

        // After a tick the tree is verified as it is.
        s.send(Command::Tick);
        s.until("a tick", |e| matches!(e, Event::Ticked { .. }))
            .await;
        s.send(Command::Verify);
        let got = s
            .until("the report", |e| matches!(e, Event::Verified { .. }))
            .await;
        let Some(Event::Verified { origin, .. }) = got.last() else {
            unreachable!()
        };
        assert_eq!(origin, "planned in the planner's model");
    });
}

#[test]
fn a_rejected_change_that_failed_its_check_is_undone_and_told_to_the_model() {
    rt().block_on(async {
        let mut s = Session::start(fragile_setup());
        s.run_to_proposal().await;
        let planned = bt::to_text(&tree_of(&s.seen).unwrap().0);
        s.send(Command::Approve);
        s.until("the verdict", |e| matches!(e, Event::ChangeViolates { .. }))
            .await;
        s.send(Command::Reject);
        let got = s
            .until("undone", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        assert!(got.iter().any(|e| matches!(e, Event::DidNotHelp { reason }
            if reason.contains("fails verification in the model"))));
        assert_eq!(bt::to_text(&tree_of(&got).unwrap().0), planned);
        // The failure is met again; the refused fix is no longer offered to the model.
        s.send(Command::Run);
        s.until("the shortlist", |e| {
            matches!(e, Event::Notice { message } if message.contains("(1 refused before, left out)"))
        })
        .await;
    });
}
