//! Tests of the judge: misreadings undone one after another, and a wish of several.

use super::*;
use crate::reading::Lexicon;
use std::path::Path;

fn cafe() -> Scenario {
    Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml"))
        .expect("cafe scenario")
}

fn judge<'a>(
    scenario: &'a Scenario,
    lexicon: &'a Lexicon,
    request: &'a str,
    one_of_several: bool,
) -> Judge<'a> {
    Judge {
        scenario,
        world: crate::world::load(scenario).expect("cafe world"),
        request: Request::new(request, scenario, lexicon),
        shown: Vec::new(),
        misreadings: crate::reading::MISREADINGS.to_vec(),
        one_of_several,
    }
}

#[test]
fn misreadings_are_undone_one_after_another() {
    let cafe = cafe();
    let request = "Please bring a dessert to table 3 and turn on the AC.";
    let lexicon = Lexicon::new(&cafe.domain.vocabulary, &cafe.examples);
    let j = judge(&cafe, &lexicon, request, false);
    let answer = cafe
        .parse_goal("Exists_Dessert & RobotNear_Table3")
        .expect("parses");
    let undone = j.undone_in_turn(&answer);
    let last = undone
        .iter()
        .find(|(g, why)| {
            why.is_ok() && Some(g.clone()) == cafe.parse_goal("On_Dessert_Table3 & Active_AC").ok()
        })
        .map(|(_, why)| why.clone());
    let why = last
        .expect("the AC asked for put beside, then the dessert put there")
        .expect("well typed");
    assert!(why.contains("; then "), "{why}");
    // What it came to has no misreading left.
    let done = cafe
        .parse_goal("On_Dessert_Table3 & Active_AC")
        .expect("parses");
    assert_eq!(j.misread(&done), None);
    // A step that puts an object where its predicate does not take it comes out refused:
    // the chips named in the coffee's place of `Exists_Coffee`, which only makable things fit.
    let lexicon = Lexicon::new(&cafe.domain.vocabulary, &cafe.examples);
    let j = judge(&cafe, &lexicon, "Please bring the chips to table 3.", false);
    let answer = cafe
        .parse_goal("Exists_Coffee & RobotNear_Table3")
        .expect("parses");
    assert!(
        j.undone_in_turn(&answer)
            .iter()
            .any(|(g, why)| why.is_err() && g.to_string().contains("Exists_Chips"))
    );
}

#[test]
fn a_wish_of_several_may_hold_already() {
    let cafe = cafe();
    let request = "please keep the AC switched off";
    let goal = cafe.parse_goal("~Active_AC").expect("parses");
    let lexicon = Lexicon::new(&cafe.domain.vocabulary, &cafe.examples);
    let whole = judge(&cafe, &lexicon, request, false).assess(&goal);
    assert_eq!(whole.map(|p| p.kind), Some(ProblemKind::HoldsAlready));
    assert_eq!(judge(&cafe, &lexicon, request, true).assess(&goal), None);
}

#[test]
fn what_was_undone_may_leave_a_part_nothing_asks_for_which_goes() {
    let cafe = cafe();
    let request = "Come to table 3 and pick up my vacuum cup.";
    let lexicon = Lexicon::new(&cafe.domain.vocabulary, &cafe.examples);
    let j = judge(&cafe, &lexicon, request, false);
    let answer = cafe
        .parse_goal("On_Teacup_Table3 & ~On_VacuumCup_Table1")
        .expect("parses");
    let undone: Vec<String> = j
        .undone_in_turn(&answer)
        .into_iter()
        .filter(|(_, why)| why.is_ok())
        .map(|(g, _)| g.to_string())
        .collect();
    assert!(
        undone.contains(&"RobotNear_Table3 & Holding_VacuumCup".to_string()),
        "{undone:?}"
    );
}

#[test]
fn a_relation_the_other_way_round_is_a_misreading_undone() {
    let cell = Scenario::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml"),
    )
    .expect("cell scenario");
    let request = "Put the blue cube on the green cube";
    let lexicon = Lexicon::new(&cell.domain.vocabulary, &cell.examples);
    let j = judge(&cell, &lexicon, request, false);
    let reversed = cell
        .parse_goal(r#""green cube" on "blue cube""#)
        .expect("parses");
    let why = j.misread(&reversed).expect("a misreading");
    assert!(why.contains("other way round"), "{why}");
    let as_said = cell
        .parse_goal(r#""blue cube" on "green cube""#)
        .expect("parses");
    assert!(j.misread(&as_said).is_none());
    assert!(
        j.undone_in_turn(&reversed)
            .iter()
            .any(|(g, why)| *g == as_said && why.is_ok()),
        "turned round as the request says"
    );
}
