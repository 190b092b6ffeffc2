//! The goal parser, minimal DNF and goal comparison on the 100 gold goals of LLM-OBTEA.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use crate::support;

use betr::dataset::{self, Case, Difficulty};
use betr::goal::{Formula, equivalent, same_dnf};

fn cases() -> Vec<Case> {
    let dir = support::repo::dataset_dir();
    dataset::load(&dir).unwrap_or_else(|e| panic!("{e}"))
}

fn gold(case: &Case) -> Formula {
    Formula::parse(&case.gold)
        .unwrap_or_else(|e| panic!("{} #{}: {:?}: {e}", case.difficulty, case.index, case.gold))
}

/// Both comparisons, checked to agree.
fn equal(a: &Formula, b: &Formula) -> bool {
    let by_table = equivalent(a, b).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        by_table,
        same_dnf(a, b),
        "the two rules disagree on {a} vs {b}"
    );
    by_table
}

/// Every `&` / `|` list reversed.
fn reversed(f: &Formula) -> Formula {
    match f {
        Formula::Atom(_) => f.clone(),
        Formula::Not(x) => Formula::Not(Box::new(reversed(x))),
        Formula::And(v) => Formula::And(v.iter().rev().map(reversed).collect()),
        Formula::Or(v) => Formula::Or(v.iter().rev().map(reversed).collect()),
    }
}

/// Printed with parentheses around every atom and group, and extra spaces.
fn loud(f: &Formula) -> String {
    let list = |v: &[Formula], op: &str| {
        let items: Vec<String> = v.iter().map(loud).collect();
        format!("( {} )", items.join(&format!("  {op}\t")))
    };
    match f {
        Formula::Atom(a) => format!("(({a}))"),
        Formula::Not(x) => format!("~ ({})", loud(x)),
        Formula::And(v) => list(v, "&"),
        Formula::Or(v) => list(v, "|"),
    }
}

/// Paths (child indices from the root) to every atom.
fn atom_paths(f: &Formula, prefix: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
    match f {
        Formula::Atom(_) => out.push(prefix.clone()),
        Formula::Not(x) => {
            prefix.push(0);
            atom_paths(x, prefix, out);
            prefix.pop();
        }
        Formula::And(v) | Formula::Or(v) => {
            for (i, x) in v.iter().enumerate() {
                prefix.push(i);
                atom_paths(x, prefix, out);
                prefix.pop();
            }
        }
    }
}

/// `f` with the atom at `path` negated.
fn negate_at(f: &Formula, path: &[usize]) -> Formula {
    match (f, path) {
        (_, []) => Formula::Not(Box::new(f.clone())),
        (Formula::Not(x), [_, rest @ ..]) => Formula::Not(Box::new(negate_at(x, rest))),
        (Formula::And(v) | Formula::Or(v), [i, rest @ ..]) => {
            let mut v = v.clone();
            v[*i] = negate_at(&v[*i], rest);
            if matches!(f, Formula::And(_)) {
                Formula::And(v)
            } else {
                Formula::Or(v)
            }
        }
        _ => panic!("bad path"),
    }
}

/// `f` with the literal holding the atom at `path` (the atom, or `~` of it) removed from
/// its `&` / `|` list; `None` when that literal is not directly in a list of two or more.
fn drop_at(f: &Formula, path: &[usize]) -> Option<Formula> {
    match (f, path) {
        (Formula::Not(x), [_, rest @ ..]) => Some(Formula::Not(Box::new(drop_at(x, rest)?))),
        (Formula::And(v) | Formula::Or(v), [i, rest @ ..]) => {
            let mut v = v.clone();
            let is_literal = |x: &Formula| match x {
                Formula::Atom(_) => true,
                Formula::Not(inner) => matches!(**inner, Formula::Atom(_)),
                _ => false,
            };
            if is_literal(&v[*i]) {
                if v.len() < 2 {
                    return None;
                }
                v.remove(*i);
            } else {
                v[*i] = drop_at(&v[*i], rest)?;
            }
            Some(if matches!(f, Formula::And(_)) {
                Formula::and(v)
            } else {
                Formula::or(v)
            })
        }
        _ => None,
    }
}

