//! Judging the candidate goals of one reading: the checks each passes or fails, the plain
//! misreadings of the request and the candidates made by undoing them, and the vote.
//!
//! Plain misreadings: a number the request says left out ("table six" read as table 1);
//! a condition the other way round from the request's words ("do not open the curtain"
//! read as open); an item the request sends to a place with no condition relating them
//! ("a dessert at the bar" read as a dessert made and the robot at the bar); one of two
//! things named side by side left out ("fries or a dessert" read as the dessert); a
//! measure in the place of what it holds ("a glass of water" read as the glass); an
//! object nobody named in the place of one the request names ("fries" read as coffee).

use crate::domain::VocabularyError;
use crate::goal::{self, Formula};
use crate::llm::lexicon::Lexicon;
use crate::llm::reply::{GoalAnswer, ReplyError};
use crate::scenario::Scenario;
use crate::world::World;

use super::goal_checks::{
    GoalProblem, ProblemKind, assess, renumbered, swapped_back, swapped_object, unanswered_names,
    without_copied, without_unasked,
};
use super::placement::{moved_there, not_put, put_there};
use super::polarity::{left_unanswered, turned_around, turned_back, with_unanswered};
use super::relation_words::{convention_followed, relation_as_said};
use super::side_by_side::{left_out, measure_for_content, with_content, with_left_out};
use super::types::Event;

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
/// the prompt showed, the words of the vocabulary and the place numbers the request says.
pub(super) struct Judge<'a> {
    pub(super) scenario: &'a Scenario,
    pub(super) world: Box<dyn World>,
    pub(super) instruction: &'a str,
    pub(super) shown: Vec<&'a crate::scenario::Example>,
    pub(super) lexicon: Lexicon,
    pub(super) place_numbers: Vec<String>,
    /// The request is one wish of several: what it asks for may hold already (the robot
    /// is not at the bar now, and "stay away from the bar" beside a delivery still asks
    /// it to stay away), as long as the wishes together ask for a change.
    pub(super) one_of_several: bool,
}

impl Judge<'_> {
    /// Why `goal` should not be used, if it should not.
    pub(super) fn assess(&self, goal: &Formula) -> Option<GoalProblem> {
        assess(
            self.scenario,
            self.world.as_ref(),
            goal,
            (&self.shown, &self.lexicon),
            self.instruction,
        )
        .filter(|p| !(self.one_of_several && p.kind == ProblemKind::HoldsAlready))
    }

    /// The place numbers the request says that no condition of `goal` is about.
    pub(super) fn missing_numbers(&self, goal: &Formula) -> Vec<String> {
        unanswered_names(goal, self.instruction, &self.lexicon)
            .into_iter()
            .filter(|w| self.place_numbers.contains(w))
            .collect()
    }

    /// How `goal` has misread the request, if it plainly has: it leaves out a number the
    /// request says ("table six" read as table 1), asks for a condition the other way round
    /// from the request's words ("do not open the curtain" read as open), or puts an object
    /// nobody named in the place of one the request names ("fries" read as coffee).
    pub(super) fn misread(&self, goal: &Formula) -> Option<String> {
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
        if let Some((atom, wanted, word)) =
            left_unanswered(goal, self.instruction, self.vocabulary())
        {
            let asked = if wanted {
                atom.to_string()
            } else {
                format!("~{atom}")
            };
            return Some(format!(
                "the request says \"{word}\", which asks for {asked}, and {goal} has no condition about it"
            ));
        }
        if let Some((said, word)) = relation_as_said(goal, self.instruction, self.vocabulary()) {
            return Some(format!(
                "the request says \"{word}\" before the place, which asks for {said}, not {goal}"
            ));
        }
        if let Some((put, word)) = convention_followed(goal, self.instruction, self.scenario) {
            return Some(format!(
                "the request says \"{word}\", which here asks for {put}, not {goal}"
            ));
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

    /// `goal` with each plain misreading undone that can be, each with what was undone:
    /// the place renumbered when the request numbers another one of its kind ("table six"
    /// read as Table1), a swapped object put back, conditions asked the other way round
    /// turned, items sent to a place put there, a thing left out put beside the one named
    /// with it, a measure replaced by what it holds.
    fn undone(&self, goal: &Formula) -> Vec<(Formula, String)> {
        let (request, vocabulary) = (self.instruction, self.vocabulary());
        let mut out = Vec::new();
        if let Some((g, from, to)) = renumbered(goal, &self.missing_numbers(goal), vocabulary) {
            out.push((
                g,
                format!("the request numbers a place the answer does not: {to} is the only one like {from} with that number"),
            ));
        }
        if let Some((g, from, to)) = swapped_back(goal, request, &self.lexicon, vocabulary) {
            out.push((
                g,
                format!("the request names {to} where the answer has {from}, which it never names"),
            ));
        }
        if let Some(why) = turned_around(goal, request, vocabulary)
            && let Some(g) = turned_back(goal, request, vocabulary)
        {
            out.push((g, why.to_string()));
        }
        if let Some(g) = with_unanswered(goal, request, vocabulary) {
            out.push((
                g,
                format!("the request asks in its own words for a condition {goal} leaves out"),
            ));
        }
        if let Some((g, word)) = relation_as_said(goal, request, vocabulary) {
            out.push((
                g,
                format!("the request says \"{word}\" before the place, which {goal} reads as another relation"),
            ));
        }
        if let Some((g, word)) = convention_followed(goal, request, self.scenario) {
            out.push((
                g,
                format!("the request says \"{word}\", which by this scene's conventions asks for where {goal} does not put it"),
            ));
        }
        if let Some(g) = put_there(goal, request, vocabulary) {
            out.push((
                g,
                format!("the request sends an item to a place that {goal} only has apart"),
            ));
        }
        if let Some(g) = moved_there(goal, request, vocabulary) {
            out.push((
                g,
                format!("the request sends an item to a place that {goal} has it at another place, which the request never names"),
            ));
        }
        if let Some(g) = with_left_out(goal, request, vocabulary) {
            out.push((
                g,
                format!("the request names things side by side that {goal} has only one of"),
            ));
        }
        if let Some(g) = with_content(goal, request, vocabulary) {
            out.push((
                g,
                format!("the request names a measure of something that {goal} has in its place"),
            ));
        }
        out
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
                    let pruned = without_unasked(&g, self.instruction, &self.lexicon).map(|p| {
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
            Ok(a) if problem.is_some() => without_copied(&a.goal, &self.shown, self.instruction)
                .or_else(|| without_unasked(&a.goal, self.instruction, &self.lexicon)),
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
    a.goal == b.goal || goal::equivalent(&a.goal, &b.goal).unwrap_or(false)
}

#[cfg(test)]
#[path = "judge_tests.rs"]
mod tests;
