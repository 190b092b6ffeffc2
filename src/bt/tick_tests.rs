//! Unit tests for ticking, in the style of py_trees' tests: tiny trees, scripted leaves,
//! and the status of every node written down and asserted at every tick.

use super::*;
use crate::bt::test_util::{act, cond};
use Status::{Failure as F, Halted as H, Idle as I, Running as R, Success as S};

/// Leaves whose answers are scripted per tick (the last entry repeats), logging every call.
#[derive(Default)]
struct Script {
    now: usize,
    conditions: Vec<(&'static str, Vec<bool>)>,
    actions: Vec<(&'static str, Vec<ActionStep>)>,
    log: Vec<String>,
    /// Conditions checked, in order.
    checked: Vec<String>,
}

fn at<T: Clone>(script: &[T], tick: usize) -> T {
    script[tick.min(script.len() - 1)].clone()
}

impl Leaves for Script {
    fn check(&mut self, condition: &Condition) -> bool {
        let text = condition.to_string();
        self.checked.push(text.clone());
        let (_, answers) = self.conditions.iter().find(|(c, _)| *c == text).unwrap();
        at(answers, self.now)
    }

    fn step(&mut self, node: NodeId, action: &ActionCall, started: bool) -> ActionStep {
        let text = action.to_string();
        let verb = if started { "start" } else { "step" };
        self.log.push(format!("{}: {verb} {node}", self.now + 1));
        let (_, answers) = self.actions.iter().find(|(a, _)| *a == text).unwrap();
        at(answers, self.now)
    }

    fn halt(&mut self, node: NodeId, _action: &ActionCall) {
        self.log.push(format!("{}: halt {node}", self.now + 1));
    }
}

fn run(ticker: &mut Ticker, tree: &Tree, script: &mut Script) -> TickRecord {
    script.now = ticker.tick_count() as usize;
    ticker.tick(tree, script)
}

fn run_forced(
    ticker: &mut Ticker,
    tree: &Tree,
    script: &mut Script,
    forced: &[(NodeId, Forced)],
) -> TickRecord {
    script.now = ticker.tick_count() as usize;
    let forced: ForcedStatuses = forced.iter().copied().collect();
    ticker.tick_forced(tree, script, &forced)
}

#[test]
fn running_action_is_halted_when_its_guard_fails() {
    // [0] sequence
    // [1]   "path" clear?          T  T  F  T
    // [2]   move "robot" "table"!  R  R  .  R
    let mut t = Tree::new(NodeKind::Sequence);
    let guard = t.add_child(t.root(), cond("\"path\" clear")).unwrap();
    let mv = t
        .add_child(t.root(), act("move \"robot\" \"table\""))
        .unwrap();
    assert_eq!((guard, mv), (NodeId(1), NodeId(2)));
    let mut script = Script {
        conditions: vec![("\"path\" clear", vec![true, true, false, true])],
        actions: vec![("move \"robot\" \"table\"", vec![ActionStep::Running])],
        ..Script::default()
    };
    let mut ticker = Ticker::new();
    // tick 1: sequence R, guard S, move R (fresh start)
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!((r.tick, r.root), (1, Outcome::Running));
    assert_eq!(r.statuses, vec![R, S, R]);
    assert_eq!(r.visited, vec![NodeId(0), guard, mv]);
    assert_eq!(r.running_action(), Some(mv));
    // tick 2: sequence R, guard S, move R (continuing)
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![R, S, R]);
    // tick 3: guard fails -> sequence F, guard F, move Halted (not ticked, halted)
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.root, Outcome::Failure);
    assert_eq!(r.statuses, vec![F, F, H]);
    assert_eq!(r.visited, vec![NodeId(0), guard]);
    assert_eq!(r.halted, vec![mv]);
    assert_eq!(r.running_action(), None);
    // tick 4: guard holds again -> move starts afresh: R, S, R
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![R, S, R]);
    assert!(r.halted.is_empty());
    assert_eq!(
        script.log,
        ["1: start #2", "2: step #2", "3: halt #2", "4: start #2"]
    );
}

