//! The model asked about the goal it read, one condition at a time.
//!
//! A small model writes a whole formula less well than it answers a narrow question: it
//! turns a condition round ("switch the lights off" read as the lights on) or adds one
//! nobody asked for, and the same model, shown the same prompt and asked about that one
//! condition — must it be true, false, or is it not asked about — often says so. Each
//! question is the goal prompt with another answer format, so a model that keeps the
//! prompt's state pays only for the question. A condition the model says is wanted the
//! other way round is turned; one it says the request does not ask about is taken out
//! when it stands beside others. The goal so changed is kept only when it passes the
//! goal's checks (plannable, not contradictory, not true already), and the goal the model
//! wrote first stays the second reading: where the two steps disagree, the person sees
//! both.

use crate::domain::Atom;
use crate::goal::Formula;
use crate::goal::rewrite::flipped;
use crate::llm::prompt::{CONDITION_VERDICTS, Context};
use crate::llm::{ChatReply, LanguageModel, grammar, schema};
use crate::scenario::Scenario;
use crate::world::World;

use super::ask::ask;
use super::goal_checks::check_goal;
use super::interpret::{Interpretation, MAX_READINGS};
use super::judge::same_goal;
use super::readings::in_words;
use super::types::{Event, Options, SessionError};

/// The most conditions of one goal asked about: a goal longer than this is asked about
/// its first ones, so a long request waits a bounded time.
const MOST_QUESTIONED: usize = 6;

/// What the model answered about one condition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    True,
    False,
    Unasked,
}

