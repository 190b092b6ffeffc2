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
//! misread the request — it leaves out a number the request says ("table six" read as
//! table 1), asks for a condition the other way round from the request's words ("do not
//! open the curtain" read as open), or puts an object nobody named in the place of one the
//! request names ("fries" read as coffee) — draws more candidates too, and one that does
//! not wins; a renumbered or turned-back version of it is a candidate of its own. The chosen goal's alternatives are put in the
//! order the request names them, since a behavior tree tries them in that order.

use crate::goal::{self, Formula};
use crate::llm::examples::terms;
use crate::llm::lexicon::{Lexicon, in_request_order};
use crate::llm::prompt::Context;
use crate::llm::reply::{self, GoalAnswer, ReplyError};
use crate::llm::{LanguageModel, Message, Role, grammar, schema};
use crate::scenario::Scenario;
use crate::world::World;

use super::ask::ask;
use super::goal_checks::{
    GoalProblem, assess, renumbered, swapped_back, swapped_object, unanswered_names,
    without_copied, without_unasked,
};
use super::interpret_parts::{PartsRead, read_parts};
use super::placement::{not_put, put_there};
use super::polarity::{turned_around, turned_back};
use super::side_by_side::{left_out, measure_for_content, with_content, with_left_out};
use super::types::{Event, Options, SessionError};
use crate::llm::request_parts::split;

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
}

/// One candidate: the reply's text and what it was read as.
struct Candidate {
    text: String,
    read: Result<GoalAnswer, ReplyError>,
    problem: Option<GoalProblem>,
    /// The model's first answer, or that answer with a part taken out.
    first: bool,
}

impl Candidate {
    fn clean(&self) -> bool {
        self.read.is_ok() && self.problem.is_none()
    }
    fn doubtful(&self) -> bool {
        self.read.is_ok() && self.problem.as_ref().is_some_and(|p| p.doubt)
    }
}

/// What every candidate goal for one request is judged against: the scene, the examples
/// the prompt showed, the words of the vocabulary and the place numbers the request says.
struct Judge<'a> {
    scenario: &'a Scenario,
    world: Box<dyn World>,
    instruction: &'a str,
    shown: Vec<&'a crate::scenario::Example>,
    lexicon: Lexicon,
    place_numbers: Vec<String>,
}

