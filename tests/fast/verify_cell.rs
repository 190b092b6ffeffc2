//! Verification in the tabletop cell. The initial state is `World::facts()` of the
//! geometric cell, so the facts must report what the geometry says for every condition a
//! tree observes (wildcards included) — checked along real runs. Deliberately broken cell
//! trees fail with a counterexample whose last state really violates the property, and
//! the geometric world agrees (the action the counterexample blames fails there too);
//! the repaired tree of scenario 1 recovers from the disturbance its scenario declares,
//! and not from one it has no branch for. SPIN agrees on every verdict.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use crate::support;

use betr::bt::{NodeId, NodeKind, Outcome, Tree};
use betr::domain::{Atom, Condition};
use betr::planner::{RunEnd, run_tree};
use betr::scenario::Scenario;
use betr::verify::counterexample::{Counterexample, Event};
use betr::verify::{self, PropertyKind, Rule, VerifyConfig};
use betr::world::{self, World};
use support::verify::{
    before_last, check, counterexample, has, holds_over, load, repaired, root, spin_agrees, text,
    tick_over,
};

const CELL: [&str; 7] = [
    "scenarios/cell/red_on_blue.toml",
    "scenarios/cell/blocked_both.toml",
    "scenarios/cell/flip_cup.toml",
    "scenarios/cell/centrifuge.toml",
    "scenarios/cell/cupboard.toml",
    "scenarios/cell/banana_unknown.toml",
    "scenarios/cell/banana_far.toml",
];

/// Every condition a verification of `tree` can observe: the tree's conditions, its
/// actions' declared preconditions, and the goal's atoms.
fn observed(s: &Scenario, tree: &Tree) -> Vec<Condition> {
    let mut out: Vec<Condition> = tree
        .conditions()
        .into_iter()
        .map(|(_, c)| c.clone())
        .collect();
    for (_, a) in tree.actions() {
        out.extend(s.domain.resolve(a).unwrap().pre);
    }
    out.extend(
        s.goal
            .clone()
            .unwrap()
            .atoms()
            .into_iter()
            .map(Condition::pos),
    );
    out
}

fn atoms(world: &dyn World) -> Vec<Atom> {
    world.facts().into_iter().map(|c| c.atom).collect()
}

/// The facts agree with the geometry on every observed condition.
fn agree(file: &str, world: &dyn World, conditions: &[Condition], when: &str) {
    let facts = atoms(world);
    for c in conditions {
        assert_eq!(
            holds_over(&facts, c),
            world.check(c),
            "{file} {when}: {c} over the facts {facts:?}"
        );
    }
}

#[test]
fn cell_facts_report_the_geometry_every_observed_condition_needs() {
    // The obstacle of each scenario is in the facts, and what is fine is too.
    let expect: [(&str, &[&str], &[&str]); 7] = [
        (
            CELL[0],
            &[
                "\"red cube\" on \"blue cube\"",
                "\"blue cube\" on \"table\"",
                "\"red cube\" near robot",
            ],
            &["\"blue cube\" grasped"],
        ),
        (
            CELL[1],
            &[
                "\"red cube\" on \"blue cube\"",
                "\"yellow cube\" on \"green cube\"",
            ],
            &[],
        ),
        (
            CELL[2],
            &["\"green cube\" upright", "\"red cup\" location known"],
            &["\"red cup\" upright"],
        ),
        (
            CELL[3],
            &["\"test tube\" on \"table\"", "\"centrifuge\" unlocked"],
            &["\"centrifuge\" open"],
        ),
        (
            CELL[4],
            &["\"plate\" near robot"],
            &["\"cupboard\" unlocked", "\"cupboard\" open"],
        ),
        (
            CELL[5],
            &["\"tray\" location known", "\"banana\" on \"table\""],
            &["\"banana\" location known"],
        ),
        (
            CELL[6],
            &["\"tray\" near robot", "\"banana\" location known"],
            &["\"banana\" near robot"],
        ),
    ];
    for (file, present, absent) in expect {
        let s = load(file);
        let tree = repaired(&s);
        let conditions = observed(&s, &tree);
        for variant in [None, Some("clear")] {
            let world = world::load_variant(&s, variant).unwrap();
            if variant.is_none() {
                let facts = atoms(world.as_ref());
                for a in present {
                    assert!(has(&facts, a), "{file}: {a} missing from {facts:?}");
                }
                for a in absent {
                    assert!(!has(&facts, a), "{file}: {a} in {facts:?}");
                }
            }
            // Along the whole run, as grasps, places, flips and drives change the scene.
            let mut exec = world.fork();
            agree(file, exec.as_ref(), &conditions, "initially");
            let report = run_tree(&tree, exec.as_mut(), &s.domain, 1000, |_, w| {
                agree(file, w, &conditions, "during the run");
                true
            });
            assert_eq!(report.end, RunEnd::Success, "{file} {variant:?}");
            agree(file, exec.as_ref(), &conditions, "at the end");
        }
    }
}

