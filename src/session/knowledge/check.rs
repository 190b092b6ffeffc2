//! Whether a rule may be kept: it fits the skill, contradicts nothing the skill declares,
//! and every goal of the domain — each scenario file beside the domain's base file, each
//! worked example of the pool, planned in the scenario and in the base file — that planned
//! with the rules kept so far still plans with it. Also the rule a fix is offered as.

use std::path::{Path, PathBuf};

use crate::domain::{ActionCall, Condition, LearnError, LearnedRule};
use crate::planner::{Outcome, RepairError};
use crate::scenario::{Scenario, ScenarioError};
use crate::verify::plan_in_model;

use super::{Knowledge, domain_of};

/// Why a rule was not kept.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Refusal {
    #[error("{0}")]
    DoesNotFit(LearnError),
    #[error(
        "it contradicts {skill}'s declared precondition {declared}: the action could never run"
    )]
    ContradictsPrecondition { skill: String, declared: String },
    #[error(
        "it asks for {skill}'s own effect {effect} before the action, which is there to make it true"
    )]
    ContradictsEffect { skill: String, effect: String },
    #[error("with it, {scenario}'s goal {goal} can no longer be planned ({why})")]
    GoalUnplannable {
        scenario: String,
        goal: String,
        why: Box<Unplannable>,
    },
    #[error("it is kept already as {0}")]
    Known(String),
}

/// Why a goal does not plan to success in the model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unplannable {
    #[error(transparent)]
    Planning(#[from] RepairError),
    #[error("{condition} cannot be achieved")]
    Unreachable { condition: Condition },
    #[error("{action}! fails: {error}")]
    ActionFails { action: ActionCall, error: String },
    /// A bound ran out; the planner's reason.
    #[error("{0}")]
    Exhausted(String),
}

/// The rule a fix teaches, as it would be kept: lifted to the action's parameters where
/// the condition names the action's objects, else (nothing to generalise) only for them.
pub fn offered_rule(action: &ActionCall, condition: &Condition, only: bool) -> LearnedRule {
    let lifted = LearnedRule::from_fix(action, condition, false);
    if only || !lifted.generalises() {
        LearnedRule::from_fix(action, condition, true)
    } else {
        lifted
    }
}

/// Whether `rule` may be kept for `scenario`'s domain, given the rules kept already:
/// it fits, contradicts no declaration, and every scenario of the domain still plans.
pub fn check_rule(
    rule: &LearnedRule,
    scenario: &Scenario,
    knowledge: &Knowledge,
) -> Result<(), Refusal> {
    let domain = domain_of(scenario);
    if let Some(same) = knowledge
        .rules_of(&domain)
        .find(|k| k.skill == rule.skill && k.requires == rule.requires && k.only == rule.only)
    {
        return Err(Refusal::Known(same.id.clone()));
    }
    fits_declarations(rule, scenario)?;
    examples_still_plan(rule, scenario, knowledge)?;
    scenarios_still_plan(rule, scenario, knowledge)
}

/// The rule fits the domain and contradicts no precondition or effect its skill declares.
fn fits_declarations(rule: &LearnedRule, scenario: &Scenario) -> Result<(), Refusal> {
    let mut probe = scenario.domain.clone();
    probe.learn(rule).map_err(Refusal::DoesNotFit)?;
    for skill in scenario
        .domain
        .skills
        .iter()
        .filter(|s| s.name == rule.skill)
    {
        let t = rule.template(skill).map_err(Refusal::DoesNotFit)?;
        if let Some(declared) = skill
            .pre
            .iter()
            .find(|p| p.atom == t.atom && p.negated != t.negated)
        {
            return Err(Refusal::ContradictsPrecondition {
                skill: skill.name.clone(),
                declared: template_text(skill, declared),
            });
        }
        if !t.negated && skill.add.contains(&t.atom) {
            return Err(Refusal::ContradictsEffect {
                skill: skill.name.clone(),
                effect: template_text(
                    skill,
                    &crate::domain::skill::LiteralTemplate {
                        atom: t.atom.clone(),
                        negated: false,
                    },
                ),
            });
        }
    }
    Ok(())
}

/// `s` with the rules kept so far: a rule is judged against them, so that only its own
/// effect counts.
fn with_known(knowledge: &Knowledge, s: &Scenario) -> Scenario {
    let mut s = s.clone();
    knowledge.apply(&mut s);
    s
}

/// `s` with the rules kept so far and `rule`, when it fits.
fn with_rule(knowledge: &Knowledge, rule: &LearnedRule, s: &Scenario) -> Option<Scenario> {
    let mut s = with_known(knowledge, s);
    s.domain.learn(rule).ok().map(|()| s)
}

