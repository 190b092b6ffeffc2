//! The checks a candidate goal passes before it is used, and the ones that only raise a
//! doubt. Wrong: it does not parse, contradicts itself, cannot be planned, offers more
//! alternatives than the request gives, or holds already through an object the request
//! never names. Doubtful: it holds already, or a part of it is pasted from a shown
//! example, or no word of the request asks for a part of it (such parts can be taken out,
//! giving a candidate of its own). Words are matched through the scene's lexicon, on the
//! request as [`Request`] reads it.

use crate::domain::Condition;
use crate::goal::Formula;
use crate::planner::{Outcome, Planner};
use crate::reading::Request;
use crate::reading::names::{
    copied_from_example, guessed_for_unknown, more_alternatives_than_asked, unasked, unnamed_object,
};
use crate::scenario::Scenario;
use crate::world::World;

/// Why a candidate goal cannot be what the person meant, or may not be.
#[derive(Debug, Clone, PartialEq)]
pub struct GoalProblem {
    pub reason: String,
    pub kind: ProblemKind,
}

/// How sure a [`GoalProblem`] is. A doubtful first answer is kept unless the part it
/// pasted can be taken out; a wrong one (unreadable, contradictory, unplannable) never is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProblemKind {
    /// Proven wrong: unreadable, contradictory, unplannable, or not what the words say.
    Wrong,
    /// A doubt: a condition comes from a shown example or no word asks for it (an
    /// indirect request may mean just that).
    Doubt,
    /// A doubt: the goal holds already in the scene (a person may ask for what is true,
    /// and one wish of several may hold while the others do not).
    HoldsAlready,
}

impl GoalProblem {
    pub fn wrong(reason: impl Into<String>) -> Self {
        Self {
            reason: reason.into(),
            kind: ProblemKind::Wrong,
        }
    }

    pub fn doubt(reason: impl Into<String>) -> Self {
        Self {
            reason: reason.into(),
            kind: ProblemKind::Doubt,
        }
    }

    /// A doubt rather than a proof.
    pub fn is_doubt(&self) -> bool {
        self.kind != ProblemKind::Wrong
    }
}

/// Why a goal that is true in the scene now is doubtful.
pub const HOLDS_ALREADY: &str =
    "it holds already in the scene now, but the request asks for a change";

/// Check a candidate goal against the skills and the scene: not contradictory,
/// plannable, and (a doubt) not already true.
pub fn check_goal(
    scenario: &Scenario,
    world: &dyn World,
    goal: &Formula,
) -> Result<(), GoalProblem> {
    let wrong = GoalProblem::wrong;
    let dnf = goal.to_dnf();
    if dnf.is_false() {
        return Err(wrong(
            "it contradicts itself: no situation makes it true".into(),
        ));
    }
    // A negation whose DNF is too large to write out is no tautology betr can show.
    if Formula::Not(Box::new(goal.clone()))
        .to_dnf_within(crate::goal::MAX_ALTERNATIVES)
        .is_ok_and(|d| d.is_false())
    {
        return Err(wrong(
            "it is true in every situation (something and its negation as alternatives), so it asks for nothing".into(),
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
            reason: HOLDS_ALREADY.into(),
            kind: ProblemKind::HoldsAlready,
        });
    }
    Ok(())
}

/// An object of a condition of `goal` that holds now and that no word of the request
/// names: a goal made true already by a place the model chose itself ("bring me a
/// banana" read as the banana on the table it lies on). A goal that holds through what
/// the request does say ("check that the hall light is on") stays a doubt.
fn unsaid_object_holding(goal: &Formula, world: &dyn World, request: &Request) -> Option<String> {
    let holding = goal
        .atoms()
        .into_iter()
        .filter(|a| world.check(&Condition::pos(a.clone())));
    unnamed_object(holding, request)
}

/// Every check of a readable candidate, the wrong ones first.
pub(super) fn assess(
    scenario: &Scenario,
    world: &dyn World,
    goal: &Formula,
    shown: &[&crate::scenario::Example],
    request: &Request,
) -> Option<GoalProblem> {
    let doubt = GoalProblem::doubt;
    match check_goal(scenario, world, goal) {
        Err(p) if !p.is_doubt() => Some(p),
        _ if let Some(reason) = more_alternatives_than_asked(goal, request) => {
            Some(GoalProblem::wrong(reason))
        }
        Err(_) if let Some(object) = unsaid_object_holding(goal, world, request) => {
            Some(GoalProblem::wrong(format!(
                "it holds already in the scene now, through {object}, which the request \
                 never mentions; the request asks for a change"
            )))
        }
        checked => guessed_for_unknown(goal, request)
            .or_else(|| copied_from_example(goal, shown, request))
            .map(doubt)
            .or_else(|| {
                let extra = unasked(goal, request);
                (!extra.is_empty()).then(|| {
                    let parts: Vec<String> = extra.iter().map(ToString::to_string).collect();
                    doubt(format!(
                        "no word of the request asks for {}",
                        parts.join(" or ")
                    ))
                })
            })
            .or(checked.err())
            .or_else(|| {
                // Text that names nothing of the scene (an instruction to the tool rather
                // than the robot, or a request in words the scene does not know) gets a
                // goal only as a doubt a person settles.
                request
                    .lexicon
                    .covered(goal, &request.terms)
                    .is_empty()
                    .then(|| {
                        doubt(format!(
                            "no word of the request names anything {goal} is about"
                        ))
                    })
            }),
    }
}

#[cfg(test)]
#[path = "goal_checks_tests.rs"]
mod tests;
