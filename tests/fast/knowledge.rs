//! Fixes that carry over: a fix approved and kept as a rule in one task plans the next
//! task of the same kind right from the start (the real binary, a model server that
//! counts its calls), rules are checked before they are kept, and the knowledge file can
//! be listed, shown and revoked.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::Path;

use betr::domain::{ActionCall, Condition};
use betr::session::knowledge::{Knowledge, Refusal, check_rule, learned_in_tree, offered_rule};
use support::cli::{KEY_VAR, betr, resolve_yes, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

fn scenario_path(rel: &str) -> String {
    fixtures::root().join(rel).to_string_lossy().into_owned()
}

/// `betr resolve SCENARIO --yes` against the fake server, keeping policies in `policies`.
fn resolve<'a>(scenario: &'a str, base: &'a str, policies: &'a str) -> Vec<&'a str> {
    let mut args = resolve_yes(scenario, base);
    args.extend(["--policy-dir", policies]);
    args
}

#[test]
fn a_kept_fix_plans_the_next_task_with_no_model_call_and_no_failure() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("knowledge-carry");
    let policies = dir.join("policies").to_string_lossy().into_owned();
    let base = server.base_url();

    // Scenario 1, resolved once, its fix kept as a rule.
    let first = scenario_path("scenarios/cell/red_on_blue.toml");
    let mut args = resolve(&first, &base, &policies);
    args.push("--learn");
    let out = betr(&dir, &args);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        log.contains("Kept rule r1: grasp {x} needs ~\"any object\" on \"{x}\""),
        "{log}"
    );
    let calls_after_first = server.received().len();
    assert!(calls_after_first >= 2, "goal and fix: {calls_after_first}");
    let knowledge = Knowledge::open(&Path::new(&policies).join("knowledge.toml")).unwrap();
    assert_eq!(knowledge.rules.len(), 1);
    assert_eq!(knowledge.rules[0].requires, "~\"any object\" on \"{1}\"");
    assert!(
        knowledge.rules[0]
            .proposed_by
            .contains("hand-written fixture")
    );

    // A new task with other cubes in the same kind of stack: no call, no failure.
    let next = scenario_path("scenarios/cell/tasks/yellow_on_red.toml");
    let mut args = resolve(&next, &base, &policies);
    args.push("--stated-goal");
    let out = betr(&dir, &args);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(log.contains("SUCCESS in simulation"), "{log}");
    assert!(log.contains("0 question(s) about failures"), "{log}");
    assert!(!log.contains("failed"), "no failure in the world:\n{log}");
    assert!(log.contains("1 learned rule(s)"), "{log}");
    assert_eq!(server.received().len(), calls_after_first, "no model call");

    // Without the knowledge the same task fails in the world and asks the model.
    let mut args = resolve(&next, &base, &policies);
    args.extend(["--stated-goal", "--no-knowledge"]);
    let out = betr(&dir, &args);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(log.contains("No collision free path found"), "{log}");
    assert!(server.received().len() > calls_after_first);

    // `betr verify` names the rule the tree depends on.
    let out = betr(&dir, &["verify", &next, "--policy-dir", &policies]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        log.contains(
            "Learned:  ~\"any object\" on \"yellow cube\"? before grasp \"yellow cube\"! (rule r1)"
        ),
        "{log}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn knowledge_is_listed_shown_and_revoked() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("knowledge-cli");
    let policies = dir.join("p").to_string_lossy().into_owned();
    let base = server.base_url();
    let first = scenario_path("scenarios/cell/red_on_blue.toml");
    let mut args = resolve(&first, &base, &policies);
    args.push("--learn");
    assert_eq!(betr(&dir, &args).status.code(), Some(0));

    let out = betr(&dir, &["knowledge", "list", "--policy-dir", &policies]);
    let log = text(&out);
    assert!(
        log.contains("r1   cell   grasp {1} needs ~\"any object\" on \"{1}\""),
        "{log}"
    );
    let out = betr(
        &dir,
        &["knowledge", "show", "r1", "--policy-dir", &policies],
    );
    let log = text(&out);
    assert!(
        log.contains("Fix:         ~\"any object\" on \"blue cube\" before grasp \"blue cube\"!"),
        "{log}"
    );
    assert!(log.contains("Kept by:     --yes --learn"), "{log}");
    assert!(log.contains("red_on_blue.toml"), "{log}");

    // The same task again: the rule plans it, nothing fails, nothing new is kept.
    let out = betr(&dir, &args);
    assert!(text(&out).contains("0 change(s) kept"), "{}", text(&out));
    let knowledge = Knowledge::open(&Path::new(&policies).join("knowledge.toml")).unwrap();
    assert_eq!(knowledge.rules.len(), 1);
    // Offered again, a kept rule is refused as known.
    let again = knowledge.rules[0].rule();
    let e = check_rule(
        &again,
        &scenario("scenarios/cell/red_on_blue.toml"),
        &knowledge,
    );
    assert_eq!(e, Err(Refusal::Known("r1".into())));

    let out = betr(
        &dir,
        &["knowledge", "revoke", "r7", "--policy-dir", &policies],
    );
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("no rule \"r7\""), "{}", text(&out));
    assert!(text(&out).contains("rules: r1"), "{}", text(&out));
    let out = betr(
        &dir,
        &["knowledge", "revoke", "r1", "--policy-dir", &policies],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let out = betr(&dir, &["knowledge", "list", "--policy-dir", &policies]);
    assert!(text(&out).contains("No learned rules"), "{}", text(&out));

    // A knowledge file that cannot be read is refused with where it is wrong.
    std::fs::write(
        Path::new(&policies).join("knowledge.toml"),
        "version = 1\n[[rules]]\nid = 3\n",
    )
    .unwrap();
    let next = scenario_path("scenarios/cell/tasks/yellow_on_red.toml");
    let out = betr(&dir, &["plan", &next, "--policy-dir", &policies]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        text(&out).contains("knowledge.toml: line 3"),
        "{}",
        text(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

use support::repo::{rule, scenario};

fn empty_knowledge() -> Knowledge {
    Knowledge {
        path: "unused.toml".into(),
        rules: Vec::new(),
        examples: Default::default(),
    }
}

#[test]
fn rules_that_contradict_the_skills_or_break_a_goal_are_refused() {
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let k = empty_knowledge();
    // grasp declares ~"any object" grasped: its negation could never hold with it.
    let e = check_rule(&rule("grasp", "\"any object\" grasped"), &s, &k).unwrap_err();
    assert!(matches!(e, Refusal::ContradictsPrecondition { .. }), "{e}");
    // grasp makes its object grasped: asking for that first makes it pointless.
    let e = check_rule(&rule("grasp", "\"{1}\" grasped"), &s, &k).unwrap_err();
    assert!(matches!(e, Refusal::ContradictsEffect { .. }), "{e}");
    // Nothing may lie on the table before anything is grasped: every cell task that
    // grasps something on the table becomes unplannable.
    let e = check_rule(&rule("grasp", "~\"any object\" on \"table\""), &s, &k).unwrap_err();
    assert!(matches!(e, Refusal::GoalUnplannable { .. }), "{e}");
    assert!(e.to_string().contains("can no longer be planned"), "{e}");
    // A rule naming a skill the domain does not have.
    let e = check_rule(&rule("fly", "\"{1}\" open"), &s, &k).unwrap_err();
    assert!(matches!(e, Refusal::DoesNotFit(_)), "{e}");
    // Scenario 1's fix is fine.
    check_rule(&rule("grasp", "~\"any object\" on \"{1}\""), &s, &k).unwrap();

    // A fix of the fries lifted too far: every item would have to lie on the bar before
    // it is picked up, and the cafe's worked examples that fetch things from elsewhere no
    // longer plan (to put an item on the bar the robot must pick it up first).
    let cafe = scenario("scenarios/cafe/no_coffee.toml");
    let e = check_rule(&rule("PickUp", "On_{1}_Bar"), &cafe, &k).unwrap_err();
    assert!(matches!(e, Refusal::GoalUnplannable { .. }), "{e}");
    assert!(e.to_string().contains("worked example"), "{e}");
    // The no-coffee fix lifted: a makable item must have been made before it is picked
    // up. The predicate takes only makables, so the rule says nothing of other items, and
    // every example still plans.
    check_rule(&rule("PickUp", "Exists_{1}"), &cafe, &k).unwrap();
    let mut d = cafe.domain.clone();
    d.learn(&rule("PickUp", "Exists_{1}")).unwrap();
    let pick = |item: &str| {
        d.resolve(&ActionCall::parse(&format!("PickUp \"{item}\"")).unwrap())
            .unwrap()
            .pre
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
    };
    assert_eq!(pick("Coffee")[0], "Exists_Coffee");
    assert!(!pick("Chips").iter().any(|c| c.starts_with("Exists")));
}

#[test]
fn a_fix_naming_none_of_the_actions_objects_is_offered_only_for_them_and_checked_in_the_base_domain()
 {
    // The fries' fix: the robot near the bar. Nothing ties the bar to the chips in the
    // vocabulary, so the rule cannot be lifted to every item.
    let action = ActionCall::parse("PickUp \"Chips\"").unwrap();
    let fix = Condition::parse("RobotNear_Bar").unwrap();
    let r = offered_rule(&action, &fix, false);
    assert_eq!(r.only, Some(vec!["Chips".to_string()]));
    let s = scenario("scenarios/cafe/find_fries.toml");
    assert_eq!(
        r.describe(&s.domain),
        "PickUp \"Chips\" needs RobotNear_Bar (only for these objects)"
    );
    // The scenario's PickUp leaves out where the robot must be; the cafe's own PickUp
    // needs the robot near the item, and it cannot be near the chips and the bar at once
    // (moving goes next to one thing): the rule would make fetching the chips
    // impossible, so it is refused.
    let e = check_rule(&r, &s, &empty_knowledge()).unwrap_err();
    assert!(
        e.to_string().contains("RobotNear_Chips cannot be achieved"),
        "{e}"
    );
}

#[test]
fn the_tree_marks_the_conditions_a_rule_put_there() {
    let mut s = scenario("scenarios/cell/tasks/yellow_on_red.toml");
    let mut r = rule("grasp", "~\"any object\" on \"{1}\"");
    r.id = "r4".into();
    s.domain.learn(&r).unwrap();
    let world = betr::world::load(&s).unwrap();
    let plan = betr::planner::Planner::new(&s.domain)
        .plan(&s.goal.clone().unwrap().to_dnf(), world.as_ref())
        .unwrap();
    assert_eq!(plan.outcome, betr::planner::Outcome::Success);
    let marked = learned_in_tree(&s.domain, &plan.tree);
    let text: Vec<String> = marked
        .iter()
        .map(|m| {
            format!(
                "{} before {} ({})",
                m.condition,
                m.action,
                m.rules.join(",")
            )
        })
        .collect();
    assert!(
        text.contains(
            &"~\"any object\" on \"yellow cube\" before grasp \"yellow cube\" (r4)".to_string()
        ),
        "{text:?}"
    );
}

#[test]
fn the_sequence_eval_reports_calls_and_failures_with_and_without_kept_knowledge() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("knowledge-sequence");
    let scenarios = fixtures::root().join("scenarios").display().to_string();
    let base = server.base_url();
    let args = [
        "eval",
        "resolve",
        "--sequence",
        "--goal",
        "scenario",
        "--scenarios",
        &scenarios,
        "--out",
        "out",
        "--backend",
        "openai",
        "--base-url",
        &base,
        "--model",
        "fake-model",
        "--api-key-env",
        KEY_VAR,
    ];
    let out = betr(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/results.json")).unwrap())
            .unwrap();
    let steps = results["steps"].as_array().unwrap();
    let tasks = std::fs::read_dir(fixtures::root().join("scenarios/cell/tasks"))
        .unwrap()
        .count();
    assert_eq!(steps.len(), 2 * (10 + tasks));
    let step = |scenario: &str, with: bool| {
        steps
            .iter()
            .find(|s| s["scenario"] == scenario && s["with_knowledge"] == with)
            .unwrap_or_else(|| panic!("no step {scenario} {with}"))
    };
    for s in steps {
        assert_eq!(s["success"], true, "{s}");
    }
    // Scenario 1 keeps the grasp rule; the new cube task then needs nothing.
    let first = step("cell/red_on_blue.toml", true);
    assert!(
        first["rules_kept"][0]
            .as_str()
            .unwrap()
            .starts_with("r1 grasp {x} needs"),
        "{first}"
    );
    let cubes = step("cell/tasks/yellow_on_red.toml", true);
    assert_eq!(cubes["calls"], 0, "{cubes}");
    assert_eq!(cubes["world_failures"], 0, "{cubes}");
    let without = step("cell/tasks/yellow_on_red.toml", false);
    assert_eq!(without["world_failures"], 1, "{without}");
    assert_eq!(without["calls"], 1, "{without}");
    // Over the new tasks, kept knowledge never costs calls or failures.
    let total = |with: bool, key: &str| -> u64 {
        steps
            .iter()
            .filter(|s| s["with_knowledge"] == with)
            .filter(|s| s["scenario"].as_str().unwrap().starts_with("cell/tasks/"))
            .map(|s| s[key].as_u64().unwrap())
            .sum()
    };
    assert!(total(true, "calls") < total(false, "calls"));
    assert!(total(true, "world_failures") < total(false, "world_failures"));
    let table = std::fs::read_to_string(dir.join("out/table.md")).unwrap();
    assert!(table.contains("the new tasks:"), "{table}");
    assert!(table.contains("Rules kept along the way:"), "{table}");

    // Run again: every step is in the journal, nothing is asked.
    let calls = server.received().len();
    let out = betr(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert_eq!(server.received().len(), calls);
    std::fs::remove_dir_all(&dir).unwrap();
}

mod engine {
    use std::sync::Arc;
    use std::time::Duration;

    use betr::scenario::Scenario;
    use betr::session::{Command, Engine, Event, Knowledge, Setup};
    use tokio::sync::mpsc::UnboundedReceiver;

    use super::support::fake_model::FixtureModel;
    use super::support::fixtures;

    async fn until(events: &mut UnboundedReceiver<Event>, pred: impl Fn(&Event) -> bool) -> Event {
        let wait = async {
            loop {
                let e = events.recv().await.expect("the engine stopped");
                if pred(&e) {
                    return e;
                }
            }
        };
        tokio::time::timeout(Duration::from_secs(120), wait)
            .await
            .expect("timed out")
    }

    #[test]
    fn an_approved_fix_is_offered_kept_and_marked_in_the_tree() {
        let dir = super::tmp("knowledge-engine");
        let file = dir.join("knowledge.toml");
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .unwrap();
        rt.block_on(async {
            let path = fixtures::root().join("scenarios/cell/red_on_blue.toml");
            let scenario = Scenario::load(&path).unwrap();
            let model = FixtureModel::new(fixtures::every_reply());
            let setup = Setup {
                knowledge: Some(Knowledge::open(&file).unwrap()),
                ..Setup::new(Arc::new(scenario.clone()), path, Ok(Arc::new(model)))
            };
            let (engine, mut events) = Engine::spawn(setup).unwrap();
            engine.send(Command::SubmitGoal {
                goal: scenario.goal.clone().unwrap(),
                instruction: scenario.instruction.clone().unwrap(),
            });
            until(&mut events, |e| matches!(e, Event::TreeChanged { .. })).await;
            engine.send(Command::Run);
            until(&mut events, |e| matches!(e, Event::Proposal { .. })).await;
            engine.send(Command::Approve);
            let offer = until(&mut events, |e| matches!(e, Event::RuleOffered { .. })).await;
            let Event::RuleOffered { rule, only, .. } = offer else {
                unreachable!()
            };
            assert_eq!(rule, "grasp {x} needs ~\"any object\" on \"{x}\"");
            assert_eq!(
                only.as_deref(),
                Some("grasp \"blue cube\" needs ~\"any object\" on \"blue cube\" (only for these objects)")
            );
            // Nothing is kept before a person says so.
            assert!(Knowledge::open(&file).unwrap().rules.is_empty());
            engine.send(Command::KeepRule { only: false });
            let kept = until(&mut events, |e| matches!(e, Event::RuleKept { .. })).await;
            let Event::RuleKept { id, .. } = kept else {
                unreachable!()
            };
            assert_eq!(id, "r1");
            // The tree now shows which of its conditions the rule explains.
            let marked = until(&mut events, |e| {
                matches!(e, Event::TreeChanged { learned, .. } if !learned.is_empty())
            })
            .await;
            let Event::TreeChanged { tree, learned, .. } = marked else {
                unreachable!()
            };
            let (node, rules) = &learned[0];
            assert_eq!(rules, &vec!["r1".to_string()]);
            assert_eq!(
                tree.kind(*node).unwrap().as_condition().unwrap().to_string(),
                "~\"any object\" on \"blue cube\""
            );
            let k = Knowledge::open(&file).unwrap();
            assert_eq!(k.rules.len(), 1);
            assert_eq!(k.rules[0].kept_by, "a person (workbench)");
            // Nothing more is offered; the view lists the rule.
            engine.send(Command::DeclineRule);
            until(&mut events, |e| matches!(e, Event::Error { .. })).await;
            engine.send(Command::ShowKnowledge);
            let view = until(&mut events, |e| matches!(e, Event::Knowledge { .. })).await;
            let Event::Knowledge { rules, .. } = view else {
                unreachable!()
            };
            assert_eq!(rules.len(), 1);
            assert!(rules[0].starts_with("r1: grasp {x} needs"), "{rules:?}");
            engine.send(Command::Shutdown);
        });
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn learn_without_yes_asks_and_can_keep_the_rule_for_the_fixs_objects_only() {
    use std::io::Write;
    use std::process::Stdio;
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("knowledge-ask");
    let policies = dir.join("p").to_string_lossy().into_owned();
    let base = server.base_url();
    let first = scenario_path("scenarios/cell/red_on_blue.toml");
    let mut args = resolve(&first, &base, &policies);
    args.retain(|a| *a != "--yes");
    args.push("--learn");
    let mut child = support::cli::command(&dir, &args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Approve the fix, then keep it only for the blue cube.
    child.stdin.take().unwrap().write_all(b"y\no\n").unwrap();
    let out = child.wait_with_output().unwrap();
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        log.contains("Keep as a rule: grasp {x} needs ~\"any object\" on \"{x}\"? [y]es / [o]nly grasp \"blue cube\" needs"),
        "{log}"
    );
    let knowledge = Knowledge::open(&Path::new(&policies).join("knowledge.toml")).unwrap();
    assert_eq!(knowledge.rules.len(), 1);
    assert_eq!(knowledge.rules[0].only, Some(vec!["blue cube".to_string()]));
    assert_eq!(knowledge.rules[0].kept_by, "a person");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// In the engine, a reading chosen that was not offered first is kept as an example of the
/// domain, with the reading it replaced, and said; the engine's own pool has it at once.
#[tokio::test]
async fn a_reading_chosen_not_first_is_kept_as_an_example_of_the_domain() {
    use betr::session::knowledge::examples::KeptExamples;
    use betr::session::{Command, Event};
    let dir = support::cli::tmp("engine-correction");
    let path = support::repo::root().join("scenarios/cafe/cafe.toml");
    let scenario = betr::scenario::Scenario::load(&path).unwrap();
    let model =
        support::fake_model::FixtureModel::new(support::fixtures::replies_of("readings_cafe.toml"));
    let mut setup = betr::session::Setup::new(
        std::sync::Arc::new(scenario),
        path,
        Ok(std::sync::Arc::new(model)),
    );
    setup.options.choose_reading = true;
    setup.knowledge = Some(Knowledge::open(&Knowledge::path_in(&dir)).unwrap());
    let mut session = support::engine::Session::start(setup);
    session.send(Command::Submit("Bring something sweet to table 3.".into()));
    session
        .until("readings", |e| matches!(e, Event::Readings { .. }))
        .await;
    session.send(Command::ChooseReading(1));
    session
        .until("the correction kept", |e| {
            matches!(e, Event::Notice { message } if message.contains("correction kept as example e1 of the cafe domain"))
        })
        .await;
    let kept = KeptExamples::open(&KeptExamples::path_in(&dir)).unwrap();
    assert_eq!(kept.examples.len(), 1);
    let e = &kept.examples[0];
    assert_eq!(
        (
            e.instruction.as_str(),
            e.goal.as_str(),
            e.replaced.as_deref()
        ),
        (
            "Bring something sweet to table 3.",
            "On_Chocolate_Table3",
            Some("On_Dessert_Table3")
        )
    );
    assert!(e.kept_by.contains("choosing a reading"), "{}", e.kept_by);
}
