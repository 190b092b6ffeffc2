//! How a goal read from an instruction is checked, with a scripted model whose answer
//! depends on the draw (greedy, or sampled with seed k): a number the request says and the
//! first answer leaves out draws more candidates, and so does an object put in the place
//! of one the request names; a misreading that can be undone (a condition turned around,
//! an item sent to a place but not put there, one of two things named side by side left
//! out, a swapped object, a relation other than the one the request says before the place,
//! what a convention's words put somewhere left elsewhere) gives the undone goal as a
//! candidate; a condition no word of
//! the request asks for is taken out; a
//! failure is asked about with the conditions that fix it in simulation as the only
//! choices. And with a model that answers by the request it is asked about: a request of
//! several wishes is read a wish at a time.

#![allow(clippy::unwrap_used)] // tests may panic on what they check

use crate::support;
use std::sync::Arc;

use betr::goal::{Formula, equivalent};
use betr::llm::{ChatRequest, LanguageModel, OutputConstraint};
use betr::scenario::Scenario;
use betr::session::{self, Event, Options, Proposal};
use betr::world;
use support::fake_model::AnswersBy;

/// Answers by draw: `greedy` for the first call, `sampled[k - 1]` for seed k.
fn by_draw(greedy: &str, sampled: &[&str]) -> AnswersBy<impl Fn(&ChatRequest) -> String + use<>> {
    let greedy = greedy.to_string();
    let sampled: Vec<String> = sampled.iter().map(|s| (*s).to_string()).collect();
    AnswersBy::new(move |request: &ChatRequest| match request.seed {
        None => greedy.clone(),
        Some(k) => sampled
            .get(usize::try_from(k).unwrap() - 1)
            .cloned()
            .unwrap_or_else(|| greedy.clone()),
    })
}

use support::repo::scenario;

async fn read(
    scenario: &Scenario,
    model: &dyn LanguageModel,
    instruction: &str,
) -> (Formula, usize) {
    let w = world::load(scenario).unwrap();
    let mut notices = Vec::new();
    let reading = session::interpret::interpret(
        scenario,
        w,
        instruction,
        model,
        &Options::default(),
        &mut |e| {
            if let Event::Notice { message } = e {
                notices.push(message.clone());
            }
        },
    )
    .await
    .unwrap();
    (reading.answer.goal, reading.calls)
}

#[tokio::test]
async fn a_number_the_first_answer_leaves_out_draws_candidates_that_use_it() {
    let cafe = scenario("scenarios/cafe/cafe.toml");
    // One place in the answer, one place of its kind numbered 5: put right, one call.
    let model = by_draw("Goal: On_Coffee_Table1", &[]);
    let (goal, calls) = read(&cafe, &model, "Take a coffee to table five by the window.").await;
    assert_eq!(goal.to_string(), "On_Coffee_WindowTable5");
    assert_eq!(calls, 1);

    // The second place asked by no word: taken out, and the place left renumbered; one call.
    let model = by_draw("Goal: On_Coffee_Table1 & RobotNear_Table2", &[]);
    let (goal, calls) = read(&cafe, &model, "Take a coffee to table five by the window.").await;
    assert_eq!(goal.to_string(), "On_Coffee_WindowTable5");
    assert_eq!(calls, 1);

    // No number in the request: the first clean answer is taken, one call.
    let model = by_draw("Goal: On_Coffee_Table1", &["Goal: On_Coffee_Bar"]);
    let (goal, calls) = read(&cafe, &model, "Take a coffee to the first table.").await;
    assert_eq!(goal.to_string(), "On_Coffee_Table1");
    assert_eq!(calls, 1);
}

#[tokio::test]
async fn a_condition_no_word_asks_for_is_taken_out() {
    let cafe = scenario("scenarios/cafe/cafe.toml");
    let model = by_draw("Goal: On_Chips_Table3 & RobotNear_Table3", &[]);
    let (goal, calls) = read(&cafe, &model, "Some crisps for table three, please.").await;
    let expected = Formula::parse("On_Chips_Table3").unwrap();
    assert!(equivalent(&goal, &expected).unwrap(), "{goal}");
    assert_eq!(calls, 1);
}

