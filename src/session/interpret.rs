//! Reading an instruction as a goal, checked before it is used.
//!
//! One call gives the model's first answer. An answer is kept only if it parses over the
//! vocabulary, is not contradictory, does not hold already (a request asks for a change)
//! and can be planned with the scenario's skills. When the first answer fails a check,
//! more candidates are drawn from the same prompt (sampled, so they differ; the prompt is
//! in the model's cache, so each costs only its own tokens) and the survivors vote: the
//! largest group of logically equivalent goals wins, the earliest drawn breaking ties.
//! When none survives, the model is told why, in the same conversation, and asked again
//! (reflective feedback), for a bounded number of rounds. A first answer that leaves out a
//! number the request says ("table six" read as table 1) draws more candidates too, and
//! one that uses the number wins the vote.

use crate::domain::{Condition, Scenario};
use crate::goal::{self, Formula};
use crate::llm::examples::terms;
use crate::llm::lexicon::{Lexicon, same_word};
use crate::llm::prompt::Context;
use crate::llm::reply::{self, GoalAnswer, ReplyError};
use crate::llm::{LanguageModel, Message, Role, grammar, schema};
use crate::planner::{Outcome, Planner};
use crate::world::World;

use super::ask::ask;
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
}

/// Why a candidate goal cannot be what the person meant, or may not be.
#[derive(Debug, Clone, PartialEq)]
pub struct GoalProblem {
    pub reason: String,
    /// A doubt rather than a proof: the goal holds already (a person may ask for what is
    /// true), or a condition of it comes from a shown example (an indirect request may
    /// mean just that). A doubtful first answer is kept unless the part it pasted can be
    /// taken out; a wrong one (unreadable, contradictory, unplannable) never is.
    pub doubt: bool,
}

/// Check a candidate goal against the skills and the scene: not contradictory,
/// plannable, and (a doubt) not already true.
pub fn check_goal(
    scenario: &Scenario,
    world: &dyn World,
    goal: &Formula,
) -> Result<(), GoalProblem> {
    let wrong = |reason: String| GoalProblem {
        reason,
        doubt: false,
    };
    let dnf = goal.to_dnf();
    if dnf.is_false() {
        return Err(wrong(
            "it contradicts itself: no situation makes it true".into(),
        ));
    }
    let planner = Planner::new(&scenario.domain);
    let plan = planner
        .plan(&dnf, world)
        .map_err(|e| wrong(e.to_string()))?;
    match plan.outcome {
        // An action that fails in simulation is what failure resolution is for: the goal
        // itself was plannable.
        Outcome::Success | Outcome::ActionFailed { .. } => {}
        Outcome::Unreachable {
            condition, reason, ..
        } => {
            return Err(wrong(format!(
                "the robot cannot make {condition} true: {reason}"
            )));
        }
        Outcome::Exhausted { reason } => {
            return Err(wrong(format!("the robot cannot reach it: {reason}")));
        }
    }
    // The world answers for "any object" as well as for plain atoms.
    let holds = |atom: &crate::domain::Atom| world.check(&Condition::pos(atom.clone()));
    if goal.eval(&holds) {
        return Err(GoalProblem {
            reason: "it holds already in the scene now, but the request asks for a change".into(),
            doubt: true,
        });
    }
    Ok(())
}

/// A condition of `goal` that one of the `shown` examples' goals holds and that shares no
/// word with the request: pasted from the example rather than asked for (small models
/// copy an example's place, or its extra "hand empty", into unrelated answers).
pub fn copied_from_example(
    goal: &Formula,
    shown: &[&crate::domain::Example],
    request: &str,
) -> Option<String> {
    let asked: Vec<String> = terms(request);
    goal.atoms()
        .into_iter()
        .find(|atom| is_copied(atom, shown, &asked))
        .map(|atom| format!("{atom} comes from an example, and the request says nothing about it"))
}

fn is_copied(
    atom: &crate::domain::Atom,
    shown: &[&crate::domain::Example],
    asked: &[String],
) -> bool {
    let in_example = shown
        .iter()
        .any(|e| Formula::parse(&e.goal).is_ok_and(|f| f.atoms().contains(atom)));
    in_example && !terms(&atom.to_string()).iter().any(|w| asked.contains(w))
}

