//! Tests of the checks a candidate goal must pass.

use super::*;
use crate::goal::Formula;
use crate::reading::Lexicon;
use crate::reading::names::{
    factored, guessed_for_unknown, swapped_back, swapped_object, without_copied, without_unasked,
};
use crate::reading::words::same_word;
use std::path::Path;

fn cafe() -> (Scenario, Box<dyn World>) {
    let s = Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml"))
        .expect("cafe scenario");
    let w = crate::world::load(&s).expect("cafe world");
    (s, w)
}

fn check(goal: &str) -> Result<(), String> {
    let (s, w) = cafe();
    let f = s.parse_goal(goal).expect("goal parses");
    check_goal(&s, w.as_ref(), &f).map_err(|p| p.reason)
}

#[test]
fn checks_refuse_what_cannot_be_meant() {
    assert!(check("On_Coffee_Table1").is_ok());
    assert!(check("Active_AC & ~Active_HallLight").is_ok());
    let e = check("Active_AC & ~Active_AC").unwrap_err();
    assert!(e.contains("contradicts"), "{e}");
    let e = check("RobotNear_Bar | ~RobotNear_Bar").unwrap_err();
    assert!(e.contains("every situation"), "{e}");
    // Already true in the cafe's first state.
    let e = check("On_Chips_Bar").unwrap_err();
    assert!(e.contains("already"), "{e}");
    let e = check("RobotNear_Table1 & RobotNear_Table2").unwrap_err();
    assert!(e.contains("cannot"), "{e}");
}