#[test]
fn action_takes_three_ticks_then_the_next_runs() {
    // [0] sequence
    // [1]   fallback
    // [2]     "blue cube" grasped?                  F  F  F  T  T
    // [3]     grasp "blue cube"!                    R  R  S  .  .
    // [4]   place "blue cube" "green cube"!         .  .  R  R  S
    let mut t = Tree::new(NodeKind::Sequence);
    let f = t.add_child(t.root(), NodeKind::Fallback).unwrap();
    t.add_child(f, cond("\"blue cube\" grasped")).unwrap();
    let grasp = t.add_child(f, act("grasp \"blue cube\"")).unwrap();
    let place = t
        .add_child(t.root(), act("place \"blue cube\" \"green cube\""))
        .unwrap();
    use ActionStep::{Running as AR, Success as AS};
    let mut script = Script {
        conditions: vec![("\"blue cube\" grasped", vec![false, false, false, true])],
        actions: vec![
            ("grasp \"blue cube\"", vec![AR, AR, AS]),
            (
                "place \"blue cube\" \"green cube\"",
                vec![AR, AR, AR, AR, AS],
            ),
        ],
        ..Script::default()
    };
    let mut ticker = Ticker::new();
    // tick 1: seq R, fallback R, grasped F, grasp R (start), place idle
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![R, R, F, R, I]);
    // tick 2: same, grasp continuing
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![R, R, F, R, I]);
    assert!(r.completed.is_empty());
    // tick 3: grasp succeeds -> fallback S -> place starts: R, S, F, S, R
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![R, S, F, S, R]);
    assert_eq!(r.completed, vec![grasp]);
    assert_eq!(r.running_action(), Some(place));
    // tick 4: grasped holds; grasp not reached but it was not Running, so no halt
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![R, S, S, I, R]);
    assert!(r.halted.is_empty());
    // tick 5: place succeeds -> everything done: S, S, S, idle, S
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.root, Outcome::Success);
    assert_eq!(r.statuses, vec![S, S, S, I, S]);
    assert_eq!(r.completed, vec![place]);
    assert_eq!(
        script.log,
        [
            "1: start #3",
            "2: step #3",
            "3: step #3",
            "3: start #4",
            "4: step #4",
            "5: step #4"
        ]
    );
    assert_eq!(ticker.tick_count(), 5);
}

#[test]
fn fallback_halts_when_goal_starts_to_hold_and_failures_carry_text() {
    // [0] fallback
    // [1]   On_Coffee_Table1?         F  T  F
    // [2]   PutDown "Coffee" "Table1"!  R  H  F("gripper jammed")
    let mut t = Tree::new(NodeKind::Fallback);
    t.add_child(t.root(), cond("On_Coffee_Table1")).unwrap();
    let put = t
        .add_child(t.root(), act("PutDown \"Coffee\" \"Table1\""))
        .unwrap();
    let mut script = Script {
        conditions: vec![("On_Coffee_Table1", vec![false, true, false])],
        actions: vec![(
            "PutDown \"Coffee\" \"Table1\"",
            vec![
                ActionStep::Running,
                ActionStep::Running,
                ActionStep::Failure("gripper jammed".into()),
            ],
        )],
        ..Script::default()
    };
    let mut ticker = Ticker::new();
    // tick 1: R, F, R
    assert_eq!(run(&mut ticker, &t, &mut script).statuses, vec![R, F, R]);
    // tick 2: goal holds: S, S, Halted
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![S, S, H]);
    assert_eq!(r.halted, vec![put]);
    // tick 3: goal gone, action restarts and fails: F, F, F
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![F, F, F]);
    assert_eq!(r.failures, vec![(put, "gripper jammed".to_string())]);
    assert_eq!(script.log, ["1: start #2", "2: halt #2", "3: start #2"]);
}

#[test]
fn halt_all_halts_once() {
    // [0] sequence
    // [1]   Sweep!   R
    let mut t = Tree::new(NodeKind::Sequence);
    let sweep = t.add_child(t.root(), act("Sweep")).unwrap();
    let mut script = Script {
        actions: vec![("Sweep", vec![ActionStep::Running])],
        ..Script::default()
    };
    let mut ticker = Ticker::new();
    assert_eq!(run(&mut ticker, &t, &mut script).statuses, vec![R, R]);
    assert_eq!(ticker.running(), vec![sweep]);
    assert_eq!(ticker.halt_all(&t, &mut script), vec![sweep]);
    assert!(ticker.running().is_empty());
    assert_eq!(ticker.halt_all(&t, &mut script), Vec::<NodeId>::new());
    // After halt_all the next tick is a fresh start: R, R.
    assert_eq!(run(&mut ticker, &t, &mut script).statuses, vec![R, R]);
    assert_eq!(script.log, ["1: start #1", "1: halt #1", "2: start #1"]);
    ticker.reset();
    assert_eq!(ticker.tick_count(), 0);
    assert_eq!(run(&mut ticker, &t, &mut script).tick, 1);
    assert_eq!(script.log.last().unwrap(), "1: start #1");
}

#[test]
fn edits_between_ticks() {
    // tick 1:                  tick 2 (after edits):
    // [0] sequence      R       [0] sequence              F
    // [1]   Sweep!      R       [1]   (removed)           H
    //                           [2]   Clean_Floor?        F
    let mut t = Tree::new(NodeKind::Sequence);
    let sweep = t.add_child(t.root(), act("Sweep")).unwrap();
    let mut script = Script {
        conditions: vec![("Clean_Floor", vec![false])],
        actions: vec![("Sweep", vec![ActionStep::Running])],
        ..Script::default()
    };
    let mut ticker = Ticker::new();
    assert_eq!(run(&mut ticker, &t, &mut script).statuses, vec![R, R]);
    let check = t.add_child(t.root(), cond("Clean_Floor")).unwrap();
    t.remove_subtree(sweep).unwrap();
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![F, H, F]);
    assert_eq!(r.statuses.len(), t.capacity());
    assert_eq!(r.halted, vec![sweep]);
    assert_eq!(r.visited, vec![t.root(), check]);
    assert_eq!(r.status(NodeId(40)), I);
    assert_eq!(script.log, ["1: start #1", "2: halt #1"]);
}

