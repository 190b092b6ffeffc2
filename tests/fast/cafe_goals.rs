//! Every one of the 100 gold goals of the LLM-OBTEA dataset, planned from the shared cafe
//! state: the planner builds a tree that succeeds in the symbolic world, or says precisely
//! why the goal is unreachable. Only contradictory goals may be unreachable.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use crate::support;

use betr::dataset::{self, Case};
use betr::goal::Formula;
use betr::planner::{Outcome, Planner, RunEnd, run_tree};
use betr::world;

fn cases() -> Vec<Case> {
    dataset::load(&support::repo::dataset_dir())
        .expect("the dataset lies in ../shared/datasets/llm-obtea")
}

#[test]
fn every_gold_goal_is_planned_to_success_or_explained() {
    let scenario = support::repo::scenario("scenarios/cafe/cafe.toml");
    let world = world::load(&scenario).unwrap();
    let planner = Planner::new(&scenario.domain);
    let mut failures = Vec::new();
    let mut unreachable = Vec::new();
    for case in cases() {
        let goal = Formula::parse(&case.gold).unwrap();
        let dnf = goal.to_dnf();
        let plan = planner.plan(&dnf, world.as_ref()).unwrap();
        match &plan.outcome {
            Outcome::Success => {
                // The tree also succeeds when run from scratch, and the goal then holds.
                let mut exec = world.fork();
                let report = run_tree(
                    &plan.tree,
                    exec.as_mut(),
                    &scenario.domain,
                    10_000,
                    |_, _| true,
                );
                assert_eq!(
                    report.end,
                    RunEnd::Success,
                    "{}: {}",
                    case.difficulty.as_str(),
                    case.gold
                );
                assert!(
                    goal.eval(&|a| exec.check(&betr::domain::Condition::pos(a.clone()))),
                    "goal false after success: {}",
                    case.gold
                );
            }
            Outcome::Unreachable {
                condition,
                path,
                reason,
                ..
            } => unreachable.push(format!("{} → {condition} at {path:?}: {reason}", case.gold)),
            other => failures.push(format!(
                "{} [{}] → {other:?}",
                case.gold,
                case.difficulty.as_str()
            )),
        }
    }
    assert!(
        failures.is_empty(),
        "{} goal(s) not planned:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // The dataset's goals are all satisfiable, and the cafe can reach every one of them.
    assert!(
        unreachable.is_empty(),
        "unreachable:\n{}",
        unreachable.join("\n")
    );
}
