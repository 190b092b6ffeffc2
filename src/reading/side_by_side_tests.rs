use super::*;
use crate::domain::{Predicate, StateWords, Vocabulary};

fn object(name: &str, types: &[&str], called: &[&str]) -> Object {
    Object {
        name: name.into(),
        types: types.iter().map(|t| t.to_string()).collect(),
        called: called.iter().map(|c| c.to_string()).collect(),
    }
}

fn vocabulary() -> Vocabulary {
    let predicate = |name: &str, slots: &[&str]| Predicate {
        name: name.into(),
        arg_types: slots.iter().map(|s| vec![s.to_string()]).collect(),
        description: String::new(),
        words: StateWords::default(),
    };
    Vocabulary {
        objects: vec![
            object("Chips", &["item"], &["fries"]),
            object("Dessert", &["item"], &[]),
            object("Milk", &["item"], &[]),
            object("Glass", &["item"], &[]),
            object("Yogurt", &["item"], &[]),
            object("Bar", &["place"], &[]),
            object("Bar2", &["place"], &[]),
            object("Table3", &["place"], &[]),
        ],
        predicates: vec![
            predicate("On", &["item", "place"]),
            predicate("RobotNear", &["place"]),
        ],
    }
}

fn added(goal: &str, request: &str) -> Option<String> {
    let goal = Formula::parse(goal).expect("test goal parses");
    let vocabulary = vocabulary();
    with_left_out(&goal, &Request::among(request, &vocabulary)).map(|g| g.to_string())
}

#[test]
fn a_choice_read_as_one_of_its_sides_gets_the_other_beside_it() {
    let request = "I'm at the third table, could you bring me either some fries or a dessert?";
    let goal = Formula::parse("On_Dessert_Table3").expect("parses");
    assert_eq!(
        left_out(&goal, &Request::among(request, &vocabulary())),
        Some(LeftOut {
            kept: "Dessert".into(),
            left_out: "Chips".into(),
            choice: true,
            first: true,
        })
    );
    assert_eq!(
        added("On_Dessert_Table3", request).as_deref(),
        Some("On_Chips_Table3 | On_Dessert_Table3")
    );
    assert_eq!(added("On_Chips_Table3 | On_Dessert_Table3", request), None);
}

#[test]
fn things_joined_by_and_are_both_asked_for_and_a_negated_pair_wants_neither() {
    assert_eq!(
        added("On_Milk_Bar", "Bring milk and some yogurt to the bar").as_deref(),
        Some("On_Milk_Bar & On_Yogurt_Bar")
    );
    assert_eq!(
        added("~RobotNear_Bar", "Try not to hang around bar and bar 2").as_deref(),
        Some("~RobotNear_Bar & ~RobotNear_Bar2")
    );
}

#[test]
fn only_things_of_a_kind_right_beside_the_joining_word_are_a_pair() {
    // "a glass of milk or some yogurt": milk and yogurt, not the glass.
    assert_eq!(
        added(
            "On_Glass_Bar | On_Yogurt_Bar",
            "a glass of milk or some yogurt at the bar"
        )
        .as_deref(),
        Some("On_Glass_Bar | On_Milk_Bar | On_Yogurt_Bar")
    );
    // A place and an item joined by "and" are no pair.
    assert_eq!(
        added("On_Milk_Bar", "Milk to bar 2 and the dessert to the bar"),
        None
    );
    // Neither side in the goal: another misreading, not this one.
    assert_eq!(added("On_Glass_Bar", "fries or a dessert"), None);
}

#[test]
fn the_scenes_own_worked_examples_leave_nothing_out() {
    crate::session::for_each_worked_example(|scene, scenario, example, goal| {
        let lexicon = crate::reading::Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
        let request = Request::new(&example.instruction, scenario, &lexicon);
        assert_eq!(
            left_out(goal, &request),
            None,
            "{scene}: {:?}",
            example.instruction
        );
    });
}

#[test]
fn a_thing_had_only_beside_an_object_nobody_names_is_left_out() {
    // Bar 2 is in the goal only with the milk, which the request never names.
    assert_eq!(
        added(
            "~On_Chips_Bar & ~On_Milk_Bar2",
            "Make sure the chips are not on the bar and bar 2."
        )
        .as_deref(),
        Some("~On_Chips_Bar & ~On_Chips_Bar2 & ~On_Milk_Bar2")
    );
    // Named, the milk's condition is the request's own: nothing is left out.
    assert_eq!(
        added(
            "~On_Chips_Bar & ~On_Milk_Bar2",
            "No chips on the bar and bar 2 for the milk."
        ),
        None
    );
}
