//! Judging the candidate goals of one reading: the checks each passes or fails, the plain
//! misreadings of the request and the candidates made by undoing them, and the vote.
//!
//! The plain misreadings are the detectors registered in [`crate::reading::misreading`]
//! (its table lists each: what it finds and how it undoes it); an evaluation may leave
//! any of them out.

use crate::domain::VocabularyError;
use crate::goal::{self, Formula};
use crate::llm::reply::{GoalAnswer, ReplyError};
use crate::reading::names::{without_copied, without_unasked};
use crate::reading::{Misreading, Request};
use crate::scenario::Scenario;
use crate::world::World;

use super::super::types::Event;
use super::goal_checks::{GoalProblem, ProblemKind, assess};

/// How many times a goal's misreadings are undone one after another.
const UNDO_STEPS: usize = 3;
/// How many goals undoing one answer's misreadings may make.
const UNDONE_AT_MOST: usize = 12;

/// One candidate: the reply's text and what it was read as.
pub(super) struct Candidate {
    pub(super) text: String,
    pub(super) read: Result<GoalAnswer, ReplyError>,
    pub(super) problem: Option<GoalProblem>,
    /// The model's first answer, or that answer with a part taken out.
    pub(super) first: bool,
}

impl Candidate {
    pub(super) fn clean(&self) -> bool {
        self.read.is_ok() && self.problem.is_none()
    }
    pub(super) fn doubtful(&self) -> bool {
        self.read.is_ok() && self.problem.as_ref().is_some_and(GoalProblem::is_doubt)
    }
}

/// What every candidate goal for one request is judged against: the scene, the examples
/// the prompt showed, and the request read once in the scene's words.
pub(super) struct Judge<'a> {
    pub(super) scenario: &'a Scenario,
    pub(super) world: Box<dyn World>,
    pub(super) request: Request<'a>,
    pub(super) shown: Vec<&'a crate::scenario::Example>,
    /// The detectors of plain misreadings in use (all registered ones but in experiments).
    pub(super) misreadings: Vec<&'static dyn Misreading>,
    /// The request is one wish of several: what it asks for may hold already (the robot
    /// is not at the bar now, and "stay away from the bar" beside a delivery still asks
    /// it to stay away), as long as the wishes together ask for a change.
    pub(super) one_of_several: bool,
}

impl<'a> Judge<'a> {
    /// The judge of `request` read in `scenario` from `world`: the examples a prompt
    /// shows for it from the pool `options` give, and the detectors of misreadings in use.
    pub(super) fn new(
        scenario: &'a Scenario,
        world: Box<dyn World>,
        request: Request<'a>,
        options: &'a super::super::types::Options,
        one_of_several: bool,
    ) -> Result<Self, super::super::types::SessionError> {
        let pool = super::example_pool(scenario, options);
        Ok(Judge {
            scenario,
            world,
            shown: options.steps.prompt.choose(pool, request.text),
            request,
            misreadings: crate::reading::misreadings_without(&options.steps.without_misreadings)?,
            one_of_several,
        })
    }
}

