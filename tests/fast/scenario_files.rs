//! Scenario files: every shipped scenario loads, and each kind of mistake in a file is
//! reported with its file, line and column and what was expected.

#![allow(clippy::unwrap_used)]
use crate::support;
use std::path::{Path, PathBuf};

use betr::scenario::{Scenario, ScenarioError};
use betr::world;

fn error(text: &str) -> ScenarioError {
    let path = Path::new("bad.toml");
    match Scenario::from_text(path, text).and_then(|s| world::load(&s).map(|_| s)) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

const HEAD: &str = r#"[scenario]
name = "t"
goal = "Holding_Cup"

[objects]
item = ["Cup"]
nothing = ["Nothing"]

[[predicates]]
name = "Holding"
args = ["item|nothing"]
description = "the robot holds it"
"#;

fn lines_before(text: &str, needle: &str) -> usize {
    text[..text.find(needle).unwrap()].matches('\n').count() + 1
}

#[test]
fn every_shipped_scenario_loads() {
    let root = support::repo::path("scenarios");
    let mut files: Vec<PathBuf> = Vec::new();
    let mut stack = vec![root];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "toml") {
                files.push(p);
            }
        }
    }
    assert!(files.len() >= 4);
    // The files that `key = "name"` lines of the scenario files point at.
    let named_by = |key: &str| -> Vec<PathBuf> {
        files
            .iter()
            .filter_map(|f| {
                let text = std::fs::read_to_string(f).unwrap();
                let line = text.lines().find(|l| l.starts_with(key))?;
                let name = line.split('"').nth(1)?;
                Some(f.parent()?.join(name).canonicalize().unwrap())
            })
            .collect()
    };
    // A base file that other files extend need not be a scenario by itself.
    let extended = named_by("extends");
    // Example pools that scenarios name are lists of examples, loaded with them.
    let pools = named_by("example_pool");
    assert!(!pools.is_empty());
    for f in files {
        if pools.contains(&f.canonicalize().unwrap()) {
            continue;
        }
        let is_base = extended.contains(&f.canonicalize().unwrap());
        let text = std::fs::read_to_string(&f).unwrap();
        if is_base && !text.lines().any(|l| l.trim() == "[scenario]") {
            continue;
        }
        let s = Scenario::load(&f).unwrap_or_else(|e| panic!("{e}"));
        world::load(&s).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn toml_syntax_errors_are_located() {
    let text = format!("{HEAD}\n[[skills]\nname = \"x\"\n");
    let e = error(&text);
    assert_eq!(e.file, Path::new("bad.toml"));
    assert_eq!(e.line, lines_before(&text, "[[skills]"));
    assert!(e.to_string().starts_with("bad.toml:"), "{e}");
}

#[test]
fn unknown_predicate_in_a_skill_points_at_the_string() {
    let text = format!(
        "{HEAD}\n[[skills]]\nname = \"Grab\"\nparams = [\"i: item\"]\nadd = [\"Holds_{{i}}\"]\n"
    );
    let e = error(&text);
    assert_eq!(e.line, lines_before(&text, "add = "));
    assert_eq!(e.column, 9, "the first character inside the quotes");
    assert!(e.message.contains("unknown predicate \"Holds\""), "{e}");
}

#[test]
fn unknown_parameter_and_type_are_named() {
    let text = format!(
        "{HEAD}\n[[skills]]\nname = \"Grab\"\nparams = [\"i: item\"]\nadd = [\"Holding_{{x}}\"]\n"
    );
    assert!(error(&text).message.contains("{x}"), "{}", error(&text));
    let text = format!("{HEAD}\n[[skills]]\nname = \"Grab\"\nparams = [\"i: thing\"]\n");
    let e = error(&text);
    assert!(
        e.message.contains("unknown type or object \"thing\""),
        "{e}"
    );
    assert_eq!(e.line, lines_before(&text, "params = "));
}

#[test]
fn a_bad_goal_gives_the_column_inside_the_string() {
    let text = HEAD.replace("goal = \"Holding_Cup\"", "goal = \"Holding_Cup &\"");
    let e = error(&text);
    assert_eq!(e.line, 3);
    assert!(e.message.contains("expected"), "{e}");
    let text = HEAD.replace("goal = \"Holding_Cup\"", "goal = \"Holding_Tea\"");
    assert!(error(&text).message.contains("unknown object \"Tea\""));
}

#[test]
fn world_facts_and_rules_are_checked() {
    let text = format!("{HEAD}\n[world]\ninitial = [\"Holding_Nothing\", \"Holding_Tea\"]\n");
    let e = error(&text);
    assert_eq!(e.line, lines_before(&text, "initial = "));
    assert!(e.message.contains("unknown object \"Tea\""), "{e}");

    let text = format!("{HEAD}\n[world]\ninitial = [\"~Holding_Nothing\"]\n");
    assert!(error(&text).message.contains("no `~`"));

    let text = format!(
        "{HEAD}\n[[world.rules]]\naction = 'Grab \"Cup\"'\nrequires = \"Holding_Nothing\"\nerror = \"x\"\n"
    );
    assert!(error(&text).message.contains("no skill named \"Grab\""));

    let skill = "\n[[skills]]\nname = \"Grab\"\nparams = [\"i: item\"]\nadd = [\"Holding_{i}\"]\n";
    let text = format!(
        "{HEAD}{skill}\n[[world.rules]]\naction = 'Grab \"Cup\"'\nrequires = \"Holding_Nothing\"\n"
    );
    assert!(error(&text).message.contains("needs `error`"));
    let text = format!(
        "{HEAD}{skill}\n[[world.rules]]\naction = 'Grab \"Cup\"'\nrequires = \"Holding_Nothing\"\notherwise = \"explode\"\n"
    );
    assert!(error(&text).message.contains("\"fail\" or \"no effect\""));
}

#[test]
fn unknown_fields_and_missing_bases_are_errors() {
    let text = format!("{HEAD}\nsurprise = 1\n");
    assert!(
        error(&text).message.contains("surprise"),
        "{}",
        error(&text)
    );
    let e = error(&format!("extends = \"missing.toml\"\n{HEAD}"));
    assert_eq!((e.line, e.column), (1, 12));
    assert!(e.message.contains("does not exist"));
}

#[test]
fn a_declared_value_range_must_be_a_range_of_numbers() {
    let skill = |values: &str| {
        format!(
            "{HEAD}\n[[skills]]\nname = \"Grab\"\nparams = [\"i: item\"]\nadd = [\"Holding_{{i}}\"]\nvalues = [{values}]\n"
        )
    };
    let text = skill(r#"{ name = "force", unit = "N", min = 9.0, max = 3.0 }"#);
    let e = error(&text);
    assert_eq!(e.line, lines_before(&text, "name = \"Grab\""));
    assert!(e.message.contains("min 9 is above max 3"), "{e}");
    let e = error(&skill(
        r#"{ name = "tool", categories = ["a"], max = 3.0 }"#,
    ));
    assert!(e.message.contains("for a number with a unit"), "{e}");
    let e = error(&skill(r#"{ name = "force", unit = "N", max = nan }"#));
    assert!(e.message.contains("finite"), "{e}");
}

#[test]
fn a_conventions_checkable_form_names_a_relation_and_one_of_its_objects() {
    let relating = format!(
        "{HEAD}\n[[predicates]]\nname = \"On\"\nargs = [\"item\", \"item|nothing\"]\ndescription = \"rests on\"\n"
    );
    let convention = |body: &str| {
        format!("{relating}\n[[conventions]]\ntext = \"t\"\nobjects = [\"Nothing\"]\n{body}\n")
    };
    let e = error(&convention(
        "words = [\"bring me\"]\nputs = { relation = \"Holding\", place = \"Nothing\" }",
    ));
    assert!(
        e.message
            .contains("\"Holding\" is not a predicate of two arguments"),
        "{e}"
    );
    let text = convention("words = [\"bring me\"]\nputs = { relation = \"On\", place = \"Cup\" }");
    let e = error(&text);
    assert!(
        e.message
            .contains("\"Cup\" is not one of the convention's objects"),
        "{e}"
    );
    assert_eq!(e.line, lines_before(&text, "puts ="));
    let e = error(&convention("words = [\"bring me\"]"));
    assert!(e.message.contains("needs `puts`"), "{e}");
    let e = error(&convention(
        "puts = { relation = \"On\", place = \"Nothing\" }",
    ));
    assert!(e.message.contains("needs `words`"), "{e}");
    let e = error(&convention(
        "words = [\"--\"]\nputs = { relation = \"On\", place = \"Nothing\" }",
    ));
    assert!(e.message.contains("has no letters"), "{e}");
    let ok =
        convention("words = [\"bring me\"]\nputs = { relation = \"On\", place = \"Nothing\" }");
    let scenario = Scenario::from_text(Path::new("ok.toml"), &ok).unwrap();
    let puts = scenario.conventions[0].puts.as_ref().unwrap();
    assert_eq!(
        (puts.relation.as_str(), puts.place.as_str()),
        ("On", "Nothing")
    );
}
