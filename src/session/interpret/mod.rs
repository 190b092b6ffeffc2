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

pub mod doubt;
pub mod goal_checks;
pub mod judge;
pub mod made_pool;
mod parts;
pub mod readings;
pub mod submitted;

use crate::domain::Vocabulary;
use crate::goal::{self, Formula};
use crate::llm::prompt::Context;
use crate::llm::reply::{self, GoalAnswer, ReplyError};
use crate::llm::{ChatReply, LanguageModel, Message, OutputConstraint, Role, grammar, schema};
use crate::reading::Request;
use crate::reading::lexicon::{Lexicon, in_request_order};
use crate::reading::parts::split;
use crate::scenario::Scenario;
use crate::world::World;

use super::Question;
use super::call::ask;
use super::types::{Event, Options, SessionError};
use goal_checks::GoalProblem;
use judge::{Candidate, Judge};
use parts::{PartsRead, read_parts};

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
    /// What speaks for and against the goal chosen, summed up in its doubt level: a
    /// doubtful goal is for the person to look at before it runs.
    pub evidence: doubt::Evidence,
    /// The distinct readings that passed the checks, the chosen one first, then the others
    /// by their votes (at most [`MAX_READINGS`]): what a person chooses among when they
    /// would make the robot do different things.
    pub readings: Vec<Formula>,
}

