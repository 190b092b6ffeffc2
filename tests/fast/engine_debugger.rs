//! The session engine's debugger, headless, on scenario 1 without a model: a breakpoint
//! stops a run before the tick that would enter its node (the preview leaves the world as
//! it was), a run resumed from there does not stop again at once; a condition forced to
//! fail sends its fallback to the other branch until the force is cleared; break on
//! failure; marks cleared when the tree is replaced.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::sync::Arc;

use betr::bt::{Forced, NodeId, Status, TickRecord, Tree};
use betr::session::{BreakReason, Command, Event, NoModel, Setup};
use support::engine::{Session, setup, tree_of};
use support::repo::runtime as rt;

/// Scenario 1 without the red cube on the blue one (`--variant clear`): planned, it
/// grasps the blue cube (ticks 1–3), then places it (3–5) and succeeds.
async fn clear_cell() -> (Session, Arc<Tree>) {
    let mut s = Session::start(Setup {
        variant: Some("clear".into()),
        ..setup(Err(NoModel::NotUsed("this test")), None)
    });
    s.send(Command::Plan);
    let got = s
        .until("the tree", |e| matches!(e, Event::TreeChanged { .. }))
        .await;
    (s, tree_of(&got).unwrap().0)
}

/// The node whose text (`grasp "blue cube"!` without the mark) starts with `text`.
fn node(tree: &Tree, text: &str) -> NodeId {
    let found = tree.preorder().into_iter().find(|&n| {
        let kind = tree.kind(n).unwrap();
        kind.as_action().is_some_and(|a| a.to_string() == text)
            || kind.as_condition().is_some_and(|c| c.to_string() == text)
    });
    found.unwrap_or_else(|| panic!("no node {text} in\n{}", betr::bt::to_text(tree)))
}

fn ticks(events: &[Event]) -> Vec<Arc<TickRecord>> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Ticked { record } => Some(record.clone()),
            _ => None,
        })
        .collect()
}

fn hits(events: &[Event]) -> usize {
    events
        .iter()
        .filter(|e| matches!(e, Event::BreakpointHit { .. }))
        .count()
}

#[test]
fn a_breakpoint_stops_the_run_before_the_tick_that_enters_its_node() {
    rt().block_on(async {
        let (mut s, tree) = clear_cell().await;
        let grasp = node(&tree, "grasp \"blue cube\"");
        let place = node(&tree, "place \"blue cube\" \"green cube\"");
        s.send(Command::ToggleBreakpoint(place));
        let got = s
            .until("the breakpoints", |e| {
                matches!(e, Event::Breakpoints { .. })
            })
            .await;
        assert!(matches!(
            got.last(),
            Some(Event::Breakpoints { nodes, on_failure: false }) if *nodes == [place]
        ));

        // The grasp completes in tick 3 and the place starts in the same tick: the run
        // stops before tick 3, having performed ticks 1 and 2 only.
        s.send(Command::Run);
        let got = s
            .until("the hit", |e| matches!(e, Event::BreakpointHit { .. }))
            .await;
        let Some(Event::BreakpointHit {
            node,
            node_path,
            tick,
            reason,
        }) = got.last()
        else {
            unreachable!()
        };
        assert_eq!(
            (*node, node_path.as_slice(), *tick, *reason),
            (place, [1, 1].as_slice(), 3, BreakReason::Breakpoint)
        );
        let performed: Vec<u64> = ticks(&got).iter().map(|r| r.tick).collect();
        assert_eq!(performed, [1, 2]);
        assert!(
            got.iter()
                .any(|e| matches!(e, Event::RunState { running: false }))
        );

        // A single step performs tick 3 in a world the preview did not touch: the grasp
        // completes there now (had the preview completed it, it would not be reached).
        s.send(Command::Tick);
        let got = s
            .until("tick 3", |e| matches!(e, Event::Ticked { .. }))
            .await;
        let record = ticks(&got).pop().unwrap();
        assert_eq!(record.tick, 3);
        assert_eq!(record.completed, [grasp]);
        assert_eq!(record.status(place), Status::Running);

        // Afresh: the breakpoint stays; a run resumed from the hit performs that tick and
        // runs on to success without stopping again at the same place.
        s.send(Command::ResetWorld);
        s.send(Command::Run);
        s.until("the hit again", |e| {
            matches!(e, Event::BreakpointHit { tick: 3, .. })
        })
        .await;
        s.send(Command::Run);
        let got = s
            .until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        assert_eq!(hits(&got), 0, "{got:#?}");
        assert_eq!(ticks(&got).first().map(|r| r.tick), Some(3));

        // Cleared, the run is not stopped.
        s.send(Command::ToggleBreakpoint(place));
        s.until(
            "no breakpoint",
            |e| matches!(e, Event::Breakpoints { nodes, .. } if nodes.is_empty()),
        )
        .await;
        s.send(Command::ResetWorld);
        s.send(Command::Run);
        let got = s
            .until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        assert_eq!(hits(&got), 0, "{got:#?}");
    });
}

