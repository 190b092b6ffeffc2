//! The embedded model, for real: the default model in llama.cpp with grammars built from
//! the scenario's vocabulary. The model is fetched into the cache first if it is missing
//! (about 10 s on this network), then loaded once for all tests here.

#![allow(clippy::unwrap_used)] // tests may panic on what they check

use crate::support;

use std::sync::Arc;

use betr::domain::Condition;
use betr::llm::local::LocalModel;
use betr::llm::prompt::{Context, Templates, Variant};
use betr::llm::{ChatRequest, LanguageModel, OutputConstraint, grammar, reply};
use betr::session::{self, Ending, Options, Proposal};
use betr::world;

fn local() -> &'static Arc<LocalModel> {
    support::embedded::language_model(support::embedded::every_core())
}

use support::repo::scenario;

#[tokio::test]
async fn interprets_scenario_1_exactly() {
    let _turn = support::embedded::turn().await;
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let reading = session::interpret(
        &s,
        world::load(&s).unwrap(),
        s.instruction.as_deref().unwrap(),
        local(),
        &Options::default(),
        &mut |_| {},
    )
    .await
    .unwrap();
    assert_eq!(
        reading.answer.goal.to_string(),
        "\"blue cube\" on \"green cube\""
    );
    assert!(reading.doubt().is_none(), "{:?}", reading.evidence);
}

#[tokio::test]
async fn reads_a_cafe_request_with_a_disjunction_and_a_negation() {
    let _turn = support::embedded::turn().await;
    // Written for this test (not from the evaluation dataset, nor from the example pool).
    let s = scenario("scenarios/cafe/cafe.toml");
    let instruction = "I'm at the quiet table number nine: bring me a banana or an orange, and please switch off the hall light.";
    let reading = session::interpret(
        &s,
        world::load(&s).unwrap(),
        instruction,
        local(),
        &Options::default(),
        &mut |_| {},
    )
    .await
    .unwrap();
    let expected = s
        .parse_goal("(On_Banana_QuietTable9 | On_Orange_QuietTable9) & ~Active_HallLight")
        .unwrap();
    assert!(
        betr::goal::equivalent(&expected, &reading.answer.goal).unwrap(),
        "read as {} (first answer {:?}, {} calls)",
        reading.answer.goal,
        reading.first.map(|f| f.to_string()),
        reading.calls
    );
}

