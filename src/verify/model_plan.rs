//! Planning before execution: the whole tree grown in the planner's own model (the
//! skills' preconditions and effects from the world's first facts, no simulation), with
//! the scenario's safety properties as constraints.
//!
//! A tree that has not run cannot depend on what the world will do, so verification
//! before execution plans where nothing fails unexpectedly. A safety property (`never F`,
//! or `always F` read as `never ~F`) says which states must not be reached; when an
//! action's effects would complete such a state but for one condition it leaves as it
//! was, that condition's negation becomes the action's first precondition, as a repair
//! would insert it. `never "blue cube" grasped & "any object" on "blue cube"` thus makes
//! `~"any object" on "blue cube"` a precondition of `grasp "blue cube"`.
//!
//! Backchaining expands only the conditions that fail on the way to the goal; a condition
//! true from the start is left bare. When a disturbance the scenario declares can make
//! such a condition false, the tree must be able to make it true again, so it is expanded
//! as well: grown once more in a model where that condition does not hold.

use std::collections::HashSet;
use std::sync::Arc;

use super::config::{Disturbance, NamedProperty};
use super::temporal::Temporal;
use crate::bt::NodeKind;
use crate::domain::{ActionCall, Condition, Domain, GroundSkill};
use crate::goal::{Dnf, Formula};
use crate::planner::{Outcome, Plan, Planner, RepairError};
use crate::world::SymbolicWorld;

/// A precondition a safety property asked of an action.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Constraint {
    pub action: ActionCall,
    pub condition: Condition,
    /// The property's text.
    pub property: String,
}

/// A tree planned in the model, with the constraints the properties added to it.
#[derive(Debug, Clone)]
pub struct ModelPlan {
    pub plan: Plan,
    pub constraints: Vec<Constraint>,
}

/// The world of the planner's model: `initial`'s true atoms, changed only by the skills'
/// declared effects.
pub fn model_world(domain: &Domain, initial: &[Condition]) -> SymbolicWorld {
    SymbolicWorld::new(
        Arc::new(domain.clone()),
        initial
            .iter()
            .filter(|c| !c.negated)
            .map(|c| c.atom.clone()),
        Vec::new(),
    )
}

/// Plan `goal` in the model from `initial`; expand the conditions `disturbances` can make
/// false; then give each action the preconditions the safety properties ask of it (each
/// once), expanded like any repair.
pub fn plan_in_model(
    domain: &Domain,
    initial: &[Condition],
    goal: &Dnf,
    properties: &[NamedProperty],
    disturbances: &[Disturbance],
) -> Result<ModelPlan, RepairError> {
    let model = model_world(domain, initial);
    let planner = Planner::new(domain);
    let mut plan = planner.plan(goal, &model)?;
    if !disturbances.is_empty() && plan.outcome == Outcome::Success {
        plan = expand_disturbable(&planner, plan, initial, disturbances, &model);
    }
    let mut constraints = Vec::new();
    let mut asked: HashSet<(String, Condition)> = HashSet::new();
    loop {
        let next = plan.tree.preorder().into_iter().find_map(|id| {
            let Ok(NodeKind::Action(call)) = plan.tree.kind(id) else {
                return None;
            };
            let ground = domain.resolve(call)?;
            let new: Vec<(Condition, String)> = safety_preconditions(&ground, properties)
                .into_iter()
                .filter(|(c, _)| !asked.contains(&(call.to_string(), c.clone())))
                .collect();
            (!new.is_empty()).then(|| (id, call.clone(), new))
        });
        let Some((node, action, new)) = next else {
            break;
        };
        for (c, _) in &new {
            asked.insert((action.to_string(), c.clone()));
        }
        let conditions: Vec<Condition> = new.iter().map(|(c, _)| c.clone()).collect();
        match planner.repair(plan.tree.clone(), node, &conditions, &model) {
            Ok(repaired) => {
                plan = repaired;
                constraints.extend(new.into_iter().map(|(condition, property)| Constraint {
                    action: action.clone(),
                    condition,
                    property,
                }));
            }
            // Already guarded by the plan: nothing to add.
            Err(RepairError::NothingNew(_)) => {}
            Err(e) => return Err(e),
        }
    }
    Ok(ModelPlan { plan, constraints })
}

/// Expand every condition of the tree that a disturbance can make false: grow the tree in
/// a model where the condition does not hold, and keep the growth when the tree then
/// succeeds there and still succeeds from the first state.
fn expand_disturbable(
    planner: &Planner,
    mut plan: Plan,
    initial: &[Condition],
    disturbances: &[Disturbance],
    model: &SymbolicWorld,
) -> Plan {
    let mut tried: HashSet<Condition> = HashSet::new();
    loop {
        let next = plan
            .tree
            .preorder()
            .into_iter()
            .find_map(|id| match plan.tree.kind(id) {
                Ok(NodeKind::Condition(c))
                    if !tried.contains(c) && disturbable(c, disturbances) =>
                {
                    Some(c.clone())
                }
                _ => None,
            });
        let Some(condition) = next else {
            return plan;
        };
        tried.insert(condition.clone());
        let mut facts: Vec<Condition> = initial
            .iter()
            .filter(|f| f.atom != condition.atom)
            .cloned()
            .collect();
        if condition.negated && !condition.atom.has_wildcard() {
            facts.push(Condition::pos(condition.atom.clone()));
        }
        let disturbed = model_world(planner.domain, &facts);
        let grown = planner.grow(plan.tree.clone(), &disturbed);
        if grown.outcome != Outcome::Success || grown.new_nodes.is_empty() {
            continue;
        }
        let again = planner.grow(grown.tree, model);
        if again.outcome == Outcome::Success {
            let mut new_nodes = plan.new_nodes;
            new_nodes.extend(grown.new_nodes);
            new_nodes.extend(again.new_nodes);
            plan = Plan {
                tree: again.tree,
                new_nodes,
                expansions: plan.expansions + grown.expansions + again.expansions,
                ..again
            };
        }
    }
}

