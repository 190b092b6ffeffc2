//! `betr eval goals`: recorded answers scored by the dataset rule (gold → 100 %, known
//! mistakes → exactly the expected tallies, a wrong line count → exit 2), and the same
//! experiment against the fake OpenAI server answering hand-written fixture replies
//! (generated here from the gold goals, with deliberate mistakes), including an
//! interrupted run that is resumed without asking finished cases again.

#![allow(clippy::unwrap_used)]

mod support;

use std::path::{Path, PathBuf};

use betr::dataset::{self, Case};
use betr::goal::{Formula, same_dnf};
use serde_json::Value as Json;
use support::cli::{KEY_VAR, betr, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures::{self, FixtureReply};

fn dataset_dir() -> PathBuf {
    fixtures::root().join("../shared/datasets/llm-obtea")
}

fn cafe() -> String {
    fixtures::root()
        .join("scenarios/cafe/cafe.toml")
        .display()
        .to_string()
}

fn cases() -> Vec<Case> {
    dataset::load(&dataset_dir()).unwrap()
}

fn read_json(path: &Path) -> Json {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn tally(results: &Json, difficulty: &str) -> (u64, u64) {
    let t = &results[difficulty];
    (t["correct"].as_u64().unwrap(), t["total"].as_u64().unwrap())
}

/// A goal that is valid in the vocabulary but not the gold one.
fn different_goal(gold: &str) -> String {
    let g = Formula::parse(gold).unwrap();
    ["Active_AC", "~Active_AC", "Active_TubeLight"]
        .into_iter()
        .find(|a| !same_dnf(&Formula::parse(a).unwrap(), &g))
        .unwrap()
        .to_string()
}

fn score_answers(dir: &Path, lines: &[String]) -> std::process::Output {
    std::fs::write(dir.join("answers.txt"), lines.join("\n") + "\n").unwrap();
    let d = dataset_dir().display().to_string();
    betr(
        dir,
        &[
            "eval",
            "goals",
            "--dataset",
            &d,
            "--scenario",
            &cafe(),
            "--answers",
            "answers.txt",
            "--out",
            "out",
        ],
    )
}

#[test]
fn gold_answers_score_100_percent() {
    let dir = tmp("eval-gold");
    let gold: Vec<String> = cases().iter().map(|c| c.gold.clone()).collect();
    let o = score_answers(&dir, &gold);
    assert!(o.status.success(), "{}", text(&o));
    let r = read_json(&dir.join("out/results.json"));
    assert_eq!(tally(&r, "easy"), (30, 30));
    assert_eq!(tally(&r, "medium"), (30, 30));
    assert_eq!(tally(&r, "hard"), (40, 40));
    assert_eq!(r["cases"].as_array().unwrap().len(), 100);
    let case = &r["cases"][0];
    for field in ["difficulty", "instruction", "gold", "answer", "correct"] {
        assert!(!case[field].is_null(), "case lacks {field}: {case}");
    }
    let table = std::fs::read_to_string(dir.join("out/table.md")).unwrap();
    assert!(
        table.contains("| 100.0% (30/30) | 100.0% (30/30) | 100.0% (40/40) | 100.0% (100/100) |"),
        "{table}"
    );
    assert!(text(&o).contains(table.trim()));
    let csv = std::fs::read_to_string(dir.join("out/results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 101);
}

#[test]
fn deliberate_mistakes_score_exactly_the_expected_numbers() {
    let dir = tmp("eval-mistakes");
    let cases = cases();
    let mut lines: Vec<String> = cases.iter().map(|c| c.gold.clone()).collect();
    lines[0] = "Active_AC &".into(); // does not parse
    lines[1] = "Active_Fan".into(); // outside the vocabulary
    lines[2] = different_goal(&cases[2].gold); // a different goal
    let hard0 = cases
        .iter()
        .position(|c| c.difficulty.as_str() == "hard")
        .unwrap();
    lines[hard0] = String::new(); // no answer
    lines[hard0 + 5] = "   ".into(); // no answer
    let o = score_answers(&dir, &lines);
    assert!(o.status.success(), "{}", text(&o));
    let r = read_json(&dir.join("out/results.json"));
    assert_eq!(tally(&r, "easy"), (27, 30));
    assert_eq!(tally(&r, "medium"), (30, 30));
    assert_eq!(tally(&r, "hard"), (38, 40));
    let problem = |i: usize| r["cases"][i]["problem"].as_str().unwrap_or("").to_string();
    assert!(problem(0).starts_with("does not parse"), "{}", problem(0));
    assert!(
        problem(1).contains("outside the vocabulary"),
        "{}",
        problem(1)
    );
    assert_eq!(r["cases"][2]["correct"], false);
    assert_eq!(problem(hard0), "no answer");
    assert!(
        text(&o).contains("| 90.0% (27/30) | 100.0% (30/30) | 95.0% (38/40) | 95.0% (95/100) |")
    );
}

#[test]
fn a_wrong_line_count_is_bad_input() {
    let dir = tmp("eval-count");
    let gold: Vec<String> = cases().iter().skip(1).map(|c| c.gold.clone()).collect();
    let o = score_answers(&dir, &gold);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("expected 100 lines"), "{}", text(&o));
    assert!(text(&o).contains("found 99"), "{}", text(&o));
}

/// Fixture replies for all 100 instructions: the gold goal, except a deliberately wrong
/// goal for every case whose index ends in 3 (3 easy, 3 medium, 4 hard).
fn goal_fixtures() -> Vec<FixtureReply> {
    cases()
        .iter()
        .map(|c| FixtureReply {
            when: vec![
                "# Task: goal interpretation".into(),
                format!("## Request\n{}\n", c.instruction),
            ],
            text: if c.index % 10 == 3 {
                format!("Goal: {}", different_goal(&c.gold))
            } else {
                format!("Goal: {}", c.gold)
            },
            note: format!(
                "{}: generated from the gold goals in tests/eval_cmds.rs",
                fixtures::SOURCE
            ),
        })
        .collect()
}

fn model_goals(dir: &Path, server: &FakeServer, extra: &[&str]) -> std::process::Output {
    let d = dataset_dir().display().to_string();
    let url = server.base_url();
    let scenario = cafe();
    let mut args = vec![
        "eval",
        "goals",
        "--dataset",
        &d,
        "--scenario",
        &scenario,
        "--out",
        "out",
        "--backend",
        "openai",
        "--base-url",
        &url,
        "--model",
        "fake-model",
        "--api-key-env",
        KEY_VAR,
    ];
    args.extend_from_slice(extra);
    betr(dir, &args)
}

const MODEL_ROW: &str = "| fake-model (openai), prompt full | 90.0% (27/30) | 90.0% (27/30) | 90.0% (36/40) | 90.0% (90/100) | 100 |";

#[test]
fn goals_against_the_fake_server_are_scored_and_tabled() {
    let dir = tmp("eval-goals-model");
    let server = FakeServer::start(vec![], Behavior::Fixtures(goal_fixtures()));
    let o = model_goals(&dir, &server, &["--concurrency", "4"]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(server.received().len(), 100);
    assert!(server.received().iter().all(|r| r.body["seed"] == 1));
    let r = read_json(&dir.join("out/results.json"));
    assert_eq!(tally(&r, "easy"), (27, 30));
    assert_eq!(tally(&r, "medium"), (27, 30));
    assert_eq!(tally(&r, "hard"), (36, 40));
    assert_eq!(r["usage"]["calls"], 100);
    assert_eq!(r["usage"]["sources"]["hand-written"], 100);
    let table = std::fs::read_to_string(dir.join("out/table.md")).unwrap();
    assert!(table.contains(MODEL_ROW), "{table}");
    assert!(table.contains("| $0.0000 |"), "{table}");
    assert!(table.contains("100 of 100 replies were hand-written fixtures, not a model's answers"));
    assert!(table.contains("Temperature 0"));
    // Tokens in the table are those the server reported.
    let prompt_tokens: u64 = r["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["call"]["prompt_tokens"].as_u64().unwrap())
        .sum();
    assert!(
        table.contains(&format!("| 100 | {prompt_tokens} |")),
        "{table}"
    );
    assert!(dir.join("out/cases.jsonl").is_file() && dir.join("out/results.csv").is_file());
    // No progress bar escape codes when stderr is not a terminal.
    assert!(!String::from_utf8_lossy(&o.stderr).contains('\u{1b}'));
}

#[test]
fn an_interrupted_run_resumes_without_asking_finished_cases_again() {
    let dir = tmp("eval-resume");
    let server = FakeServer::start(vec![], Behavior::Fixtures(goal_fixtures()));
    let o = model_goals(&dir, &server, &["--limit", "10", "--concurrency", "2"]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(server.received().len(), 10);
    let jsonl = std::fs::read_to_string(dir.join("out/cases.jsonl")).unwrap();
    assert_eq!(jsonl.lines().count(), 10);
    assert!(
        text(&o).contains("Partial: 10 of 100 cases finished"),
        "{}",
        text(&o)
    );
    let first: Vec<String> = server.received().iter().map(|r| r.prompt()).collect();

    // Another prompt variant must not be mixed into the same directory.
    let o = model_goals(&dir, &server, &["--prompt", "cot"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("prompt"), "{}", text(&o));
    assert_eq!(server.received().len(), 10);

    let o = model_goals(&dir, &server, &[]);
    assert!(o.status.success(), "{}", text(&o));
    let received = server.received();
    assert_eq!(
        received.len(),
        100,
        "only the 90 unfinished cases are asked"
    );
    for r in &received[10..] {
        assert!(
            !first.contains(&r.prompt()),
            "a finished case was asked again"
        );
    }
    let r = read_json(&dir.join("out/results.json"));
    assert_eq!(r["cases"].as_array().unwrap().len(), 100);
    assert_eq!(tally(&r, "easy"), (27, 30));
    assert_eq!(tally(&r, "hard"), (36, 40));
    assert!(text(&o).contains(MODEL_ROW), "{}", text(&o));
}

#[test]
fn original_examples_without_a_file_is_refused() {
    let dir = tmp("eval-orig");
    let server = FakeServer::start(vec![], Behavior::Fixtures(goal_fixtures()));
    let o = model_goals(&dir, &server, &["--prompt", "original-examples"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("not shipped"), "{}", text(&o));
    assert!(server.received().is_empty());
}
