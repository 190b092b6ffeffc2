//! `betr eval resolve` and `betr eval params` against the fake OpenAI server answering
//! the hand-written fixture replies of `tests/fixtures/replies/`: tables, JSON and CSV
//! checked; a rerun asks nothing again; a rejected value followed by a corrected one is
//! recorded with the world's verdict on each.

#![allow(clippy::unwrap_used)]

use crate::support;

use std::path::Path;

use serde_json::Value as Json;
use support::cli::{betr, openai_flags, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures::{self, FixtureReply};

fn read_json(path: &Path) -> Json {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn session_eval(
    dir: &Path,
    server: &FakeServer,
    experiment: &str,
    runs: &str,
) -> std::process::Output {
    session_eval_with(dir, server, &[experiment, "--runs", runs])
}

/// `betr eval ARGS…` on the repository's scenarios into `out`, answered by `server`.
fn session_eval_with(dir: &Path, server: &FakeServer, args: &[&str]) -> std::process::Output {
    let scenarios = fixtures::root().join("scenarios").display().to_string();
    let url = server.base_url();
    let mut all = vec!["eval"];
    all.extend_from_slice(args);
    all.extend(["--scenarios", &scenarios, "--out", "out"]);
    all.extend(openai_flags(&url));
    betr(dir, &all)
}

#[test]
fn resolve_runs_every_failure_scenario_against_fixture_replies() {
    let dir = tmp("eval-resolve");
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let o = session_eval(&dir, &server, "resolve", "2");
    assert!(o.status.success(), "{}", text(&o));
    let r = read_json(&dir.join("out/results.json"));
    let scenarios = r["scenarios"].as_array().unwrap();
    assert_eq!(scenarios.len(), 10);
    assert_eq!(r["cases"].as_array().unwrap().len(), 20);
    for s in scenarios {
        assert_eq!(s["successes"], 2, "{s}");
        assert_eq!(s["wrong_proposals"], 0, "{s}");
    }
    // Scenario 2 needs two proposals per run, every other one.
    let proposals: Vec<u64> = scenarios
        .iter()
        .map(|s| s["proposals"].as_u64().unwrap())
        .collect();
    assert_eq!(proposals, [2, 4, 2, 2, 2, 2, 2, 2, 2, 2]);
    let table = std::fs::read_to_string(dir.join("out/table.md")).unwrap();
    assert!(table.contains("| 1 | "), "{table}");
    assert!(
        table
            .lines()
            .filter(|l| l.contains("| 100% (2/2) | "))
            .count()
            == 10,
        "{table}"
    );
    assert!(
        table
            .contains("| 2 | Cubes on both cubes | 2/2 | 2/2 | 0 | 100% (2/2) | 4 | 0 | 0 | 3.0 |"),
        "{table}"
    );
    let calls = server.received().len() as u64;
    assert_eq!(r["usage"]["calls"].as_u64(), Some(calls));
    assert!(table.contains(&format!("- {calls} LLM call(s)")), "{table}");
    assert!(
        table.contains("replies were hand-written fixtures"),
        "{table}"
    );
    let csv = std::fs::read_to_string(dir.join("out/results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 21);

    // Rerunning the same command asks nothing again.
    let o = session_eval(&dir, &server, "resolve", "2");
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(server.received().len() as u64, calls);
}

#[test]
fn params_records_values_and_the_worlds_verdicts() {
    let dir = tmp("eval-params");
    // For the egg, a first value that breaks it, then a corrected one when the prompt
    // carries the world's complaint; the other scenarios answer from their fixture files.
    let note = format!("{}: tests/fast/eval_cmds.rs", fixtures::SOURCE);
    let mut replies = vec![
        FixtureReply {
            seed: None,
            when: vec![
                "# Task: parameter value".into(),
                "Bring me an egg".into(),
                "The egg broke".into(),
            ],
            text: "Reasoning: gentler.\nParameter value: 5 N".into(),
            note: note.clone(),
        },
        FixtureReply {
            seed: None,
            when: vec!["# Task: parameter value".into(), "Bring me an egg".into()],
            text: "Reasoning: hold it firmly.\nParameter value: 12 N".into(),
            note,
        },
    ];
    replies.extend(fixtures::every_reply());
    let server = FakeServer::start(vec![], Behavior::Fixtures(replies));
    let o = session_eval(&dir, &server, "params", "2");
    assert!(o.status.success(), "{}", text(&o));
    let r = read_json(&dir.join("out/results.json"));
    let scenarios = r["scenarios"].as_array().unwrap();
    assert_eq!(scenarios.len(), 7);
    for s in scenarios {
        assert_eq!(s["successes"], 2, "{s}");
    }
    let egg = &scenarios[0];
    assert_eq!(egg["first_accepted"], 0);
    assert_eq!(egg["values_proposed"], 4);
    assert_eq!(egg["values_accepted"], 2);
    assert_eq!(egg["limits"]["max"], 6.0);
    let egg_run = &r["cases"][0];
    assert_eq!(egg_run["values"][0]["accepted"], false);
    assert!(
        egg_run["values"][0]["error"]
            .as_str()
            .unwrap()
            .contains("The egg broke")
    );
    assert_eq!(egg_run["values"][1]["accepted"], true);
    let table = std::fs::read_to_string(dir.join("out/table.md")).unwrap();
    assert!(
        table.contains("| force | 12 N ✗ → 5 N, 12 N ✗ → 5 N | 12.00 ± 0.00 N | 1–6 N | 0/2 | 2/2 | 2/4 | 2/2 | 0 | 2/2 | 5.3 N |"),
        "{table}"
    );
    // Every other scenario's fixture value is accepted at once.
    for s in &scenarios[1..] {
        assert_eq!(s["first_accepted"], 2, "{s}");
    }
    assert!(
        table.contains(
            "| tool | shovel, shovel | shovel ×2 | shovel, spoon | 2/2 | 2/2 | 2/2 | 2/2 | 0 | 2/2 | shovel |"
        ),
        "{table}"
    );
    let csv = std::fs::read_to_string(dir.join("out/results.csv")).unwrap();
    assert!(
        csv.contains("\"cell/params/egg.toml\",1,1,\"12 N\",12,false,"),
        "{csv}"
    );
}

#[test]
fn values_beyond_what_the_world_refused_are_not_tried_and_a_midway_value_is() {
    let dir = tmp("eval-params-bounds");
    // The egg: too much force first; told so, a value still above the limit the world
    // stated (turned away untried), then one too little; a value midway is then tried
    // by betr. The other scenarios answer from their fixture files.
    let note = format!("{}: tests/fast/eval_sessions.rs", fixtures::SOURCE);
    let reply = |when: &[&str], value: &str| FixtureReply {
        seed: None,
        when: when.iter().map(|w| (*w).to_string()).collect(),
        text: format!("Reasoning: a guess.\nParameter value: {value}"),
        note: note.clone(),
    };
    let task = "# Task: parameter value";
    let egg = "Bring me an egg";
    let mut replies = vec![
        reply(&[task, egg, "not tried: 8 N"], "0.5 N"),
        reply(&[task, egg, "The egg broke"], "8 N"),
        reply(&[task, egg], "10 N"),
    ];
    replies.extend(fixtures::every_reply());
    let server = FakeServer::start(vec![], Behavior::Fixtures(replies));
    let o = session_eval(&dir, &server, "params", "1");
    assert!(o.status.success(), "{}", text(&o));
    let r = read_json(&dir.join("out/results.json"));
    let case = &r["cases"][0];
    assert_eq!(case["scenario"], "cell/params/egg.toml");
    assert_eq!(case["resolved"], true, "{case}");
    let values: Vec<(&str, bool)> = case["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            (
                v["value"].as_str().unwrap(),
                v["accepted"].as_bool().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        values,
        [
            ("10 N", false),
            ("8 N", false),
            ("0.5 N", false),
            ("3.5 N", true)
        ],
        "{case}"
    );
    let error = |i: usize| case["values"][i]["error"].as_str().unwrap().to_string();
    assert!(error(0).starts_with("tried in simulation"), "{}", error(0));
    assert!(
        error(1).starts_with("not tried: 8 N is not at most 6 N"),
        "{}",
        error(1)
    );
    assert_eq!(case["values"][1]["not_tried"], true);
    assert!(error(2).contains("too little"), "{}", error(2));
    assert_eq!(
        case["values"][3]["by"],
        "betr, midway between values the world refused"
    );
    // The model was asked first for a level of the robot's range (and answered a number,
    // which is taken as it is), then told the bounds in words.
    let prompts: Vec<String> = server
        .received()
        .iter()
        .map(|r| r.body.to_string())
        .filter(|p| p.contains(egg) && p.contains(task))
        .collect();
    assert!(
        prompts[0].contains("as a level of what the robot can do (0 to 80 N): very low = 4 N"),
        "{}",
        prompts[0]
    );
    // Once the world has answered, the questions ask for numbers.
    let numbers = prompts
        .iter()
        .position(|p| p.contains("the robot can do at most 80 N"))
        .expect("a question for a number");
    assert!(
        prompts[numbers..]
            .iter()
            .all(|p| !p.contains("as a level of")),
        "{prompts:?}"
    );
    assert!(
        prompts
            .iter()
            .any(|p| p.contains("leaves only values at most 6 N")),
        "{prompts:?}"
    );
    let table = std::fs::read_to_string(dir.join("out/table.md")).unwrap();
    // Three values tried (the one turned away is not a try): the third was accepted.
    assert!(
        table.contains(
            "| 10 N ✗ → 8 N ⊘ → 0.5 N ✗ → 3.5 N (midway) | 10.00 ± 0.00 N | 1–6 N | 0/1 | 1/1 |"
        ),
        "{table}"
    );
}

#[test]
fn three_settings_are_run_each_into_its_folder_and_tabled_side_by_side() {
    let dir = tmp("eval-settings");
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let follower = fixtures::root()
        .join("tests/fixtures/executor/follower.py")
        .display()
        .to_string();
    let executor = format!("python3 {follower}");
    let o = session_eval_with(
        &dir,
        &server,
        &[
            "resolve",
            "--three-settings",
            "--runs",
            "1",
            "--goal",
            "scenario",
            "--executor",
            &executor,
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let table = std::fs::read_to_string(dir.join("out/settings.md")).unwrap();
    // Each setting's levers, as its folder records them.
    let lever = |folder: &str, key: &str| {
        let run = read_json(&dir.join(format!("out/{folder}/run.json")));
        let r = read_json(&dir.join(format!("out/{folder}/results.json")));
        assert_eq!(r["scenarios"].as_array().unwrap().len(), 10, "{folder}");
        run["settings"][key].as_str().map(str::to_string)
    };
    assert_eq!(lever("model-alone", "shortlist").as_deref(), Some("false"));
    assert_eq!(
        lever("model-alone", "screen_proposals").as_deref(),
        Some("false")
    );
    assert_eq!(lever("model-alone", "executor"), None);
    assert_eq!(
        lever("twin-screened", "planning_without_hidden_rules").as_deref(),
        Some("true")
    );
    assert_eq!(lever("twin-screened", "executor"), None);
    assert_eq!(lever("executed", "executor"), Some(executor.clone()));
    assert!(
        table.starts_with("| # | scenario | model alone | twin-screened | executed by python3 "),
        "{table}"
    );
    // The executor performs the cell scenarios only: the cafe's rows are left out there.
    let sweep = table
        .lines()
        .find(|l| l.contains("Sweep without a mop"))
        .unwrap();
    assert!(sweep.trim_end().ends_with("| — |"), "{sweep}");
    // The fixtures answer the named fix: the model alone resolves all ten, and the cell
    // scenarios resolve with the follower performing their actions.
    let all = table.lines().last().unwrap();
    assert!(all.starts_with("| | all | 10/10 | "), "{all}");
    assert!(all.trim_end().ends_with("| 7/7 |"), "{all}");
}
