//! The `bt` public API as the planner and front ends use it: parse a policy, tick it
//! against a tiny world, repair it with `wrap`, render it.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use betr::bt::{
    ASCII, ActionStep, Leaves, NodeId, NodeKind, Outcome, Status, Ticker, Tree, UNICODE, parse,
    render, to_text,
};
use betr::domain::{ActionCall, Condition};

/// A one-fact world: the cube is on the table once `place` has run for two ticks.
#[derive(Default)]
struct World {
    placed: bool,
    progress: u32,
    halted: Vec<NodeId>,
}

impl Leaves for World {
    fn check(&mut self, condition: &Condition) -> bool {
        let holds = condition.atom.predicate == "on" && self.placed;
        holds != condition.negated
    }

    fn step(&mut self, _node: NodeId, action: &ActionCall, started: bool) -> ActionStep {
        if action.skill != "place" {
            return ActionStep::Failure(format!("unknown skill {}", action.skill));
        }
        if started {
            self.progress = 0;
        }
        self.progress += 1;
        if self.progress >= 2 {
            self.placed = true;
            ActionStep::Success
        } else {
            ActionStep::Running
        }
    }

    fn halt(&mut self, node: NodeId, _action: &ActionCall) {
        self.halted.push(node);
    }
}

#[test]
fn parse_tick_wrap_render() {
    let policy = "# goal: \"cube\" on \"table\"\nsequence\n  place \"cube\" \"table\"!\n";
    let mut tree: Tree = parse(policy).unwrap();
    let place = tree.node_at_path(&[0]).unwrap();

    // Repair as the planner does: guard the action with its goal condition.
    let goal = tree
        .insert_child(
            place,
            0,
            NodeKind::Condition(Condition::parse("\"cube\" on \"table\"").unwrap()),
        )
        .unwrap();
    // That made a leaf with children; validate says so, and we fix it.
    assert!(tree.validate().is_err());
    tree.remove_subtree(goal).unwrap();
    let fallback = tree.wrap(place, NodeKind::Fallback).unwrap();
    let goal = tree
        .insert_child(
            fallback,
            0,
            NodeKind::Condition(Condition::parse("\"cube\" on \"table\"").unwrap()),
        )
        .unwrap();
    tree.validate().unwrap();
    assert_eq!(
        to_text(&tree),
        "sequence\n  fallback\n    \"cube\" on \"table\"?\n    place \"cube\" \"table\"!\n"
    );
    assert_eq!(parse(&to_text(&tree)).unwrap(), tree);

    let mut world = World::default();
    let mut ticker = Ticker::new();
    let first = ticker.tick(&tree, &mut world);
    assert_eq!(first.root, Outcome::Running);
    assert_eq!(first.running_action(), Some(place));
    assert_eq!(first.status(goal), Status::Failure);
    let second = ticker.tick(&tree, &mut world);
    assert_eq!(second.root, Outcome::Success);
    assert_eq!(second.completed, vec![place]);
    let third = ticker.tick(&tree, &mut world);
    assert_eq!(third.status(goal), Status::Success);
    assert_eq!(third.status(place), Status::Idle);
    assert!(world.halted.is_empty());

    assert_eq!(
        render(&tree, Some(&first), &UNICODE),
        [
            "[-] Sequence [*]",
            "    [o] Fallback [*]",
            "        --> \"cube\" on \"table\"? [✕]",
            "        --> place \"cube\" \"table\"! [*]",
        ]
    );
    assert_eq!(
        render(&tree, Some(&third), &ASCII)[3],
        "        --> place \"cube\" \"table\"! [-]"
    );
}
