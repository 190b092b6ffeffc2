use super::*;
use std::path::PathBuf;

fn scenario() -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/no_coffee.toml");
    Scenario::load(&path).unwrap()
}

#[test]
fn goal_prompt_has_every_part() {
    let s = scenario();
    let facts = vec![Condition::parse("Holding_Nothing").unwrap()];
    let variant = Variant::default();
    let ctx = Context {
        scenario: &s,
        facts: &facts,
        instruction: "Bring coffee to table six",
        variant: &variant,
    };
    let m = ctx.goal(&Templates::builtin()).unwrap();
    let text = &m[1].content;
    for part in [
        "On_<item>_<place>: the item is at the place",
        // What the scene says objects are called, beside their names.
        "Bar (bar counter), Bar2 (second bar, other bar counter), WaterStation (water dispenser)",
        "- appliance: AC (air conditioning, air conditioner, aircon), TubeLight",
        "## Examples",
        // Retrieval puts the pool's examples that share the most words first.
        "Instruction: There are no tissues at window table six",
        "- Holding_Nothing",
        "Bring coffee to table six",
        "Goal: <formula>",
    ] {
        assert!(text.contains(part), "missing {part:?} in\n{text}");
    }
    assert!(!text.contains("{{"));
    let bare = Variant {
        no_descriptions: true,
        no_object_rule: true,
        chain_of_thought: true,
        examples: Some(vec![]),
        ..Variant::default()
    };
    let ctx = Context {
        variant: &bare,
        ..ctx
    };
    let text = ctx.goal(&Templates::builtin()).unwrap()[1].content.clone();
    assert!(!text.contains("the item is at the place"));
    assert!(!text.contains("most similar"));
    assert!(text.contains("Reasoning:"));
}

#[test]
fn resolve_prompt_names_the_failure() {
    let s = scenario();
    let variant = Variant::default();
    let ctx = Context {
        scenario: &s,
        facts: &[],
        instruction: "Bring coffee to table six",
        variant: &variant,
    };
    let action = ActionCall::new("MoveTo", ["Coffee"]);
    let text = ctx
        .resolve(&Templates::builtin(), &action, "Coffee not found", &[], &[])
        .unwrap()[1]
        .content
        .clone();
    assert!(text.contains("`MoveTo \"Coffee\"`"));
    assert!(text.contains("\"Coffee not found\""));
    assert!(text.contains("Conditions:"));
}

#[test]
fn fill_reports_unknown_placeholders() {
    let e = fill("t", "a {{x}} b", &[]).unwrap_err();
    assert!(e.to_string().contains("{{x}}"), "{e}");
    assert!(fill("t", "a {{x", &[]).is_err());
    assert_eq!(
        fill("t", "a {{ x }}", &[("x", "1".into())]).unwrap(),
        "a 1\n"
    );
}

#[test]
fn a_convention_is_told_only_in_a_scene_with_its_objects() {
    let goal_prompt = |file: &str| {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(file);
        let s = Scenario::load(&path).unwrap();
        let variant = Variant::default();
        let ctx = Context {
            scenario: &s,
            facts: &[],
            instruction: "Bring me an egg",
            variant: &variant,
        };
        ctx.goal(&Templates::builtin()).unwrap()[1].content.clone()
    };
    let with_tray = goal_prompt("scenarios/cell/params/egg.toml");
    assert!(
        with_tray.contains("## What requests mean here\n- What the person asks to be brought"),
        "{with_tray}"
    );
    let without = goal_prompt("scenarios/cell/red_on_blue.toml");
    assert!(!without.contains("What requests mean here"), "{without}");
    // A scene without conventions reads as before: the object rule, then the next part.
    let cafe = goal_prompt("scenarios/cafe/no_coffee.toml");
    assert!(
        cafe.contains("use Couch).\n\n## How to write a goal"),
        "{cafe}"
    );
}

#[test]
fn an_object_in_two_types_is_glossed_once() {
    use crate::domain::{Object, Vocabulary};
    let object = |name: &str, types: &[&str], called: &[&str]| Object {
        name: name.into(),
        types: types.iter().map(|t| (*t).to_string()).collect(),
        called: called.iter().map(|c| (*c).to_string()).collect(),
    };
    let vocabulary = Vocabulary {
        objects: vec![
            object("Coffee", &["item", "makable"], &["espresso"]),
            object("Chips", &["item"], &["crisps", "fries"]),
            object("Table1", &["place"], &[]),
        ],
        predicates: Vec::new(),
    };
    assert_eq!(
        objects_text(&vocabulary),
        "- item: Coffee (espresso), Chips (crisps, fries)\n- makable: Coffee\n- place: Table1"
    );
}

