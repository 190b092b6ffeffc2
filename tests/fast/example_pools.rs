//! The domains' pools of worked examples: every goal is well formed over its domain, the
//! pools are large and varied enough to choose from, no goal mixes `&` and `|` without
//! parentheses (the grammar forbids it, so an example must not teach it), and no example
//! copies or closely paraphrases an instruction of the evaluation dataset.

#![allow(clippy::unwrap_used)] // tests may panic on what they check

use crate::support;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use betr::dataset;
use betr::goal::Formula;
use betr::reading::words::terms;

use support::repo::scenario;

/// `&` and `|` never side by side at one level of the text.
fn mixes_operators(goal: &str) -> bool {
    let mut levels: Vec<(bool, bool)> = vec![(false, false)];
    for c in goal.chars() {
        match c {
            '(' => levels.push((false, false)),
            ')' => {
                levels.pop();
            }
            '&' | '|' => {
                if let Some(level) = levels.last_mut() {
                    if c == '&' {
                        level.0 = true;
                    } else {
                        level.1 = true;
                    }
                    if level.0 && level.1 {
                        return true;
                    }
                }
            }
            _ => {}
        }
    }
    false
}

#[test]
fn the_cafe_pool_covers_every_predicate_over_the_cafe_vocabulary() {
    let s = scenario("scenarios/cafe/cafe.toml");
    assert!(s.examples.len() >= 40, "{} examples", s.examples.len());
    let mut predicates = BTreeSet::new();
    let mut names: BTreeMap<String, usize> = BTreeMap::new();
    let (mut or, mut not, mut nested) = (0, 0, 0);
    for e in &s.examples {
        let goal = s
            .parse_goal(&e.goal)
            .unwrap_or_else(|err| panic!("{:?}: {err}", e.goal));
        assert!(!mixes_operators(&e.goal), "{:?}", e.goal);
        for atom in goal.atoms() {
            predicates.insert(atom.predicate.clone());
            for a in &atom.args {
                *names.entry(a.clone()).or_default() += 1;
            }
        }
        or += usize::from(e.goal.contains('|'));
        not += usize::from(e.goal.contains('~'));
        nested += usize::from(e.goal.contains('('));
    }
    for p in &s.domain.vocabulary.predicates {
        assert!(predicates.contains(&p.name), "no example uses {}", p.name);
    }
    assert!(
        or >= 5 && not >= 5 && nested >= 3,
        "| {or}, ~ {not}, () {nested}"
    );
    // Items and places rotate: none dominates the pool. (There are only three
    // appliances, one curtain and one control: those repeat by necessity.)
    let vocabulary = &s.domain.vocabulary;
    names.retain(|n, _| {
        vocabulary
            .object(n)
            .is_some_and(|o| o.types.iter().any(|t| t == "item" || t == "place"))
    });
    let most = names.iter().max_by_key(|(_, n)| **n).unwrap();
    assert!(*most.1 <= 6, "{} appears in {} atoms", most.0, most.1);
}

#[test]
fn the_cell_pool_is_written_in_the_cell_vocabulary() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    assert!(s.examples.len() >= 25, "{} examples", s.examples.len());
    let known: BTreeSet<&str> = s
        .domain
        .vocabulary
        .predicates
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    let mut used = BTreeSet::new();
    for e in &s.examples {
        // Examples name objects of other scenes; their predicates are the cell's.
        let goal = Formula::parse(&e.goal).unwrap_or_else(|err| panic!("{:?}: {err}", e.goal));
        assert!(!mixes_operators(&e.goal), "{:?}", e.goal);
        for atom in goal.atoms() {
            assert!(known.contains(atom.predicate.as_str()), "{:?}", e.goal);
            used.insert(atom.predicate.clone());
        }
    }
    assert_eq!(used.len(), known.len(), "predicates used: {used:?}");
}

#[test]
fn no_example_copies_or_paraphrases_a_dataset_instruction() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/datasets/llm-obtea");
    let cases = dataset::load(&dir).expect("the dataset lies in ../shared/datasets/llm-obtea");
    let s = scenario("scenarios/cafe/cafe.toml");
    let words = |t: &str| terms(t).into_iter().collect::<BTreeSet<String>>();
    for e in &s.examples {
        let mine = words(&e.instruction);
        for c in &cases {
            let theirs = words(&c.instruction);
            let shared = mine.intersection(&theirs).count() as f64;
            let union = mine.union(&theirs).count().max(1) as f64;
            assert!(
                shared / union < 0.6,
                "{:?} is too close to a dataset instruction ({:?})",
                e.instruction,
                c.instruction
            );
        }
    }
}

#[test]
fn operators_mixed_without_parentheses_are_found() {
    assert!(mixes_operators("A | B & C"));
    assert!(!mixes_operators("(A | B) & C"));
    assert!(!mixes_operators("A & ~(B | C) & D"));
}
