//! The readings of an instruction a person chooses among. The planner rules out what it
//! can: a reading it cannot achieve from the current world is dropped, and readings that
//! would make the robot do the same things are one. What is left — when more than one —
//! differs in what the robot would do, and is shown with each reading in words and the
//! first actions of its plan, for the person to choose.

use crate::domain::{Atom, Vocabulary};
use crate::goal::Formula;
use crate::planner::{Outcome, Planner, RunEnd, run_tree};
use crate::scenario::Scenario;
use crate::world::World;

use super::super::types::Reading;

/// How many actions of a reading's plan are shown.
const FIRST_ACTIONS: usize = 3;

/// Ticks a reading's plan is run for to find its actions.
const RUN_TICKS: u64 = 400;

/// The readings among `goals` (best first) that the planner can achieve from `world`,
/// without those whose plan runs the same actions as an earlier one's.
pub fn distinct_readings(
    scenario: &Scenario,
    world: &dyn World,
    goals: &[Formula],
) -> Vec<Reading> {
    let planner = Planner::new(&scenario.domain);
    let mut out: Vec<Reading> = Vec::new();
    for goal in goals {
        let Ok(plan) = planner.plan(&goal.to_dnf(), world) else {
            continue;
        };
        // An action failing in simulation is what failure resolution is for: the goal
        // itself is achievable.
        if !matches!(
            plan.outcome,
            Outcome::Success | Outcome::ActionFailed { .. }
        ) {
            continue;
        }
        let mut run_world = world.fork();
        let mut actions: Vec<String> = Vec::new();
        let report = run_tree(
            &plan.tree,
            run_world.as_mut(),
            &scenario.domain,
            RUN_TICKS,
            |record, _| {
                for id in &record.completed {
                    if let Some(a) = plan.tree.kind(*id).ok().and_then(|k| k.as_action()) {
                        actions.push(format!("{a}!"));
                    }
                }
                true
            },
        );
        if let RunEnd::Failure {
            action: Some((id, _)),
        } = &report.end
            && let Some(a) = plan.tree.kind(*id).ok().and_then(|k| k.as_action())
        {
            actions.push(format!("{a}! (fails in simulation)"));
        }
        if out.iter().any(|r| r.actions == actions) {
            continue;
        }
        out.push(Reading {
            words: in_words(goal, &scenario.domain.vocabulary),
            first_actions: actions.iter().take(FIRST_ACTIONS).cloned().collect(),
            actions,
            goal: goal.clone(),
        });
    }
    out
}

/// The readings offered in one line, numbered from 1, with the doubt about a single one:
/// how logs and recordings tell the choice.
pub fn summary(readings: &[Reading], doubt: Option<&str>) -> String {
    let goals: Vec<String> = readings
        .iter()
        .enumerate()
        .map(|(i, r)| format!("{} {}", i + 1, r.goal))
        .collect();
    let doubt = doubt
        .map(|why| format!(" (doubtful: {why})"))
        .unwrap_or_default();
    format!("readings to choose among{doubt}: {}", goals.join("; "))
}

/// [`distinct_readings`] from the scenario's first state.
pub fn distinct_readings_in_scenario(
    scenario: &Scenario,
    goals: &[Formula],
) -> Result<Vec<Reading>, crate::scenario::ScenarioError> {
    let world = crate::world::load(scenario)?;
    Ok(distinct_readings(scenario, world.as_ref(), goals))
}

/// `goal` in words: each condition by its predicate's description with the objects put
/// in for the words of their types ("the item is at the place" → "Chips is at Table3"),
/// joined by "and", "or" and "not".
pub fn in_words(goal: &Formula, vocabulary: &Vocabulary) -> String {
    match goal {
        Formula::Atom(a) => atom_in_words(a, vocabulary),
        Formula::Not(inner) => format!("not ({})", in_words(inner, vocabulary)),
        Formula::And(items) | Formula::Or(items) => {
            let joint = if matches!(goal, Formula::And(_)) {
                " and "
            } else {
                " or "
            };
            let parts: Vec<String> = items
                .iter()
                .map(|i| match i {
                    Formula::And(_) | Formula::Or(_) => format!("({})", in_words(i, vocabulary)),
                    _ => in_words(i, vocabulary),
                })
                .collect();
            parts.join(joint)
        }
    }
}

/// One condition in words; its written form when the description names no argument.
fn atom_in_words(atom: &Atom, vocabulary: &Vocabulary) -> String {
    let Some(predicate) = vocabulary
        .predicates
        .iter()
        .find(|p| p.name == atom.predicate)
    else {
        return atom.to_string();
    };
    // The description up to its first parenthesis: what follows explains special cases.
    let mut text = predicate
        .description
        .split(" (")
        .next()
        .unwrap_or_default()
        .to_string();
    let mut put = 0;
    for (arg, types) in atom.args.iter().zip(&predicate.arg_types) {
        let ordinal = ["the first object", "the second object", "the second"];
        let found = types
            .iter()
            .map(|t| format!("the {t}"))
            .chain(ordinal.iter().map(|o| o.to_string()))
            .find(|w| contains_word(&text, w));
        if let Some(w) = found {
            text = text.replacen(&w, &format!("\"{arg}\""), 1);
            put += 1;
        }
    }
    if put < atom.args.len() || text.is_empty() {
        return atom.to_string();
    }
    text
}

/// Whether `text` holds `phrase` as whole words.
fn contains_word(text: &str, phrase: &str) -> bool {
    text.match_indices(phrase).any(|(at, _)| {
        let after = text[at + phrase.len()..].chars().next();
        after.is_none_or(|c| !c.is_alphanumeric())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn cafe() -> Scenario {
        Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml"))
            .expect("cafe scenario")
    }

    fn f(s: &Scenario, text: &str) -> Formula {
        s.parse_goal(text).expect("parses")
    }

    #[test]
    fn a_goal_reads_in_its_predicates_words() {
        let cafe = cafe();
        let v = &cafe.domain.vocabulary;
        assert_eq!(
            in_words(&f(&cafe, "On_Chips_Table3"), v),
            "\"Chips\" is at \"Table3\""
        );
        assert_eq!(
            in_words(
                &f(&cafe, "On_Chips_Table3 | Exists_Dessert & ~Active_AC"),
                v
            ),
            "\"Chips\" is at \"Table3\" or (\"Dessert\" has been made and can be used and not (\"AC\" is on))"
        );
    }

    #[test]
    fn readings_the_planner_cannot_achieve_or_that_do_the_same_are_dropped() {
        let cafe = cafe();
        let world = crate::world::load(&cafe).expect("cafe world");
        let goals = [
            f(&cafe, "On_Chips_Table3"),
            f(&cafe, "On_Dessert_Table3"),
            // The same actions as the first: one reading.
            f(&cafe, "On_Chips_Table3 & Holding_Nothing"),
        ];
        let readings = distinct_readings(&cafe, world.as_ref(), &goals);
        assert_eq!(readings.len(), 2, "{readings:#?}");
        assert_eq!(readings[0].goal, goals[0]);
        assert_eq!(readings[1].goal, goals[1]);
        assert!(
            readings[0].first_actions[0].starts_with("MoveTo"),
            "{:?}",
            readings[0].first_actions
        );
        assert_ne!(readings[0].first_actions, readings[1].first_actions);
    }
}
