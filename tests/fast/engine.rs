//! The session engine, headless, on scenario 1 (red cube on the blue cube) with an
//! in-process model answering from the hand-written fixtures: submit → plan → tick to the
//! failure → proposal pending (tree untouched) → approve → tree changed with new nodes →
//! run → success; reject; an invalid edit; undo; a slow model call that does not block
//! ticks; a saved policy that makes the next session need no model call; no model at all.
//! (Changes checked by verification before they run: `engine_verification.rs`.)

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::sync::Arc;
use std::time::Duration;

use betr::bt;
use betr::domain::{Condition, Value};
use betr::scenario::Scenario;
use betr::session::repair::values;
use betr::session::{Command, Edit, Event, NoModel, Setup};
use support::engine::{FIX, INSTRUCTION, Session, edit, fix_inserted, model, setup, tree_of};
use support::repo::runtime as rt;

#[test]
fn submit_plan_fail_propose_approve_run_to_success() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        let got = s.run_to_proposal().await;
        let failed = s.seen.iter().find_map(|e| match e {
            Event::ActionFailed { action, error, .. } => Some((action.to_string(), error.clone())),
            _ => None,
        });
        let (action, error) = failed.expect("an action failed");
        assert_eq!(action, "grasp \"blue cube\"");
        // The arm's reason when the robot's description is in the cache, else the sweep's.
        assert!(
            error == "No collision free path found"
                || (error.starts_with("No collision free path found for yumi_link_7_")
                    && error.ends_with("collides with red cube")),
            "{error}"
        );
        // Nothing proposed changes the tree before approval.
        assert!(!got.iter().any(|e| matches!(e, Event::TreeChanged { .. })));
        let planned = tree_of(&s.seen).unwrap().0;
        let got = s.approve().await;
        let (tree, _) = tree_of(&got).unwrap();
        assert!(tree.len() > planned.len());
        assert!(fix_inserted(&got), "{}", bt::to_text(&tree));
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
        // An edit that cannot be read never reaches the engine: an unknown object, a
        // dangling `|`.
        let e = edit("\"purple cube\" on \"blue cube\"").unwrap_err();
        assert!(e.to_string().contains("purple cube"), "{e}");
        assert!(edit("~\"blue cube\" on \"blue cube\" | ").is_err());
        // The engine refuses what was read but does not fit: a value where the failure
        // calls for conditions, and conditions outside the vocabulary from a sender that did
        // not read them over it.
        s.send(edit("5 N").unwrap());
        let got = s
            .until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(
            format!("{got:?}").contains("calls for conditions"),
            "{got:?}"
        );
        let unknown = Condition::parse("\"purple cube\" on \"blue cube\"").unwrap();
        s.send(Command::Edit(Edit::Conditions(vec![unknown])));
        let got = s
            .until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(format!("{got:?}").contains("purple cube"), "{got:?}");
        // Neither the rejection nor the bad edits changed the tree.
        let changes = s
            .seen
            .iter()
            .filter(|e| matches!(e, Event::TreeChanged { .. }))
            .count();
        assert_eq!(changes, 1, "only the planned tree");
        // A valid edit is applied like an approved proposal.
        s.send(edit(FIX).unwrap());
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
        s.until("the question", |e| {
            matches!(
                e,
                Event::Asking {
                    what: betr::session::Question::Preconditions { .. }
                }
            )
        })
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

/// A question to a slow model is cancelled: no answer is waited for, the failure is left
/// to the person, whose fix is taken as when no model was asked; a second cancel has
/// nothing to cancel.
#[test]
fn a_question_to_the_model_is_cancelled_and_the_person_writes_the_fix() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::from_secs(600)))), None));
        s.send(Command::Submit("\"blue cube\" on \"green cube\"".into()));
        s.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Run);
        s.until("the question", |e| matches!(e, Event::Asking { .. }))
            .await;
        s.send(Command::Cancel);
        let got = s
            .until("the cancel", |e| {
                matches!(e, Event::PersonDecides { why, rounds_left: true, .. }
                    if why.starts_with("the question was cancelled"))
            })
            .await;
        assert!(
            got.iter().any(|e| matches!(e, Event::CallCancelled)),
            "{got:#?}"
        );
        s.send(Command::Cancel);
        let got = s
            .until("nothing to cancel", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(
            format!("{:?}", got.last()).contains("nothing to cancel"),
            "{got:#?}"
        );
        s.send(edit(FIX).unwrap());
        s.until("repaired", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Run);
        let got = s
            .until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        assert!(
            !got.iter().any(|e| matches!(e, Event::Proposal { .. })),
            "a late answer was taken: {got:#?}"
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
            Err(NoModel::Unavailable(
                "the local backend is not built yet".into(),
            )),
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
        s.send(edit(FIX).unwrap());
        s.until("repaired", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
    });
}

/// A value a person set (`force of egg = 5 N`, read by the front end) is checked against
/// the skill's declaration and put on every action that uses it; one beyond what the robot
/// can do, or sent before there is a tree, is refused.
#[test]
fn a_value_set_by_a_person_is_checked_then_put_on_its_actions() {
    rt().block_on(async {
        let path = support::fixtures::root().join("scenarios/cell/params/egg.toml");
        let scenario = Arc::new(Scenario::load(&path).unwrap());
        let setting = values::parse_setting(&scenario, "force of egg = 5 N").unwrap();
        let too_strong = values::Setting {
            value: Value::Number {
                value: 120.0,
                unit: "N".into(),
            },
            ..setting.clone()
        };
        let mut s = Session::start(Setup::new(
            scenario,
            path,
            Err(NoModel::NotUsed("this test")),
        ));
        s.send(Command::SetValue(setting.clone()));
        let got = s
            .until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(format!("{got:?}").contains("plan first"), "{got:?}");
        s.send(Command::Plan);
        s.until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::SetValue(too_strong));
        let got = s
            .until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(
            format!("{got:?}").contains("more than the robot can do"),
            "{got:?}"
        );
        s.send(Command::SetValue(setting));
        let got = s
            .until("the valued tree", |e| {
                matches!(e, Event::TreeChanged { .. })
            })
            .await;
        assert!(
            got.iter()
                .any(|e| matches!(e, Event::Repaired { valued_nodes, .. } if *valued_nodes > 0)),
            "{got:?}"
        );
    });
}

/// The model alone (the lab's `--no-shortlist --no-screening`): nothing is tried in
/// simulation before the model is asked or before its answer is proposed, and the
/// proposal says so; approved, the change still meets its own check.
#[test]
fn the_model_alone_proposes_its_answer_untried() {
    rt().block_on(async {
        let mut setup = setup(Ok(Arc::new(model(Duration::ZERO))), None);
        setup.options.steps.shortlist = false;
        setup.options.steps.screen_proposals = false;
        let mut s = Session::start(setup);
        let got = s.run_to_proposal().await;
        assert!(
            !got.iter()
                .any(|e| matches!(e, Event::Screened { .. } | Event::CandidateRejected { .. })),
            "{got:#?}"
        );
        let findings = got.iter().find_map(|e| match e {
            Event::Proposal {
                proposal, evidence, ..
            } => Some((proposal.to_string(), evidence.clone())),
            _ => None,
        });
        let (proposal, evidence) = findings.unwrap();
        assert!(proposal.contains(FIX), "{proposal}");
        let evidence = evidence.unwrap();
        assert!(
            evidence
                .findings
                .iter()
                .any(|f| f == "this change was not tried in simulation before it was offered"),
            "{evidence:#?}"
        );
        assert!(fix_inserted(&s.approve().await));
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
    });
}
