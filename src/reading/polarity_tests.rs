use super::*;
use crate::domain::{Object, Predicate, StateWords, Vocabulary};

fn object(name: &str, kind: &str, called: &[&str]) -> Object {
    Object {
        name: name.into(),
        types: vec![kind.into()],
        called: called.iter().map(|c| c.to_string()).collect(),
    }
}

fn predicate(name: &str, kind: &str, says: &[&str], opposite: &[&str]) -> Predicate {
    let list = |l: &[&str]| l.iter().map(|w| w.to_string()).collect();
    Predicate {
        name: name.into(),
        arg_types: vec![vec![kind.into()]],
        description: String::new(),
        words: StateWords {
            says: list(says),
            opposite: list(opposite),
        },
    }
}

fn vocabulary() -> Vocabulary {
    Vocabulary {
        objects: vec![
            object("Curtain", "furnishing", &["drapes"]),
            object("AC", "appliance", &["air conditioning"]),
            object("TubeLight", "appliance", &[]),
            object("HallLight", "appliance", &[]),
            object(
                "ACTemperature",
                "control",
                &["air conditioning temperature"],
            ),
            object("Coffee", "item", &[]),
        ],
        predicates: vec![
            predicate(
                "Closed",
                "furnishing",
                &["close", "shut"],
                &["open", "draw back"],
            ),
            predicate("Active", "appliance", &["on", "activate"], &["off"]),
            predicate("Low", "control", &["low", "lower"], &["moderate", "raise"]),
            predicate("Holding", "item", &["hold"], &["put down"]),
        ],
    }
}

fn turned(goal: &str, request: &str) -> Option<String> {
    let goal = Formula::parse(goal).expect("test goal parses");
    turned_around(&goal, &Request::among(request, &vocabulary())).map(|t| t.to_string())
}

fn back(goal: &str, request: &str) -> Option<String> {
    let goal = Formula::parse(goal).expect("test goal parses");
    turned_back(&goal, &Request::among(request, &vocabulary())).map(|g| g.to_string())
}

#[test]
fn a_negated_word_asks_for_the_opposite_of_its_own_way() {
    let request = "Do not open the curtain, and switch on the tube light.";
    assert_eq!(
        turned("~Closed_Curtain & Active_TubeLight", request).as_deref(),
        Some(
            "the request says \"open\", which asks for Closed_Curtain, where the goal has ~Closed_Curtain"
        )
    );
    assert_eq!(turned("Closed_Curtain & Active_TubeLight", request), None);
    assert_eq!(
        back("~Closed_Curtain & Active_TubeLight", request).as_deref(),
        Some("Closed_Curtain & Active_TubeLight")
    );
}

#[test]
fn two_negations_cancel_and_a_negation_stays_in_its_clause() {
    assert_eq!(
        turned(
            "Active_HallLight",
            "Please don't forget to turn on the hall light"
        ),
        None
    );
    assert!(
        turned(
            "~Active_HallLight",
            "Please don't forget to turn on the hall light"
        )
        .is_some()
    );
    // "not" belongs to the first clause; "on" of the second asks for the light on.
    let request = "Do not close the drapes and make sure the tube light is on";
    assert_eq!(turned("~Closed_Curtain & Active_TubeLight", request), None);
    assert_eq!(
        back("Closed_Curtain & ~Active_TubeLight", request).as_deref(),
        Some("~Closed_Curtain & Active_TubeLight")
    );
}

#[test]
fn each_named_object_takes_the_word_of_its_own_clause() {
    let request = "Make sure the tube light is on and the hall light is turned off.";
    assert_eq!(
        turned("Active_TubeLight & ~Active_HallLight", request),
        None
    );
    assert_eq!(
        back("Active_TubeLight & Active_HallLight", request).as_deref(),
        Some("Active_TubeLight & ~Active_HallLight")
    );
    // A phrase of several words: "draw back" the drapes opens them.
    assert!(turned("Closed_Curtain", "Could you draw back the drapes?").is_some());
}

