//! Structural rules and model checking on tiny hand-written trees over a tiny domain.

use std::path::Path;

use super::*;
use crate::bt::parse;
use crate::scenario::Scenario;
use crate::world;

const DOMAIN: &str = r#"
[scenario]
name = "tiny"
[objects]
item = ["Cup", "Mop"]
nothing = ["Nothing"]
place = ["Bar", "Table"]
[[predicates]]
name = "RobotNear"
args = ["place"]
description = "near"
[[predicates]]
name = "Holding"
args = ["item|nothing"]
description = "holds"
[[predicates]]
name = "On"
args = ["item", "place"]
description = "on"
[[skills]]
name = "MoveTo"
params = ["target: place"]
add = ["RobotNear_{target}"]
del = ["RobotNear_{*}"]
[[skills]]
name = "PickUp"
params = ["item: item"]
pre = ["Holding_Nothing"]
add = ["Holding_{item}"]
del = ["Holding_Nothing", "On_{item}_{*}"]
[[skills]]
name = "PutDown"
params = ["item: item", "place: place"]
pre = ["Holding_{item}", "RobotNear_{place}"]
add = ["On_{item}_{place}", "Holding_Nothing"]
del = ["Holding_{item}"]
[world]
initial = ["Holding_Nothing", "RobotNear_Bar", "On_Cup_Bar"]
"#;

const FETCH: &str = r#"
fallback
  On_Cup_Table?
  sequence
    fallback
      Holding_Cup?
      sequence
        fallback
          RobotNear_Bar?
          MoveTo "Bar"!
        Holding_Nothing?
        PickUp "Cup"!
    fallback
      RobotNear_Table?
      MoveTo "Table"!
    PutDown "Cup" "Table"!
"#;

fn scenario(extra: &str) -> Scenario {
    Scenario::from_text(Path::new("tiny.toml"), format!("{DOMAIN}{extra}")).unwrap()
}

fn run(s: &Scenario, tree: &str, failures: bool, properties: &[&str]) -> Report {
    let tree = parse(tree).unwrap();
    let config = VerifyConfig::from_scenario(s).unwrap();
    let facts = world::load(s).unwrap().facts();
    let properties: Vec<NamedProperty> = properties
        .iter()
        .map(|p| NamedProperty {
            text: p.to_string(),
            property: Property::parse_checked(p, &s.domain.vocabulary).unwrap(),
        })
        .collect();
    verify(&VerifyInput {
        domain: &s.domain,
        tree: &tree,
        initial: &facts,
        disturbances: &config.disturbances,
        properties: &properties,
        limits: Limits {
            action_failures: failures,
            ..Limits::default()
        },
    })
}

fn rules(r: &Report) -> Vec<(String, Rule)> {
    r.findings
        .iter()
        .map(|f| (crate::bt::path_text(&f.path), f.rule))
        .collect()
}

fn verdict(r: &Report, kind: PropertyKind) -> &Verdict {
    &r.property(kind).unwrap().verdict
}

fn counterexample(r: &Report, kind: PropertyKind) -> &Counterexample {
    match verdict(r, kind) {
        Verdict::Violated(c) => c,
        other => panic!("expected a violation, got {other:?}"),
    }
}

#[test]
fn a_correct_tree_passes_everything() {
    let s = scenario("");
    let r = run(
        &s,
        FETCH,
        false,
        &[
            "never Holding_Cup & Holding_Nothing",
            "eventually On_Cup_Table",
        ],
    );
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    assert!(r.holds(), "{r:#?}");
    let m = r.model.as_ref().unwrap();
    // PickUp, MoveTo, PutDown, then success: four states over five observed atoms.
    assert_eq!((m.states, m.atoms), (4, 5));
    assert_eq!(
        r.property(PropertyKind::Success).unwrap().detail,
        "at most 3 tick(s) from any reachable state"
    );
}

#[test]
fn a_missing_precondition_is_found_and_shown() {
    let s = scenario("");
    let tree = "sequence\n  fallback\n    RobotNear_Table?\n    MoveTo \"Table\"!\n  PutDown \"Cup\" \"Table\"!\n";
    let r = run(&s, tree, false, &[]);
    assert_eq!(
        rules(&r),
        vec![("1".to_string(), Rule::UnguardedPrecondition)]
    );
    assert!(r.findings[0].message.contains("Holding_Cup"));
    let cx = counterexample(&r, PropertyKind::Preconditions);
    assert!(cx.violation.contains("Holding_Cup"), "{cx}");
    // The robot moves first, then starts PutDown with an empty hand.
    assert_eq!(cx.steps.len(), 2, "{cx}");
}

#[test]
fn a_fallback_child_after_an_always_true_condition_is_unreachable() {
    let s = scenario("");
    let tree =
        "sequence\n  Holding_Nothing?\n  fallback\n    Holding_Nothing?\n    PickUp \"Cup\"!\n";
    let r = run(&s, tree, false, &[]);
    assert_eq!(rules(&r), vec![("1.1".to_string(), Rule::Unreachable)]);
    assert!(
        r.findings[0].message.contains("never fails"),
        "{}",
        r.findings[0]
    );
}

