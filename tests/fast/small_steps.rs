//! The model asked in small steps around a goal, with scripted models that answer each
//! question by what it asks: before the goal, the objects the request names, which then
//! type the goal's first answer; after it, each condition of the goal (true, false or
//! not asked about), a condition said to be wanted the other way round turned and one
//! said not to be asked about taken out, the goal as first read staying a reading.

#![allow(clippy::unwrap_used)] // tests may panic on what they check

use crate::support;
use betr::goal::{Formula, equivalent};
use betr::llm::{ChatRequest, OutputConstraint};
use betr::session::types::Ablations;
use betr::session::{self, Event, Options};
use betr::world;
use support::fake_model::AnswersBy;
use support::repo::scenario;

/// Answers the question of the objects named with `named`, any goal question with `goal`.
fn names_first(named: &str, goal: &str) -> AnswersBy<impl Fn(&ChatRequest) -> String + use<>> {
    let (named, goal) = (named.to_string(), goal.to_string());
    AnswersBy::new(move |request: &ChatRequest| {
        let asks_names = matches!(
            &request.constraint,
            Some(OutputConstraint::Grammar { gbnf, .. }) if gbnf.starts_with("root ::= \"Named: \"")
        );
        if asks_names {
            named.clone()
        } else {
            goal.clone()
        }
    })
}

#[tokio::test]
async fn small_steps_type_the_first_answer_over_the_objects_the_request_names() {
    let cafe = scenario("scenarios/cafe/cafe.toml");
    let model = names_first("Named: Table1, Coffee", "Goal: On_Coffee_Table1");
    let options = Options {
        ablations: Ablations {
            small_steps: true,
            ..Ablations::default()
        },
        ..Options::default()
    };
    let reading = session::interpret::interpret(
        &cafe,
        world::load(&cafe).unwrap(),
        "Bring a coffee to the first table.",
        &model,
        &options,
        &mut |_| {},
    )
    .await
    .unwrap();
    assert_eq!(reading.answer.goal.to_string(), "On_Coffee_Table1");
    assert_eq!(reading.calls, 2);
    let grammar = |r: &ChatRequest| match &r.constraint {
        Some(OutputConstraint::Grammar { gbnf, .. }) => gbnf.clone(),
        other => panic!("not a grammar: {other:?}"),
    };
    {
        let seen = model.seen.lock().unwrap();
        // The first question offers every object of the scene and asks for no goal.
        let names = grammar(&seen[0]);
        assert!(
            names.contains("\"Table2\"") && names.contains("\"Coffee\""),
            "{names}"
        );
        assert!(
            seen[0]
                .messages
                .iter()
                .any(|m| m.content.contains("Named: <name>"))
        );
        // The goal is typed over the named objects only.
        let goal = grammar(&seen[1]);
        assert!(goal.starts_with("root ::= \"Goal: \""), "{goal}");
        assert!(
            goal.contains("\"Table1\"") && goal.contains("\"Coffee\""),
            "{goal}"
        );
        assert!(
            !goal.contains("\"Table2\"") && !goal.contains("\"Tea\""),
            "{goal}"
        );
    }

    // Off (the default): one call, typed over the whole scene.
    let model = names_first("Named: Table1", "Goal: On_Coffee_Table1");
    let (goal, calls) = {
        let r = session::interpret::interpret(
            &cafe,
            world::load(&cafe).unwrap(),
            "Bring a coffee to the first table.",
            &model,
            &Options::default(),
            &mut |_| {},
        )
        .await
        .unwrap();
        (r.answer.goal, r.calls)
    };
    assert_eq!((goal.to_string().as_str(), calls), ("On_Coffee_Table1", 1));
    assert!(grammar(&model.seen.lock().unwrap()[0]).contains("\"Table2\""));
}

/// The condition a question about one condition asks about, if it is one.
fn condition_asked(request: &ChatRequest) -> Option<String> {
    let last = request.messages.last()?;
    let rest = last
        .content
        .split("Think only of this condition: ")
        .nth(1)?;
    rest.split_whitespace().next().map(str::to_string)
}

/// Answers a goal question with `goal` and each question about one condition with the
/// verdict `verdicts` gives for it (`true` when not listed).
fn verdicts(
    goal: &str,
    verdicts: &[(&'static str, &'static str)],
) -> AnswersBy<impl Fn(&ChatRequest) -> String + use<>> {
    let (goal, verdicts) = (goal.to_string(), verdicts.to_vec());
    AnswersBy::new(
        move |request: &ChatRequest| match condition_asked(request) {
            Some(condition) => verdicts
                .iter()
                .find(|(c, _)| *c == condition)
                .map_or("true", |(_, v)| *v)
                .to_string(),
            None => goal.clone(),
        },
    )
}

#[tokio::test]
async fn conditions_asked_about_one_at_a_time_are_turned_round_or_taken_out() {
    let cafe = scenario("scenarios/cafe/cafe.toml");
    let model = verdicts(
        "Goal: On_Coffee_Table1 & Active_TubeLight & Closed_Curtain",
        &[("Active_TubeLight", "false"), ("Closed_Curtain", "unasked")],
    );
    let options = Options {
        // The checks off, so that the conditions asked about are the model's as written.
        ablations: Ablations {
            confirm_conditions: true,
            check_goals: false,
            ..Ablations::default()
        },
        ..Options::default()
    };
    let mut notices = Vec::new();
    let reading = session::interpret::interpret(
        &cafe,
        world::load(&cafe).unwrap(),
        "Coffee to table one, please.",
        &model,
        &options,
        &mut |e| {
            if let Event::Notice { message } = e {
                notices.push(message.clone());
            }
        },
    )
    .await
    .unwrap();
    // Each condition asked about once; the light turned round, the curtain taken out.
    let asked: Vec<String> = model
        .seen
        .lock()
        .unwrap()
        .iter()
        .filter_map(condition_asked)
        .collect();
    assert_eq!(
        asked,
        ["On_Coffee_Table1", "Active_TubeLight", "Closed_Curtain"]
    );
    assert!(
        equivalent(
            &reading.answer.goal,
            &Formula::parse("On_Coffee_Table1 & ~Active_TubeLight").unwrap()
        )
        .unwrap()
    );
    // The goal as written first stays a reading the person can choose.
    assert_eq!(reading.readings.len(), 2);
    assert!(
        equivalent(
            &reading.readings[1],
            &Formula::parse("On_Coffee_Table1 & Active_TubeLight & Closed_Curtain").unwrap()
        )
        .unwrap()
    );
    assert!(
        notices
            .iter()
            .any(|n| n.contains("asked condition by condition")),
        "{notices:?}"
    );

    // A change that fails the goal's checks is not kept: the tube light is off already,
    // so the light alone turned round asks for nothing.
    let model = verdicts("Goal: Active_TubeLight", &[("Active_TubeLight", "false")]);
    let reading = session::interpret::interpret(
        &cafe,
        world::load(&cafe).unwrap(),
        "The tube light.",
        &model,
        &options,
        &mut |_| {},
    )
    .await
    .unwrap();
    assert_eq!(reading.answer.goal.to_string(), "Active_TubeLight");
}