/// `found` with each of its goal's conditions asked about (`Ablations::confirm_conditions`,
/// a model held to a grammar), changed where the answers say so and the change passes the
/// checks in `world`; unchanged otherwise.
pub(super) async fn confirmed(
    scenario: &Scenario,
    world: Box<dyn World>,
    instruction: &str,
    mut found: Interpretation,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Interpretation, SessionError> {
    if !(options.ablations.confirm_conditions && options.grammar && model.supports_grammar()) {
        return Ok(found);
    }
    let goal = found.answer.goal.clone();
    let vocabulary = &scenario.domain.vocabulary;
    let facts = world.facts();
    let ctx = Context {
        scenario,
        facts: &facts,
        instruction,
        variant: &options.variant,
    };
    let verdict_grammar = || grammar::one_of_grammar(&CONDITION_VERDICTS);
    let mut opts = options.clone();
    opts.temperature = 0.0;
    // Every verdict scored, so the answer is the one the model finds most likely whole.
    opts.beams = CONDITION_VERDICTS.len() as u32;
    let mut changed = goal.clone();
    let mut said: Vec<String> = Vec::new();
    for (atom, positive) in single_signed(&goal).into_iter().take(MOST_QUESTIONED) {
        let words = in_words(&Formula::Atom(atom.clone()), vocabulary);
        let messages = ctx.condition_question(&options.templates, &atom.to_string(), &words)?;
        emit(&Event::Asking {
            what: crate::session::Question::Confirm { atom: atom.clone() },
        });
        let reply = ask(
            model,
            messages,
            (schema::goal(vocabulary), &verdict_grammar),
            &opts,
            None,
            None,
            emit,
        )
        .await?;
        found.calls += 1;
        match (verdict(&reply), positive) {
            (Some(Verdict::True), false) | (Some(Verdict::False), true) => {
                changed = flipped(&changed, &atom);
                said.push(format!("{atom} is wanted the other way round"));
            }
            (Some(Verdict::Unasked), _) => {
                if let Some(without) = without_conjunct(&changed, &atom) {
                    changed = without;
                    said.push(format!("{atom} is not asked for"));
                }
            }
            _ => {}
        }
    }
    if said.is_empty() || same_goal(&changed, &goal) {
        return Ok(found);
    }
    if let Err(problem) = check_goal(scenario, world.as_ref(), &changed) {
        emit(&Event::Notice {
            message: format!(
                "asked condition by condition, the model reads the request as {changed} ({}), which is not kept: {}",
                said.join("; "),
                problem.reason
            ),
        });
        return Ok(found);
    }
    emit(&Event::Notice {
        message: format!(
            "asked condition by condition, the model reads the request as {changed} ({}); the goal it wrote first, {goal}, is the second reading",
            said.join("; ")
        ),
    });
    let mut readings = vec![changed.clone(), goal];
    for r in std::mem::take(&mut found.readings) {
        if !readings.iter().any(|k| same_goal(k, &r)) {
            readings.push(r);
        }
    }
    readings.truncate(MAX_READINGS);
    found.readings = readings;
    found.answer.goal = changed;
    Ok(found)
}

/// The verdict a reply gives: the most likely of those searched, else its text.
fn verdict(reply: &ChatReply) -> Option<Verdict> {
    let text = reply
        .ranked
        .first()
        .map_or(reply.text.as_str(), |(t, _)| t.as_str());
    match text.trim() {
        t if t == CONDITION_VERDICTS[0] => Some(Verdict::True),
        t if t == CONDITION_VERDICTS[1] => Some(Verdict::False),
        t if t == CONDITION_VERDICTS[2] => Some(Verdict::Unasked),
        _ => None,
    }
}

/// The atoms of `goal`, in the order written, each with whether it stands plain (`true`)
/// or negated; an atom that stands both ways is left out, since turning it round would
/// turn the other one too.
fn single_signed(goal: &Formula) -> Vec<(Atom, bool)> {
    fn walk(f: &Formula, negated: bool, out: &mut Vec<(Atom, bool)>) {
        match f {
            Formula::Atom(a) => out.push((a.clone(), !negated)),
            Formula::Not(inner) => walk(inner, !negated, out),
            Formula::And(items) | Formula::Or(items) => {
                for i in items {
                    walk(i, negated, out);
                }
            }
        }
    }
    let mut all = Vec::new();
    walk(goal, false, &mut all);
    let mut out: Vec<(Atom, bool)> = Vec::new();
    for (atom, positive) in &all {
        let both_ways = all.iter().any(|(a, p)| a == atom && p != positive);
        if !both_ways && !out.iter().any(|(a, _)| a == atom) {
            out.push((atom.clone(), *positive));
        }
    }
    out
}

/// `goal` without `atom` where it is a conjunct of the whole goal beside others; `None`
/// where it is not one (inside an alternative, or the goal alone).
fn without_conjunct(goal: &Formula, atom: &Atom) -> Option<Formula> {
    let Formula::And(items) = goal else {
        return None;
    };
    let is_it = |f: &Formula| match f {
        Formula::Atom(a) => a == atom,
        Formula::Not(inner) => matches!(inner.as_ref(), Formula::Atom(a) if a == atom),
        _ => false,
    };
    if items.len() < 2 || !items.iter().any(is_it) {
        return None;
    }
    Some(Formula::and(
        items.iter().filter(|f| !is_it(f)).cloned().collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Formula {
        Formula::parse(text).expect("test formula")
    }

    #[test]
    fn atoms_standing_both_ways_are_not_asked_about() {
        let goal = parse("A & ~B & (C | ~A)");
        let names: Vec<(String, bool)> = single_signed(&goal)
            .into_iter()
            .map(|(a, p)| (a.to_string(), p))
            .collect();
        assert_eq!(names, vec![("B".into(), false), ("C".into(), true)]);
    }

    #[test]
    fn only_a_conjunct_beside_others_is_taken_out() {
        let b = single_signed(&parse("B")).remove(0).0;
        assert_eq!(
            without_conjunct(&parse("A & ~B & C"), &b),
            Some(parse("A & C"))
        );
        assert_eq!(without_conjunct(&parse("A & (B | C)"), &b), None);
        assert_eq!(without_conjunct(&parse("B"), &b), None);
    }
}
