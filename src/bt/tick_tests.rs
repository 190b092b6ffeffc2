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
}

fn at<T: Clone>(script: &[T], tick: usize) -> T {
    script[tick.min(script.len() - 1)].clone()
}

impl Leaves for Script {
    fn check(&mut self, condition: &Condition) -> bool {
        let text = condition.to_string();
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