#[test]
fn the_one_object_of_a_predicate_needs_a_word_of_it_in_the_clause() {
    assert!(turned("Low_ACTemperature", "Keep the temperature moderate, please").is_some());
    assert_eq!(
        turned(
            "~Low_ACTemperature",
            "Don't let the temperature get too low"
        ),
        None
    );
    assert!(turned("Low_ACTemperature", "Don't let the temperature get too low").is_some());
    // "lower" with no word of the temperature asks nothing about it.
    assert_eq!(
        turned("~Low_ACTemperature", "Lower the box onto the table"),
        None
    );
    // Several appliances: one must be named.
    assert_eq!(turned("Active_AC", "Switch everything off"), None);
}

#[test]
fn a_condition_asked_both_ways_or_not_in_the_goal_is_no_finding() {
    let request = "Turn the AC on. Then turn the AC off.";
    assert_eq!(turned("Active_AC", request), None);
    assert_eq!(turned("~Active_AC", request), None);
    assert_eq!(turned("Holding_Coffee", "Open the curtain"), None);
    // Under a negation of a group, the atom's sign is what counts.
    assert_eq!(
        turned("~(Closed_Curtain & Holding_Coffee)", "open the curtain"),
        None
    );
    assert_eq!(
        back("~(~Closed_Curtain & Holding_Coffee)", "open the curtain").as_deref(),
        Some("~(Closed_Curtain & Holding_Coffee)")
    );
}

#[test]
fn put_down_asks_to_hold_nothing_of_it() {
    assert_eq!(
        back("Holding_Coffee", "Can you put down the coffee for now?").as_deref(),
        Some("~Holding_Coffee")
    );
    assert_eq!(turned("Holding_Coffee", "Please hold the coffee"), None);
}

#[test]
fn the_scenes_own_worked_examples_are_read_the_way_round_they_ask() {
    crate::session::for_each_worked_example(|scene, scenario, example, goal| {
        assert_eq!(
            turned_around(
                goal,
                &Request::among(&example.instruction, &scenario.domain.vocabulary)
            )
            .map(|t| t.to_string()),
            None,
            "{scene}: {:?}",
            example.instruction
        );
    });
}

fn with_asked(goal: &str, request: &str) -> Option<String> {
    let goal = Formula::parse(goal).expect("test goal parses");
    with_unanswered(&goal, &Request::among(request, &vocabulary())).map(|g| g.to_string())
}

#[test]
fn a_condition_asked_in_its_own_words_and_left_out_is_put_beside() {
    let request = "Don't forget to turn on the hall light. And bring a coffee to table 1.";
    let goal = Formula::parse("On_Coffee_Table1").expect("parses");
    let (atom, wanted, word) = left_unanswered(&goal, &Request::among(request, &vocabulary()))
        .expect("the light is asked for");
    assert_eq!(
        (atom.to_string(), wanted, word.as_str()),
        ("Active_HallLight".into(), true, "on")
    );
    assert_eq!(
        with_asked("On_Coffee_Table1", request).as_deref(),
        Some("On_Coffee_Table1 & Active_HallLight")
    );
    // Asked the other way: put beside negated.
    assert_eq!(
        with_asked(
            "On_Coffee_Table1",
            "Bring a coffee, and switch the tube light off."
        )
        .as_deref(),
        Some("On_Coffee_Table1 & ~Active_TubeLight")
    );
    // A sentence that offers a choice may have asked for it as one alternative of several.
    assert_eq!(
        with_asked(
            "On_Coffee_Table1",
            "Bring a coffee or turn on the hall light."
        ),
        None
    );
    // Answered, either way round (turning it is another finding's work).
    assert_eq!(
        with_asked("On_Coffee_Table1 & ~Active_HallLight", request),
        None
    );
}

#[test]
fn a_longer_name_is_the_subject_not_a_shorter_one_inside_it() {
    let mut v = vocabulary();
    v.objects.push(object("SpringWater", "item", &[]));
    v.objects.push(object("Water", "item", &[]));
    v.objects.push(object("Watermelon", "item", &[]));
    let goal = Formula::parse("On_Coffee_Table1").expect("parses");
    let found = left_unanswered(
        &goal,
        &Request::among("Please hold a bottle of spring water.", &v),
    )
    .map(|(atom, _, _)| atom.to_string());
    assert_eq!(found.as_deref(), Some("Holding_SpringWater"));
}
