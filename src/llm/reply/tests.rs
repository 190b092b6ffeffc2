use std::path::PathBuf;

use proptest::prelude::*;

use super::*;
use crate::domain::{Object, Predicate};
use crate::scenario::Scenario;

fn cafe() -> Vocabulary {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml");
    Scenario::load(&path).unwrap().domain.vocabulary
}

fn cell() -> Vocabulary {
    let obj = |n: &str, t: &str| Object {
        name: n.into(),
        types: vec![t.into()],
        called: Vec::new(),
    };
    Vocabulary {
        objects: vec![
            obj("blue cube", "block"),
            obj("green cube", "block"),
            obj("red cup", "cup"),
        ],
        predicates: vec![
            Predicate {
                name: "on".into(),
                arg_types: vec![vec!["block".into()], vec!["block".into(), "cup".into()]],
                description: "a rests on b".into(),
                words: Default::default(),
            },
            Predicate {
                name: "upright".into(),
                arg_types: vec![vec!["cup".into()]],
                description: "stands upright".into(),
                words: Default::default(),
            },
        ],
    }
}

fn force() -> ValueParam {
    ValueParam {
        name: "force".into(),
        unit: Some("N".into()),
        categories: vec![],
        description: String::new(),
        min: None,
        max: None,
    }
}

fn tool() -> ValueParam {
    ValueParam {
        name: "tool".into(),
        unit: None,
        categories: vec!["shovel".into(), "sponge".into(), "brush".into()],
        description: String::new(),
        min: None,
        max: None,
    }
}

#[test]
fn goals_are_found_in_many_shapes() {
    let v = cafe();
    for text in [
        "Goal: On_Coffee_WindowTable6",
        "```\nGoal: On_Coffee_WindowTable6\n```",
        "Sure! Here it is.\n\n**Goal:** `On_Coffee_WindowTable6`.",
        "The person wants coffee at table six, so the final Goal: On_Coffee_WindowTable6",
        "Goal:\n  On_Coffee_WindowTable6",
        "On_Coffee_WindowTable6",
        "Goal: On_Coffee_WindowTable6 (coffee on the window table)",
        "{\"reasoning\": \"r\", \"goal\": [[\"On_Coffee_WindowTable6\"]]}",
        "{\"goal\": \"On_Coffee_WindowTable6\"}",
    ] {
        let a = goal(text, &v, MIN_SIMILARITY).unwrap_or_else(|e| panic!("{text:?}: {e}"));
        assert_eq!(a.goal.to_string(), "On_Coffee_WindowTable6", "{text:?}");
    }
}

#[test]
fn reasoning_before_or_after() {
    let v = cafe();
    let a = goal(
        "Reasoning: the guest wants chips. Goal:\nGoal: On_Chips_Table3",
        &v,
        0.5,
    )
    .unwrap();
    assert_eq!(a.reasoning.as_deref(), Some("the guest wants chips."));
    let a = goal(
        "Reasoning: chips or dessert.\nGoal: On_Chips_Table3 | On_Dessert_Table3",
        &v,
        0.5,
    )
    .unwrap();
    assert_eq!(a.reasoning.as_deref(), Some("chips or dessert."));
    let a = goal("Goal: Active_AC\nReasoning: it is hot.", &v, 0.5).unwrap();
    assert_eq!(a.reasoning.as_deref(), Some("it is hot."));
    let a = goal("It is hot, the AC should run.\nGoal: Active_AC", &v, 0.5).unwrap();
    assert_eq!(
        a.reasoning.as_deref(),
        Some("It is hot, the AC should run.")
    );
}

#[test]
fn unknown_objects_are_refused_with_the_nearest_names_never_replaced() {
    let v = cafe();
    let e = goal("Goal: On_Cofee_WindowTable6", &v, MIN_SIMILARITY).unwrap_err();
    assert!(
        matches!(&e, ReplyError::UnknownObject { object, nearest, .. }
            if object == "Cofee" && nearest.first().map(String::as_str) == Some("Coffee")),
        "{e}"
    );
    assert!(e.to_string().contains("did you mean \"Coffee\""), "{e}");
    let e = goal("Goal: On_Fries_Table3", &v, MIN_SIMILARITY).unwrap_err();
    assert!(
        matches!(&e, ReplyError::UnknownObject { object, .. } if object == "Fries"),
        "{e}"
    );
    let e = goal(
        "Goal: \"purple cube\" on \"green cube\"",
        &cell(),
        MIN_SIMILARITY,
    )
    .unwrap_err();
    let said = e.to_string();
    assert!(said.contains("\"purple cube\""), "{said}");
    assert!(said.contains("is not in the scene"), "{said}");
    assert!(said.contains("did you mean \"blue cube\""), "{said}");
    let e = goal("Goal: Under_Coffee_Table3", &v, MIN_SIMILARITY).unwrap_err();
    assert!(e.to_string().contains("Under_Coffee_Table3"), "{e}");
    let e = goal("Goal: On_Table3_Coffee", &v, MIN_SIMILARITY).unwrap_err();
    assert!(e.to_string().contains("must be item"), "{e}");
    let e = goal("I cannot help with that.", &v, MIN_SIMILARITY).unwrap_err();
    assert!(matches!(e, ReplyError::MissingAnswer { .. }), "{e}");
}

