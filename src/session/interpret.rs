//! Reading an instruction as a goal, checked before it is used.
//!
//! One call gives the model's first answer. An answer is kept only if it parses over the
//! vocabulary, is not contradictory, does not hold already (a request asks for a change)
//! and can be planned with the scenario's skills. When the first answer fails a check,
//! more candidates are drawn from the same prompt (sampled, so they differ; the prompt is
//! in the model's cache, so each costs only its own tokens) and the survivors vote: the
//! largest group of logically equivalent goals wins, the earliest drawn breaking ties.
//! When none survives, the model is told why, in the same conversation, and asked again
//! (reflective feedback), for a bounded number of rounds. A first answer that plainly
//! misread the request draws more candidates too, and one that does not wins; where the
//! misreading can be undone, the undone answer is a candidate of its own (`judge`). The
//! chosen goal's alternatives are put in the order the request names them, since a
//! behavior tree tries them in that order.

use crate::goal::{self, Formula};
use crate::llm::prompt::Context;
use crate::llm::reply::{self, GoalAnswer, ReplyError};
use crate::llm::{LanguageModel, Message, Role, grammar, schema};
use crate::reading::Request;
use crate::reading::lexicon::{Lexicon, in_request_order};
use crate::reading::parts::split;
use crate::scenario::Scenario;
use crate::world::World;

use super::Question;
use super::ask::ask;
use super::goal_checks::GoalProblem;
use super::interpret_parts::{PartsRead, read_parts};
use super::judge::{Candidate, Judge};
use super::types::{Event, Options, SessionError};

/// Sampling temperature of the extra candidates: enough to make them differ from the
/// first answer, low enough to stay on the request.
const SAMPLE_TEMPERATURE: f32 = 0.7;

/// A goal read from an instruction, with how it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct Interpretation {
    pub answer: GoalAnswer,
    /// The first call's answer as it came (before any check), `None` if unusable.
    pub first: Option<Formula>,
    /// Calls made, the first included.
    pub calls: usize,
    /// Feedback rounds used (0: the first round's candidates sufficed).
    pub feedback_rounds: usize,
    /// A doubt the checks raised about the chosen goal (it holds already, or a condition
    /// of it comes from an example), for the person to look at before it runs.
    pub doubt: Option<String>,
    /// The distinct readings that passed the checks, the chosen one first, then the others
    /// by their votes (at most [`MAX_READINGS`]): what a person chooses among when they
    /// would make the robot do different things.
    pub readings: Vec<Formula>,
}

/// How many readings an interpretation offers at most.
pub const MAX_READINGS: usize = 3;

/// [`interpret`] against the scenario's first state.
pub async fn interpret_in_scenario(
    scenario: &Scenario,
    instruction: &str,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Interpretation, SessionError> {
    let world = crate::world::load(scenario)?;
    interpret(scenario, world, instruction, model, options, emit).await
}

/// Ask for the goal `instruction` means in `scenario`, in the state of `world`, checked
/// as the module says (`options.ablations.check_goals` off: the first usable answer, as the paper's
/// single call). A request of several wishes is read a wish at a time
/// (`options.ablations.read_by_parts`, see [`super::interpret_parts`]) when checks are on.
pub async fn interpret(
    scenario: &Scenario,
    world: Box<dyn World>,
    instruction: &str,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Interpretation, SessionError> {
    let mut earlier_calls = 0;
    let asked_in = world.fork();
    if options.ablations.check_goals && options.ablations.read_by_parts {
        let lexicon = Lexicon::new(&scenario.domain.vocabulary, example_pool(scenario, options));
        let parts = split(instruction, &lexicon);
        if parts.len() > 1 {
            let forked = world.fork();
            match read_parts(scenario, forked, &parts, instruction, model, options, emit).await? {
                PartsRead::Read(found) => {
                    let found = super::confirm::confirmed(
                        scenario,
                        asked_in,
                        instruction,
                        found,
                        model,
                        options,
                        emit,
                    )
                    .await?;
                    announce(scenario, &found, emit);
                    return Ok(found);
                }
                PartsRead::Whole { calls } => earlier_calls = calls,
            }
        }
    }
    let mut found = read_goal(scenario, world, instruction, false, model, options, emit).await?;
    found.calls += earlier_calls;
    let found =
        super::confirm::confirmed(scenario, asked_in, instruction, found, model, options, emit)
            .await?;
    announce(scenario, &found, emit);
    Ok(found)
}

/// The examples a goal prompt chooses from: another prompt's, for an ablation, or the
/// scenario's pool.
pub(super) fn example_pool<'a>(
    scenario: &'a Scenario,
    options: &'a Options,
) -> &'a [crate::scenario::Example] {
    options
        .variant
        .examples
        .as_deref()
        .unwrap_or(&scenario.examples)
}

