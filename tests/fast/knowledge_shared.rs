//! One policy store, shared: sessions and processes keeping rules in one policy
//! directory keep each other's rules (the knowledge file changed under a lock, as it is
//! then), and `betr resolve` keeps its policy where the workbench and `--learn` look.
//! The real binary against a fake server that answers with hand-written fixtures.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::Path;

use betr::domain::{ActionCall, Condition};
use betr::session::knowledge::{KeptRule, Knowledge, Provenance};
use support::cli::{betr, resolve_yes, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::repo::{rule, scenario};

fn scenario_path(rel: &str) -> String {
    fixtures::root().join(rel).to_string_lossy().into_owned()
}

/// A kept rule of `skill` as one made in scenario 1.
fn kept(s: &betr::scenario::Scenario, skill: &str, requires: &str) -> KeptRule {
    let action = ActionCall::parse(&format!("{skill} \"blue cube\"")).unwrap();
    let condition = Condition::parse("~\"any object\" on \"blue cube\"").unwrap();
    KeptRule::new(
        &rule(skill, requires),
        s,
        Provenance {
            scenario_file: "scenarios/cell/red_on_blue.toml".into(),
            action: &action,
            condition: &condition,
            proposed_by: "a test".into(),
            kept_by: "a test".into(),
        },
    )
}

#[test]
fn sessions_sharing_a_knowledge_file_keep_each_others_rules() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let dir = tmp("knowledge-shared");
    let path = dir.join("knowledge.toml");
    // Both sessions read the file before either keeps a rule.
    let mut first = Knowledge::open(&path).unwrap();
    let mut second = Knowledge::open(&path).unwrap();
    let (a, _) = first
        .keep(kept(&s, "grasp", "~\"any object\" on \"{1}\""))
        .unwrap();
    let (b, new) = second
        .keep(kept(&s, "grasp", "~\"any object\" grasped"))
        .unwrap();
    assert_eq!((a.id.as_str(), b.id.as_str(), new), ("r1", "r2", true));
    // The same rule again is the one kept, not a second copy.
    let (again, new) = first
        .keep(kept(&s, "grasp", "~\"any object\" grasped"))
        .unwrap();
    assert_eq!((again.id.as_str(), new), ("r2", false));
    // Nor one for some objects that r1 holds for every object.
    let mut narrow = kept(&s, "grasp", "~\"any object\" on \"{1}\"");
    narrow.only = Some(vec!["blue cube".into()]);
    let (held, new) = second.keep(narrow).unwrap();
    assert_eq!((held.id.as_str(), new), ("r1", false));
    let file = Knowledge::open(&path).unwrap();
    let ids: Vec<&str> = file.rules.iter().map(|r| r.id.as_str()).collect();
    assert_eq!(ids, ["r1", "r2"]);
    // A revoke from a session that read the file before works on the file as it is.
    let mut stale = Knowledge {
        path: path.clone(),
        rules: Vec::new(),
        examples: Default::default(),
    };
    stale.revoke("r1").unwrap();
    let ids: Vec<String> = Knowledge::open(&path)
        .unwrap()
        .rules
        .into_iter()
        .map(|r| r.id)
        .collect();
    assert_eq!(ids, ["r2"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `betr resolve --yes --learn` of each scenario at once, all keeping their rules in
/// one policy directory: what each printed, and the knowledge file after.
fn learn_at_once(name: &str, scenarios: &[String]) -> (Vec<String>, Knowledge) {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp(name);
    let policies = dir.join("policies").to_string_lossy().into_owned();
    let base = server.base_url();
    let children: Vec<_> = scenarios
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let mut args = resolve_yes(s, &base);
            args.extend(["--policy-dir", &policies]);
            let save = format!("tree-{i}.bt");
            args.extend(["--learn", "--save", &save]);
            support::cli::command(&dir, &args)
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut said = Vec::new();
    for child in children {
        let out = child.wait_with_output().unwrap();
        let log = text(&out);
        assert_eq!(out.status.code(), Some(0), "{log}");
        said.push(log);
    }
    let knowledge = Knowledge::open(&Path::new(&policies).join("knowledge.toml")).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    (said, knowledge)
}

#[test]
fn two_learning_processes_sharing_a_policy_directory_both_keep_their_rules() {
    let scenarios = [
        scenario_path("scenarios/cell/red_on_blue.toml"),
        scenario_path("scenarios/cafe/no_coffee.toml"),
    ];
    let (said, knowledge) = learn_at_once("knowledge-two-domains", &scenarios);
    let domains: Vec<&str> = knowledge.rules.iter().map(|r| r.domain.as_str()).collect();
    assert_eq!(knowledge.rules.len(), 2, "{domains:?}\n{}", said.join("\n"));
    assert!(
        domains.contains(&"cell") && domains.contains(&"cafe"),
        "{domains:?}"
    );
}

#[test]
fn the_same_rule_learned_by_two_processes_at_once_is_kept_once_and_said_so() {
    let scenario = scenario_path("scenarios/cell/red_on_blue.toml");
    let (said, knowledge) = learn_at_once("knowledge-same-rule", &[scenario.clone(), scenario]);
    assert_eq!(
        knowledge.rules.len(),
        1,
        "{:#?}\n{}",
        knowledge.rules,
        said.join("\n---\n")
    );
    let kept = said.iter().filter(|l| l.contains("Kept rule r1")).count();
    assert_eq!(kept, 1, "one process keeps it:\n{}", said.join("\n---\n"));
    assert!(
        !said.iter().any(|l| l.contains("rule r2")),
        "{}",
        said.join("\n")
    );
}

#[test]
fn resolve_keeps_its_policy_where_the_workbench_and_learn_look() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("knowledge-one-store");
    let scenario = scenario_path("scenarios/cell/red_on_blue.toml");
    let out = betr(&dir, &resolve_yes(&scenario, &server.base_url()));
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        !dir.join("policies").exists(),
        "nothing in the working directory"
    );
    let store = betr::session::PolicyStore::new(dir.join("data/betr/policies"));
    let s = scenario_of(&scenario);
    let path = store.path_for(Path::new(&scenario), s.goal.as_ref().unwrap());
    assert!(
        log.contains(&format!("Saved the tree to {}", path.display())),
        "{log}"
    );
    let saved = betr::session::policy::load(&path, &s.domain).unwrap();
    assert_eq!(
        saved.instruction.as_deref(),
        Some("Put the blue cube on the green cube")
    );
    assert_eq!(saved.fixes.len(), 1, "the approved fix with its provenance");
    assert!(!saved.fixes[0].nodes.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

fn scenario_of(path: &str) -> betr::scenario::Scenario {
    betr::scenario::Scenario::load(Path::new(path)).unwrap()
}
