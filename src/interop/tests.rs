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
    assert!(e.reason.contains("port item is missing"), "{e}");
    let e = import(r#"<grasped item="red cube" arg1="blue cube"/>"#, &s).unwrap_err();
    assert!(
        e.reason
            .contains("ports item and arg1 name the same argument"),
        "{e}"
    );
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

#[test]
fn condition_ports_are_named_after_their_slots_and_read_by_name_or_position() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let on = s
        .domain
        .vocabulary
        .predicates
        .iter()
        .find(|p| p.name == "on")
        .expect("on");
    assert_eq!(condition_ports(on), ["item", "item_or_fixture"]);
    let twin = crate::domain::vocabulary::Predicate {
        name: "beside".into(),
        arg_types: vec![
            vec!["item".into()],
            vec!["item".into()],
            vec!["name".into()],
        ],
        description: String::new(),
        words: Default::default(),
    };
    assert_eq!(condition_ports(&twin), ["item", "item_2", "arg3"]);

    let expected = "\"blue cube\" on \"green cube\"?\n";
    for xml in [
        r#"<on item="blue cube" item_or_fixture="green cube"/>"#,
        r#"<on arg1="blue cube" arg2="green cube"/>"#,
        r#"<Condition ID="on" item_or_fixture="green cube" item="blue cube"/>"#,
        r#"<Condition ID="on" arg1="blue cube" item_or_fixture="green cube"/>"#,
    ] {
        let read = import(xml, &s).unwrap_or_else(|e| panic!("{xml}: {e}"));
        assert_eq!(bt::to_text(&read.tree), expected, "{xml}");
    }
    for xml in [
        r#"<grasp x="blue cube"/>"#,
        r#"<Action ID="grasp" x="blue cube"/>"#,
    ] {
        let read = import(xml, &s).unwrap_or_else(|e| panic!("{xml}: {e}"));
        assert_eq!(bt::to_text(&read.tree), "grasp \"blue cube\"!\n", "{xml}");
    }
}

#[test]
fn the_export_writes_compact_leaves_with_named_ports() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let read = import(
        r#"<ReactiveSequence><Inverter><grasped arg1="any object"/></Inverter><grasp x="blue cube"/></ReactiveSequence>"#,
        &s,
    )
    .expect("tree");
    let xml = to_btcpp(&read.tree, &s.domain, "Main").expect("export");
    assert!(
        xml.contains(
            r#"<Inverter>
        <grasped item="any object"/>
      </Inverter>
      <grasp x="blue cube"/>"#
        ),
        "{xml}"
    );
    assert!(!xml.contains("<Action ID=\"grasp\" x="), "{xml}");
    assert!(!xml.contains("<Condition ID=\"grasped\" arg"), "{xml}");
    assert!(
        xml.contains(
            r#"<Condition ID="grasped">
      <input_port name="item" type="std::string">item, or any object</input_port>"#
        ),
        "{xml}"
    );
}

/// Every node kind BehaviorTree.CPP 4 ships that betr's engine does not run, written in
/// BT.CPP's own style: each refused with its line and element, as the node it is.
#[test]
fn btcpp_built_ins_betr_cannot_run_are_refused_by_line_and_kind() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let cases = [
        (
            "<Parallel success_count=\"1\"><AlwaysSuccess/></Parallel>",
            "Parallel",
            "control node",
        ),
        (
            "<IfThenElse><AlwaysSuccess/><AlwaysSuccess/></IfThenElse>",
            "IfThenElse",
            "control node",
        ),
        (
            "<Switch2 variable=\"{v}\" case_1=\"1\"><AlwaysSuccess/><AlwaysSuccess/><AlwaysSuccess/></Switch2>",
            "Switch2",
            "control node",
        ),
        (
            "<RetryUntilSuccessful num_attempts=\"3\"><AlwaysSuccess/></RetryUntilSuccessful>",
            "RetryUntilSuccessful",
            "decorator",
        ),
        (
            "<Timeout msec=\"100\"><AlwaysSuccess/></Timeout>",
            "Timeout",
            "decorator",
        ),
        (
            "<Repeat num_cycles=\"2\"><AlwaysSuccess/></Repeat>",
            "Repeat",
            "decorator",
        ),
        ("<Script code=\"x:=1\"/>", "Script", "action"),
        (
            "<SetBlackboard value=\"1\" output_key=\"x\"/>",
            "SetBlackboard",
            "action",
        ),
        (
            "<ScriptCondition code=\"x==1\"/>",
            "ScriptCondition",
            "condition",
        ),
    ];
    for (xml, id, kind) in cases {
        let e = import(&format!("<Sequence>\n{xml}\n</Sequence>"), &s).unwrap_err();
        assert_eq!(e.line, 2, "{id}: {e}");
        assert!(e.element.starts_with(&format!("<{id}")), "{id}: {e}");
        assert!(
            e.reason.starts_with(&format!(
                "{id} is a BehaviorTree.CPP {kind} that betr's engine does not run"
            )),
            "{id}: {e}"
        );
    }
}