impl Judge<'_> {
    /// Why `goal` should not be used, if it should not.
    fn assess(&self, goal: &Formula) -> Option<GoalProblem> {
        assess(
            self.scenario,
            self.world.as_ref(),
            goal,
            (&self.shown, &self.lexicon),
            self.instruction,
        )
    }

    /// The place numbers the request says that no condition of `goal` is about.
    fn missing_numbers(&self, goal: &Formula) -> Vec<String> {
        unanswered_names(goal, self.instruction, &self.lexicon)
            .into_iter()
            .filter(|w| self.place_numbers.contains(w))
            .collect()
    }

    /// How `goal` has misread the request, if it plainly has: it leaves out a number the
    /// request says ("table six" read as table 1), asks for a condition the other way round
    /// from the request's words ("do not open the curtain" read as open), or puts an object
    /// nobody named in the place of one the request names ("fries" read as coffee).
    fn misread(&self, goal: &Formula) -> Option<String> {
        let numbers = self.missing_numbers(goal);
        if !numbers.is_empty() {
            return Some(format!(
                "the request says {}, and no condition of {goal} is about it",
                numbers.join(", ")
            ));
        }
        if let Some(turned) = turned_around(goal, self.instruction, self.vocabulary()) {
            return Some(turned.to_string());
        }
        if let Some(sent) = not_put(goal, self.instruction, self.vocabulary()) {
            return Some(format!(
                "the request sends {} to {}, and no condition of {goal} puts it there",
                sent.item, sent.place
            ));
        }
        if let Some((measure, content)) =
            measure_for_content(goal, self.instruction, self.vocabulary())
        {
            return Some(format!(
                "the request asks for {content} by the {measure}, and {goal} has the {measure} in its place"
            ));
        }
        if let Some(gap) = left_out(goal, self.instruction, self.vocabulary()) {
            return Some(format!(
                "the request names {} beside {}, and {goal} leaves {} out",
                gap.left_out, gap.kept, gap.left_out
            ));
        }
        swapped_object(goal, self.instruction, &self.lexicon).map(|(object, words)| {
            format!(
                "the request says {}, which no condition of {goal} answers, and never names {object}",
                words.join(", ")
            )
        })
    }

    fn vocabulary(&self) -> &crate::domain::Vocabulary {
        &self.scenario.domain.vocabulary
    }

    /// A clean candidate that has not plainly misread the request.
    fn answers_request(&self, c: &Candidate) -> bool {
        c.clean()
            && c.read
                .as_ref()
                .is_ok_and(|a| self.misread(&a.goal).is_none())
    }

    /// Candidates made from an answer that failed a check: without what it pasted from an
    /// example, or without the parts no word of the request asks for; and, when checks
    /// are on, with the place renumbered when the request numbers another one of its kind
    /// ("table six" read as Table1), and with the conditions the request asks for the
    /// other way round turned ("do not open" read as open). Each is checked like the
    /// others.
    fn derived(
        &self,
        read: &Result<GoalAnswer, ReplyError>,
        problem: Option<&GoalProblem>,
        check_goals: bool,
        first: bool,
        emit: &mut (dyn FnMut(&Event) + Send),
    ) -> Vec<Candidate> {
        let pruned = match read {
            Ok(a) if problem.is_some() => without_copied(&a.goal, &self.shown, self.instruction)
                .or_else(|| without_unasked(&a.goal, self.instruction, &self.lexicon)),
            _ => None,
        };
        let renumber = match read {
            Ok(a) if check_goals => renumbered(
                &a.goal,
                &self.missing_numbers(&a.goal),
                &self.scenario.domain.vocabulary,
            ),
            _ => None,
        };
        if let Some((goal, from, to)) = &renumber {
            emit(&Event::Notice {
                message: format!(
                    "the request numbers a place the answer does not: {to} is the only one like {from} with that number, so {goal} is a candidate too"
                ),
            });
        }
        let turned = match read {
            Ok(a) if check_goals => turned_around(&a.goal, self.instruction, self.vocabulary())
                .and_then(|why| {
                    let goal = turned_back(&a.goal, self.instruction, self.vocabulary())?;
                    emit(&Event::Notice {
                        message: format!("{why}, so {goal} is a candidate too"),
                    });
                    Some(goal)
                }),
            _ => None,
        };
        let placed = match read {
            Ok(a) if check_goals => put_there(&a.goal, self.instruction, self.vocabulary())
                .inspect(|goal| {
                    emit(&Event::Notice {
                        message: format!(
                            "the request sends an item to a place that {} only has apart, so {goal} is a candidate too",
                            a.goal
                        ),
                    });
                }),
            _ => None,
        };
        let beside = match read {
            Ok(a) if check_goals => with_left_out(&a.goal, self.instruction, self.vocabulary())
                .inspect(|goal| {
                    emit(&Event::Notice {
                        message: format!(
                            "the request names things side by side that {} has only one of, so {goal} is a candidate too",
                            a.goal
                        ),
                    });
                }),
            _ => None,
        };
        let unswapped = match read {
            Ok(a) if check_goals => {
                swapped_back(&a.goal, self.instruction, &self.lexicon, self.vocabulary()).inspect(
                    |(goal, from, to)| {
                        emit(&Event::Notice {
                            message: format!(
                                "the request names {to} where the answer has {from}, which it never names, so {goal} is a candidate too"
                            ),
                        });
                    },
                )
            }
            _ => None,
        };
        let content = match read {
            Ok(a) if check_goals => with_content(&a.goal, self.instruction, self.vocabulary())
                .inspect(|goal| {
                    emit(&Event::Notice {
                        message: format!(
                            "the request names a measure of something that {} has in its place, so {goal} is a candidate too",
                            a.goal
                        ),
                    });
                }),
            _ => None,
        };
        let mut out = Vec::new();
        for goal in pruned
            .into_iter()
            .chain(renumber.map(|(g, _, _)| g))
            .chain(unswapped.map(|(g, _, _)| g))
            .chain(turned)
            .chain(placed)
            .chain(beside)
            .chain(content)
        {
            // A derived goal may put an object where its predicate does not take it
            // ("fries" put in the place of a made dessert): it is no candidate.
            if let Err(e) = goal
                .atoms()
                .iter()
                .try_for_each(|a| self.vocabulary().check_atom(a))
            {
                emit(&Event::CandidateRejected {
                    candidate: goal.to_string(),
                    proposal: None,
                    reason: e.to_string(),
                    author: Some("betr, from the model's answer".into()),
                });
                continue;
            }
            let problem = self.assess(&goal);
            if let Some(p) = &problem {
                emit(&Event::CandidateRejected {
                    candidate: goal.to_string(),
                    proposal: None,
                    reason: p.reason.clone(),
                    author: Some("betr, from the model's answer".into()),
                });
            }
            out.push(Candidate {
                text: format!("Goal: {goal}"),
                read: Ok(GoalAnswer {
                    goal,
                    reasoning: None,
                    substitutions: Vec::new(),
                }),
                problem,
                first,
            });
        }
        out
    }

    /// The goal chosen among `candidates`, with the doubt raised about it: a clean one
    /// that has not plainly misread the request, else a clean one, else — when it is the
    /// model's own first answer or no round is left — a doubtful one (those set aside in
    /// earlier rounds vote too).
    fn choose(
        &self,
        candidates: &[Candidate],
        set_aside: &[Candidate],
        last_round: bool,
    ) -> Option<(GoalAnswer, Option<String>)> {
        let first_doubtful = candidates.iter().any(|c| c.first && c.doubtful());
        vote(candidates, |c| self.answers_request(c))
            .or_else(|| vote(candidates, Candidate::clean))
            .map(|a| (a, None))
            .or_else(|| {
                if !(first_doubtful || last_round) {
                    return None;
                }
                let pool: Vec<&Candidate> = candidates.iter().chain(set_aside).collect();
                vote_refs(&pool, Candidate::doubtful).map(|a| {
                    let why = pool
                        .iter()
                        .find(|c| c.doubtful() && c.read.as_ref().is_ok_and(|r| same(r, &a)))
                        .and_then(|c| c.problem.as_ref())
                        .map(|p| p.reason.clone());
                    (a, why)
                })
            })
    }
}

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
/// as the module says (`options.check_goals` off: the first usable answer, as the paper's
/// single call). A request of several wishes is read a wish at a time
/// (`options.read_by_parts`, see [`super::interpret_parts`]) when checks are on.
pub async fn interpret(
    scenario: &Scenario,
    world: Box<dyn World>,
    instruction: &str,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Interpretation, SessionError> {
    let mut earlier_calls = 0;
    if options.check_goals && options.read_by_parts {
        let lexicon = Lexicon::new(&scenario.domain.vocabulary, example_pool(scenario, options));
        let parts = split(instruction, &lexicon);
        if parts.len() > 1 {
            let forked = world.fork();
            match read_parts(scenario, forked, &parts, instruction, model, options, emit).await? {
                PartsRead::Read(found) => {
                    announce(scenario, &found, emit);
                    return Ok(found);
                }
                PartsRead::Whole { calls } => earlier_calls = calls,
            }
        }
    }
    let mut found = read_goal(scenario, world, instruction, model, options, emit).await?;
    found.calls += earlier_calls;
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
/// announcing it.
pub(super) async fn read_goal(
    scenario: &Scenario,
    world: Box<dyn World>,
    instruction: &str,
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
    let judge = Judge {
        scenario,
        world,
        instruction,
        shown: options.variant.choose(pool, instruction),
        place_numbers: lexicon.place_numbers(&terms(instruction)),
        lexicon,
    };
    let vocabulary = &scenario.domain.vocabulary;
    let constraint = schema::goal(vocabulary);
    let cot = options.variant.chain_of_thought;
    let goal_grammar = || grammar::goal_grammar(vocabulary, true, cot);
    let mut calls = 0;
    let mut first: Option<Option<Formula>> = None;
    let rounds = if options.check_goals {
        options.goal_feedback_rounds + 1
    } else {
        1
    };
    let mut last_error = ReplyError::NoConditions;
    // Doubtful candidates of earlier rounds, eligible again in the last round's vote.
    let mut set_aside: Vec<Candidate> = Vec::new();
    for round in 0..rounds {
        let mut candidates: Vec<Candidate> = Vec::new();
        let draws = if options.check_goals {
            options.candidates.max(1)
        } else {
            1
        };
        for draw in 0..draws {
            emit(&Event::Asking {
                what: if draw == 0 {
                    "the goal of the instruction".into()
                } else {
                    format!("another candidate goal ({} of {draws})", draw + 1)
                },
            });
            let mut opts = options.clone();
            let seed = if draw > 0 {
                opts.temperature = opts.temperature.max(SAMPLE_TEMPERATURE);
                Some(draw as u64)
            } else {
                None
            };
            let r = ask(
                model,
                messages.clone(),
                (constraint.clone(), &goal_grammar),
                &opts,
                seed,
                emit,
            )
            .await?;
            calls += 1;
            let read = reply::goal(&r.text, vocabulary, options.min_similarity);
            let problem = match &read {
                Err(e) => Some(GoalProblem {
                    reason: e.to_string(),
                    doubt: false,
                }),
                Ok(_) if !options.check_goals => None,
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
                options.check_goals,
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
            if draw == 0
                && let Some(why) = misread
                && options.check_goals
                && !candidates.iter().any(|c| judge.answers_request(c))
            {
                emit(&Event::Notice {
                    message: format!("{why}: drawing more candidates"),
                });
                continue;
            }
            if draw == 0 && candidates.iter().any(|c| c.clean() || c.doubtful()) {
                break;
            }
        }
        // A doubtful answer is taken when it is the model's own first answer, or when no
        // round is left: a doubtful sample after a wrong first answer is asked about again
        // (told why), and stays eligible for the last round's vote.
        let last_round = round + 1 == rounds;
        let chosen = judge.choose(&candidates, &set_aside, last_round);
        if let Some((mut answer, doubt)) = chosen {
            if options.check_goals {
                let ordered = in_request_order(&judge.lexicon, &answer.goal, &terms(instruction));
                if ordered != answer.goal {
                    emit(&Event::Notice {
                        message: format!(
                            "alternatives put in the order the request names them: {ordered}"
                        ),
                    });
                    answer.goal = ordered;
                }
            }
            return Ok(Interpretation {
                answer,
                first: first.flatten(),
                calls,
                feedback_rounds: round,
                doubt,
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
        substitutions: answer.substitutions.clone(),
        matches_expected,
    });
}

/// The answer of the largest group of equivalent candidates that passed the checks; ties
/// go to the group drawn first (the greedy answer, when it passed).
fn vote(candidates: &[Candidate], eligible: impl Fn(&Candidate) -> bool) -> Option<GoalAnswer> {
    vote_refs(&candidates.iter().collect::<Vec<_>>(), eligible)
}

/// [`vote`] over borrowed candidates.
fn vote_refs(
    candidates: &[&Candidate],
    eligible: impl Fn(&Candidate) -> bool,
) -> Option<GoalAnswer> {
    let passed: Vec<&GoalAnswer> = candidates
        .iter()
        .copied()
        .filter(|c| eligible(c))
        .filter_map(|c| c.read.as_ref().ok())
        .collect();
    let mut best: Option<(usize, &GoalAnswer)> = None;
    for (i, a) in passed.iter().enumerate() {
        // Counted once per group, at its first member.
        if passed[..i].iter().any(|b| same(a, b)) {
            continue;
        }
        let votes = passed.iter().filter(|b| same(a, b)).count();
        if best.is_none_or(|(v, _)| votes > v) {
            best = Some((votes, a));
        }
    }
    best.map(|(_, a)| a.clone())
}

fn same(a: &GoalAnswer, b: &GoalAnswer) -> bool {
    a.goal == b.goal || goal::equivalent(&a.goal, &b.goal).unwrap_or(false)
}

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
            Err(_) => c.text.trim().lines().last().unwrap_or("").to_string(),
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
    messages.push(Message {
        role: Role::Assistant,
        content: first.text.trim().to_string(),
    });
    messages.push(Message::user(format!(
        "That cannot be the goal the person means:\n{}\nRead the request again and write a goal that fixes this, in the same answer format.",
        problems.join("\n")
    )));
}

#[cfg(test)]
#[path = "interpret_tests.rs"]
mod tests;
