//! docs/SCENARIO-FILES.md stays true: its complete example is a scenario file that loads,
//! whose world and `[verify]` table read, whose goal plans and fails in the world the way
//! the page says, and whose words rewrite the misreadings the page lists.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::Path;

use betr::goal::Formula;
use betr::reading::{Lexicon, MISREADINGS, Request};
use betr::scenario::Scenario;

/// The one fenced TOML block under the page's "A complete small domain" heading.
fn example() -> String {
    let page = std::fs::read_to_string(support::repo::path("docs/SCENARIO-FILES.md")).unwrap();
    let section = page
        .split("\n## A complete small domain\n")
        .nth(1)
        .expect("the page has its example section");
    let block = section
        .split("```toml\n")
        .nth(1)
        .expect("the section has a toml block");
    let end = block.find("\n```").expect("the toml block is closed");
    assert_eq!(
        section.matches("```toml").count(),
        1,
        "one example in the section"
    );
    block[..end + 1].to_string()
}

fn load() -> Scenario {
    Scenario::from_text(Path::new("flat.toml"), example()).unwrap_or_else(|e| panic!("{e}"))
}

/// What the detector `name` makes of `goal` read for `request`: the goals it rewrites
/// it to.
fn undone(scenario: &Scenario, name: &str, request: &str, goal: &str) -> Vec<String> {
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
    let request = Request::new(request, scenario, &lexicon);
    let detector = MISREADINGS.iter().find(|m| m.name() == name).unwrap();
    let goal = Formula::parse(goal).unwrap();
    assert!(
        detector.find(&goal, &request).is_some(),
        "{name} finds nothing in {goal} for {:?}",
        request.text
    );
    detector
        .undo(&goal, &request)
        .into_iter()
        .map(|(g, _)| g.to_string())
        .collect()
}

#[test]
fn the_example_domain_loads_with_its_world_and_verification() {
    let scenario = load();
    assert_eq!(scenario.name, "Keys in the drawer");
    assert_eq!(scenario.goal.as_ref().unwrap().to_string(), "On_Keys_Tray");
    assert_eq!(scenario.examples.len(), 4);
    assert_eq!(scenario.conventions.len(), 1);
    let keys = scenario.domain.vocabulary.object("Keys").unwrap();
    assert_eq!(keys.called, vec!["house keys", "key ring"]);
    betr::world::symbolic::SymbolicWorld::from_scenario(&scenario).unwrap();
    let verify = betr::verify::VerifyConfig::from_scenario(&scenario).unwrap();
    assert_eq!((verify.properties.len(), verify.disturbances.len()), (1, 1));
}

#[test]
fn the_example_plans_and_fails_where_the_page_says() {
    let dir = support::cli::tmp("scenario-doc");
    std::fs::write(dir.join("flat.toml"), example()).unwrap();
    let out = support::cli::betr(&dir, &["plan", "flat.toml"]);
    let text = support::cli::text(&out);
    assert!(
        text.contains("PickUp \"Keys\"") && text.contains("The keys are in the closed drawer"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_examples_words_rewrite_the_misreadings_the_page_lists() {
    let scenario = load();
    let bring = "Bring me the house keys";
    assert_eq!(
        undone(&scenario, "convention", bring, "Holding_Keys"),
        vec!["On_Keys_Tray"]
    );
    assert_eq!(
        undone(&scenario, "swapped-object", bring, "On_Cup_Tray"),
        vec!["On_Keys_Tray"]
    );
    assert_eq!(
        undone(
            &scenario,
            "turned-around",
            "Turn off the reading light",
            "Lit_Lamp"
        ),
        vec!["~Lit_Lamp"]
    );
    assert_eq!(
        undone(
            &scenario,
            "left-unanswered",
            "Bring the cup to the desk and don't forget to switch on the lamp",
            "On_Cup_Desk"
        ),
        vec!["On_Cup_Desk & Lit_Lamp"]
    );
}
