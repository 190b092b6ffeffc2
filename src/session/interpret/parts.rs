//! A request of several wishes read one wish at a time.
//!
//! Each part (`reading::parts`) is read as a request of its own, with the examples
//! most like it and every check of a whole reading, and the parts' goals are joined as the
//! request joins them. The joined goal is checked once more against the whole request
//! (contradictions between parts, a goal that cannot be planned); when it fails, or a part
//! cannot be read at all, the request is read whole instead.

use crate::goal::Formula;
use crate::llm::LanguageModel;
use crate::llm::reply::GoalAnswer;
use crate::reading::parts::{Join, Part};
use crate::reading::{Lexicon, Request};
use crate::scenario::Scenario;
use crate::world::World;

use super::super::types::{Event, Options, SessionError};
use super::judge::Judge;
use super::{Interpretation, example_pool, read_goal};

/// What reading a request part by part came to.
pub(super) enum PartsRead {
    /// Every part read, and the joined goal passed its checks.
    Read(Box<Interpretation>),
    /// The request is to be read whole; `calls` were spent on the parts.
    Whole { calls: usize },
}

/// Read each of `parts` of `instruction` and join their goals; see the module.
pub(super) async fn read_parts(
    scenario: &Scenario,
    world: Box<dyn World>,
    parts: &[Part],
    instruction: &str,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<PartsRead, SessionError> {
    let quoted: Vec<String> = parts
        .iter()
        .map(|p| format!("\u{ab}{}\u{bb}", p.text))
        .collect();
    emit(&Event::Notice {
        message: format!(
            "the request asks for {} things; each is read on its own: {}",
            parts.len(),
            quoted.join(", ")
        ),
    });
    let mut read: Vec<Interpretation> = Vec::new();
    let mut calls = 0;
    for part in parts {
        match read_goal(
            scenario,
            world.fork(),
            &part.text,
            true,
            model,
            options,
            emit,
        )
        .await
        {
            Ok(found) => {
                calls += found.calls;
                read.push(found);
            }
            Err(SessionError::NoGoal { attempts, last }) => {
                calls += attempts;
                emit(&Event::Notice {
                    message: format!(
                        "no goal for \u{ab}{}\u{bb} ({last}): reading the request whole",
                        part.text
                    ),
                });
                return Ok(PartsRead::Whole { calls });
            }
            Err(e) => return Err(e),
        }
    }
    let goal = joined(parts, read.iter().map(|r| r.answer.goal.clone()).collect());
    let pool = example_pool(scenario, options);
    let lexicon = Lexicon::new(&scenario.domain.vocabulary, pool);
    let request = Request::new(instruction, scenario, &lexicon);
    let judge = Judge::new(scenario, world.fork(), request, options, false)?;
    let problem = judge.assess(&goal);
    if let Some(p) = problem.as_ref().filter(|p| !p.is_doubt()) {
        emit(&Event::CandidateRejected {
            candidate: goal.to_string(),
            proposal: None,
            reason: p.reason.clone(),
            author: Some("betr, joining the parts' goals".into()),
        });
        emit(&Event::Notice {
            message: "the parts' goals do not go together: reading the request whole".into(),
        });
        return Ok(PartsRead::Whole { calls });
    }
    // Each part was judged against its own words; what the whole request says about the
    // joined goal ("bread at the reading corner, or failing that an apple": the apple's
    // place is said only in the other part) is judged here.
    let (goal, problem) = match undone_whole(&judge, &goal) {
        Some((undone, why, problem)) => {
            emit(&Event::CandidateRejected {
                candidate: goal.to_string(),
                proposal: None,
                reason: judge.misread(&goal).unwrap_or_else(|| why.clone()),
                author: Some("betr, joining the parts' goals".into()),
            });
            emit(&Event::Notice {
                message: format!("read as {undone}: {why}"),
            });
            (undone, problem)
        }
        None => (goal, problem),
    };
    Ok(PartsRead::Read(Box::new(joined_reading(
        parts,
        &read,
        (goal, problem.map(|p| p.reason)),
        calls,
    ))))
}

/// The reading of the whole request from its parts' `read`: the joined `goal` with the
/// whole's own doubt, the parts' first answers joined alike, their reasoning, calls and
/// evidence.
fn joined_reading(
    parts: &[Part],
    read: &[Interpretation],
    (goal, doubt): (Formula, Option<String>),
    calls: usize,
) -> Interpretation {
    let first = read
        .iter()
        .map(|r| r.first.clone())
        .collect::<Option<Vec<Formula>>>()
        .map(|firsts| joined(parts, firsts));
    let reasoning: Vec<String> = read
        .iter()
        .filter_map(|r| r.answer.reasoning.clone())
        .collect();
    Interpretation {
        answer: GoalAnswer {
            goal: goal.clone(),
            reasoning: (!reasoning.is_empty()).then(|| reasoning.join("\n")),
        },
        first,
        calls,
        feedback_rounds: read.iter().map(|r| r.feedback_rounds).max().unwrap_or(0),
        // A part's own doubt may not hold for the whole ("the light is off already" is
        // no doubt about "the light off and a tea on the bar"): the whole's is the one.
        evidence: super::doubt::Evidence::joined(
            &read.iter().map(|r| r.evidence.clone()).collect::<Vec<_>>(),
            doubt,
        ),
        readings: vec![goal],
    }
}

/// The joined `goal` with what it plainly misread in the whole request undone, when it
/// has misread it and an undone goal passes every check but doubts and misreads nothing:
/// that goal, what was undone, and its doubt.
fn undone_whole(
    judge: &Judge,
    goal: &Formula,
) -> Option<(Formula, String, Option<super::goal_checks::GoalProblem>)> {
    judge.misread(goal)?;
    judge
        .undone_in_turn(goal)
        .into_iter()
        .filter_map(|(g, why)| Some((g, why.ok()?)))
        .find_map(|(g, why)| {
            let problem = judge.assess(&g);
            let usable = problem.as_ref().is_none_or(|p| p.is_doubt());
            (usable && judge.misread(&g).is_none()).then_some((g, why, problem))
        })
}

/// The goals of `parts` joined as the parts are: alternatives grouped, the groups
/// conjoined.
fn joined(parts: &[Part], goals: Vec<Formula>) -> Formula {
    let mut groups: Vec<Vec<Formula>> = Vec::new();
    for (part, goal) in parts.iter().zip(goals) {
        match (part.join, groups.last_mut()) {
            (Join::Or, Some(group)) => group.push(goal),
            _ => groups.push(vec![goal]),
        }
    }
    Formula::and(groups.into_iter().map(Formula::or).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn part(join: Join) -> Part {
        Part {
            text: String::new(),
            join,
        }
    }

    fn f(text: &str) -> Formula {
        Formula::parse(text).expect("parses")
    }

    #[test]
    fn alternatives_group_and_groups_conjoin() {
        let parts = [part(Join::And), part(Join::Or), part(Join::And)];
        let goal = joined(&parts, vec![f("A_X"), f("B_X | C_X"), f("~D_X")]);
        assert_eq!(goal, f("(A_X | B_X | C_X) & ~D_X"));
        let parts = [part(Join::And), part(Join::And)];
        assert_eq!(
            joined(&parts, vec![f("A_X & B_X"), f("C_X")]),
            f("A_X & B_X & C_X")
        );
    }
}
