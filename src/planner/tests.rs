//! Planner tests on a small cafe written inline: the shape of expansions, conflicts,
//! unreachable conditions, repair and value propagation.

use std::path::Path;

use super::*;
use crate::bt::{self, NodeKind};
use crate::domain::Value;
use crate::goal::Formula;
use crate::scenario::Scenario;
use crate::world;

const MINI_CAFE: &str = r#"
[scenario]
name = "mini cafe"

[objects]
item = ["Cup", "Milk"]
place = ["Bar", "Table"]
nothing = ["Nothing"]
appliance = ["AC"]

[[predicates]]
name = "RobotNear"
args = ["place|item"]
description = "the robot is near it"
[[predicates]]
name = "On"
args = ["item", "place"]
description = "the item is at the place"
[[predicates]]
name = "Holding"
args = ["item|nothing"]
description = "the robot holds it"
[[predicates]]
name = "Active"
args = ["appliance"]
description = "the appliance is on"

[[skills]]
name = "MoveTo"
params = ["t: place|item"]
add = ["RobotNear_{t}"]
del = ["RobotNear_{*}"]
cost = 10
ticks = 2
[[skills]]
name = "PickUp"
params = ["i: item"]
pre = ["RobotNear_{i}", "Holding_Nothing"]
add = ["Holding_{i}"]
del = ["Holding_Nothing", "On_{i}_{*}"]
cost = 2
[[skills]]
name = "PutDown"
params = ["i: item", "p: place"]
pre = ["Holding_{i}", "RobotNear_{p}"]
add = ["On_{i}_{p}", "Holding_Nothing"]
del = ["Holding_{i}"]
cost = 100

[world]
initial = ["Holding_Nothing", "RobotNear_Bar", "On_Cup_Bar", "On_Milk_Bar"]
"#;

fn mini() -> Scenario {
    Scenario::from_text(Path::new("mini.toml"), MINI_CAFE).unwrap()
}

fn plan(scenario: &Scenario, goal: &str) -> Plan {
    let world = world::load(scenario).unwrap();
    let dnf = Formula::parse(goal).unwrap().to_dnf();
    Planner::new(&scenario.domain)
        .plan(&dnf, world.as_ref())
        .unwrap()
}

#[test]
fn goal_tree_follows_the_dnf() {
    let dnf = |g: &str| Formula::parse(g).unwrap().to_dnf();
    let text = |g: &str| bt::to_text(&Planner::goal_tree(&dnf(g)).unwrap());
    assert_eq!(text("On_Cup_Table"), "On_Cup_Table?\n");
    assert_eq!(
        text("On_Cup_Table & Holding_Nothing"),
        "sequence\n  On_Cup_Table?\n  Holding_Nothing?\n"
    );
    assert_eq!(
        text("On_Cup_Table | On_Milk_Table & Holding_Nothing"),
        "fallback\n  On_Cup_Table?\n  sequence\n    On_Milk_Table?\n    Holding_Nothing?\n"
    );
    assert_eq!(
        Planner::goal_tree(&dnf("Active_AC & ~Active_AC")).unwrap_err(),
        RepairError::FalseGoal
    );
}

#[test]
fn a_failing_condition_becomes_fallback_of_condition_and_achieving_skill() {
    let s = mini();
    let p = plan(&s, "On_Cup_Table");
    assert_eq!(p.outcome, Outcome::Success);
    // PutDown needs the cup in hand and the robot at the table; each expanded in turn.
    assert_eq!(
        bt::to_text(&p.tree),
        "fallback\n  On_Cup_Table?\n  sequence\n    fallback\n      Holding_Cup?\n      sequence\n        fallback\n          RobotNear_Cup?\n          MoveTo \"Cup\"!\n        Holding_Nothing?\n        PickUp \"Cup\"!\n    fallback\n      RobotNear_Table?\n      MoveTo \"Table\"!\n    PutDown \"Cup\" \"Table\"!\n"
    );
    assert_eq!(p.expansions, 4);
    assert_eq!(p.reorders, 0);
}

#[test]
fn a_subtree_that_undoes_an_earlier_goal_is_moved_before_it() {
    let s = mini();
    // Holding the cup first, then fetching milk, would put the cup down: the planner
    // must deliver the milk first.
    let p = plan(&s, "Holding_Cup & On_Milk_Table");
    assert_eq!(p.outcome, Outcome::Success, "{}", bt::to_text(&p.tree));
    assert!(p.reorders >= 1);
    let root = p.tree.root();
    let first = p.tree.children(root).unwrap()[0];
    let first_condition = p.tree.children(first).map(|c| c[0]).unwrap_or(first);
    assert!(
        matches!(p.tree.kind(first_condition).unwrap(), NodeKind::Condition(c) if c.to_string() == "On_Milk_Table")
    );
}

/// A room behind a door that one-tick skills open and close.
const DOOR: &str = r#"
[scenario]
name = "door"

[objects]
item = ["Cup"]
place = ["Bar", "Room"]
door = ["Door"]
nothing = ["Nothing"]

[[predicates]]
name = "RobotNear"
args = ["place|item"]
description = "the robot is near it"
[[predicates]]
name = "On"
args = ["item", "place"]
description = "the item is at the place"
[[predicates]]
name = "Holding"
args = ["item|nothing"]
description = "the robot holds it"
[[predicates]]
name = "Open"
args = ["door"]
description = "the door is open"