fn print(what: &str, cx: &Counterexample) {
    eprintln!("--- {what}\n{cx}");
}

/// The Fallback that is `parent`'s child whose first child is the condition `c`.
fn fallback_for(tree: &Tree, parent: NodeId, c: &str) -> NodeId {
    let children = tree.children(parent).unwrap().to_vec();
    children
        .into_iter()
        .find(|&f| {
            matches!(tree.kind(f), Ok(NodeKind::Fallback))
                && matches!(tree.kind(tree.children(f).unwrap()[0]), Ok(NodeKind::Condition(k)) if k.to_string() == c)
        })
        .unwrap_or_else(|| panic!("no fallback for {c}:\n{}", text(tree)))
}

fn action(tree: &Tree, call: &str) -> NodeId {
    let (n, _) = tree
        .actions()
        .into_iter()
        .find(|(_, a)| a.to_string() == call)
        .unwrap();
    n
}

/// Run `tree` in the scenario's geometric world; the action that fails and its text.
fn geometric_failure(s: &Scenario, tree: &Tree) -> Option<(String, String)> {
    let mut exec = world::load(s).unwrap().fork();
    let report = run_tree(tree, exec.as_mut(), &s.domain, 1000, |_, _| true);
    match report.end {
        RunEnd::Failure { action } => action.map(|(n, e)| {
            let Ok(NodeKind::Action(a)) = tree.kind(n) else {
                panic!()
            };
            (a.to_string(), e)
        }),
        other => panic!("expected the geometric world to fail, got {other:?}"),
    }
}

#[test]
fn without_the_inserted_branch_the_blue_cube_is_lifted_with_the_red_one_on_it() {
    let s = load(CELL[0]);
    let mut tree = repaired(&s);
    let grasp = action(&tree, "grasp \"blue cube\"");
    let seq = tree.parent(grasp).unwrap().unwrap();
    tree.remove_subtree(fallback_for(&tree, seq, "~\"any object\" on \"blue cube\""))
        .unwrap();

    let (report, model) = check(&s, &tree, false);
    let cx = counterexample(&report, PropertyKind::User(0));
    print("scenario 1 without the inserted branch", cx);
    let Some(Event::Tick { .. }) = cx.steps.last().map(|s| &s.event) else {
        panic!("{cx}")
    };
    let last = cx.last_state();
    assert!(
        has(last, "\"blue cube\" grasped") && has(last, "\"red cube\" on \"blue cube\""),
        "{cx}"
    );
    let (_, started) = tick_over(&tree, before_last(cx));
    assert_eq!(started[0].to_string(), "grasp \"blue cube\"", "{cx}");
    // The geometry agrees: that grasp has no collision free path.
    let (failed, error) = geometric_failure(&s, &tree).unwrap();
    assert_eq!(
        (failed.as_str(), error.as_str()),
        ("grasp \"blue cube\"", "No collision free path found")
    );
    spin_agrees(&report, &model, "cell-no-branch");
}

#[test]
fn without_the_hand_empty_expansion_the_blue_cube_is_grasped_with_the_hand_full() {
    let s = load(CELL[0]);
    let mut tree = repaired(&s);
    let grasp = action(&tree, "grasp \"blue cube\"");
    let seq = tree.parent(grasp).unwrap().unwrap();
    tree.remove_subtree(fallback_for(&tree, seq, "~\"any object\" grasped"))
        .unwrap();

    let (report, model) = check(&s, &tree, false);
    assert!(
        report
            .findings
            .iter()
            .any(|f| f.rule == Rule::UnguardedPrecondition && f.path == tree.path(grasp).unwrap()),
        "{:?}",
        report.findings
    );
    let cx = counterexample(&report, PropertyKind::Preconditions);
    print(
        "scenario 1 without the expansion of ~\"any object\" grasped",
        cx,
    );
    let Some(Event::Tick { unmet, .. }) = cx.steps.last().map(|s| &s.event) else {
        panic!("{cx}")
    };
    assert_eq!(unmet[0].0.call.to_string(), "grasp \"blue cube\"", "{cx}");
    assert_eq!(unmet[0].1.to_string(), "~\"any object\" grasped");
    let before = before_last(cx);
    assert!(has(before, "\"red cube\" grasped"), "{cx}");
    assert_eq!(
        tick_over(&tree, before).1[0].to_string(),
        "grasp \"blue cube\""
    );
    let (failed, error) = geometric_failure(&s, &tree).unwrap();
    assert_eq!(failed, "grasp \"blue cube\"");
    assert!(error.contains("needs a free hand"), "{error}");
    spin_agrees(&report, &model, "cell-hand-full");
}

