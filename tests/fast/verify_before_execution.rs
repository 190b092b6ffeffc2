//! Verification before execution: every scenario's tree planned in the planner's model
//! (no simulation) verifies, through the real binary with exit 0, and so do the trees of
//! the cafe's 100 gold goals; SPIN agrees with betr on every scenario's exported model.
//! The gate on approved changes is tested in `engine.rs` and `resolve_loop.rs`.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use crate::support;

use std::path::{Path, PathBuf};

use betr::dataset;
use betr::domain::Condition;
use betr::goal::{Dnf, Formula};
use betr::planner::Outcome;
use betr::scenario::Scenario;
use betr::verify::{self, Limits, VerifyConfig, VerifyInput, plan_in_model};
use betr::world;
use support::cli::{betr, text, tmp};
use support::spread;
use support::verify::{check, root, spin_agrees};

/// Every scenario file: the ten failure scenarios, the seven parameter scenarios and the
/// cafe of the dataset (example pools and the cell's base file are not scenarios).
fn scenario_files() -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![root().join("scenarios")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                dirs.push(path);
            } else if name.ends_with(".toml") && name != "examples.toml" && name != "cell.toml" {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// `goal` planned in the model from `initial`, under the scenario's `[verify]` table;
/// it must succeed there.
fn model_tree(s: &Scenario, initial: &[Condition], goal: &Dnf) -> betr::bt::Tree {
    let config = VerifyConfig::from_scenario(s).unwrap();
    let planned = plan_in_model(
        &s.domain,
        initial,
        goal,
        &config.properties,
        &config.disturbances,
    )
    .unwrap();
    assert_eq!(
        planned.plan.outcome,
        Outcome::Success,
        "{}: {goal:?}",
        s.name
    );
    planned.plan.tree
}

#[test]
fn betr_verify_passes_on_every_scenario_file() {
    let files = scenario_files();
    // 10 failure scenarios, the 2 only real arms fail, 7 parameter scenarios, the cafe,
    // the 7 new tasks, the greenhouse, the lab, the warehouse and the hospital.
    assert_eq!(files.len(), 31, "{files:?}");
    let dir = tmp("verify-every-scenario");
    for file in files {
        let out = betr(&dir, &["verify", file.to_str().unwrap()]);
        let said = text(&out);
        assert_eq!(out.status.code(), Some(0), "{}:\n{said}", file.display());
        assert!(
            said.contains("planned in the planner's model") && said.contains("VERIFIED"),
            "{}:\n{said}",
            file.display()
        );
    }
}

#[test]
fn the_trees_of_the_hundred_cafe_gold_goals_verify_in_the_model() {
    let s = Scenario::load(&root().join("scenarios/cafe/cafe.toml")).unwrap();
    let config = VerifyConfig::from_scenario(&s).unwrap();
    let initial = world::load(&s).unwrap().facts();
    let cases = dataset::load(Path::new(&root().join("../shared/datasets/llm-obtea"))).unwrap();
    assert_eq!(cases.len(), 100);
    let mut failed = Vec::new();
    for case in cases {
        let goal = Formula::parse(&case.gold).unwrap().to_dnf();
        let tree = model_tree(&s, &initial, &goal);
        let input = VerifyInput {
            domain: &s.domain,
            tree: &tree,
            initial: &initial,
            disturbances: &config.disturbances,
            properties: &config.properties,
            limits: Limits::default(),
        };
        let report = verify::verify(&input);
        if !report.holds() {
            let why = report
                .findings
                .iter()
                .map(|f| format!("{:?} at {:?}", f.rule, f.path))
                .chain(report.model.iter().flat_map(|m| {
                    m.properties
                        .iter()
                        .filter(|p| !p.verdict.holds())
                        .map(|p| p.name.clone())
                }))
                .collect::<Vec<_>>()
                .join("; ");
            failed.push(format!(
                "{} [{}]: {why}",
                case.gold,
                case.difficulty.as_str()
            ));
        }
    }
    assert!(
        failed.is_empty(),
        "{} of 100 do not verify:\n{}",
        failed.len(),
        failed.join("\n")
    );
}

#[test]
fn spin_agrees_on_every_scenario_model_planned_in_the_model() {
    // Each scenario is checked on its own, so they run on every core.
    spread::each(
        &scenario_files(),
        |f| f.display().to_string(),
        |file| {
            let s = Scenario::load(file).unwrap();
            let initial = world::load(&s).unwrap().facts();
            let tree = model_tree(&s, &initial, &s.goal.clone().unwrap().to_dnf());
            let (report, model) = check(&s, &tree, false);
            assert!(report.holds(), "{}:\n{report:#?}", file.display());
            let name = format!("model-{}", s.name.replace([' ', ':', '/'], "_"));
            // `None`: SPIN is missing outside CI (said loudly by the helper).
            if let Some(claims) = spin_agrees(&report, &model, &name) {
                assert!(!claims.is_empty(), "{}", file.display());
            }
        },
    );
}
