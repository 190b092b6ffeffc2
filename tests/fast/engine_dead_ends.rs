//! No dead ends after a person turns a proposal down: undo puts the undone fix back among
//! the candidates of the next question, and a rejection asks the model again with the
//! rejected fix left out, until a limit after which the person types the fix.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::sync::Arc;
use std::time::Duration;

use betr::session::{Command, Event, Proposal, Shortlist};
use support::engine::{Session, model, setup};
use support::fake_model::FixtureModel;
use support::fixtures;
use support::repo::runtime as rt;

/// The conditions of the last proposal among `events`, as text.
fn proposed(events: &[Event]) -> Option<String> {
    events.iter().rev().find_map(|e| match e {
        Event::Proposal {
            proposal: Proposal::Conditions { conditions, .. },
            ..
        } => Some(
            conditions
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(" & "),
        ),
        _ => None,
    })
}

/// What trying conditions in simulation found before the model was asked.
fn screened(events: &[Event]) -> Option<Shortlist> {
    events.iter().rev().find_map(|e| match e {
        Event::Screened { shortlist, .. } => Some(shortlist.clone()),
        _ => None,
    })
}

#[test]
fn an_undone_fix_is_a_candidate_again() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        s.run_to_proposal().await;
        s.send(Command::Approve);
        s.until(
            "one fix unsaved",
            |e| matches!(e, Event::FixCounts(c) if c.unsaved == 1),
        )
        .await;
        s.send(Command::Undo);
        // The engine's count follows the tree: the undone fix is no longer unsaved, and
        // a second undo (nothing to undo) changes no count.
        s.until(
            "no fix unsaved",
            |e| matches!(e, Event::FixCounts(c) if c.unsaved == 0),
        )
        .await;
        s.send(Command::Undo);
        let got = s
            .until("nothing to undo", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(
            !got.iter().any(|e| matches!(e, Event::FixCounts(_))),
            "{got:#?}"
        );
        s.seen.clear();
        let again = s.run_to_proposal().await;
        let list = screened(&again).unwrap();
        assert_eq!(list.refused, 0, "{list:?}");
        // The undone fix is the first choice again (how many others fix the failure
        // depends on where the arm left things).
        assert_eq!(
            list.fixes.first().map(ToString::to_string).as_deref(),
            Some("~\"any object\" on \"blue cube\""),
            "{list:?}"
        );
        assert_eq!(
            proposed(&again).as_deref(),
            Some("~\"any object\" on \"blue cube\"")
        );
    });
}

#[test]
fn a_rejected_fix_applied_by_hand_then_undone_is_a_candidate_again() {
    rt().block_on(async {
        let mut s = Session::start(setup(Ok(Arc::new(model(Duration::ZERO))), None));
        s.run_to_proposal().await;
        s.send(Command::Reject);
        s.until("rejected", |e| matches!(e, Event::Rejected)).await;
        s.send(support::engine::edit(support::engine::FIX).unwrap());
        s.until("edited", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.send(Command::Undo);
        s.until("undone", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        s.seen.clear();
        let again = s.run_to_proposal().await;
        let list = screened(&again).unwrap();
        assert_eq!(list.refused, 0, "{list:?}");
        assert_eq!(
            proposed(&again).as_deref(),
            Some("~\"any object\" on \"blue cube\"")
        );
    });
}

#[test]
fn a_rejection_asks_again_without_the_rejected_fix_then_leaves_it_to_the_person() {
    rt().block_on(async {
        let mut s = Session::start(one_rejection());
        s.run_to_proposal().await;
        s.send(Command::Reject);
        let got = s
            .until("the next proposal", |e| matches!(e, Event::Proposal { .. }))
            .await;
        let list = screened(&got).unwrap();
        assert_eq!(list.refused, 1, "{list:?}");
        assert!(
            list.to_string().contains("(1 refused before, left out)"),
            "{list}"
        );
        assert_eq!(
            proposed(&got).as_deref(),
            Some("~\"red cube\" on \"blue cube\"")
        );
        // Rejected again: past the limit (one, here), the model is not asked again and
        // the person types the fix.
        s.send(Command::Reject);
        let got = s
            .until("left to the person", |e| {
                matches!(e, Event::PersonDecides { why, .. } if why == "2 proposal(s) rejected")
            })
            .await;
        assert!(
            !got.iter().any(|e| matches!(e, Event::Asking { .. })),
            "{got:#?}"
        );
    });
}

/// A session whose person may reject one proposal per failure before typing the fix.
fn one_rejection() -> betr::session::Setup {
    // Scenario 1's own replies: another scenario's would answer its prompt first.
    let model = FixtureModel::new(fixtures::replies_of("red_on_blue.toml"));
    let mut setup = setup(Ok(Arc::new(model)), None);
    setup.options.max_rejections = 1;
    setup
}