impl Interpretation {
    /// Why the goal chosen is doubtful; `None` when its doubt is low.
    pub fn doubt(&self) -> Option<String> {
        self.evidence.doubt()
    }
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
/// as the module says (`options.steps.check_goals` off: the first usable answer, as the paper's
/// single call). A request of several wishes is read a wish at a time
/// (`options.steps.read_by_parts`, see [`super::interpret_parts`]) when checks are on.
pub async fn interpret(
    scenario: &Scenario,
    world: Box<dyn World>,
    instruction: &str,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Interpretation, SessionError> {
    let mut earlier_calls = 0;
    if options.steps.check_goals && options.steps.read_by_parts {
        let lexicon = Lexicon::new(&scenario.domain.vocabulary, example_pool(scenario, options));
        let parts = split(instruction, &lexicon);
        if parts.len() > 1 {
            let forked = world.fork();
            match read_parts(scenario, forked, &parts, instruction, model, options, emit).await? {
                PartsRead::Read(found) => {
                    announce(scenario, &found, emit);
                    return Ok(*found);
                }
                PartsRead::Whole { calls } => earlier_calls = calls,
            }
        }
    }
    let mut found = read_goal(scenario, world, instruction, false, model, options, emit).await?;
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
        .steps
        .prompt
        .examples
        .as_deref()
        .unwrap_or(&scenario.examples)
}

/// Tell the front end the goal chosen (with the model's first answer when it was another),
/// and the doubt raised about it.
fn announce(scenario: &Scenario, found: &Interpretation, emit: &mut (dyn FnMut(&Event) + Send)) {
    let chosen = &found.answer.goal;
    let first = found
        .first
        .as_ref()
        .filter(|first| !goal::equivalent(first, chosen).unwrap_or(*first == chosen));
    emit_goal(scenario, found, first, emit);
    if let Some(why) = found.doubt() {
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
        variant: &options.steps.prompt,
    };
    let mut messages = ctx.goal(&options.templates)?;
    let vocabulary = &scenario.domain.vocabulary;
    let lexicon = Lexicon::new(vocabulary, example_pool(scenario, options));
    let request = Request::new(instruction, scenario, &lexicon);
    let mut judge = Judge::new(scenario, world, request, options, one_of_several)?;
    tell_kept_examples(&judge.shown, emit);
    let drawer = Drawer {
        model,
        options,
        vocabulary,
        constraint: schema::goal(vocabulary),
    };
    let checks = options.steps.check_goals;
    let rounds = if checks {
        options.goal_feedback_rounds + 1
    } else {
        1
    };
    let mut drawn = Drawn {
        calls: 0,
        first: None,
        last_error: ReplyError::NoConditions,
        runners_up: Vec::new(),
        margin: None,
        beams: 0,
    };
    // Doubtful candidates of earlier rounds, eligible again in the last round's vote.
    let mut set_aside: Vec<Candidate> = Vec::new();
    for round in 0..rounds {
        let candidates =
            draw_round(&drawer, &mut judge, &messages, round, &mut drawn, emit).await?;
        // A doubtful answer is taken when it is the model's own first answer, or when no
        // round is left: a doubtful sample after a wrong first answer is asked about again
        // (told why), and stays eligible for the last round's vote.
        let last_round = round + 1 == rounds;
        if let Some((answer, doubt)) = judge.choose(&candidates, &set_aside, last_round) {
            let answer = in_asked_order(answer, &lexicon, &judge, checks, emit);
            let others: Vec<&Candidate> = set_aside.iter().chain(&drawn.runners_up).collect();
            let readings = judge.readings(&answer.goal, &candidates, &others, MAX_READINGS);
            let first = drawn.first.flatten();
            let usable = candidates.iter().filter_map(|c| c.read.as_ref().ok());
            let evidence = doubt::Evidence {
                first_kept: first
                    .as_ref()
                    .is_some_and(|f| judge::same_goal(f, &answer.goal)),
                margin: drawn.margin,
                beams: drawn.beams,
                votes: usable
                    .clone()
                    .filter(|a| judge::same_goal(&a.goal, &answer.goal))
                    .count(),
                candidates: usable.count(),
                feedback_rounds: round,
                checked_doubt: doubt,
                parts: 0,
            };
            return Ok(Interpretation {
                answer,
                first,
                calls: drawn.calls,
                feedback_rounds: round,
                evidence,
                readings,
            });
        }
        if !last_round {
            feedback(&mut messages, &candidates);
            set_aside.extend(candidates.into_iter().filter(Candidate::doubtful));
        }
    }
    Err(SessionError::NoGoal {
        attempts: drawn.calls,
        last: drawn.last_error,
    })
}

/// Say which kept corrections the prompt shows as examples: a request phrased like a
/// corrected one is read with its correction.
fn tell_kept_examples(shown: &[&crate::scenario::Example], emit: &mut (dyn FnMut(&Event) + Send)) {
    let kept: Vec<String> = shown
        .iter()
        .filter_map(|e| match &e.source {
            crate::scenario::ExampleSource::Kept(id) => Some(format!(
                "{id} (\u{ab}{}\u{bb} \u{2192} {})",
                e.instruction, e.goal
            )),
            _ => None,
        })
        .collect();
    if kept.is_empty() {
        return;
    }
    tracing::info!(examples = %kept.join(", "), "kept examples shown to the model");
    emit(&Event::Notice {
        message: format!("read with the kept example(s) {}", kept.join(", ")),
    });
}

/// What every draw of one reading shares: the model, the options, and the answer's format
/// (a JSON schema for servers that take one, a grammar for the embedded model).
struct Drawer<'a> {
    model: &'a dyn LanguageModel,
    options: &'a Options,
    vocabulary: &'a Vocabulary,
    constraint: OutputConstraint,
}

/// What the draws of one reading found so far, over its rounds.
struct Drawn {
    /// Calls made.
    calls: usize,
    /// The first call's answer as it came, once asked (`None` inside: unusable).
    first: Option<Option<Formula>>,
    /// Why the last unusable reply was refused (the error when no goal is found).
    last_error: ReplyError,
    /// The model's runners-up to its first answer (beams), judged like any candidate.
    runners_up: Vec<Candidate>,
    /// How far the first answer's beam is ahead of the best beam with another goal.
    margin: Option<f64>,
    /// How many beams the first answer was searched with.
    beams: usize,
}

impl Drawer<'_> {
    /// Draw `draw` of `draws` from the conversation `messages`: the first greedy, the
    /// others sampled (seeded by their draw) at a temperature that makes them differ.
    async fn ask(
        &self,
        messages: &[Message],
        draw: usize,
        draws: usize,
        emit: &mut (dyn FnMut(&Event) + Send),
    ) -> Result<ChatReply, SessionError> {
        emit(&Event::Asking {
            what: Question::Goal { draw, draws },
        });
        let mut opts = self.options.clone();
        let seed = if draw > 0 {
            opts.temperature = opts.temperature.max(SAMPLE_TEMPERATURE);
            Some(draw as u64)
        } else {
            None
        };
        let cot = self.options.steps.prompt.chain_of_thought;
        let typed = || grammar::goal_grammar(self.vocabulary, true, cot);
        let constraint = (
            self.constraint.clone(),
            &typed as &(dyn Fn() -> String + Sync),
        );
        ask(self.model, messages.to_vec(), constraint, &opts, seed, emit).await
    }

    /// A reply read as a goal over the vocabulary and, with checks on, judged.
    fn judged(&self, judge: &Judge<'_>, text: &str, first: bool) -> Candidate {
        let read = reply::goal(text, self.vocabulary, self.options.min_similarity);
        let problem = match &read {
            Err(e) => Some(GoalProblem::wrong(e.to_string())),
            Ok(_) if !self.options.steps.check_goals => None,
            Ok(a) => judge.assess(&a.goal),
        };
        Candidate {
            text: text.to_string(),
            read,
            problem,
            first,
        }
    }
}