#[test]
fn a_condition_pasted_from_an_example_is_found() {
    let example = crate::scenario::Example {
        instruction: "Put the sponge in the bowl and leave your gripper empty".into(),
        goal: r#""sponge" in "bowl" & ~"any object" grasped"#.into(),
        source: Default::default(),
    };
    let shown = [&example];
    let request = "Put the blue cube on the green cube";
    let pasted =
        Formula::parse(r#""blue cube" on "green cube" & ~"any object" grasped"#).expect("parses");
    let why = copied_from_example(&pasted, &shown, &Request::words_only(request)).expect("found");
    assert!(why.contains("grasped"), "{why}");
    let plain = Formula::parse(r#""blue cube" on "green cube""#).expect("parses");
    assert!(copied_from_example(&plain, &shown, &Request::words_only(request)).is_none());
    // Asked for in other words ("hand empty" is not "grasped", but the object is
    // named): not a copy.
    let named = Formula::parse(r#"~"sponge" in "bowl""#).expect("parses");
    assert!(
        copied_from_example(&named, &shown, &Request::words_only("take the sponge out")).is_none()
    );
}

#[test]
fn a_pasted_conjunct_goes_only_when_the_rest_covers_the_request() {
    let example = crate::scenario::Example {
        instruction: "It's really stuffy in here, and leave your gripper empty".into(),
        goal: r#"Active_AC & ~"any object" grasped"#.into(),
        source: Default::default(),
    };
    let shown = [&example];
    let pasted =
        Formula::parse(r#""blue cube" on "green cube" & ~"any object" grasped"#).expect("parses");
    let rest = without_copied(
        &pasted,
        &shown,
        &Request::words_only("Put the blue cube on the green cube"),
    )
    .expect("pruned");
    assert_eq!(rest.to_string(), r#""blue cube" on "green cube""#);
    // "hot" is not covered by the curtain: the AC may be what it asks for.
    let indirect = Formula::parse("Closed_Curtain & Active_AC").expect("parses");
    assert!(
        without_copied(
            &indirect,
            &shown,
            &Request::words_only("It's hot here, close the curtain")
        )
        .is_none()
    );
    assert!(same_word("clos", "close") && same_word("cube", "cube") && !same_word("ac", "at"));
}

#[test]
fn a_condition_no_word_asks_for_is_taken_out() {
    let (scenario, _) = cafe();
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
    let g = |t: &str| Formula::parse(t).expect("parses");
    let request = "Please take a sandwich to the second table.";
    let appended = g("On_Sandwiches_Table2 & RobotNear_Table2");
    assert_eq!(
        unasked(&appended, &Request::new(request, &scenario, &lexicon)),
        vec![g("RobotNear_Table2")]
    );
    assert_eq!(
        without_unasked(&appended, &Request::new(request, &scenario, &lexicon)),
        Some(g("On_Sandwiches_Table2"))
    );
    // Every part answers to words of its own: nothing goes.
    let request = "Mop the floor, and bring a teacup to table two.";
    let both = g("IsClean_Floor & On_Teacup_Table2");
    assert!(unasked(&both, &Request::new(request, &scenario, &lexicon)).is_empty());
    assert_eq!(
        without_unasked(&both, &Request::new(request, &scenario, &lexicon)),
        None
    );
    // A single condition is never taken out, however indirect the request.
    assert_eq!(
        without_unasked(
            &g("Active_AC"),
            &Request::new("I'm melting.", &scenario, &lexicon)
        ),
        None
    );
    // A word said as often as conditions claim it asks for each of them.
    let request = "Ensure that chips are not on bar and bar2 and deliver the milk to bar.";
    let bars = g("~On_Chips_Bar & ~On_Chips_Bar2 & On_Milk_Bar");
    assert!(unasked(&bars, &Request::new(request, &scenario, &lexicon)).is_empty());
}

#[test]
fn an_object_put_in_the_place_of_a_named_one_is_a_swap() {
    let (scenario, _) = cafe();
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
    let g = |t: &str| Formula::parse(t).expect("parses");
    let request = "I'm at the third table, bring me either some fries or a dessert.";
    let (object, words) = swapped_object(
        &g("(Exists_Dessert | Exists_Coffee) & RobotNear_Table3"),
        &Request::new(request, &scenario, &lexicon),
    )
    .expect("a swap");
    assert_eq!(object, "Coffee");
    assert!(words.iter().any(|w| same_word(w, "fries")), "{words:?}");
    assert!(
        swapped_object(
            &g("On_Chips_Table3 | On_Dessert_Table3"),
            &Request::new(request, &scenario, &lexicon)
        )
        .is_none()
    );
    // Every object named, though a word is left over: no swap.
    assert!(
        swapped_object(
            &g("On_Milk_Table2"),
            &Request::new("A glass of milk to table 2", &scenario, &lexicon)
        )
        .is_none()
    );
    // A word that is only part of a name ("area" of LoungeArea) names nothing alone.
    assert!(
        swapped_object(
            &g("On_VacuumCup_WaterStation"),
            &Request::new(
                "Would you take my vacuum cup to the hydration area?",
                &scenario,
                &lexicon
            )
        )
        .is_none()
    );
    // Nothing named is left out: no swap, whatever the goal's objects.
    assert!(
        swapped_object(
            &g("Active_AC"),
            &Request::new("It's so hot in here", &scenario, &lexicon)
        )
        .is_none()
    );
}

#[test]
fn a_swapped_object_is_put_back_when_the_word_names_one_thing_of_its_kind() {
    let (scenario, _) = cafe();
    let vocabulary = &scenario.domain.vocabulary;
    let lexicon = Lexicon::new(vocabulary, &scenario.examples);
    let g = |t: &str| Formula::parse(t).expect("parses");
    let request = "I'm at the third table, bring me either some fries or a dessert.";
    let (goal, from, to) = swapped_back(
        &g("On_Dessert_Table3 | On_Softdrink_Table3"),
        &Request::in_scene(request, vocabulary, &[], &lexicon),
    )
    .expect("put back");
    assert_eq!((from.as_str(), to.as_str()), ("Softdrink", "Chips"));
    assert_eq!(goal.to_string(), "On_Dessert_Table3 | On_Chips_Table3");
    // No swap, nothing to put back.
    assert!(
        swapped_back(
            &g("On_Chips_Table3"),
            &Request::in_scene(request, vocabulary, &[], &lexicon)
        )
        .is_none()
    );
    // A name of two words is the object it names, not the one its last word names.
    let (goal, _, to) = swapped_back(
        &g("Holding_Coffee"),
        &Request::in_scene(
            "Please pick up and hold the spring water.",
            vocabulary,
            &[],
            &lexicon,
        ),
    )
    .expect("put back");
    assert_eq!(
        (to.as_str(), goal.to_string().as_str()),
        ("SpringWater", "Holding_SpringWater")
    );
}

#[test]
fn the_empty_hand_is_no_object_a_request_must_name() {
    let (scenario, world) = cafe();
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
    let g = |t: &str| Formula::parse(t).expect("parses");
    let request = "Make sure you are not holding anything.";
    assert_eq!(
        unnamed_object(
            g("Holding_Nothing").atoms(),
            &Request::new(request, &scenario, &lexicon)
        ),
        None
    );
    // The hand is empty now: a doubt, not a goal refused for an object nobody named.
    let problem = assess(
        &scenario,
        world.as_ref(),
        &g("Holding_Nothing"),
        &[],
        &Request::new(request, &scenario, &lexicon),
    )
    .expect("it holds already");
    assert!(problem.is_doubt(), "{problem:?}");
}

#[test]
fn a_goal_may_offer_only_the_choices_the_request_gives() {
    let g = |t: &str| Formula::parse(t).expect("parses");
    let request = "Bring me a banana or an orange, and switch off the hall light.";
    assert!(
        more_alternatives_than_asked(
            &g("On_Banana_Bar | On_Orange_Bar | ~Active_HallLight"),
            &Request::words_only(request)
        )
        .is_some()
    );
    assert_eq!(
        more_alternatives_than_asked(
            &g("(On_Banana_Bar | On_Orange_Bar) & ~Active_HallLight"),
            &Request::words_only(request)
        ),
        None
    );
    // A list ending in "or" offers one choice per item.
    let listed = g("On_Coffee_Bar | On_Cake_Bar | On_Tea_Bar");
    assert_eq!(
        more_alternatives_than_asked(
            &listed,
            &Request::words_only("Coffee, cake, or tea at the bar.")
        ),
        None
    );
    // "Neither ... nor" offers no choice: the disjunction is under a negation.
    let neither = g("~(On_Mop_Entrance | On_Mop_Exit)");
    assert_eq!(
        more_alternatives_than_asked(
            &neither,
            &Request::words_only("Keep the mop away from the entrance and the exit.")
        ),
        None
    );
    assert_eq!(
        more_alternatives_than_asked(
            &g("IsClean_Chairs | Exists_Coffee"),
            &Request::words_only("Clean the chairs; if not, make coffee.")
        ),
        None
    );
}

#[test]
fn a_goal_true_through_a_place_nobody_named_is_wrong() {
    let (scenario, world) = cafe();
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
    let g = |t: &str| Formula::parse(t).expect("parses");
    // The chips lie on the bar already; the request says nothing of the bar.
    assert_eq!(
        unsaid_object_holding(
            &g("On_Chips_Bar"),
            world.as_ref(),
            &Request::new("Bring me the chips", &scenario, &lexicon)
        ),
        Some("Bar".to_string())
    );
    // The hall light is on already, and the request names it: a doubt, not a mistake.
    assert_eq!(
        unsaid_object_holding(
            &g("Active_HallLight"),
            world.as_ref(),
            &Request::new(
                "Could you check that the hall light is on?",
                &scenario,
                &lexicon
            )
        ),
        None
    );
}

#[test]
fn what_every_alternative_repeats_is_judged_once() {
    let (scenario, _) = cafe();
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
    let g = |t: &str| Formula::parse(t).expect("parses");
    let goal = g("RobotNear_Table3 & On_Chips_Table3 | RobotNear_Table3 & On_Dessert_Table3");
    assert_eq!(
        factored(&goal).to_string(),
        "RobotNear_Table3 & (On_Chips_Table3 | On_Dessert_Table3)"
    );
    let request = "I'm at the third table, bring me fries or a dessert";
    assert_eq!(
        without_unasked(&goal, &Request::new(request, &scenario, &lexicon))
            .map(|f| f.to_string())
            .as_deref(),
        Some("On_Chips_Table3 | On_Dessert_Table3")
    );
    // Nothing shared, or an alternative that is only the shared part: as it is.
    let apart = g("On_Chips_Table3 | On_Dessert_Table3");
    assert_eq!(factored(&apart), apart);
    let absorbing = g("RobotNear_Table3 | RobotNear_Table3 & On_Chips_Table3");
    assert_eq!(factored(&absorbing), absorbing);
}

#[test]
fn alternatives_claim_each_word_once_per_condition() {
    let (s, _) = cafe();
    let lexicon = Lexicon::new(&s.domain.vocabulary, &s.examples);
    let request = "Switch on the AC, and bring chips to table 1 or juice to table 2.";
    let goal = s
        .parse_goal("Active_AC & (On_Chips_Table1 | On_NFCJuice_Table2) & RobotNear_Table1")
        .expect("parses");
    let extra: Vec<String> = unasked(&goal, &Request::new(request, &s, &lexicon))
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(extra, ["RobotNear_Table1"]);
    let asked = s
        .parse_goal("Active_AC & (On_Chips_Table1 | On_NFCJuice_Table2)")
        .expect("parses");
    assert!(unasked(&asked, &Request::new(request, &s, &lexicon)).is_empty());
}

#[test]
fn an_object_the_scene_lacks_answered_with_another_of_its_kind_is_a_guess() {
    let scenario = Scenario::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml"),
    )
    .expect("cell scenario");
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
    let guessed = |request: &str, goal: &str| {
        guessed_for_unknown(
            &scenario.parse_goal(goal).expect("parses"),
            &Request::new(request, &scenario, &lexicon),
        )
    };
    let why = guessed(
        "Put the purple cube on the green cube",
        r#""blue cube" on "green cube""#,
    )
    .expect("a guess");
    assert!(
        why.contains("\"purple cube\"") && why.contains("\"blue cube\""),
        "{why}"
    );
    // Named in full, or named by a word the scene knows: no guess.
    assert_eq!(
        guessed(
            "Put the blue cube on the green cube",
            r#""blue cube" on "green cube""#
        ),
        None
    );
    assert_eq!(
        guessed(
            "Put the cube on the green cube",
            r#""blue cube" on "green cube""#
        ),
        None
    );
    // A word not after an article says no particular object.
    assert_eq!(
        guessed(
            "Stack purple cubes on the green cube",
            r#""blue cube" on "green cube""#
        ),
        None
    );
}