#[test]
fn value_prompt_is_about_the_object_and_the_task() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/params/egg.toml");
    let s = Scenario::load(&path).unwrap();
    let facts = vec![Condition::parse("\"egg\" on \"table\"").unwrap()];
    let variant = Variant::default();
    let ctx = Context {
        scenario: &s,
        facts: &facts,
        instruction: "Bring me an egg",
        variant: &variant,
    };
    let action = ActionCall::new("grasp", ["egg"]);
    let ask = |param: &ValueParam| {
        ctx.value(
            &Templates::builtin(),
            &action,
            param,
            "no force",
            (&[], None),
        )
        .unwrap()[1]
            .content
            .clone()
    };
    let force = ValueParam {
        name: "force".into(),
        unit: Some("N".into()),
        categories: vec![],
        description: "grasping force".into(),
        min: None,
        max: Some(80.0),
    };
    let text = ask(&force);
    for part in [
        "The person asked: Bring me an egg",
        "`grasp \"egg\"`",
        "\"no force\"",
        "the robot can do at most 80 N",
        "Parameter value: 20 ml/s",
        "Parameter value: <number> N",
    ] {
        assert!(text.contains(part), "missing {part:?} in\n{text}");
    }
    // The scene's conditions and the goal examples are not what a value depends on.
    assert!(!text.contains("\"egg\" on \"table\""), "{text}");
    assert!(!text.contains("Instruction:"), "{text}");
    assert!(!text.contains("{{"), "{text}");
    let tool = ValueParam {
        name: "tool".into(),
        unit: None,
        categories: vec!["shovel".into(), "spoon".into()],
        description: String::new(),
        min: None,
        max: None,
    };
    let text = ask(&tool);
    assert!(text.contains("Parameter value: slow"), "{text}");
    assert!(!text.contains("ml/s"), "{text}");
    assert!(text.contains("one of: shovel, spoon"), "{text}");
}

#[test]
fn everything_before_the_examples_is_the_same_for_every_request() {
    // The embedded model keeps the longest common beginning of the prompts it was sent in
    // its cache: everything the same for every request of a scene comes first.
    let s = scenario();
    let facts = vec![Condition::parse("Holding_Nothing").unwrap()];
    let variant = Variant::default();
    let prompt = |instruction: &str| {
        Context {
            scenario: &s,
            facts: &facts,
            instruction,
            variant: &variant,
        }
        .goal(&Templates::builtin())
        .unwrap()[1]
            .content
            .clone()
    };
    let a = prompt("Bring coffee to table six");
    let b = prompt("Turn on the air conditioning");
    let common = a
        .char_indices()
        .zip(b.chars())
        .find(|((_, x), y)| x != y)
        .map_or(a.len(), |((i, _), _)| i);
    let (shared, rest) = a.split_at(common);
    for part in [
        "## Objects in this scene",
        "## The scene now",
        "## Examples",
    ] {
        assert!(
            shared.contains(part),
            "{part:?} is not before the examples in\n{a}"
        );
    }
    assert!(rest.contains("Bring coffee to table six"));
    let headings: Vec<&str> = rest.lines().filter(|l| l.starts_with("## ")).collect();
    assert_eq!(
        headings,
        ["## Request", "## Answer format"],
        "after the examples:\n{rest}"
    );
}

#[test]
fn the_refusals_told_back_are_the_latest_each_cut_short() {
    let tried: Vec<String> = (0..20)
        .map(|i| {
            format!(
                "insert Cond_{i} ({})",
                "after the change, x ".repeat(i * 10)
            )
        })
        .collect();
    let text = tried_text(&tried);
    assert!(text.contains("- (8 earlier ones left out)"), "{text}");
    assert!(!text.contains("Cond_7 "), "{text}");
    assert!(text.contains("insert Cond_19 "), "{text}");
    assert!(
        text.lines()
            .all(|l| l.chars().count() <= MAX_TRIED_CHARS + 3),
        "{text}"
    );
    assert!(text.contains('…'));
    // A short list is told whole.
    let short = tried_text(&tried[..2]);
    assert!(
        short.contains("- insert Cond_0 ()") && !short.contains("left out"),
        "{short}"
    );
}