#[test]
fn a_condition_forced_to_fail_sends_the_fallback_to_its_other_branch() {
    // [0] fallback
    // [1]   "blue cube" on "green cube"?   holds, but forced to Failure
    // [2]   place "blue cube" "green cube"!
    let mut t = Tree::new(NodeKind::Fallback);
    let goal = t
        .add_child(t.root(), cond("\"blue cube\" on \"green cube\""))
        .unwrap();
    let place = t
        .add_child(t.root(), act("place \"blue cube\" \"green cube\""))
        .unwrap();
    let mut script = Script {
        conditions: vec![("\"blue cube\" on \"green cube\"", vec![true])],
        actions: vec![(
            "place \"blue cube\" \"green cube\"",
            vec![ActionStep::Running],
        )],
        ..Script::default()
    };
    let mut ticker = Ticker::new();
    // Unforced: the goal holds, the action is not reached.
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![S, S, I]);
    assert!(r.forced.is_empty());
    assert_eq!(script.checked.len(), 1);
    // Forced to fail: not checked, the fallback takes its other branch.
    let r = run_forced(&mut ticker, &t, &mut script, &[(goal, Forced::Failure)]);
    assert_eq!(r.statuses, vec![R, F, R]);
    assert_eq!(r.forced, vec![goal]);
    assert_eq!(r.running_action(), Some(place));
    assert_eq!(script.checked.len(), 1, "a forced condition is not checked");
    // Cleared: the goal is checked again, holds, and the running action is halted.
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![S, S, H]);
    assert_eq!(r.halted, vec![place]);
    assert_eq!(script.log, ["2: start #2", "3: halt #2"]);
}

#[test]
fn a_forced_action_is_not_stepped_and_a_forced_running_one_never_starts() {
    // [0] sequence
    // [1]   grasp "blue cube"!
    let mut t = Tree::new(NodeKind::Sequence);
    let grasp = t.add_child(t.root(), act("grasp \"blue cube\"")).unwrap();
    let mut script = Script {
        actions: vec![("grasp \"blue cube\"", vec![ActionStep::Running])],
        ..Script::default()
    };
    let mut ticker = Ticker::new();
    let r = run_forced(&mut ticker, &t, &mut script, &[(grasp, Forced::Success)]);
    assert_eq!((r.root, r.statuses.clone()), (Outcome::Success, vec![S, S]));
    assert!(r.completed.is_empty(), "forced, not completed");
    assert!(
        script.log.is_empty(),
        "Leaves::step was called: {:?}",
        script.log
    );
    // Forced Running: shown running, but not started in the world nor remembered, so
    // nothing is halted once the force is cleared, and the next tick starts it afresh.
    let r = run_forced(&mut ticker, &t, &mut script, &[(grasp, Forced::Running)]);
    assert_eq!(r.statuses, vec![R, R]);
    assert!(ticker.running().is_empty());
    let r = run(&mut ticker, &t, &mut script);
    assert_eq!(r.statuses, vec![R, R]);
    assert!(r.halted.is_empty());
    assert_eq!(script.log, ["3: start #1"]);
    // Forced while it runs in the world: halted there, shown with the forced status.
    let r = run_forced(&mut ticker, &t, &mut script, &[(grasp, Forced::Failure)]);
    assert_eq!((r.root, r.statuses.clone()), (Outcome::Failure, vec![F, F]));
    assert_eq!(r.halted, vec![grasp]);
    assert!(
        r.failures.is_empty(),
        "a forced failure is not the action's"
    );
    assert_eq!(script.log, ["3: start #1", "4: halt #1"]);
}

#[test]
fn a_forced_composite_does_not_tick_its_children() {
    // [0] sequence            forced Success
    // [1]   "path" clear?
    // [2]   Sweep!
    let mut t = Tree::new(NodeKind::Sequence);
    t.add_child(t.root(), cond("\"path\" clear")).unwrap();
    t.add_child(t.root(), act("Sweep")).unwrap();
    let mut script = Script::default();
    let mut ticker = Ticker::new();
    let root = t.root();
    let r = run_forced(&mut ticker, &t, &mut script, &[(root, Forced::Success)]);
    assert_eq!(r.statuses, vec![S, I, I]);
    assert_eq!(r.visited, vec![root]);
    assert!(script.checked.is_empty() && script.log.is_empty());
}