impl Judge<'_> {
    /// Why `goal` should not be used, if it should not.
    pub(super) fn assess(&self, goal: &Formula) -> Option<GoalProblem> {
        assess(
            self.scenario,
            self.world.as_ref(),
            goal,
            &self.shown,
            &self.request,
        )
        .filter(|p| !(self.one_of_several && p.kind == ProblemKind::HoldsAlready))
    }

    /// How `goal` has misread the request, if it plainly has: the first finding of the
    /// detectors in use (`reading::misreading`).
    pub(super) fn misread(&self, goal: &Formula) -> Option<String> {
        self.misreadings
            .iter()
            .find_map(|m| m.find(goal, &self.request))
    }

    pub(super) fn vocabulary(&self) -> &crate::domain::Vocabulary {
        &self.scenario.domain.vocabulary
    }

    /// A clean candidate that has not plainly misread the request.
    pub(super) fn answers_request(&self, c: &Candidate) -> bool {
        c.clean()
            && c.read
                .as_ref()
                .is_ok_and(|a| self.misread(&a.goal).is_none())
    }

    /// `goal` with each plain misreading undone that can be, each with what was undone,
    /// in the order the detectors are registered.
    fn undone(&self, goal: &Formula) -> Vec<(Formula, String)> {
        self.misreadings
            .iter()
            .flat_map(|m| m.undo(goal, &self.request))
            .collect()
    }

    /// `goal` with its plain misreadings undone one after another: a goal can misread a
    /// request in more than one way ("deliver milk and dessert to the bar" read as the
    /// dessert made and the robot at the bar: put there, then the milk put beside it), so
    /// each goal undone is undone again, up to [`UNDO_STEPS`] times and [`UNDONE_AT_MOST`]
    /// goals, each with what was undone on the way. Goals that put an object where its
    /// predicate does not take it come out with why, and are not undone further.
    pub(super) fn undone_in_turn(
        &self,
        goal: &Formula,
    ) -> Vec<(Formula, Result<String, VocabularyError>)> {
        let mut out: Vec<(Formula, Result<String, VocabularyError>)> = Vec::new();
        let mut frontier = vec![(goal.clone(), String::new())];
        for _ in 0..UNDO_STEPS {
            let mut next = Vec::new();
            for (from, path) in &frontier {
                let undone = self.undone(from).into_iter().flat_map(|(g, why)| {
                    // What was undone may make a part nothing asks for plain to see.
                    let pruned = without_unasked(&g, &self.request).map(|p| {
                        (
                            p,
                            format!(
                                "{why}; then without the parts no word of the request asks for"
                            ),
                        )
                    });
                    std::iter::once((g, why)).chain(pruned)
                });
                for (g, why) in undone {
                    if g == *goal || out.iter().any(|(seen, _)| *seen == g) {
                        continue;
                    }
                    if out.len() == UNDONE_AT_MOST {
                        return out;
                    }
                    let why = if path.is_empty() {
                        why
                    } else {
                        format!("{path}; then {why}")
                    };
                    match g
                        .atoms()
                        .iter()
                        .try_for_each(|a| self.vocabulary().check_atom(a))
                    {
                        Ok(()) => {
                            next.push((g.clone(), why.clone()));
                            out.push((g, Ok(why)));
                        }
                        Err(e) => out.push((g, Err(e))),
                    }
                }
            }
            frontier = next;
        }
        out
    }

    /// Candidates made from an answer that failed a check: without what it pasted from an
    /// example, or without the parts no word of the request asks for; and, when checks
    /// are on, any answer with its plain misreadings undone ([`Judge::undone`]). Each is
    /// checked like the others.
    pub(super) fn derived(
        &self,
        read: &Result<GoalAnswer, ReplyError>,
        problem: Option<&GoalProblem>,
        check_goals: bool,
        first: bool,
        emit: &mut (dyn FnMut(&Event) + Send),
    ) -> Vec<Candidate> {
        let pruned = match read {
            Ok(a) if problem.is_some() => without_copied(&a.goal, &self.shown, &self.request)
                .or_else(|| without_unasked(&a.goal, &self.request)),
            _ => None,
        };
        // The answer and, when parts were taken out of it, what is left are both undone.
        let mut undone: Vec<(Formula, Result<String, VocabularyError>)> = Vec::new();
        if let Ok(a) = read
            && check_goals
        {
            for from in std::iter::once(&a.goal).chain(pruned.as_ref()) {
                for (goal, why) in self.undone_in_turn(from) {
                    if Some(&goal) != pruned.as_ref() && !undone.iter().any(|(g, _)| *g == goal) {
                        undone.push((goal, why));
                    }
                }
            }
        }
        let mut made = Vec::new();
        for (goal, why) in undone {
            match why {
                Ok(why) => {
                    emit(&Event::Notice {
                        message: format!("{why}, so {goal} is a candidate too"),
                    });
                    made.push(goal);
                }
                // A goal undone may put an object where its predicate does not take it
                // ("fries" put in the place of a made dessert): it is no candidate.
                Err(e) => emit(&Event::CandidateRejected {
                    candidate: goal.to_string(),
                    proposal: None,
                    reason: e.to_string(),
                    author: Some("betr, from the model's answer".into()),
                }),
            }
        }
        let mut out = Vec::new();
        for goal in pruned.into_iter().chain(made) {
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
    pub(super) fn choose(
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

impl Judge<'_> {
    /// The distinct readings among `candidates` (and `others`) that pass every check and
    /// plainly misread nothing, `chosen` first, then by the size of their group of
    /// equivalent candidates, earlier drawn first on a tie; at most `k`. A doubtful or
    /// misread answer is no reading to offer: the judge has reasons against it.
    pub(super) fn readings(
        &self,
        chosen: &Formula,
        candidates: &[Candidate],
        others: &[&Candidate],
        k: usize,
    ) -> Vec<Formula> {
        let eligible: Vec<&GoalAnswer> = candidates
            .iter()
            .chain(others.iter().copied())
            .filter(|c| self.answers_request(c))
            .filter_map(|c| c.read.as_ref().ok())
            .collect();
        let mut groups: Vec<(usize, &Formula)> = Vec::new();
        for a in &eligible {
            if let Some(g) = groups.iter_mut().find(|(_, f)| same_goal(f, &a.goal)) {
                g.0 += 1;
            } else {
                groups.push((1, &a.goal));
            }
        }
        // A stable sort keeps the order drawn among groups of one size.
        groups.sort_by_key(|g| std::cmp::Reverse(g.0));
        let mut out = vec![chosen.clone()];
        for (_, goal) in groups {
            if out.len() == k {
                break;
            }
            if !out.iter().any(|o| same_goal(o, goal)) {
                out.push(goal.clone());
            }
        }
        out
    }
}

/// The answer of the largest group of equivalent candidates that passed the checks; ties
/// go to the group drawn first (the greedy answer, when it passed).
pub(super) fn vote(
    candidates: &[Candidate],
    eligible: impl Fn(&Candidate) -> bool,
) -> Option<GoalAnswer> {
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
    same_goal(&a.goal, &b.goal)
}

/// Two goals that are one: written alike, or true in the same situations.
pub(super) fn same_goal(a: &Formula, b: &Formula) -> bool {
    a == b || goal::equivalent(a, b).unwrap_or(false)
}

#[cfg(test)]
#[path = "judge_tests.rs"]
mod tests;