/// Tell the front end the goal chosen, and the doubt raised about it.
fn announce(scenario: &Scenario, found: &Interpretation, emit: &mut (dyn FnMut(&Event) + Send)) {
    emit_goal(scenario, &found.answer, emit);
    if let Some(why) = &found.doubt {
        emit(&Event::Notice {
            message: format!("check the goal before it runs: {why}"),
        });
    }
}

/// One reading of `instruction` as a goal — candidates, checks, vote, feedback — without
/// announcing it; `one_of_several` when it is one wish of a longer request.
pub(super) async fn read_goal(
    scenario: &Scenario,
    world: Box<dyn World>,
    instruction: &str,
    one_of_several: bool,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Interpretation, SessionError> {
    let facts = world.facts();
    let ctx = Context {
        scenario,
        facts: &facts,
        instruction,
        variant: &options.variant,
    };
    let mut messages = ctx.goal(&options.templates)?;
    let pool = example_pool(scenario, options);
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, pool);
    let request = Request::new(instruction, scenario, &lexicon);
    let judge = Judge::new(scenario, world, request, options, one_of_several)?;
    let vocabulary = &scenario.domain.vocabulary;
    let constraint = schema::goal(vocabulary);
    let cot = options.variant.chain_of_thought;
    // The answer's `Goal:` written into the prompt for the model to continue, the grammar
    // typing only the formula (an ablation), or the grammar typing both.
    let prefill = (options.ablations.goal_prefix_in_prompt && !cot).then_some(grammar::GOAL_PREFIX);
    let typed = |v: &crate::domain::Vocabulary| match prefill {
        Some(_) => grammar::goal_grammar_after_prefix(v, true),
        None => grammar::goal_grammar(v, true, cot),
    };
    let goal_grammar = || typed(vocabulary);
    let mut calls = 0;
    // The small step first: the objects the request names type the first answer.
    let mut narrowed: Option<crate::domain::Vocabulary> = None;
    if options.ablations.small_steps && !cot && options.grammar && model.supports_grammar() {
        calls += 1;
        if let Some(named) = super::named_first::named_objects(&ctx, model, options, emit).await? {
            narrowed = super::named_first::narrowed(vocabulary, &named);
        }
    }
    let narrowed_grammar = || match &narrowed {
        Some(v) => typed(v),
        None => goal_grammar(),
    };
    let mut first: Option<Option<Formula>> = None;
    let rounds = if options.ablations.check_goals {
        options.goal_feedback_rounds + 1
    } else {
        1
    };
    let mut last_error = ReplyError::NoConditions;
    // Doubtful candidates of earlier rounds, eligible again in the last round's vote.
    let mut set_aside: Vec<Candidate> = Vec::new();
    // The model's runners-up to its first answer (beams), judged like any candidate.
    let mut runners_up: Vec<Candidate> = Vec::new();
    for round in 0..rounds {
        let mut candidates: Vec<Candidate> = Vec::new();
        let draws = if options.ablations.check_goals {
            options.candidates.max(1)
        } else {
            1
        };
        for draw in 0..draws {
            emit(&Event::Asking {
                what: Question::Goal { draw, draws },
            });
            let mut opts = options.clone();
            let seed = if draw > 0 {
                opts.temperature = opts.temperature.max(SAMPLE_TEMPERATURE);
                Some(draw as u64)
            } else {
                None
            };
            let typed_by: &(dyn Fn() -> String + Sync) = if round == 0 && draw == 0 {
                &narrowed_grammar
            } else {
                &goal_grammar
            };
            let r = ask(
                model,
                messages.clone(),
                (constraint.clone(), typed_by),
                &opts,
                seed,
                prefill,
                emit,
            )
            .await?;
            calls += 1;
            if round == 0 && draw == 0 && options.ablations.check_goals {
                runners_up = r
                    .ranked
                    .iter()
                    .skip(1)
                    .map(|(text, _)| {
                        let read = reply::goal(text, vocabulary, options.min_similarity);
                        let problem = match &read {
                            Err(e) => Some(GoalProblem::wrong(e.to_string())),
                            Ok(a) => judge.assess(&a.goal),
                        };
                        Candidate {
                            text: text.clone(),
                            read,
                            problem,
                            first: false,
                        }
                    })
                    .collect();
            }
            let read = reply::goal(&r.text, vocabulary, options.min_similarity);
            let problem = match &read {
                Err(e) => Some(GoalProblem::wrong(e.to_string())),
                Ok(_) if !options.ablations.check_goals => None,
                Ok(a) => judge.assess(&a.goal),
            };
            if first.is_none() {
                first = Some(read.as_ref().ok().map(|a| a.goal.clone()));
            }
            match (&read, &problem) {
                (Err(e), _) => {
                    emit(&Event::InvalidReply {
                        error: e.to_string(),
                    });
                    last_error = e.clone();
                }
                (Ok(a), Some(p)) => emit(&Event::CandidateRejected {
                    candidate: a.goal.to_string(),
                    proposal: None,
                    reason: p.reason.clone(),
                    author: None,
                }),
                (Ok(_), None) => {}
            }
            let first_draw = round == 0 && draw == 0;
            let derived = judge.derived(
                &read,
                problem.as_ref(),
                options.ablations.check_goals,
                first_draw,
                emit,
            );
            candidates.push(Candidate {
                text: r.text,
                read,
                problem,
                first: first_draw,
            });
            candidates.extend(derived);
            // More draws only for a first answer that is wrong: one that passes (or
            // passes once what it pasted is taken out) is taken, and a doubtful one is
            // kept, since sampled alternatives to the model's best answer are worse more
            // often than better.
            // One exception: a first answer that plainly misread the request (left out a
            // number it says, or put an unnamed object in the place of a named one); more
            // candidates are drawn, and one that does not misread wins the vote.
            let misread = candidates
                .first()
                .and_then(|c| c.read.as_ref().ok())
                .and_then(|a| judge.misread(&a.goal));
            if draw > 0 {
                continue;
            }
            let settled = match &misread {
                Some(_) if options.ablations.check_goals => {
                    candidates.iter().any(|c| judge.answers_request(c))
                }
                _ => candidates.iter().any(|c| c.clean() || c.doubtful()),
            };
            if settled {
                break;
            }
            // Before any sample: the model's own runners-up, which cost no call.
            if !runners_up.is_empty() {
                candidates.append(&mut runners_up);
                if candidates.iter().any(|c| judge.answers_request(c)) {
                    emit(&Event::Notice {
                        message: "the first answer fails its checks: the model's next most likely answers are candidates".into(),
                    });
                    break;
                }
            }
            if let Some(why) = misread
                && options.ablations.check_goals
            {
                emit(&Event::Notice {
                    message: format!("{why}: drawing more candidates"),
                });
            }
        }
        // A doubtful answer is taken when it is the model's own first answer, or when no
        // round is left: a doubtful sample after a wrong first answer is asked about again
        // (told why), and stays eligible for the last round's vote.
        let last_round = round + 1 == rounds;
        let chosen = judge.choose(&candidates, &set_aside, last_round);
        if let Some((mut answer, doubt)) = chosen {
            if options.ablations.check_goals {
                let ordered = in_request_order(&lexicon, &answer.goal, &judge.request.terms);
                if ordered != answer.goal {
                    emit(&Event::Notice {
                        message: format!(
                            "alternatives put in the order the request names them: {ordered}"
                        ),
                    });
                    answer.goal = ordered;
                }
            }
            let others: Vec<&Candidate> = set_aside.iter().chain(&runners_up).collect();
            let readings = judge.readings(&answer.goal, &candidates, &others, MAX_READINGS);
            return Ok(Interpretation {
                answer,
                first: first.flatten(),
                calls,
                feedback_rounds: round,
                doubt,
                readings,
            });
        }
        if !last_round {
            feedback(&mut messages, &candidates);
            set_aside.extend(candidates.into_iter().filter(Candidate::doubtful));
        }
    }
    Err(SessionError::NoGoal {
        attempts: calls,
        last: last_error,
    })
}