#[tokio::test]
async fn resolves_scenario_1_with_a_condition_that_fixes_it_in_simulation() {
    let _turn = support::embedded::turn().await;
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let mut proposals = Vec::new();
    let resolved = session::resolve(
        &s,
        None,
        local().clone() as Arc<dyn LanguageModel>,
        &Options::default(),
        &mut |p| {
            proposals.push(p.clone());
            true
        },
        &mut |_| {},
    )
    .await
    .unwrap();
    assert!(
        matches!(resolved.ending, Ending::Success { .. }),
        "{:?} after {proposals:?}",
        resolved.ending
    );
    assert!(resolved.repairs >= 1);
    // What the model proposed is in the tree as the grasp's first precondition, and the
    // tree succeeds in a fresh world with the red cube on the blue cube.
    let Some(Proposal::Conditions { conditions, .. }) = proposals
        .iter()
        .find(|p| matches!(p, Proposal::Conditions { .. }))
    else {
        panic!("no condition proposal: {proposals:?}");
    };
    // The conditions the shortlist offers for this failure name the blue cube's top as
    // what must be clear; the general one comes first and the greedy answer takes it.
    let clear = Condition::parse(r#"~"any object" on "blue cube""#).unwrap();
    let this_cube = Condition::parse(r#"~"red cube" on "blue cube""#).unwrap();
    assert!(
        conditions.contains(&clear) || conditions.contains(&this_cube),
        "{conditions:?}"
    );
    let mut exec = world::load(&s).unwrap();
    let report =
        betr::planner::run_tree(&resolved.tree, exec.as_mut(), &s.domain, 10_000, |_, _| {
            true
        });
    assert_eq!(report.end, betr::planner::RunEnd::Success);
}

/// The goal prompt for `instruction` in scenario `s`'s world as it starts.
fn goal_prompt(s: &betr::scenario::Scenario, instruction: &str) -> Vec<betr::llm::Message> {
    let facts = world::load(s).unwrap().facts();
    let variant = Variant::default();
    let ctx = Context {
        scenario: s,
        facts: &facts,
        instruction,
        variant: &variant,
    };
    ctx.goal(&Templates::builtin()).unwrap()
}

#[tokio::test]
async fn under_the_grammar_no_object_outside_the_scene_can_be_named() {
    let _turn = support::embedded::turn().await;
    // Ask for a banana in a scene that has none, several times with sampling on: every
    // reply must still parse and use only the scene's objects, with no substitution.
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let messages = goal_prompt(&s, "Put the banana on the pineapple");
    let vocabulary = &s.domain.vocabulary;
    for seed in 0..4 {
        let mut request = ChatRequest::new(messages.clone());
        request.temperature = 1.0;
        request.seed = Some(seed);
        request.max_tokens = 60;
        request.constraint = Some(OutputConstraint::Grammar {
            name: "goal".into(),
            gbnf: grammar::goal_grammar(vocabulary, true, false),
        });
        let r = local().chat(&request).await.unwrap();
        // Every name the reply quotes, up to where it was cut off, is one of the scene's.
        let quoted: Vec<&str> = r.text.split('"').skip(1).step_by(2).collect();
        let closed = if r.text.matches('"').count() % 2 == 1 {
            &quoted[..quoted.len().saturating_sub(1)]
        } else {
            &quoted[..]
        };
        for name in closed {
            assert!(
                *name == betr::domain::ANY_OBJECT
                    || vocabulary.objects.iter().any(|o| o.name == *name),
                "{name:?} is not in the scene: {}",
                r.text
            );
        }
        // Sampling may run a long conjunction past the token limit; a reply that ended
        // on its own must parse, naming only the scene's objects.
        if r.usage.completion_tokens >= u64::from(request.max_tokens) {
            continue;
        }
        let answer =
            reply::goal(&r.text, vocabulary, 1.0).unwrap_or_else(|e| panic!("{:?}: {e}", r.text));
        for atom in answer.goal.atoms() {
            vocabulary.check_atom(&atom).unwrap();
        }
    }
}

#[tokio::test]
async fn a_greedy_reply_follows_a_grammar_that_refuses_the_models_own_first_choice() {
    let _turn = support::embedded::turn().await;
    // The model would answer "blue cube" on "green cube"; a grammar that allows only
    // another goal must still be followed token by token, ending where the grammar ends.
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let mut request = ChatRequest::new(goal_prompt(&s, s.instruction.as_deref().unwrap()));
    request.temperature = 0.0;
    request.max_tokens = 40;
    request.constraint = Some(OutputConstraint::Grammar {
        name: "fixed".into(),
        gbnf: r#"root ::= "Goal: " ("\"red cube\" grasped" | "\"red cube\" upright")"#.into(),
    });
    let r = local().chat(&request).await.unwrap();
    assert!(
        r.text == "Goal: \"red cube\" grasped" || r.text == "Goal: \"red cube\" upright",
        "{:?}",
        r.text
    );
}

#[tokio::test]
async fn a_reply_cut_by_the_token_limit_is_refused_after_bounded_calls() {
    let _turn = support::embedded::turn().await;
    let s = scenario("scenarios/cell/red_on_blue.toml");
    let mut calls = 0;
    let reading = session::interpret(
        &s,
        world::load(&s).unwrap(),
        s.instruction.as_deref().unwrap(),
        local(),
        // Three tokens: no goal fits, every answer is cut.
        &Options {
            max_tokens: 3,
            ..Options::default()
        },
        &mut |e| {
            if matches!(e, session::Event::Replied { .. }) {
                calls += 1;
            }
        },
    )
    .await;
    let Err(error) = reading else {
        panic!("a cut answer is not a goal");
    };
    let error = error.to_string();
    assert!(error.contains("no usable goal"), "{error}");
    assert!((1..=12).contains(&calls), "{calls} calls");
}