/// Whether some disturbance can make `c` false: it deletes atoms of `c`'s predicate
/// (for a positive `c`) or adds them (for a negated one). Matching by predicate may
/// expand a condition no disturbance reaches, which costs nodes but never correctness.
fn disturbable(c: &Condition, disturbances: &[Disturbance]) -> bool {
    disturbances.iter().any(|d| {
        let templates = if c.negated { &d.add } else { &d.del };
        templates.iter().any(|t| t.predicate == c.atom.predicate)
    })
}

/// The preconditions that keep `action` from completing into a state a safety property
/// forbids, each with the property's text: for every forbidden conjunction that the
/// action's effects make true in part, without undoing any of it, and that leaves exactly
/// one condition as it was, the negation of that condition.
pub fn safety_preconditions(
    action: &GroundSkill,
    properties: &[NamedProperty],
) -> Vec<(Condition, String)> {
    let mut out: Vec<(Condition, String)> = Vec::new();
    for p in properties {
        let forbidden = match p.property.temporal {
            Temporal::Never => p.property.formula.clone(),
            Temporal::Always => Formula::Not(Box::new(p.property.formula.clone())),
            Temporal::Eventually => continue,
        };
        for term in forbidden.to_dnf().0 {
            if term.iter().any(|l| action.undoes(l)) || !term.iter().any(|l| action.achieves(l)) {
                continue;
            }
            let left: Vec<&Condition> = term.iter().filter(|l| !action.achieves(l)).collect();
            if let [only] = left.as_slice() {
                let needed = only.negate();
                if !out.iter().any(|(c, _)| *c == needed) {
                    out.push((needed, p.text.clone()));
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::scenario::Scenario;
    use crate::verify::VerifyConfig;

    fn load(rel: &str) -> (Scenario, VerifyConfig) {
        let s = Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).expect("scenario");
        let config = VerifyConfig::from_scenario(&s).expect("verify table");
        (s, config)
    }

    /// The scenario's goal planned in the model from its world's first facts.
    fn planned(s: &Scenario, config: &VerifyConfig) -> ModelPlan {
        let world = crate::world::load(s).expect("world");
        let goal = s.goal.clone().expect("goal").to_dnf();
        plan_in_model(
            &s.domain,
            &world.facts(),
            &goal,
            &config.properties,
            &config.disturbances,
        )
        .expect("plan")
    }

    #[test]
    fn a_never_property_becomes_the_precondition_it_implies() {
        let (s, config) = load("scenarios/cell/red_on_blue.toml");
        let grasp = s
            .domain
            .resolve(&ActionCall::new("grasp", ["blue cube"]))
            .expect("grasp");
        let pre = safety_preconditions(&grasp, &config.properties);
        assert_eq!(pre.len(), 1);
        assert_eq!(pre[0].0.to_string(), "~\"any object\" on \"blue cube\"");
        // Grasping another cube completes no forbidden state.
        let other = s
            .domain
            .resolve(&ActionCall::new("grasp", ["red cube"]))
            .expect("grasp");
        assert!(safety_preconditions(&other, &config.properties).is_empty());
    }

    #[test]
    fn the_model_plan_carries_the_constraint_and_no_world_is_asked() {
        let (s, config) = load("scenarios/cell/red_on_blue.toml");
        let planned = planned(&s, &config);
        assert_eq!(planned.constraints.len(), 1, "{:?}", planned.constraints);
        assert_eq!(
            planned.constraints[0].action.to_string(),
            "grasp \"blue cube\""
        );
        let text = crate::bt::to_text(&planned.plan.tree);
        assert!(text.contains("~\"any object\" on \"blue cube\"?"), "{text}");
        assert!(text.contains("grasp \"red cube\"!"), "{text}");
        assert!(matches!(
            planned.plan.outcome,
            crate::planner::Outcome::Success
        ));
    }

    #[test]
    fn sweeping_needs_the_mop_and_an_always_property_reads_as_never_its_negation() {
        let (s, config) = load("scenarios/cafe/sweep.toml");
        let planned = planned(&s, &config);
        let found: Vec<String> = planned
            .constraints
            .iter()
            .map(|c| format!("{} before {}", c.condition, c.action))
            .collect();
        assert_eq!(found, ["Holding_Mop before Sweep \"Floor\""]);

        // `always Holding_Nothing | Holding_Chips`: picking up anything but the chips
        // would break it; picking up the chips makes it hold.
        let (fries, config) = load("scenarios/cafe/find_fries.toml");
        let chips = fries
            .domain
            .resolve(&ActionCall::new("PickUp", ["Chips"]))
            .expect("PickUp");
        assert!(safety_preconditions(&chips, &config.properties).is_empty());
        let coffee = fries
            .domain
            .resolve(&ActionCall::new("PickUp", ["Coffee"]))
            .expect("PickUp");
        let pre = safety_preconditions(&coffee, &config.properties);
        assert_eq!(pre.len(), 1, "{pre:?}");
        assert_eq!(pre[0].0.to_string(), "Holding_Chips");
    }
}