/// Words of a request that ask for no condition by themselves: how a request is phrased,
/// not what it asks for.
const PHRASING: &[&str] = &[
    "put", "place", "bring", "take", "give", "hand", "fetch", "carry", "get", "make", "set",
    "move", "go", "keep", "need", "have", "now", "then", "also", "too", "right", "away", "thank",
    "thanks", "kindly", "over",
];

/// The conjuncts of `goal` (a conjunction of two or more) that nothing in the request asks
/// for: every word of the request they answer to is claimed by more conjuncts than the
/// request says it. Small models append a condition the request never mentions ("robot
/// near table 2" after "coffee on table 2": "table" and "2" are said once and claimed
/// twice, and the second conjunct has no word of its own); a request that says "bar" twice
/// ("not on the bar and bar 2, the milk to the bar") asks for every conjunct about a bar.
pub fn unasked(goal: &Formula, request: &str, lexicon: &Lexicon) -> Vec<Formula> {
    let Formula::And(items) = goal else {
        return Vec::new();
    };
    let asked = terms(request);
    let covered: Vec<Vec<String>> = items.iter().map(|i| lexicon.covered(i, &asked)).collect();
    let said = |w: &String| asked.iter().filter(|a| same_word(a, w)).count();
    let claimed = |w: &String| covered.iter().filter(|c| c.contains(w)).count();
    items
        .iter()
        .zip(&covered)
        .filter(|(_, words)| words.iter().all(|w| claimed(w) > said(w)))
        .map(|(item, _)| item.clone())
        .collect()
}

/// Words of the request that name an object ("six" of window table 6, "juice") and that
/// no condition of `goal` answers to: the goal leaves out, or misplaces, something asked.
pub fn unanswered_names(goal: &Formula, request: &str, lexicon: &Lexicon) -> Vec<String> {
    let asked = terms(request);
    let covered = lexicon.covered(goal, &asked);
    let mut out: Vec<String> = asked
        .into_iter()
        .filter(|w| lexicon.names_an_object(w) && !covered.contains(w))
        .collect();
    out.dedup();
    out
}

/// `goal` without the conjuncts nothing asks for, taken out one at a time, the last
/// first (an appended condition comes last), while more than one is left.
fn without_unasked(goal: &Formula, request: &str, lexicon: &Lexicon) -> Option<Formula> {
    let mut current = goal.clone();
    let mut changed = false;
    while let Some(extra) = unasked(&current, request, lexicon).pop() {
        let Formula::And(items) = &current else {
            break;
        };
        let kept: Vec<Formula> = items.iter().filter(|i| **i != extra).cloned().collect();
        if kept.is_empty() || kept.len() == items.len() {
            break;
        }
        current = Formula::and(kept);
        changed = true;
    }
    changed.then_some(current)
}

/// A conjunction without its conjuncts pasted from an example, when the rest stands
/// alone: something is left, and every word of the request that asks for something is
/// covered by what is left ("put the blue cube on the green cube" read as "blue on green
/// & hand empty": the rest covers blue, green and cube, so the pasted "hand empty" goes).
/// A request with a word the rest does not cover ("it's hot, close the curtain") may
/// mean the pasted condition in other words, and keeps it.
fn without_copied(
    goal: &Formula,
    shown: &[&crate::domain::Example],
    request: &str,
) -> Option<Formula> {
    let Formula::And(items) = goal else {
        return None;
    };
    let asked = terms(request);
    let kept: Vec<Formula> = items
        .iter()
        .filter(|item| !item.atoms().iter().any(|a| is_copied(a, shown, &asked)))
        .cloned()
        .collect();
    if kept.is_empty() || kept.len() == items.len() {
        return None;
    }
    let rest = Formula::and(kept);
    let covered: Vec<String> = rest
        .atoms()
        .iter()
        .flat_map(|a| terms(&a.to_string()))
        .collect();
    let unexplained = asked
        .iter()
        .any(|w| !PHRASING.contains(&w.as_str()) && !covered.iter().any(|c| same_word(c, w)));
    (!unexplained).then_some(rest)
}

/// One candidate: the reply's text and what it was read as.
struct Candidate {
    text: String,
    read: Result<GoalAnswer, ReplyError>,
    problem: Option<GoalProblem>,
}

impl Candidate {
    fn clean(&self) -> bool {
        self.read.is_ok() && self.problem.is_none()
    }
    fn doubtful(&self) -> bool {
        self.read.is_ok() && self.problem.as_ref().is_some_and(|p| p.doubt)
    }
}

