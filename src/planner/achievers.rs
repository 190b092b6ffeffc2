//! Choosing the skill (and its objects) that achieves a failing condition.
//!
//! Parameters fixed by the condition come from unifying it with the skill's effects; the
//! others are grounded over the objects their types admit. Candidates are ranked by cost,
//! by how many of their preconditions already hold in the simulated state at the failure
//! (a robot that is at the bar puts things down at the bar), and heavily against undoing
//! a condition the tree has already achieved. Ties keep the scenario's declaration order.

use std::collections::HashSet;

use crate::domain::{ANY_OBJECT, Atom, Condition, Domain, GroundSkill};
use crate::world::World;

/// The extra cost of each precondition that does not hold yet.
const UNMET_PRECONDITION_COST: f64 = 10.0;
/// The extra cost of undoing a condition the tree has already achieved.
const UNDO_PROTECTED_COST: f64 = 1000.0;
/// Bound on the groundings tried per skill, so a skill with many free parameters over a
/// large scene stays cheap.
const MAX_GROUNDINGS_PER_SKILL: usize = 4096;

/// A ranked candidate for achieving a condition.
#[derive(Debug, Clone)]
pub struct Candidate {
    pub skill: GroundSkill,
    pub score: f64,
}

/// Objects that make the positive form of a wildcard condition true now: for
/// `~"any object" on "blue cube"` these are the objects lying on the blue cube.
pub fn wildcard_witnesses(
    domain: &Domain,
    world: &dyn World,
    condition: &Condition,
) -> Vec<Condition> {
    let Some(slot) = condition.atom.args.iter().position(|a| a == ANY_OBJECT) else {
        return Vec::new();
    };
    let Some(pred) = domain.vocabulary.predicate(&condition.atom.predicate) else {
        return Vec::new();
    };
    let Some(types) = pred.arg_types.get(slot) else {
        return Vec::new();
    };
    domain
        .vocabulary
        .objects_fitting(types)
        .filter_map(|o| {
            let mut args = condition.atom.args.clone();
            args[slot] = o.to_string();
            let atom = Atom {
                predicate: condition.atom.predicate.clone(),
                args,
            };
            world
                .check(&Condition::pos(atom.clone()))
                .then_some(Condition {
                    atom,
                    negated: condition.negated,
                })
        })
        .collect()
}

/// Every grounded skill whose declared effects make `condition` true, best first.
/// `protected` are conditions the tree has already achieved; `above` are the conditions
/// being achieved by the expansions enclosing this one. A candidate is left out when one
/// of its unmet preconditions can only be achieved through `condition` or `above` (putting
/// down a coffee the robot does not hold, to empty its hand, would first need an empty
/// hand to pick the coffee up).
pub fn rank(
    domain: &Domain,
    world: &dyn World,
    condition: &Condition,
    protected: &[Condition],
    above: &[Condition],
) -> Vec<Candidate> {
    let mut forbidden: Vec<&Condition> = above.iter().collect();
    forbidden.push(condition);
    let mut out: Vec<Candidate> = Vec::new();
    // Grounded skills carry no values yet: a call is its skill and objects.
    let mut seen: HashSet<(String, Vec<String>)> = HashSet::new();
    for ground in groundings(domain, condition) {
        if ground.pre.contains(condition)
            || seen.contains(&(ground.call.skill.clone(), ground.call.args.clone()))
        {
            continue;
        }
        let unmet: Vec<&Condition> = ground.pre.iter().filter(|p| !world.check(p)).collect();
        if unmet
            .iter()
            .any(|p| forbidden.contains(p) || !achievable_now(domain, world, p, &forbidden))
        {
            continue;
        }
        let undone = protected.iter().filter(|p| ground.undoes(p)).count() as f64;
        let score = ground.cost
            + UNMET_PRECONDITION_COST * unmet.len() as f64
            + UNDO_PROTECTED_COST * undone;
        seen.insert((ground.call.skill.clone(), ground.call.args.clone()));
        out.push(Candidate {
            skill: ground,
            score,
        });
    }
    // Stable sort: equal scores keep declaration order.
    out.sort_by(|a, b| a.score.total_cmp(&b.score));
    out
}

/// Whether `condition` can be achieved without any of `forbidden`; a wildcard condition
/// (`~"any object" on X`) through each object that falsifies it now, as expansion does.
fn achievable_now(
    domain: &Domain,
    world: &dyn World,
    condition: &Condition,
    forbidden: &[&Condition],
) -> bool {
    if !condition.atom.has_wildcard() {
        return achievable_without(domain, condition, forbidden);
    }
    let witnesses = wildcard_witnesses(domain, world, condition);
    !witnesses.is_empty()
        && witnesses
            .iter()
            .all(|w| !forbidden.contains(&w) && achievable_without(domain, w, forbidden))
}

/// Whether some skill achieves `condition` without needing any of `forbidden`.
fn achievable_without(domain: &Domain, condition: &Condition, forbidden: &[&Condition]) -> bool {
    groundings(domain, condition).into_iter().any(|g| {
        !g.pre
            .iter()
            .any(|p| p == condition || forbidden.contains(&p))
    })
}

/// Every grounding of every skill whose declared effects make `condition` true.
fn groundings(domain: &Domain, condition: &Condition) -> Vec<GroundSkill> {
    let mut out = Vec::new();
    for skill in &domain.skills {
        for binding in skill.bindings_for(condition) {
            let choices: Vec<Vec<&str>> = skill
                .params
                .iter()
                .zip(&binding)
                .map(|(p, b)| match b {
                    Some(fixed) => vec![fixed.as_str()],
                    None => p.candidates(&domain.vocabulary).collect(),
                })
                .collect();
            // Free parameters were chosen among the objects they admit; only the ones
            // the condition fixed need checking (checking all would look every object
            // up again for every grounding, quadratic in the scene's size).
            let fixed_fit = skill
                .params
                .iter()
                .zip(&binding)
                .all(|(p, b)| b.as_deref().is_none_or(|o| p.admits(&domain.vocabulary, o)));
            if !fixed_fit {
                continue;
            }
            for args in cartesian(&choices, MAX_GROUNDINGS_PER_SKILL) {
                {
                    let ground = skill.ground(&args);
                    if ground.achieves(condition) {
                        out.push(ground);
                    }
                }
            }
        }
    }
    out
}

fn cartesian(choices: &[Vec<&str>], limit: usize) -> Vec<Vec<String>> {
    let mut acc: Vec<Vec<String>> = vec![Vec::new()];
    for options in choices {
        let mut next = Vec::new();
        'outer: for prefix in &acc {
            for o in options {
                if next.len() >= limit {
                    break 'outer;
                }
                let mut v = prefix.clone();
                v.push((*o).to_string());
                next.push(v);
            }
        }
        acc = next;
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cartesian_is_bounded() {
        let a = vec!["x", "y"];
        assert_eq!(cartesian(&[a.clone(), a.clone()], 100).len(), 4);
        assert_eq!(cartesian(&[a.clone(), a], 3).len(), 3);
        assert_eq!(cartesian(&[], 3), vec![Vec::<String>::new()]);
    }
}