#[test]
fn conditions_in_lists_and_prose() {
    let v = cafe();
    for text in [
        "Reasoning: no coffee was made.\nConditions:\nExists_Coffee",
        "Reasoning: x\nConditions: Exists_Coffee",
        "Reasoning: x\nConditions:\n1. `Exists_Coffee`\n\nThis makes the coffee first.",
        "Conditions:\n- Exists_Coffee\n- Exists_Coffee",
        "Exists_Coffee",
        "{\"reasoning\": \"x\", \"conditions\": [\"Exists_Coffee\"]}",
        "{\"conditions\": [{\"negated\": false, \"predicate\": \"Exists\", \"args\": [\"Coffee\"]}]}",
    ] {
        let a = conditions(text, &v, MIN_SIMILARITY).unwrap_or_else(|e| panic!("{text:?}: {e}"));
        let got: Vec<String> = a.conditions.iter().map(ToString::to_string).collect();
        assert_eq!(got, vec!["Exists_Coffee"], "{text:?}");
    }
    let a = conditions("Conditions: RobotNear_Bar & Holding_Nothing", &v, 0.5).unwrap();
    assert_eq!(a.conditions.len(), 2);
    assert!(matches!(
        conditions("Conditions: none", &v, 0.5),
        Err(ReplyError::NoConditions)
    ));
    let e = conditions("Conditions:\n- Exists_Coffee\n- On__Bar", &v, 0.5).unwrap_err();
    assert!(e.to_string().contains("On__Bar"), "{e}");
}

#[test]
fn quoted_conditions_with_the_wildcard() {
    let v = cell();
    let a = conditions(
        "Reasoning: a cube lies on it.\nConditions:\n~\"any object\" on \"blue cube\"\n\"red cup\" upright",
        &v,
        0.5,
    )
    .unwrap();
    let got: Vec<String> = a.conditions.iter().map(ToString::to_string).collect();
    assert_eq!(
        got,
        vec!["~\"any object\" on \"blue cube\"", "\"red cup\" upright"]
    );
    let e = conditions("Conditions: ~\"any object\" on \"blue cub\"", &v, 0.5).unwrap_err();
    assert!(
        matches!(&e, ReplyError::UnknownObject { object, nearest, .. }
            if object == "blue cub" && nearest[0] == "blue cube"),
        "{e}"
    );
}

#[test]
fn values_with_units_and_categories() {
    let a = value(
        "Reasoning: eggs are fragile.\nParameter value: 5.3 N",
        &force(),
        0.5,
    )
    .unwrap();
    assert_eq!(
        a.value,
        Value::Number {
            value: 5.3,
            unit: "N".into()
        }
    );
    assert_eq!(a.reasoning.as_deref(), Some("eggs are fragile."));
    let a = value("Parameter value: **5300 mN**.", &force(), 0.5).unwrap();
    assert!(matches!(a.value, Value::Number { value, .. } if (value - 5.3).abs() < 1e-9));
    assert!(value("Parameter value: 5 m/s", &force(), 0.5).is_err());
    assert!(value("Parameter value: soft", &force(), 0.5).is_err());
    assert!(value("{\"value\": 37.2, \"unit\": \"N\"}", &force(), 0.5).is_ok());
    let a = value("Parameter value: sponge or brush", &tool(), 0.5).unwrap();
    assert_eq!(a.value, Value::Category("sponge".into()));
    let a = value("Parameter value: \"shovels\"", &tool(), 0.5).unwrap();
    assert_eq!(a.value, Value::Category("shovel".into()));
    assert!(value("Parameter value: hammer", &tool(), 0.6).is_err());
    // A category the parameter lacks is offered, never used.
    let e = value("Parameter value: spnge", &tool(), 0.6).unwrap_err();
    assert!(e.to_string().contains("did you mean \"sponge\""), "{e}");
}

fn reply_text() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        Just("Goal:".to_string()),
        Just("Conditions:".to_string()),
        Just("Reasoning:".to_string()),
        Just("Parameter value:".to_string()),
        Just("```".to_string()),
        Just("\n".to_string()),
        Just("1. ".to_string()),
        Just("- ".to_string()),
        Just("~".to_string()),
        Just("\"any object\" on \"blue cube\"".to_string()),
        Just("On_Coffee_Table1".to_string()),
        Just(" & ".to_string()),
        Just(" | ".to_string()),
        Just("(".to_string()),
        Just("{\"goal\": [[".to_string()),
        Just("İ".to_string()),
        "\\PC{0,8}",
        any::<String>(),
    ];
    prop::collection::vec(piece, 0..24).prop_map(|v| v.concat())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]
    #[test]
    fn parsers_never_panic(text in reply_text()) {
        let v = cafe();
        let _ = goal(&text, &v, MIN_SIMILARITY);
        let _ = conditions(&text, &v, MIN_SIMILARITY);
        let _ = conditions(&text, &cell(), MIN_SIMILARITY);
        let _ = value(&text, &force(), MIN_SIMILARITY);
        let _ = value(&text, &tool(), MIN_SIMILARITY);
    }

    #[test]
    fn arbitrary_strings_never_panic(text in any::<String>()) {
        let v = cell();
        let _ = goal(&text, &v, MIN_SIMILARITY);
        let _ = conditions(&text, &v, MIN_SIMILARITY);
        let _ = value(&text, &force(), MIN_SIMILARITY);
    }
}
