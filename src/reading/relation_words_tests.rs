//! Tests of the relation a request's words ask for.

use super::*;
use crate::reading::Lexicon;
use crate::scenario::Scenario;
use std::path::Path;

fn scene(file: &str) -> Scenario {
    Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).expect("scenario loads")
}

fn goal(scenario: &Scenario, text: &str) -> Formula {
    scenario.parse_goal(text).expect("parses")
}

#[test]
fn the_relation_said_before_the_place_is_the_one_asked_for() {
    let baby = scene("scenarios/cell/params/baby.toml");
    let vocabulary = &baby.domain.vocabulary;
    let on = goal(&baby, r#""baby doll" on "crib""#);
    let (swapped, word) = relation_as_said(
        &on,
        &Request::among("Lay the doll to sleep in the crib, gently", vocabulary),
    )
    .expect("in the crib asks for in");
    assert_eq!(swapped, goal(&baby, r#""baby doll" in "crib""#));
    assert_eq!(word, "in");
    // Said the other way, the other way round.
    let (swapped, _) = relation_as_said(
        &swapped,
        &Request::among("Leave the doll on the crib", vocabulary),
    )
    .expect("on");
    assert_eq!(swapped, on);
    // Nothing said right before the place, or the goal's own relation said: unchanged.
    assert_eq!(
        relation_as_said(
            &on,
            &Request::among("The crib is ready, the doll goes there", vocabulary)
        ),
        None
    );
    assert_eq!(
        relation_as_said(&on, &Request::among("Put the doll on the crib", vocabulary)),
        None
    );
    // "In front of the crib" says where, not inside.
    assert_eq!(
        relation_as_said(
            &on,
            &Request::among("Put the doll in front of the crib", vocabulary)
        ),
        None
    );
}

#[test]
fn a_scene_with_one_relation_has_nothing_to_swap() {
    let cafe = scene("scenarios/cafe/cafe.toml");
    let on = goal(&cafe, "On_Coffee_Table1");
    assert_eq!(
        relation_as_said(
            &on,
            &Request::among("coffee in table 1", &cafe.domain.vocabulary)
        ),
        None
    );
}

#[test]
fn what_the_convention_brings_is_put_where_it_says() {
    let kit = scene("scenarios/cell/params/first_aid.toml");
    let held = goal(&kit, r#""first aid kit" grasped"#);
    let (put, word) = convention_followed(
        &held,
        &Request::new(
            "Could you fetch the first aid kit for me?",
            &kit,
            &Lexicon::default(),
        ),
    )
    .expect("fetched for me goes on the tray");
    assert_eq!(put, goal(&kit, r#""first aid kit" on "tray""#));
    assert_eq!(word, "fetch");
    // Asked to hold it, in the predicate's own words: held is what is asked.
    assert_eq!(
        convention_followed(
            &held,
            &Request::new("Hold the first aid kit for me", &kit, &Lexicon::default())
        ),
        None
    );
    // Already on the tray, or no word of the convention: nothing to change.
    let on_tray = goal(&kit, r#""first aid kit" on "tray""#);
    assert_eq!(
        convention_followed(
            &on_tray,
            &Request::new("Bring me the first aid kit", &kit, &Lexicon::default())
        ),
        None
    );
    assert_eq!(
        convention_followed(
            &held,
            &Request::new("Lift the first aid kit", &kit, &Lexicon::default())
        ),
        None
    );
}

#[test]
fn a_convention_applies_only_in_a_scene_with_its_objects() {
    let cubes = scene("scenarios/cell/red_on_blue.toml");
    assert!(cubes.domain.vocabulary.object("tray").is_none());
    let held = goal(&cubes, r#""red cube" grasped"#);
    assert_eq!(
        convention_followed(
            &held,
            &Request::new("Bring me the red cube", &cubes, &Lexicon::default())
        ),
        None
    );
}

#[test]
fn the_cells_stated_goals_and_worked_examples_are_not_misreadings() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell");
    let mut files = Vec::new();
    for dir in [root.clone(), root.join("params"), root.join("tasks")] {
        for entry in std::fs::read_dir(&dir).expect("reads the folder") {
            let path = entry.expect("entry").path();
            if path.extension().is_some_and(|e| e == "toml")
                && !["cell.toml", "examples.toml"]
                    .contains(&path.file_name().and_then(|n| n.to_str()).unwrap_or(""))
            {
                files.push(path);
            }
        }
    }
    assert!(files.len() >= 15, "{files:?}");
    let mut checked = 0;
    for path in files {
        let s = Scenario::load(&path).expect("loads");
        let vocabulary = &s.domain.vocabulary;
        let stated = s.instruction.clone().zip(s.goal.clone());
        // The pool's examples whose objects this scene has, read in this scene.
        let examples = s.examples.iter().filter_map(|e| {
            s.parse_goal(&e.goal)
                .ok()
                .map(|g| (e.instruction.clone(), g))
        });
        for (request, gold) in stated.into_iter().chain(examples) {
            assert_eq!(
                relation_as_said(&gold, &Request::among(&request, vocabulary)),
                None,
                "{}: {request}",
                path.display()
            );
            assert_eq!(
                convention_followed(&gold, &Request::new(&request, &s, &Lexicon::default())),
                None,
                "{}: {request}",
                path.display()
            );
            checked += 1;
        }
    }
    assert!(checked > 30, "{checked}");
}