#[tokio::test]
async fn the_relation_and_the_convention_the_request_says_undo_a_misread_relation() {
    // "In the crib" asks for in; the answer's on is undone with no more calls.
    let baby = scenario("scenarios/cell/params/baby.toml");
    let model = by_draw(r#"Goal: "baby doll" on "crib""#, &[]);
    let (goal, calls) = read(&baby, &model, "Lay the doll to sleep in the crib, gently.").await;
    assert_eq!(goal.to_string(), r#""baby doll" in "crib""#);
    assert_eq!(calls, 1);
    // "Fetch ... for me": what is brought goes on the tray in this cell, not held.
    let kit = scenario("scenarios/cell/params/first_aid.toml");
    let model = by_draw(r#"Goal: "first aid kit" grasped"#, &[]);
    let (goal, calls) = read(&kit, &model, "Quick, fetch the first aid kit for me.").await;
    assert_eq!(goal.to_string(), r#""first aid kit" on "tray""#);
    assert_eq!(calls, 1);
    // Held, asked in its own words: held.
    let (goal, _) = read(&kit, &model, "Hold the first aid kit up for me.").await;
    assert_eq!(goal.to_string(), r#""first aid kit" grasped"#);
}

#[tokio::test]
async fn a_failure_is_asked_about_with_the_conditions_that_fix_it_as_the_only_choices() {
    let cell = Arc::new(scenario("scenarios/cell/red_on_blue.toml"));
    let model = Arc::new(by_draw(
        "Reasoning: the red cube lies on the blue cube and blocks the gripper.\nConditions:\n~\"any object\" on \"blue cube\"",
        &[],
    ));
    let options = Options {
        use_scenario_goal: true,
        ..Options::default()
    };
    let mut proposals = Vec::new();
    let resolved = session::resolve(
        &cell,
        None,
        model.clone() as Arc<dyn LanguageModel>,
        &options,
        &mut |p| {
            proposals.push(p.clone());
            true
        },
        &mut |_| {},
    )
    .await
    .unwrap();
    assert!(
        matches!(resolved.ending, session::Ending::Success { .. }),
        "{:?}",
        resolved.ending
    );
    let Some(Proposal::Conditions { conditions, .. }) = proposals.first() else {
        panic!("{proposals:?}");
    };
    assert_eq!(conditions[0].to_string(), r#"~"any object" on "blue cube""#);
    // The question listed the conditions found in simulation, and the grammar allowed
    // only those.
    let seen = model.seen.lock().unwrap();
    let question = seen
        .iter()
        .find(|r| {
            r.messages
                .iter()
                .any(|m| m.content.contains("# Task: failure resolution"))
        })
        .expect("a question about the failure");
    let prompt: String = question
        .messages
        .iter()
        .map(|m| m.content.as_str())
        .collect();
    assert!(prompt.contains("## Conditions that fix it in simulation"));
    assert!(prompt.contains(r#"- ~"any object" on "blue cube""#));
    let Some(OutputConstraint::Grammar { gbnf, .. }) = &question.constraint else {
        panic!("no grammar: {:?}", question.constraint);
    };
    assert!(
        gbnf.contains(r#"literal ::= "~\"any object\" on \"blue cube\"""#),
        "{gbnf}"
    );
    assert!(
        !gbnf.contains("atom ::="),
        "the whole vocabulary is not offered: {gbnf}"
    );
}

/// The request a prompt asks about: the line after its last `## Request`.
fn request_asked(request: &ChatRequest) -> String {
    let prompt = &request.messages.last().unwrap().content;
    prompt
        .rsplit_once("## Request\n")
        .and_then(|(_, rest)| rest.lines().next())
        .unwrap_or("")
        .trim()
        .to_string()
}

/// Answers by the request the prompt asks about ([`request_asked`]): each entry is a
/// request and its reply; any other request gets `otherwise`.
fn by_request(
    replies: &[(&str, &str)],
    otherwise: &str,
) -> AnswersBy<impl Fn(&ChatRequest) -> String + use<>> {
    let replies: Vec<(String, String)> = replies
        .iter()
        .map(|(r, a)| ((*r).to_string(), (*a).to_string()))
        .collect();
    let otherwise = otherwise.to_string();
    AnswersBy::new(move |request: &ChatRequest| {
        let asked = request_asked(request);
        replies
            .iter()
            .find(|(r, _)| *r == asked)
            .map_or_else(|| otherwise.clone(), |(_, a)| a.clone())
    })
}

async fn read_by_request(
    scenario: &Scenario,
    model: &AnswersBy<impl Fn(&ChatRequest) -> String + Send + Sync>,
    instruction: &str,
) -> (Formula, usize, Vec<String>) {
    let w = world::load(scenario).unwrap();
    let reading = session::interpret::interpret(
        scenario,
        w,
        instruction,
        model,
        &Options::default(),
        &mut |_| {},
    )
    .await
    .unwrap();
    let asked: Vec<String> = model
        .seen
        .lock()
        .unwrap()
        .iter()
        .map(request_asked)
        .collect();
    (reading.answer.goal, reading.calls, asked)
}

#[tokio::test]
async fn a_request_of_several_wishes_is_read_a_wish_at_a_time() {
    let cafe = scenario("scenarios/cafe/cafe.toml");
    let f = |t: &str| Formula::parse(t).unwrap();
    // Two sentences, the thanks kept with the second: each part asked on its own, the
    // goals joined by and.
    let model = by_request(
        &[
            (
                "Please switch off the hall light.",
                "Goal: ~Active_HallLight",
            ),
            (
                "could you bring some bread to table 2 or to table 3? Thanks!",
                "Goal: On_Bread_Table2 | On_Bread_Table3",
            ),
        ],
        "Goal: Active_AC",
    );
    let request = "Please switch off the hall light. And could you bring some bread to table 2 or to table 3? Thanks!";
    let (goal, calls, asked) = read_by_request(&cafe, &model, request).await;
    assert_eq!(
        goal,
        f("~Active_HallLight & (On_Bread_Table2 | On_Bread_Table3)"),
        "{asked:?}"
    );
    assert_eq!(calls, 2);
    assert!(!asked.iter().any(|a| a == request), "{asked:?}");

    // A part offered as the alternative to the one before: joined by or.
    let model = by_request(
        &[
            ("Could you mop the floor?", "Goal: IsClean_Floor"),
            ("bring a banana to the bar.", "Goal: On_Banana_Bar"),
        ],
        "Goal: Active_AC",
    );
    let (goal, calls, _) = read_by_request(
        &cafe,
        &model,
        "Could you mop the floor? If not, bring a banana to the bar.",
    )
    .await;
    assert_eq!(goal, f("IsClean_Floor | On_Banana_Bar"));
    assert_eq!(calls, 2);

    // Parts whose goals contradict each other: the request is read whole.
    let request = "Switch on the AC. Also, I want the AC off.";
    let model = by_request(
        &[
            ("Switch on the AC.", "Goal: Active_AC"),
            ("I want the AC off.", "Goal: ~Active_AC"),
            (request, "Goal: Active_AC"),
        ],
        "Goal: IsClean_Floor",
    );
    let (goal, calls, asked) = read_by_request(&cafe, &model, request).await;
    assert_eq!(goal, f("Active_AC"), "{asked:?}");
    assert_eq!(asked.last().map(String::as_str), Some(request));
    assert_eq!(calls, 3, "{asked:?}");
}

#[tokio::test]
async fn an_object_put_in_the_place_of_a_named_one_draws_candidates() {
    let cafe = scenario("scenarios/cafe/cafe.toml");
    // "fries" read as coffee: more candidates are drawn, and one that names the fries'
    // object wins, though the misread one came first.
    let model = by_draw(
        "Goal: (Exists_Dessert | Exists_Coffee) & RobotNear_Table3",
        &[
            "Goal: (Exists_Dessert | Exists_Coffee) & RobotNear_Table3",
            "Goal: On_Chips_Table3 | On_Dessert_Table3",
            "Goal: On_Dessert_Table3 | On_Chips_Table3",
        ],
    );
    let (goal, calls) = read(
        &cafe,
        &model,
        "I'm at the third table, bring me some fries or a dessert.",
    )
    .await;
    assert!(
        equivalent(
            &goal,
            &Formula::parse("On_Chips_Table3 | On_Dessert_Table3").unwrap()
        )
        .unwrap(),
        "{goal}"
    );
    assert_eq!(calls, 4);
}

#[tokio::test]
async fn a_misreading_that_can_be_undone_gives_the_undone_goal_as_a_candidate() {
    let cafe = scenario("scenarios/cafe/cafe.toml");
    let cases = [
        // A condition the other way round from the request's words.
        (
            "Do not open the curtain, please.",
            "Goal: ~Closed_Curtain",
            "Closed_Curtain",
        ),
        (
            "Make sure the tube light is on and the hall light is turned off.",
            "Goal: Active_TubeLight & Active_HallLight",
            "Active_TubeLight & ~Active_HallLight",
        ),
        // An item sent to a place, read as made with the robot at the place.
        (
            "I would like a dessert at the bar, please.",
            "Goal: Exists_Dessert & RobotNear_Bar",
            "On_Dessert_Bar",
        ),
        // One of two things named side by side left out.
        (
            "I'm at the third table, could you bring me some fries or a dessert?",
            "Goal: On_Dessert_Table3",
            "On_Chips_Table3 | On_Dessert_Table3",
        ),
        // A condition asked of both objects of a kind held for one of them.
        (
            "Please keep away from both bars.",
            "Goal: ~RobotNear_Bar",
            "~RobotNear_Bar & ~RobotNear_Bar2",
        ),
        // An object no word names in the place of one a word names alone.
        (
            "I'm at the third table, could you bring me some fries or a dessert?",
            "Goal: On_Dessert_Table3 | On_Softdrink_Table3",
            "On_Chips_Table3 | On_Dessert_Table3",
        ),
    ];
    for (request, answer, expected) in cases {
        // Every sampled draw repeats the misreading: only the undone goal can win.
        let model = by_draw(answer, &[answer, answer, answer]);
        let (goal, calls) = read(&cafe, &model, request).await;
        assert_eq!(goal.to_string(), expected, "{request}");
        assert_eq!(calls, 1, "{request}: the undone goal passes, no more draws");
    }
    // A right answer is taken as it is.
    let model = by_draw("Goal: Closed_Curtain", &[]);
    let (goal, _) = read(&cafe, &model, "Do not open the curtain, please.").await;
    assert_eq!(goal.to_string(), "Closed_Curtain");
}