/// How many alternatives `goal` offers beyond the first where it asks for something:
/// `A | B | C` offers two; a disjunction under a negation ("neither A nor B") offers none.
fn alternatives(goal: &Formula, negated: bool) -> usize {
    match goal {
        Formula::Atom(_) => 0,
        Formula::Not(inner) => alternatives(inner, !negated),
        Formula::And(items) | Formula::Or(items) => {
            let inner: usize = items.iter().map(|i| alternatives(i, negated)).sum();
            // `~(A & B)` is `~A | ~B`: a conjunction offers alternatives under a negation.
            let offers = matches!(goal, Formula::Or(_)) != negated;
            inner + if offers { items.len() - 1 } else { 0 }
        }
    }
}

/// Words that offer a choice between what comes before and after them.
const CHOICE_WORDS: &[&str] = &["or", "otherwise", "else", "alternatively", "instead"];

/// How many choices a request offers: each "or" (and "if not", "otherwise", ...), and each
/// comma of a list that ends in "or" ("coffee, cake, or tea").
fn choices_offered(request: &str) -> usize {
    let lower = request.to_lowercase();
    let mut choices = lower.matches("if not").count();
    for part in lower.split(['.', ';', ':', '!', '?']) {
        let words: Vec<&str> = part
            .split(|c: char| !c.is_alphanumeric() && c != ',')
            .filter(|w| !w.is_empty())
            .collect();
        let mut commas_since_choice = 0;
        for w in words {
            let word = w.trim_end_matches(',');
            if CHOICE_WORDS.contains(&word) {
                choices += 1 + commas_since_choice;
                commas_since_choice = 0;
            }
            if w.ends_with(',') {
                commas_since_choice += 1;
            }
        }
    }
    choices
}

/// Why `goal` offers more alternatives than `request` does, if it does: "a banana or an
/// orange, and switch the light off" written `A | B | ~C` makes switching the light off
/// one of three alternatives, when the request asks for it in any case.
fn more_alternatives_than_asked(goal: &Formula, request: &str) -> Option<String> {
    let offered = alternatives(goal, false);
    let asked = choices_offered(request);
    (offered > asked).then(|| {
        format!(
            "it offers {} alternatives joined by |, where the request gives {} choice(s); \
             what must hold in any case is joined with &, and a choice in parentheses: (A | B) & C",
            offered + 1,
            asked + 1
        )
    })
}

/// An object of a condition of `goal` that holds now and that no word of the request
/// names: a goal made true already by a place the model chose itself ("bring me a
/// banana" read as the banana on the table it lies on). A goal that holds through what
/// the request does say ("check that the hall light is on") stays a doubt.
fn unsaid_object_holding(
    goal: &Formula,
    world: &dyn World,
    request: &str,
    lexicon: &Lexicon,
) -> Option<String> {
    let asked = terms(request);
    goal.atoms()
        .into_iter()
        .filter(|a| world.check(&Condition::pos(a.clone())))
        .flat_map(|a| a.args.clone())
        .filter(|arg| arg != crate::domain::ANY_OBJECT)
        .find(|arg| {
            !lexicon
                .words(arg)
                .iter()
                .any(|w| asked.iter().any(|a| same_word(a, w)))
        })
}

/// Every check of a readable candidate, the wrong ones first.
fn assess(
    scenario: &Scenario,
    world: &dyn World,
    goal: &Formula,
    (shown, lexicon): (&[&crate::domain::Example], &Lexicon),
    request: &str,
) -> Option<GoalProblem> {
    let doubt = |reason: String| GoalProblem {
        reason,
        doubt: true,
    };
    match check_goal(scenario, world, goal) {
        Err(p) if !p.doubt => Some(p),
        _ if let Some(reason) = more_alternatives_than_asked(goal, request) => Some(GoalProblem {
            reason,
            doubt: false,
        }),
        Err(_) if let Some(object) = unsaid_object_holding(goal, world, request, lexicon) => {
            Some(GoalProblem {
                reason: format!(
                    "it holds already in the scene now, through {object}, which the request \
                     never mentions; the request asks for a change"
                ),
                doubt: false,
            })
        }
        checked => copied_from_example(goal, shown, request)
            .map(doubt)
            .or_else(|| {
                let extra = unasked(goal, request, lexicon);
                (!extra.is_empty()).then(|| {
                    let parts: Vec<String> = extra.iter().map(ToString::to_string).collect();
                    doubt(format!(
                        "no word of the request asks for {}",
                        parts.join(" or ")
                    ))
                })
            })
            .or(checked.err()),
    }
}

