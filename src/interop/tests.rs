use std::path::Path;

use super::*;
use crate::bt;
use crate::scenario::Scenario;

fn scenario(rel: &str) -> Scenario {
    Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).expect("scenario")
}

fn import(xml_tree: &str, s: &Scenario) -> Result<Imported, XmlError> {
    from_btcpp(
        &format!(
            "<root BTCPP_format=\"4\"><BehaviorTree ID=\"T\">{xml_tree}</BehaviorTree></root>"
        ),
        &s.domain,
    )
}

#[test]
fn a_predicate_named_like_a_skill_gets_another_id() {
    let s = scenario("scenarios/cell/centrifuge.toml");
    assert!(s.domain.skills.iter().any(|k| k.name == "open"));
    assert_eq!(condition_id(&s.domain, "open"), "is_open");
    assert_eq!(condition_id(&s.domain, "near robot"), "near_robot");
    let read = import(r#"<is_open arg1="centrifuge"/>"#, &s).expect("condition");
    assert_eq!(bt::to_text(&read.tree), "\"centrifuge\" open?\n");
}

#[test]
fn values_are_typed_by_the_skill() {
    let s = scenario("scenarios/cell/params/egg.toml");
    let read = import(r#"<Action ID="grasp" force="5.5 N" x="egg"/>"#, &s).expect("action");
    assert_eq!(bt::to_text(&read.tree), "grasp \"egg\" {force = 5.5 N}!\n");
    let e = import(r#"<Action ID="grasp" x="egg" force="5 kg"/>"#, &s).unwrap_err();
    assert!(e.reason.contains("is not a number in N"), "{e}");
    let plate = scenario("scenarios/cell/params/plate.toml");
    let skill = plate
        .domain
        .skills
        .iter()
        .find(|k| k.values.iter().any(|v| v.unit.is_none()))
        .expect("a skill with a category");
    let value = &skill.values[0];
    let ports: Vec<String> = skill
        .params
        .iter()
        .map(|p| {
            let object = p
                .candidates(&plate.domain.vocabulary)
                .next()
                .unwrap_or_default();
            format!("{}=\"{object}\"", p.name)
        })
        .collect();
    let xml = format!(
        "<Action ID=\"{}\" {} {}=\"{}\"/>",
        skill.name,
        ports.join(" "),
        value.name,
        value.categories[0]
    );
    let read = import(&xml, &plate).expect("a category");
    assert!(
        bt::to_text(&read.tree)
            .contains(&format!("{{{} = \"{}\"}}", value.name, value.categories[0])),
        "{}",
        bt::to_text(&read.tree)
    );
}

#[test]
fn an_inverter_reads_over_a_condition_only() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let twice = import(
        r#"<Inverter><Inverter><Condition ID="grasped" arg1="red cube"/></Inverter></Inverter>"#,
        &s,
    )
    .expect("double negation");
    assert_eq!(bt::to_text(&twice.tree), "\"red cube\" grasped?\n");
    let e = import(
        r#"<Inverter><Action ID="grasp" x="red cube"/></Inverter>"#,
        &s,
    )
    .unwrap_err();
    assert!(e.reason.contains("over a condition only"), "{e}");
    assert_eq!((e.line, e.element.as_str()), (1, "<Inverter>"));
}

#[test]
fn structure_errors_are_located() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let deep = format!(
        "{}<Condition ID=\"grasped\" arg1=\"red cube\"/>{}",
        "<ReactiveSequence>".repeat(300),
        "</ReactiveSequence>".repeat(300)
    );
    let e = import(&deep, &s).unwrap_err();
    assert!(e.reason.contains("nested deeper than 256"), "{e}");
    let e = import("<ReactiveSequence/>", &s).unwrap_err();
    assert!(e.reason.contains("at least one child"), "{e}");
    let e = import(
        r#"<Condition ID="grasped" arg1="red cube" _skipIf="x"/>"#,
        &s,
    )
    .unwrap_err();
    assert!(
        e.reason.contains("scripted pre- and post-conditions"),
        "{e}"
    );
    let e = import(r#"<Condition ID="grasped"/>"#, &s).unwrap_err();
    assert!(e.reason.contains("port arg1 is missing"), "{e}");
    let e = import(r#"<Condition ID="grasped" arg1="moon"/>"#, &s).unwrap_err();
    assert!(e.reason.contains("unknown object \"moon\""), "{e}");
    let e = from_btcpp(
        r#"<root BTCPP_format="3"><BehaviorTree/></root>"#,
        &s.domain,
    )
    .unwrap_err();
    assert!(e.reason.contains("betr reads BT.CPP version 4"), "{e}");
    let two = r#"<root BTCPP_format="4"><BehaviorTree ID="A"><grasped arg1="red cube"/></BehaviorTree><BehaviorTree ID="B"><grasped arg1="red cube"/></BehaviorTree></root>"#;
    let e = from_btcpp(two, &s.domain).unwrap_err();
    assert!(e.reason.contains("no main_tree_to_execute"), "{e}");
}

#[test]
fn a_tree_file_is_told_apart_by_name_or_first_character() {
    assert_eq!(
        TreeFormat::of(Path::new("t.XML"), "sequence"),
        TreeFormat::BtCpp
    );
    assert_eq!(
        TreeFormat::of(Path::new("t.bt"), "  <root/>"),
        TreeFormat::BtCpp
    );
    assert_eq!(
        TreeFormat::of(Path::new("t.bt"), "# betr policy\n"),
        TreeFormat::Text
    );
}
