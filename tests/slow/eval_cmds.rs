//! `betr eval goals` against the fake OpenAI server, killed (SIGKILL) once some cases are in
//! its journal, then resumed: every finished case is kept as it was, once, and the results
//! are those of a whole run.

#![allow(clippy::unwrap_used)]

use crate::support;

use support::cli::{KEY_VAR, text, tmp};
use support::eval_goals::{cafe, dataset_dir, goal_fixtures, model_goals, read_json, tally};
use support::fake_openai::{Behavior, FakeServer};

#[test]
fn a_run_killed_midway_resumes_to_the_same_results() {
    let dir = tmp("eval-kill");
    let server = FakeServer::start(vec![], Behavior::Fixtures(goal_fixtures()));
    let d = dataset_dir().display().to_string();
    let url = server.base_url();
    let scenario = cafe();
    let args = [
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
        "--whole-request",
    ];
    let mut child = support::cli::command(&dir, &args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Killed (SIGKILL: no chance to tidy up) once some cases are in the journal.
    let journal = dir.join("out/cases.jsonl");
    let started = std::time::Instant::now();
    while std::fs::read_to_string(&journal).map_or(0, |j| j.lines().count()) < 5 {
        assert!(
            started.elapsed() < std::time::Duration::from_secs(120),
            "the run wrote no journal"
        );
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let before = std::fs::read_to_string(&journal).unwrap();
    assert!(before.lines().count() >= 5);

    let o = model_goals(&dir, &server, &[]);
    assert!(o.status.success(), "{}", text(&o));
    let r = read_json(&dir.join("out/results.json"));
    assert_eq!(r["cases"].as_array().unwrap().len(), 100);
    assert_eq!(tally(&r, "easy"), (28, 30));
    assert_eq!(tally(&r, "hard"), (36, 40));
    // Every case the killed run finished is kept as it was, once.
    let after = std::fs::read_to_string(&journal).unwrap();
    for line in before.lines().filter(|l| l.ends_with('}')) {
        assert_eq!(
            after.lines().filter(|l| *l == line).count(),
            1,
            "a finished case was lost or asked again: {line}"
        );
    }
}