/// Ask for the goal `instruction` means in `scenario`, in the state of `world`, checked
/// as the module says (`options.check_goals` off: the first usable answer, as the paper's
/// single call).
pub async fn interpret(
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
    let pool = options
        .variant
        .examples
        .as_deref()
        .unwrap_or(&scenario.examples);
    let shown = options.variant.choose(pool, instruction);
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, pool);
    let place_numbers = lexicon.place_numbers(&terms(instruction));
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
                Ok(a) => assess(
                    scenario,
                    world.as_ref(),
                    &a.goal,
                    (&shown, &lexicon),
                    instruction,
                ),
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
                }),
                (Ok(_), None) => {}
            }
            // An answer without what it pasted from an example, or without the parts no
            // word of the request asks for, is a candidate of its own, checked like the
            // others.
            let pruned = match &read {
                Ok(a) if problem.is_some() => without_copied(&a.goal, &shown, instruction)
                    .or_else(|| without_unasked(&a.goal, instruction, &lexicon)),
                _ => None,
            };
            candidates.push(Candidate {
                text: r.text,
                read,
                problem,
            });
            if let Some(goal) = pruned {
                let problem = assess(
                    scenario,
                    world.as_ref(),
                    &goal,
                    (&shown, &lexicon),
                    instruction,
                );
                if let Some(p) = &problem {
                    emit(&Event::CandidateRejected {
                        candidate: goal.to_string(),
                        proposal: None,
                        reason: p.reason.clone(),
                    });
                }
                candidates.push(Candidate {
                    text: format!("Goal: {goal}"),
                    read: Ok(GoalAnswer {
                        goal,
                        reasoning: None,
                        substitutions: Vec::new(),
                    }),
                    problem,
                });
            }
            // More draws only for a first answer that is wrong: one that passes (or
            // passes once what it pasted is taken out) is taken, and a doubtful one is
            // kept, since sampled alternatives to the model's best answer are worse more
            // often than better.
            // One exception: a first answer that leaves out a number the request says
            // ("table six" read as table 1) has misread a place; candidates that use the
            // number are drawn.
            let misses = candidates
                .first()
                .and_then(|c| c.read.as_ref().ok())
                .map(|a| {
                    unanswered_names(&a.goal, instruction, &lexicon)
                        .into_iter()
                        .filter(|w| place_numbers.contains(w))
                        .collect::<Vec<_>>()
                });
            if draw == 0
                && let Some(missed) = misses.as_ref().filter(|m| !m.is_empty())
                && let Some(Ok(a)) = candidates.first().map(|c| &c.read)
                && options.check_goals
            {
                emit(&Event::Notice {
                    message: format!(
                        "the request says {}, and no condition of {} is about it: drawing more candidates",
                        missed.join(", "),
                        a.goal
                    ),
                });
                continue;
            }
            if draw == 0 && candidates.iter().any(|c| c.clean() || c.doubtful()) {
                break;
            }
        }
        let answers_numbers = |c: &Candidate| {
            c.clean()
                && c.read.as_ref().is_ok_and(|a| {
                    !unanswered_names(&a.goal, instruction, &lexicon)
                        .iter()
                        .any(|w| place_numbers.contains(w))
                })
        };
        let chosen = vote(&candidates, answers_numbers)
            .or_else(|| vote(&candidates, Candidate::clean))
            .map(|a| (a, None))
            .or_else(|| {
                vote(&candidates, Candidate::doubtful).map(|a| {
                    let why = candidates
                        .iter()
                        .find(|c| c.doubtful())
                        .and_then(|c| c.problem.as_ref())
                        .map(|p| p.reason.clone());
                    (a, why)
                })
            });
        if let Some((answer, doubt)) = chosen {
            emit_goal(scenario, &answer, emit);
            if let Some(why) = &doubt {
                emit(&Event::Notice {
                    message: format!("check the goal before it runs: {why}"),
                });
            }
            return Ok(Interpretation {
                answer,
                first: first.flatten(),
                calls,
                feedback_rounds: round,
                doubt,
            });
        }
        if round + 1 < rounds {
            feedback(&mut messages, &candidates);
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
    let passed: Vec<&GoalAnswer> = candidates
        .iter()
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
mod tests {
    use super::*;
    use std::path::Path;

    fn cafe() -> (Scenario, Box<dyn World>) {
        let s =
            Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml"))
                .expect("cafe scenario");
        let w = crate::world::load(&s).expect("cafe world");
        (s, w)
    }

    fn check(goal: &str) -> Result<(), String> {
        let (s, w) = cafe();
        let f = s.parse_goal(goal).expect("goal parses");
        check_goal(&s, w.as_ref(), &f).map_err(|p| p.reason)
    }

    #[test]
    fn checks_refuse_what_cannot_be_meant() {
        assert!(check("On_Coffee_Table1").is_ok());
        assert!(check("Active_AC & ~Active_HallLight").is_ok());
        let e = check("Active_AC & ~Active_AC").unwrap_err();
        assert!(e.contains("contradicts"), "{e}");
        // Already true in the cafe's first state.
        let e = check("On_Chips_Bar").unwrap_err();
        assert!(e.contains("already"), "{e}");
        let e = check("RobotNear_Table1 & RobotNear_Table2").unwrap_err();
        assert!(e.contains("cannot"), "{e}");
    }

    #[test]
    fn a_condition_pasted_from_an_example_is_found() {
        let example = crate::domain::Example {
            instruction: "Put the sponge in the bowl and leave your gripper empty".into(),
            goal: r#""sponge" in "bowl" & ~"any object" grasped"#.into(),
        };
        let shown = [&example];
        let request = "Put the blue cube on the green cube";
        let pasted = Formula::parse(r#""blue cube" on "green cube" & ~"any object" grasped"#)
            .expect("parses");
        let why = copied_from_example(&pasted, &shown, request).expect("found");
        assert!(why.contains("grasped"), "{why}");
        let plain = Formula::parse(r#""blue cube" on "green cube""#).expect("parses");
        assert!(copied_from_example(&plain, &shown, request).is_none());
        // Asked for in other words ("hand empty" is not "grasped", but the object is
        // named): not a copy.
        let named = Formula::parse(r#"~"sponge" in "bowl""#).expect("parses");
        assert!(copied_from_example(&named, &shown, "take the sponge out").is_none());
    }

    #[test]
    fn a_pasted_conjunct_goes_only_when_the_rest_covers_the_request() {
        let example = crate::domain::Example {
            instruction: "It's really stuffy in here, and leave your gripper empty".into(),
            goal: r#"Active_AC & ~"any object" grasped"#.into(),
        };
        let shown = [&example];
        let pasted = Formula::parse(r#""blue cube" on "green cube" & ~"any object" grasped"#)
            .expect("parses");
        let rest =
            without_copied(&pasted, &shown, "Put the blue cube on the green cube").expect("pruned");
        assert_eq!(rest.to_string(), r#""blue cube" on "green cube""#);
        // "hot" is not covered by the curtain: the AC may be what it asks for.
        let indirect = Formula::parse("Closed_Curtain & Active_AC").expect("parses");
        assert!(without_copied(&indirect, &shown, "It's hot here, close the curtain").is_none());
        assert!(same_word("clos", "close") && same_word("cube", "cube") && !same_word("ac", "at"));
    }

    fn candidate(goal: Option<&str>, problem: Option<&str>) -> Candidate {
        Candidate {
            text: format!("Goal: {}", goal.unwrap_or("?")),
            read: match goal {
                Some(g) => Ok(GoalAnswer {
                    goal: Formula::parse(g).expect("parses"),
                    reasoning: None,
                    substitutions: Vec::new(),
                }),
                None => Err(ReplyError::NoConditions),
            },
            problem: problem.map(|p| GoalProblem {
                reason: p.to_string(),
                doubt: false,
            }),
        }
    }

    #[test]
    fn the_largest_group_of_equivalent_survivors_wins() {
        let cs = vec![
            candidate(Some("Active_AC"), Some("holds already")),
            candidate(Some("On_Apple_Bar2"), None),
            candidate(Some("Active_TubeLight & ~Closed_Curtain"), None),
            candidate(Some("~Closed_Curtain & Active_TubeLight"), None),
            candidate(None, Some("unusable")),
        ];
        let chosen = vote(&cs, Candidate::clean).expect("a winner");
        assert_eq!(
            chosen.goal.to_string(),
            "Active_TubeLight & ~Closed_Curtain"
        );
        // A tie goes to the earliest.
        let cs = vec![
            candidate(Some("On_Apple_Bar2"), None),
            candidate(Some("On_Apple_Table3"), None),
        ];
        assert_eq!(
            vote(&cs, Candidate::clean)
                .expect("a winner")
                .goal
                .to_string(),
            "On_Apple_Bar2"
        );
        assert!(
            vote(
                &[candidate(Some("Active_AC"), Some("no"))],
                Candidate::clean
            )
            .is_none()
        );
    }

    #[test]
    fn feedback_tells_each_problem_once() {
        let mut messages = vec![Message::user("request")];
        let cs = vec![
            candidate(Some("On_Chips_Bar"), Some("it holds already")),
            candidate(Some("On_Chips_Bar"), Some("it holds already")),
        ];
        feedback(&mut messages, &cs);
        assert_eq!(messages.len(), 3);
        assert_eq!(messages[1].role, Role::Assistant);
        assert_eq!(messages[2].content.matches("On_Chips_Bar").count(), 1);
    }

    #[test]
    fn a_condition_no_word_asks_for_is_taken_out() {
        let (scenario, _) = cafe();
        let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
        let g = |t: &str| Formula::parse(t).expect("parses");
        let request = "Please take a sandwich to the second table.";
        let appended = g("On_Sandwiches_Table2 & RobotNear_Table2");
        assert_eq!(
            unasked(&appended, request, &lexicon),
            vec![g("RobotNear_Table2")]
        );
        assert_eq!(
            without_unasked(&appended, request, &lexicon),
            Some(g("On_Sandwiches_Table2"))
        );
        // Every part answers to words of its own: nothing goes.
        let request = "Mop the floor, and bring a teacup to table two.";
        let both = g("IsClean_Floor & On_Teacup_Table2");
        assert!(unasked(&both, request, &lexicon).is_empty());
        assert_eq!(without_unasked(&both, request, &lexicon), None);
        // A single condition is never taken out, however indirect the request.
        assert_eq!(
            without_unasked(&g("Active_AC"), "I'm melting.", &lexicon),
            None
        );
        // A word said as often as conditions claim it asks for each of them.
        let request = "Ensure that chips are not on bar and bar2 and deliver the milk to bar.";
        let bars = g("~On_Chips_Bar & ~On_Chips_Bar2 & On_Milk_Bar");
        assert!(unasked(&bars, request, &lexicon).is_empty());
    }

    #[test]
    fn a_goal_may_offer_only_the_choices_the_request_gives() {
        let g = |t: &str| Formula::parse(t).expect("parses");
        let request = "Bring me a banana or an orange, and switch off the hall light.";
        assert!(
            more_alternatives_than_asked(
                &g("On_Banana_Bar | On_Orange_Bar | ~Active_HallLight"),
                request
            )
            .is_some()
        );
        assert_eq!(
            more_alternatives_than_asked(
                &g("(On_Banana_Bar | On_Orange_Bar) & ~Active_HallLight"),
                request
            ),
            None
        );
        // A list ending in "or" offers one choice per item.
        let listed = g("On_Coffee_Bar | On_Cake_Bar | On_Tea_Bar");
        assert_eq!(
            more_alternatives_than_asked(&listed, "Coffee, cake, or tea at the bar."),
            None
        );
        // "Neither ... nor" offers no choice: the disjunction is under a negation.
        let neither = g("~(On_Mop_Entrance | On_Mop_Exit)");
        assert_eq!(
            more_alternatives_than_asked(
                &neither,
                "Keep the mop away from the entrance and the exit."
            ),
            None
        );
        assert_eq!(
            more_alternatives_than_asked(
                &g("IsClean_Chairs | Exists_Coffee"),
                "Clean the chairs; if not, make coffee."
            ),
            None
        );
    }

    #[test]
    fn a_goal_true_through_a_place_nobody_named_is_wrong() {
        let (scenario, world) = cafe();
        let lexicon = Lexicon::new(&scenario.domain.vocabulary, &scenario.examples);
        let g = |t: &str| Formula::parse(t).expect("parses");
        // The chips lie on the bar already; the request says nothing of the bar.
        assert_eq!(
            unsaid_object_holding(
                &g("On_Chips_Bar"),
                world.as_ref(),
                "Bring me the chips",
                &lexicon
            ),
            Some("Bar".to_string())
        );
        // The hall light is on already, and the request names it: a doubt, not a mistake.
        assert_eq!(
            unsaid_object_holding(
                &g("Active_HallLight"),
                world.as_ref(),
                "Could you check that the hall light is on?",
                &lexicon
            ),
            None
        );
    }
}