fn emit_goal(scenario: &Scenario, answer: &GoalAnswer, emit: &mut (dyn FnMut(&Event) + Send)) {
    let matches_expected = scenario
        .goal
        .as_ref()
        .and_then(|expected| goal::equivalent(expected, &answer.goal).ok());
    emit(&Event::Goal {
        goal: answer.goal.clone(),
        reasoning: answer.reasoning.clone(),
        matches_expected,
        author: "model".into(),
    });
}

/// How many characters of a refused answer the next prompt repeats to the model.
const ECHOED_ANSWER: usize = 2000;

/// Continue the conversation: the first candidate as the model's answer, and what was
/// wrong with each distinct candidate.
fn feedback(messages: &mut Vec<Message>, candidates: &[Candidate]) {
    let Some(first) = candidates.first() else {
        return;
    };
    let mut problems: Vec<String> = Vec::new();
    for c in candidates {
        let shown = match &c.read {
            Ok(a) => a.goal.to_string(),
            Err(_) => crate::excerpt::shortened(
                c.text.trim().lines().last().unwrap_or(""),
                crate::llm::reply::ECHOED,
            ),
        };
        let line = format!(
            "- {shown}: {}",
            c.problem
                .as_ref()
                .map_or("(no problem found)", |p| p.reason.as_str())
        );
        if !problems.contains(&line) {
            problems.push(line);
        }
    }
    // The answer is echoed cut, so a prompt never grows with a reply's size.
    messages.push(Message {
        role: Role::Assistant,
        content: crate::excerpt::shortened(first.text.trim(), ECHOED_ANSWER),
    });
    messages.push(Message::user(format!(
        "That cannot be the goal the person means:\n{}\nRead the request again and write a goal that fixes this, in the same answer format.",
        problems.join("\n")
    )));
}

#[cfg(test)]
#[path = "interpret_tests.rs"]
mod tests;