#[test]
fn an_oscillating_pair_is_flagged_and_livelocks() {
    let s = scenario("");
    // Going to the table before fetching the cup: fetching leaves the table, going back
    // leaves the bar, forever.
    let tree = r#"
sequence
  fallback
    RobotNear_Table?
    MoveTo "Table"!
  fallback
    Holding_Mop?
    sequence
      fallback
        RobotNear_Bar?
        MoveTo "Bar"!
      ~Holding_Mop?
      Holding_Nothing?
"#;
    let r = run(&s, tree, false, &[]);
    assert_eq!(rules(&r), vec![("1".to_string(), Rule::Oscillation)]);
    let cx = counterexample(&r, PropertyKind::Success);
    assert!(cx.violation.starts_with("livelock"), "{cx}");
    assert!(cx.loop_from.is_some());
}

#[test]
fn unknown_atoms_and_actions_are_findings() {
    let s = scenario("");
    let r = run(&s, "sequence\n  Flying_Cup?\n  Fly \"Cup\"!\n", false, &[]);
    assert_eq!(
        rules(&r),
        vec![
            ("0".to_string(), Rule::UnknownAtom),
            ("1".to_string(), Rule::UnknownAction)
        ]
    );
    assert!(r.model.is_err());
}

#[test]
fn a_dead_end_is_the_shortest_counterexample() {
    let s = scenario("");
    let r = run(
        &s,
        "fallback\n  Holding_Mop?\n  RobotNear_Table?\n",
        false,
        &[],
    );
    let cx = counterexample(&r, PropertyKind::Success);
    assert!(cx.violation.starts_with("dead end"), "{cx}");
    assert_eq!(cx.steps.len(), 1);
}

#[test]
fn disturbances_and_failures_widen_the_reachable_states() {
    let disturbed = scenario(
        r#"
[[verify.disturbances]]
description = "someone may push the robot away from the bar"
pre = ["RobotNear_Bar"]
del = ["RobotNear_Bar"]
"#,
    );
    let r = run(&disturbed, FETCH, false, &["eventually On_Cup_Table"]);
    // The tree goes back each time, but a person may keep pushing: eventually is adversarial.
    assert!(verdict(&r, PropertyKind::Success).holds(), "{r:#?}");
    let cx = counterexample(&r, PropertyKind::User(0));
    assert!(cx.loop_from.is_some(), "{cx}");
    let plain = run(&scenario(""), FETCH, false, &[]);
    assert!(
        r.model.as_ref().unwrap().states > plain.model.as_ref().unwrap().states,
        "the disturbance adds states"
    );

    // With failures, PickUp may fail and the tree simply retries: still fine.
    let r = run(
        &scenario(""),
        FETCH,
        true,
        &["always ~On_Cup_Bar | Holding_Nothing"],
    );
    assert!(r.holds(), "{r:#?}");
}

#[test]
fn always_and_never_point_at_the_first_bad_state() {
    let s = scenario("");
    let r = run(
        &s,
        FETCH,
        false,
        &["always Holding_Nothing", "never RobotNear_Table"],
    );
    let cx = counterexample(&r, PropertyKind::User(0));
    assert_eq!(cx.steps.len(), 1, "{cx}");
    assert!(
        !cx.last_state()
            .iter()
            .any(|a| a.to_string() == "Holding_Nothing")
    );
    let cx = counterexample(&r, PropertyKind::User(1));
    assert_eq!(cx.steps.len(), 2, "{cx}");
    assert!(cx.to_string().contains("+RobotNear_Table"), "{cx}");
}

#[test]
fn the_state_bound_gives_unknown_not_holds() {
    let s = scenario("");
    let tree = parse(FETCH).unwrap();
    let facts = world::load(&s).unwrap().facts();
    let r = verify(&VerifyInput {
        domain: &s.domain,
        tree: &tree,
        initial: &facts,
        disturbances: &[],
        properties: &[],
        limits: Limits {
            max_states: 2,
            ..Limits::default()
        },
    });
    assert!(matches!(
        verdict(&r, PropertyKind::Success),
        Verdict::Unknown { .. }
    ));
    assert!(!r.holds());
}

#[test]
fn promela_has_one_claim_per_property() {
    let s = scenario("");
    let tree = parse(FETCH).unwrap();
    let facts = world::load(&s).unwrap().facts();
    let props = [NamedProperty {
        text: "eventually On_Cup_Table".into(),
        property: Property::parse("eventually On_Cup_Table").unwrap(),
    }];
    let m = export_promela(&VerifyInput {
        domain: &s.domain,
        tree: &tree,
        initial: &facts,
        disturbances: &[],
        properties: &props,
        limits: Limits::default(),
    })
    .unwrap();
    let names: Vec<&str> = m.claims.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["success", "preconditions", "p0"]);
    assert!(m.text.contains("ltl p0 { <> f"), "{}", m.text);
    assert!(m.text.contains("bool calm = 1;"));
}

#[test]
fn an_unguarded_precondition_that_every_reachable_state_meets_is_a_note() {
    let s = scenario("");
    // PickUp needs Holding_Nothing; the tree never checks it, but the hand starts empty
    // and nothing else reachable fills it.
    let r = run(
        &s,
        "fallback\n  Holding_Cup?\n  PickUp \"Cup\"!\n",
        false,
        &[],
    );
    assert!(r.findings.is_empty(), "{:?}", r.findings);
    assert_eq!(r.notes.len(), 1, "{:?}", r.notes);
    assert_eq!(r.notes[0].rule, Rule::UnguardedPrecondition);
    assert!(r.notes[0].message.contains("Holding_Nothing"));
    assert!(r.holds(), "{r:#?}");
}