#[test]
fn a_condition_forced_to_fail_sends_the_fallback_to_its_other_branch_until_cleared() {
    rt().block_on(async {
        let (mut s, tree) = clear_cell().await;
        let goal = node(&tree, "\"blue cube\" on \"green cube\"");
        let grasp = node(&tree, "grasp \"blue cube\"");
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;

        // The goal holds; forced to fail, the fallback grasps the blue cube again.
        s.send(Command::Force {
            node: goal,
            status: Some(Forced::Failure),
        });
        let got = s
            .until("the forced set", |e| matches!(e, Event::Forced { .. }))
            .await;
        assert!(matches!(
            got.last(),
            Some(Event::Forced { forced }) if *forced == [(goal, Forced::Failure)]
        ));
        s.send(Command::Tick);
        let got = s
            .until("a tick", |e| matches!(e, Event::Ticked { .. }))
            .await;
        let record = ticks(&got).pop().unwrap();
        assert_eq!(record.status(goal), Status::Failure);
        assert_eq!(record.forced, [goal]);
        assert_eq!(record.status(grasp), Status::Running);
        assert_eq!(record.running_action(), Some(grasp));

        // Kept across ticks.
        s.send(Command::Tick);
        let got = s
            .until("a tick", |e| matches!(e, Event::Ticked { .. }))
            .await;
        assert_eq!(ticks(&got).pop().unwrap().status(grasp), Status::Running);

        // Cleared: the goal is checked again, holds, and the grasp is halted.
        s.send(Command::Force {
            node: goal,
            status: None,
        });
        s.until(
            "cleared",
            |e| matches!(e, Event::Forced { forced } if forced.is_empty()),
        )
        .await;
        s.send(Command::Tick);
        let got = s
            .until("a tick", |e| matches!(e, Event::Ticked { .. }))
            .await;
        let record = ticks(&got).pop().unwrap();
        assert_eq!(record.status(goal), Status::Success);
        assert!(record.forced.is_empty());
        assert_eq!(record.halted, [grasp]);
        assert_eq!(record.status(grasp), Status::Halted);
    });
}

/// Cycling a node's forced status three times at once, as keys pressed faster than the
/// engine answers: each command cycles from what the engine holds, so the node ends at
/// running (failure → success → running), and a fourth clears it.
#[test]
fn forcing_cycles_from_the_engines_own_status_however_fast_it_is_asked() {
    rt().block_on(async {
        let (mut s, tree) = clear_cell().await;
        let goal = node(&tree, "\"blue cube\" on \"green cube\"");
        for _ in 0..3 {
            s.send(Command::CycleForce(goal));
        }
        s.until(
            "forced to running",
            |e| matches!(e, Event::Forced { forced } if *forced == [(goal, Forced::Running)]),
        )
        .await;
        s.send(Command::CycleForce(goal));
        s.until(
            "cleared",
            |e| matches!(e, Event::Forced { forced } if forced.is_empty()),
        )
        .await;
    });
}

#[test]
fn break_on_failure_stops_after_the_tick_in_which_a_node_fails() {
    rt().block_on(async {
        let (mut s, tree) = clear_cell().await;
        let goal = node(&tree, "\"blue cube\" on \"green cube\"");
        s.send(Command::Run);
        s.until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        s.send(Command::BreakOnFailure(true));
        s.until("break on failure", |e| {
            matches!(
                e,
                Event::Breakpoints {
                    on_failure: true,
                    ..
                }
            )
        })
        .await;
        // The goal held in the last tick; forced to fail, the tree goes on running (it
        // grasps again), but the run stops after that tick, naming the goal.
        s.send(Command::Force {
            node: goal,
            status: Some(Forced::Failure),
        });
        s.send(Command::Run);
        let got = s
            .until("the hit", |e| matches!(e, Event::BreakpointHit { .. }))
            .await;
        let performed = ticks(&got);
        assert_eq!(performed.len(), 1, "{got:#?}");
        assert!(matches!(
            got.last(),
            Some(Event::BreakpointHit { node, tick, reason: BreakReason::Failure, .. })
                if *node == goal && *tick == performed[0].tick
        ));
        assert!(
            got.iter()
                .any(|e| matches!(e, Event::RunState { running: false }))
        );
    });
}

#[test]
fn marks_are_cleared_when_the_tree_is_replaced_and_refused_for_unknown_nodes() {
    rt().block_on(async {
        let (mut s, tree) = clear_cell().await;
        let goal = node(&tree, "\"blue cube\" on \"green cube\"");
        s.send(Command::Force {
            node: NodeId(999),
            status: Some(Forced::Success),
        });
        let got = s
            .until("an error", |e| matches!(e, Event::Error { .. }))
            .await;
        assert!(format!("{got:?}").contains("no node #999"), "{got:?}");
        s.send(Command::Force {
            node: goal,
            status: Some(Forced::Success),
        });
        s.send(Command::ToggleBreakpoint(goal));
        s.until(
            "the breakpoint",
            |e| matches!(e, Event::Breakpoints { nodes, .. } if !nodes.is_empty()),
        )
        .await;
        s.send(Command::Plan);
        let got = s
            .until("the new tree", |e| matches!(e, Event::TreeChanged { .. }))
            .await;
        assert!(
            got.iter()
                .any(|e| matches!(e, Event::Forced { forced } if forced.is_empty()))
        );
        assert!(
            got.iter()
                .any(|e| matches!(e, Event::Breakpoints { nodes, .. } if nodes.is_empty()))
        );
        assert!(
            got.iter().any(|e| matches!(e, Event::Notice { message }
                if message.contains("forced statuses and breakpoints cleared"))),
            "{got:#?}"
        );
        // The new tree runs unforced to success.
        s.send(Command::Run);
        let got = s
            .until("success", |e| matches!(e, Event::Success { .. }))
            .await;
        assert!(ticks(&got).iter().all(|r| r.forced.is_empty()));
    });
}