#[test]
fn grasping_the_cube_before_flipping_the_cup_is_a_dead_end() {
    let s = load(CELL[2]);
    let mut tree = repaired(&s);
    let put = action(&tree, "put_in \"green cube\" \"red cup\"");
    let seq = tree.parent(put).unwrap().unwrap();
    tree.move_child(seq, 1, 0).unwrap(); // "green cube" grasped before "red cup" upright

    let (report, model) = check(&s, &tree, false);
    let cx = counterexample(&report, PropertyKind::Success);
    print("scenario 3 with swapped siblings", cx);
    assert!(cx.violation.starts_with("dead end"), "{cx}");
    let last = cx.last_state();
    assert!(
        has(last, "\"green cube\" grasped") && !has(last, "\"red cup\" upright"),
        "{cx}"
    );
    assert_eq!(
        tick_over(&tree, last),
        (Outcome::Failure, Vec::new()),
        "{cx}"
    );
    // The geometric world ends the same way: the root fails with no action failing.
    assert_eq!(geometric_failure(&s, &tree), None);
    spin_agrees(&report, &model, "cell-swapped");
}

#[test]
fn the_repaired_tree_recovers_when_the_red_cube_is_put_back() {
    let s = load(CELL[0]);
    let tree = repaired(&s);
    let config = VerifyConfig::from_scenario(&s).unwrap();
    assert_eq!(config.disturbances.len(), 1);
    let initial = world::load(&s).unwrap().facts();
    let states = |disturbances: &[verify::Disturbance]| {
        let input = verify::VerifyInput {
            domain: &s.domain,
            tree: &tree,
            initial: &initial,
            disturbances,
            properties: &config.properties,
            limits: verify::Limits::default(),
        };
        assert_eq!(
            verify::build_model(&input).unwrap().disturbances.len(),
            disturbances.len()
        );
        let report = verify::verify(&input);
        assert!(report.holds(), "{report:#?}");
        report.model.unwrap().states
    };
    // The disturbance reaches states the undisturbed run never does, and from each of
    // them the tree still succeeds.
    assert!(states(&config.disturbances) > states(&[]));
    for failures in [false, true] {
        let (report, model) = check(&s, &tree, failures);
        assert!(report.holds(), "{report:#?}");
        spin_agrees(&report, &model, &format!("cell-put-back-{failures}"));
    }
}

#[test]
fn a_cube_handed_to_the_robot_is_a_dead_end() {
    let text = r#"
extends = "red_on_blue.toml"
[scenario]
name = "Red cube on the blue cube, green cube handed over"
goal = '"blue cube" on "green cube"'
expected_fix = ['~"any object" on "blue cube"']
[[verify.disturbances]]
description = "a person may hand the robot the green cube"
pre = ['~"any object" grasped', '~"any object" on "green cube"']
add = ['"green cube" grasped']
del = ['"green cube" on "{*}"']
"#;
    let s = Scenario::from_text(&root().join("scenarios/cell/handed.toml"), text).unwrap();
    let tree = repaired(&s);
    let (report, model) = check(&s, &tree, false);
    let cx = counterexample(&report, PropertyKind::Success);
    print("scenario 1 with the green cube handed over", cx);
    assert!(cx.violation.starts_with("dead end"), "{cx}");
    assert!(
        cx.steps.iter().any(|s| matches!(&s.event, Event::Disturbance { description, .. } if description.contains("green cube"))),
        "{cx}"
    );
    assert!(has(cx.last_state(), "\"green cube\" grasped"), "{cx}");
    assert_eq!(
        tick_over(&tree, cx.last_state()),
        (Outcome::Failure, Vec::new()),
        "{cx}"
    );
    spin_agrees(&report, &model, "cell-handed");
}