#[test]
fn dataset_has_the_expected_cases() {
    let cases = cases();
    for (difficulty, count) in Difficulty::ALL.into_iter().zip([30, 30, 40]) {
        let these: Vec<&Case> = cases
            .iter()
            .filter(|c| c.difficulty == difficulty)
            .collect();
        assert_eq!(these.len(), count, "{difficulty}");
        assert!(these.iter().enumerate().all(|(i, c)| c.index == i));
        assert!(these.iter().all(|c| !c.instruction.is_empty()));
    }
    assert_eq!(cases[0].difficulty, Difficulty::Easy);
    assert_eq!(cases[0].gold, "Exists_Coffee");
    assert_eq!(cases[99].difficulty, Difficulty::Hard);
}

#[test]
fn every_gold_goal_parses_and_has_a_satisfiable_equivalent_dnf() {
    for case in cases() {
        let f = gold(&case);
        let dnf = f.to_dnf();
        assert!(
            !dnf.0.is_empty() && !dnf.is_false(),
            "{}: unsatisfiable",
            case.gold
        );
        assert!(!dnf.is_true(), "{}: a tautology", case.gold);
        assert!(equal(&f, &dnf.to_formula()), "{} vs {dnf}", case.gold);
        assert_eq!(Formula::parse(&f.to_string()), Ok(f.clone()));
        // Literal order follows first appearance, which printing the DNF can change
        // (`(A | B) & C` → `A & C | B & C`), so compare as sets.
        let again = Formula::parse(&dnf.to_string()).map(|g| g.to_dnf().to_sets());
        assert_eq!(again, Ok(dnf.to_sets()));
    }
}

#[test]
fn gold_goals_equal_themselves_reordered_and_reparenthesised() {
    for case in cases() {
        let f = gold(&case);
        assert!(equal(&f, &f), "{}", case.gold);
        let again = gold(&case);
        assert!(equal(&f, &again));
        let reversed = reversed(&f);
        let printed = reversed.to_string();
        let back = Formula::parse(&printed).unwrap_or_else(|e| panic!("{printed}: {e}"));
        assert_eq!(back, reversed.flatten());
        assert!(equal(&f, &back), "{} vs {printed}", case.gold);
        for variant in [loud(&f), loud(&reversed)] {
            let back = Formula::parse(&variant).unwrap_or_else(|e| panic!("{variant}: {e}"));
            assert!(equal(&f, &back), "{} vs {variant}", case.gold);
        }
        assert_eq!(Formula::parse(&loud(&f)), Ok(f.clone()));
    }
}

#[test]
fn changed_gold_goals_are_not_equal() {
    let mut changed = 0;
    for case in cases() {
        let f = gold(&case);
        let mut paths = Vec::new();
        atom_paths(&f, &mut Vec::new(), &mut paths);
        for path in &paths {
            let negated = negate_at(&f, path);
            assert!(!equal(&f, &negated), "{} vs {negated}", case.gold);
            changed += 1;
            if let Some(dropped) = drop_at(&f, path) {
                assert!(!equal(&f, &dropped), "{} vs {dropped}", case.gold);
                changed += 1;
            }
        }
    }
    assert!(changed > 300, "only {changed} changed goals");
}

#[test]
fn planner_order_of_a_known_goal() {
    let f = Formula::parse("On_Chips_Table3 | On_Dessert_Table3").unwrap_or_else(|e| panic!("{e}"));
    let dnf = f.to_dnf();
    let first: Vec<String> = dnf.0[0].iter().map(|c| c.to_string()).collect();
    assert_eq!(first, ["On_Chips_Table3"]);
}