[[skills]]
name = "MoveTo"
params = ["t: place|item"]
pre = ["Open_Door"]
add = ["RobotNear_{t}"]
del = ["RobotNear_{*}"]
[[skills]]
name = "PickUp"
params = ["i: item"]
pre = ["RobotNear_{i}", "Holding_Nothing"]
add = ["Holding_{i}"]
del = ["Holding_Nothing", "On_{i}_{*}"]
[[skills]]
name = "PutDown"
params = ["i: item", "p: place"]
pre = ["Holding_{i}", "RobotNear_{p}"]
add = ["On_{i}_{p}", "Holding_Nothing"]
del = ["Holding_{i}"]
[[skills]]
name = "OpenDoor"
params = ["d: door"]
pre = ["~Open_{d}"]
add = ["Open_{d}"]
[[skills]]
name = "CloseDoor"
params = ["d: door"]
pre = ["Open_{d}"]
del = ["Open_{d}"]

[world]
initial = ["Holding_Nothing", "RobotNear_Bar", "On_Cup_Bar"]
"#;

#[test]
fn a_precondition_undone_once_what_it_was_for_is_done_is_no_conflict() {
    let s = Scenario::from_text(Path::new("door.toml"), DOOR).unwrap();
    // The door must be open to carry the cup in, and is closed after: closing it in the
    // tick the cup is set down undoes a precondition nothing needs any more.
    let p = plan(&s, "On_Cup_Room & ~Open_Door");
    assert_eq!(p.outcome, Outcome::Success, "{}", bt::to_text(&p.tree));
    // Holding the cup while it stands in the room is still two states at once.
    let p = plan(&s, "On_Cup_Room & Holding_Cup");
    assert!(!matches!(p.outcome, Outcome::Success), "{:?}", p.outcome);
}

#[test]
fn a_condition_no_skill_achieves_is_reported_with_where_and_why() {
    let s = mini();
    let p = plan(&s, "On_Cup_Table & Active_AC");
    match &p.outcome {
        Outcome::Unreachable {
            condition,
            path,
            reason,
            ..
        } => {
            assert_eq!(condition.to_string(), "Active_AC");
            assert_eq!(path, &vec![1]);
            assert!(
                reason.contains("no skill has an effect that makes Active_AC true"),
                "{reason}"
            );
        }
        other => panic!("expected Unreachable, got {other:?}"),
    }
}

#[test]
fn goals_that_need_opposite_states_at_once_are_reported() {
    let s = mini();
    // The cup cannot be both held and lying on the table.
    let p = plan(&s, "Holding_Cup & On_Cup_Table");
    assert!(
        !matches!(p.outcome, Outcome::Success),
        "{}",
        bt::to_text(&p.tree)
    );
    let text = format!("{:?}", p.outcome);
    assert!(
        text.contains("On_Cup_Table") && text.contains("Holding_Cup"),
        "{text}"
    );
}

#[test]
fn repair_inserts_first_preconditions_and_expands_them() {
    let s = mini();
    let p = plan(&s, "On_Cup_Table");
    let (put_down, _) = p
        .tree
        .actions()
        .into_iter()
        .find(|(_, a)| a.skill == "PutDown")
        .unwrap();
    let planner = Planner::new(&s.domain);
    let world = world::load(&s).unwrap();
    let fix = Condition::parse("On_Milk_Table").unwrap();
    let repaired = planner
        .repair(
            p.tree.clone(),
            put_down,
            std::slice::from_ref(&fix),
            world.as_ref(),
        )
        .unwrap();
    assert_eq!(
        repaired.outcome,
        Outcome::Success,
        "{}",
        bt::to_text(&repaired.tree)
    );
    let seq = repaired.tree.parent(put_down).unwrap().unwrap();
    let first = repaired.tree.children(seq).unwrap()[0];
    let first_condition = repaired.tree.children(first).map(|c| c[0]).unwrap_or(first);
    assert_eq!(
        repaired.tree.kind(first_condition).unwrap(),
        &NodeKind::Condition(fix.clone())
    );
    assert!(repaired.new_nodes.len() > 1);
    assert!(repaired.new_nodes.iter().all(|n| p.tree.kind(*n).is_err()));
    // The same proposal again adds nothing.
    let again = planner.repair(repaired.tree, put_down, &[fix], world.as_ref());
    assert!(matches!(again, Err(RepairError::NothingNew(_))));
    // Repairing a condition node is refused.
    let cond = p.tree.root();
    assert_eq!(
        planner
            .repair(p.tree.clone(), cond, &[], world.as_ref())
            .unwrap_err(),
        RepairError::NotAnAction(cond)
    );
}

#[test]
fn a_value_reaches_every_node_of_that_skill_and_object() {
    let s = mini();
    let mut tree = plan(&s, "On_Cup_Table & On_Milk_Table").tree;
    let force = Value::Number {
        value: 5.0,
        unit: "N".into(),
    };
    let changed = set_value(&mut tree, "PickUp", "Cup", "force", &force);
    assert_eq!(changed, 1);
    let with: Vec<String> = tree
        .actions()
        .into_iter()
        .filter(|(_, a)| a.value("force").is_some())
        .map(|(_, a)| a.to_string())
        .collect();
    assert_eq!(with, vec!["PickUp \"Cup\" {force = 5 N}"]);
}

#[test]
fn check_tree_names_the_node_that_does_not_fit() {
    let s = mini();
    let tree = bt::parse("sequence\n  On_Cup_Table?\n  Fly \"Cup\"!\n").unwrap();
    let e = check_tree(&s.domain, &tree).unwrap_err();
    assert_eq!(e.path, vec![1]);
    assert!(e.to_string().starts_with("node 1 (Fly \"Cup\"!)"), "{e}");
    let tree = bt::parse("On_Tea_Table?\n").unwrap();
    assert!(
        check_tree(&s.domain, &tree)
            .unwrap_err()
            .reason
            .contains("unknown object \"Tea\"")
    );
}