/// The domain's worked examples are goals a person may ask for: every one that plans
/// without the rule still plans with it, in this scenario and in the domain's base file
/// (a scenario may declare its skills differently).
fn examples_still_plan(
    rule: &LearnedRule,
    scenario: &Scenario,
    knowledge: &Knowledge,
) -> Result<(), Refusal> {
    let base = scenario
        .files
        .first()
        .and_then(|f| Scenario::load(&f.path).ok());
    for scene in std::iter::once(scenario).chain(base.as_ref()) {
        let (Some(after), Ok(facts)) = (with_rule(knowledge, rule, scene), facts_of(scene)) else {
            continue;
        };
        let before = with_known(knowledge, scene);
        for example in &scenario.examples {
            let Ok(goal) = scene.parse_goal(&example.goal) else {
                continue;
            };
            if plans(&before, &facts, &goal).is_err() {
                continue;
            }
            if let Err(why) = plans(&after, &facts, &goal) {
                return Err(Refusal::GoalUnplannable {
                    scenario: format!("the worked example {:?}", example.instruction),
                    goal: goal.to_string(),
                    why: Box::new(why),
                });
            }
        }
    }
    Ok(())
}

/// Every scenario of the domain whose goal plans without the rule still plans with it.
fn scenarios_still_plan(
    rule: &LearnedRule,
    scenario: &Scenario,
    knowledge: &Knowledge,
) -> Result<(), Refusal> {
    for (path, other) in domain_scenarios(scenario) {
        let Some(goal) = other.goal.clone() else {
            continue;
        };
        let Ok(facts) = facts_of(&other) else {
            continue;
        };
        // Unplannable without the rule too: not the rule's doing.
        if plans(&with_known(knowledge, &other), &facts, &goal).is_err() {
            continue;
        }
        let Some(after) = with_rule(knowledge, rule, &other) else {
            continue;
        };
        if let Err(why) = plans(&after, &facts, &goal) {
            return Err(Refusal::GoalUnplannable {
                scenario: path.display().to_string(),
                goal: goal.to_string(),
                why: Box::new(why),
            });
        }
    }
    Ok(())
}

/// The facts true in the scenario's world at the start.
fn facts_of(scenario: &Scenario) -> Result<Vec<Condition>, ScenarioError> {
    Ok(crate::world::load(scenario)?.facts())
}

/// Whether `goal` plans to success in the model from `facts`.
fn plans(
    scenario: &Scenario,
    facts: &[Condition],
    goal: &crate::goal::Formula,
) -> Result<(), Unplannable> {
    let planned = plan_in_model(&scenario.domain, facts, &goal.to_dnf(), &[], &[])?;
    match planned.plan.outcome {
        Outcome::Success => Ok(()),
        Outcome::Unreachable { condition, .. } => Err(Unplannable::Unreachable { condition }),
        Outcome::ActionFailed { action, error, .. } => {
            Err(Unplannable::ActionFails { action, error })
        }
        Outcome::Exhausted { reason } => Err(Unplannable::Exhausted(reason)),
    }
}

/// The scenario files of the same domain: every `.toml` under the directory of the
/// domain's base file whose chain starts at the same base file.
pub fn domain_scenarios(scenario: &Scenario) -> Vec<(PathBuf, Scenario)> {
    let Some(base) = scenario.files.first().map(|f| f.path.clone()) else {
        return Vec::new();
    };
    let canonical = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let base_canon = canonical(&base);
    let Some(dir) = base.parent() else {
        return Vec::new();
    };
    let mut files = Vec::new();
    collect_toml(dir, &mut files, 3);
    files.sort();
    files
        .into_iter()
        .filter_map(|p| Scenario::load(&p).ok().map(|s| (p, s)))
        .filter(|(_, s)| {
            s.files
                .first()
                .is_some_and(|f| canonical(&f.path) == base_canon)
        })
        .collect()
}

fn collect_toml(dir: &Path, out: &mut Vec<PathBuf>, depth: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let path = entry.path();
        if path.is_dir() && depth > 0 {
            collect_toml(&path, out, depth - 1);
        } else if path.extension().is_some_and(|e| e == "toml") {
            out.push(path);
        }
    }
}

fn template_text(
    skill: &crate::domain::Skill,
    t: &crate::domain::skill::LiteralTemplate,
) -> String {
    use crate::domain::skill::Term;
    let atom = crate::domain::Atom {
        predicate: t.atom.predicate.clone(),
        args: t
            .atom
            .args
            .iter()
            .map(|a| match a {
                Term::Param(i) => skill
                    .params
                    .get(*i)
                    .map_or_else(|| "?".into(), |p| format!("{{{}}}", p.name)),
                Term::Const(c) => c.clone(),
                Term::Every => "{*}".into(),
            })
            .collect(),
    };
    Condition {
        atom,
        negated: t.negated,
    }
    .to_string()
}

/// The rule to keep for a fix when nobody is asked (`--yes --learn`): the lifted rule, or,
/// when that is refused, the rule for the fix's objects alone; with every refusal on the
/// way (a narrower rule kept after the lifted one was refused says why).
pub fn rule_for_fix(
    action: &ActionCall,
    condition: &Condition,
    scenario: &Scenario,
    knowledge: &Knowledge,
) -> (Option<LearnedRule>, Vec<(LearnedRule, Refusal)>) {
    let lifted = offered_rule(action, condition, false);
    let only = offered_rule(action, condition, true);
    let mut refused: Vec<(LearnedRule, Refusal)> = Vec::new();
    for rule in [lifted, only] {
        if refused.iter().any(|(r, _)| *r == rule) {
            continue;
        }
        match check_rule(&rule, scenario, knowledge) {
            Ok(()) => return (Some(rule), refused),
            Err(e) => refused.push((rule, e)),
        }
    }
    (None, refused)
}