/// One round's candidates: the first answer, what the judge derives from it, and more
/// draws only when the first does not settle the round (with checks on).
async fn draw_round(
    drawer: &Drawer<'_>,
    // Mutable only to be sent between threads with the future: a judge is `Send`, not
    // `Sync` (its world is not).
    judge: &mut Judge<'_>,
    messages: &[Message],
    round: usize,
    drawn: &mut Drawn,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Vec<Candidate>, SessionError> {
    let checks = drawer.options.steps.check_goals;
    let draws = if checks {
        drawer.options.candidates.max(1)
    } else {
        1
    };
    let mut candidates: Vec<Candidate> = Vec::new();
    for draw in 0..draws {
        let r = drawer.ask(messages, draw, draws, emit).await?;
        drawn.calls += 1;
        let first_draw = round == 0 && draw == 0;
        if first_draw {
            let beams: Vec<(Option<Formula>, f64)> = r
                .ranked
                .iter()
                .map(|(text, score)| {
                    let read = reply::goal(text, drawer.vocabulary, drawer.options.min_similarity);
                    (read.ok().map(|a| a.goal), *score)
                })
                .collect();
            drawn.margin = doubt::margin(&beams, judge::same_goal);
            drawn.beams = beams.len();
        }
        if first_draw && checks {
            drawn.runners_up = r
                .ranked
                .iter()
                .skip(1)
                .map(|(text, _)| drawer.judged(judge, text, false))
                .collect();
        }
        let candidate = drawer.judged(judge, &r.text, first_draw);
        if drawn.first.is_none() {
            drawn.first = Some(candidate.read.as_ref().ok().map(|a| a.goal.clone()));
        }
        report(&candidate, &mut drawn.last_error, emit);
        let derived = judge.derived(
            &candidate.read,
            candidate.problem.as_ref(),
            checks,
            first_draw,
            emit,
        );
        candidates.push(candidate);
        candidates.extend(derived);
        if draw == 0 && settled(judge, &mut candidates, &mut drawn.runners_up, checks, emit) {
            break;
        }
    }
    Ok(candidates)
}

/// Tell the front end why a candidate is refused (unusable, or failing a check), keeping
/// the last unusable reply's error.
fn report(
    candidate: &Candidate,
    last_error: &mut ReplyError,
    emit: &mut (dyn FnMut(&Event) + Send),
) {
    match (&candidate.read, &candidate.problem) {
        (Err(e), _) => {
            emit(&Event::InvalidReply {
                error: e.to_string(),
            });
            *last_error = e.clone();
        }
        (Ok(a), Some(p)) => emit(&Event::CandidateRejected {
            candidate: a.goal.to_string(),
            proposal: None,
            reason: p.reason.clone(),
            author: None,
        }),
        (Ok(_), None) => {}
    }
}

/// After a round's first draw: whether its candidates settle the round, the model's
/// runners-up (which cost no call) joined to them before any sample is drawn.
///
/// More draws only for a first answer that is wrong: one that passes (or passes once what
/// it pasted is taken out) is taken, and a doubtful one is kept, since sampled
/// alternatives to the model's best answer are worse more often than better. One
/// exception: a first answer that plainly misread the request (left out a number it says,
/// or put an unnamed object in the place of a named one); more candidates are drawn, and
/// one that does not misread wins the vote.
fn settled(
    judge: &Judge<'_>,
    candidates: &mut Vec<Candidate>,
    runners_up: &mut Vec<Candidate>,
    checks: bool,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> bool {
    let misread = candidates
        .first()
        .and_then(|c| c.read.as_ref().ok())
        .and_then(|a| judge.misread(&a.goal));
    let settled = match &misread {
        Some(_) if checks => candidates.iter().any(|c| judge.answers_request(c)),
        _ => candidates.iter().any(|c| c.clean() || c.doubtful()),
    };
    if settled {
        return true;
    }
    if !runners_up.is_empty() {
        candidates.append(runners_up);
        if candidates.iter().any(|c| judge.answers_request(c)) {
            emit(&Event::Notice {
                message: "the first answer fails its checks: the model's next most likely answers are candidates".into(),
            });
            return true;
        }
    }
    if let Some(why) = misread
        && checks
    {
        emit(&Event::Notice {
            message: format!("{why}: drawing more candidates"),
        });
    }
    false
}

/// With checks on, the chosen answer's alternatives put in the order the request names
/// them, since a behavior tree tries them in that order.
fn in_asked_order(
    mut answer: GoalAnswer,
    lexicon: &Lexicon,
    judge: &Judge<'_>,
    checks: bool,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> GoalAnswer {
    if checks {
        let ordered = in_request_order(lexicon, &answer.goal, &judge.request.terms);
        if ordered != answer.goal {
            emit(&Event::Notice {
                message: format!("alternatives put in the order the request names them: {ordered}"),
            });
            answer.goal = ordered;
        }
    }
    answer
}

fn emit_goal(
    scenario: &Scenario,
    found: &Interpretation,
    first_answer: Option<&Formula>,
    emit: &mut (dyn FnMut(&Event) + Send),
) {
    let answer = &found.answer;
    let matches_expected = scenario
        .goal
        .as_ref()
        .and_then(|expected| goal::equivalent(expected, &answer.goal).ok());
    emit(&Event::Goal {
        goal: answer.goal.clone(),
        reasoning: answer.reasoning.clone(),
        matches_expected,
        author: "model".into(),
        first_answer: first_answer.cloned(),
        doubt: Some(found.evidence.summary()),
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
