//! A world of facts: skills apply their declared effects after their number of ticks, and
//! hidden rules — requirements the skills do not declare — make an action fail with its
//! error text, or finish without its effect.
//!
//! Scenario syntax (`[world]` table, merged base first when a scenario `extends` another):
//!
//! ```toml
//! [world]
//! kind = "symbolic"
//! initial = ["Holding_Nothing", "RobotNear_Bar2", "On_Chips_Bar"]
//! set = ["RobotNear_Bar2"]     # applied after `initial` (a child changing its base's state)
//! unset = ["RobotNear_Bar"]
//!
//! [[world.rules]]
//! action = 'MoveTo "Coffee"'   # a skill name alone matches every use of the skill
//! requires = "Exists_Coffee"   # a goal formula that must hold when the action starts
//! error = "Coffee not found"   # what the skill reports when it does not
//! # otherwise = "no effect"    # instead: the action completes without its effects
//! ```

use std::collections::{BTreeSet, HashMap};
use std::sync::Arc;

use serde::Deserialize;
use toml::Spanned;

use super::{Snapshot, Step, World, WorldError};
use crate::domain::names::{MIN_SIMILARITY, did_you_mean, nearest};
use crate::domain::{ANY_OBJECT, ActionCall, Atom, Condition, Domain, Vocabulary};
use crate::goal::Formula;
use crate::scenario::{Scenario, ScenarioError, SourceFile};

/// What happens when a rule's requirement does not hold.
#[derive(Debug, Clone, PartialEq)]
pub enum Violation {
    /// The action fails at its first tick with this error text.
    Fail(String),
    /// The action runs to completion but changes nothing.
    NoEffect,
}

/// A requirement of the world that the planner's skill model may not know.
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    pub skill: String,
    /// `None`: every use of the skill.
    pub args: Option<Vec<String>>,
    pub requires: Formula,
    pub violation: Violation,
}

#[derive(Debug, Clone, PartialEq)]
struct State {
    facts: BTreeSet<Atom>,
    /// Ticks done so far by each running action (keyed by its text).
    progress: HashMap<String, u32>,
}

#[derive(Clone)]
pub struct SymbolicWorld {
    domain: Arc<Domain>,
    rules: Arc<Vec<Rule>>,
    state: State,
}

#[derive(Deserialize)]
struct WorldTable {
    world: Option<RawWorld>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorld {
    #[allow(dead_code)]
    kind: Option<String>,
    initial: Option<Vec<Spanned<String>>>,
    #[serde(default)]
    set: Vec<Spanned<String>>,
    #[serde(default)]
    unset: Vec<Spanned<String>>,
    #[serde(default)]
    rules: Vec<RawRule>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRule {
    action: Spanned<String>,
    requires: Spanned<String>,
    error: Option<String>,
    otherwise: Option<Spanned<String>>,
}

/// A fact of a `[world]` table: a plain atom of the vocabulary.
fn read_fact(
    file: &SourceFile,
    vocabulary: &Vocabulary,
    f: &Spanned<String>,
) -> Result<Atom, ScenarioError> {
    let c = Condition::parse(f.get_ref()).map_err(|e| {
        file.error_in_string(
            &f.span(),
            e.at,
            format!("expected {}, found {}", e.expected, e.found),
        )
    })?;
    if c.negated || c.atom.has_wildcard() {
        return Err(file.error_in_string(
            &f.span(),
            0,
            "facts are plain atoms: no `~`, no \"any object\" (unlisted atoms are false)",
        ));
    }
    vocabulary
        .check_atom(&c.atom)
        .map_err(|e| file.error_in_string(&f.span(), 0, e.to_string()))?;
    Ok(c.atom)
}

impl RawRule {
    /// The rule as the world keeps it, checked against the scenario.
    fn read(self, scenario: &Scenario, file: &SourceFile) -> Result<Rule, ScenarioError> {
        let action = self.action(scenario, file)?;
        let requires = scenario
            .parse_goal(self.requires.get_ref())
            .map_err(|e| file.error_in_string(&self.requires.span(), e.at(), e))?;
        let violation = self.violation(file)?;
        Ok(Rule {
            skill: action.skill,
            args: (!action.args.is_empty()).then_some(action.args),
            requires,
            violation,
        })
    }

    /// The action the rule is on: a skill of the scenario, on objects its scene has.
    fn action(&self, scenario: &Scenario, file: &SourceFile) -> Result<ActionCall, ScenarioError> {
        let vocabulary = &scenario.domain.vocabulary;
        let action = ActionCall::parse(self.action.get_ref()).map_err(|e| {
            file.error_in_string(
                &self.action.span(),
                e.at,
                format!("expected {}, found {}", e.expected, e.found),
            )
        })?;
        if !scenario
            .domain
            .skills
            .iter()
            .any(|s| s.name == action.skill)
        {
            return Err(file.error_in_string(
                &self.action.span(),
                0,
                format!("no skill named {:?} in this scenario", action.skill),
            ));
        }
        // A rule on an object the scene lacks would never fire.
        if let Some(missing) = action.args.iter().find(|a| vocabulary.object(a).is_none()) {
            let text = self.action.get_ref();
            let at = text
                .find(&format!("\"{missing}\""))
                .map(|i| i + 1)
                .or_else(|| text.find(missing.as_str()))
                .unwrap_or(0);
            let listed = vocabulary.objects.iter().map(|o| o.name.as_str());
            let near = nearest(missing, listed, MIN_SIMILARITY);
            return Err(file.error_in_string(
                &self.action.span(),
                at,
                format!(
                    "no object named {missing:?} in this scenario{}",
                    did_you_mean(&near)
                ),
            ));
        }
        Ok(action)
    }

    /// What happens when the requirement does not hold: `otherwise` is "fail" (the
    /// default, with `error` the text the skill reports) or "no effect".
    fn violation(self, file: &SourceFile) -> Result<Violation, ScenarioError> {
        match self.otherwise.as_ref().map(|o| o.get_ref().as_str()) {
            None | Some("fail") => match self.error {
                Some(e) if !e.trim().is_empty() => Ok(Violation::Fail(e)),
                _ => Err(file.error_in_string(
                    &self.action.span(),
                    0,
                    "a failing rule needs `error`, the text the skill reports",
                )),
            },
            Some("no effect") => Ok(Violation::NoEffect),
            Some(other) => {
                let span = self
                    .otherwise
                    .as_ref()
                    .map(Spanned::span)
                    .unwrap_or_default();
                Err(file.error_in_string(
                    &span,
                    0,
                    format!("expected \"fail\" or \"no effect\", found {other:?}"),
                ))
            }
        }
    }
}

impl Rule {
    fn applies_to(&self, action: &ActionCall) -> bool {
        self.skill == action.skill && self.args.as_ref().is_none_or(|a| *a == action.args)
    }
}

impl SymbolicWorld {
    /// This world without its hidden rules: the scenario's model of it.
    pub fn without_rules(mut self) -> Self {
        self.rules = Arc::new(Vec::new());
        self
    }

    pub fn new(
        domain: Arc<Domain>,
        initial: impl IntoIterator<Item = Atom>,
        rules: Vec<Rule>,
    ) -> Self {
        SymbolicWorld {
            domain,
            rules: Arc::new(rules),
            state: State {
                facts: initial.into_iter().collect(),
                progress: HashMap::new(),
            },
        }
    }

    /// Read the `[world]` tables of a scenario's files: the last `initial` list wins, rules
    /// accumulate from base to child.
    pub fn from_scenario(scenario: &Scenario) -> Result<Self, ScenarioError> {
        let vocabulary = &scenario.domain.vocabulary;
        let mut initial = BTreeSet::new();
        let mut rules = Vec::new();
        for file in &scenario.files {
            let table: WorldTable = file.parse()?;
            let Some(world) = table.world else { continue };
            let fact = |f: &Spanned<String>| read_fact(file, vocabulary, f);
            if let Some(facts) = &world.initial {
                initial = facts.iter().map(fact).collect::<Result<_, _>>()?;
            }
            for f in &world.unset {
                initial.remove(&fact(f)?);
            }
            for f in &world.set {
                initial.insert(fact(f)?);
            }
            for r in world.rules {
                rules.push(r.read(scenario, file)?);
            }
        }
        Ok(SymbolicWorld::new(
            Arc::new(scenario.domain.clone()),
            initial,
            rules,
        ))
    }

    fn holds(&self, atom: &Atom) -> bool {
        if atom.has_wildcard() {
            self.state.facts.iter().any(|f| {
                f.predicate == atom.predicate
                    && f.args.len() == atom.args.len()
                    && f.args
                        .iter()
                        .zip(&atom.args)
                        .all(|(x, y)| y == ANY_OBJECT || x == y)
            })
        } else {
            self.state.facts.contains(atom)
        }
    }

    fn violated(&self, action: &ActionCall) -> Option<&Rule> {
        self.rules
            .iter()
            .find(|r| r.applies_to(action) && !r.requires.eval(&|a: &Atom| self.holds(a)))
    }
}

impl World for SymbolicWorld {
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn kind(&self) -> &'static str {
        "symbolic"
    }

    fn check(&self, condition: &Condition) -> bool {
        self.holds(&condition.atom) != condition.negated
    }

    fn step(&mut self, action: &ActionCall, started: bool) -> Step {
        let Some(ground) = self.domain.resolve(action) else {
            return Step::Failure(format!("Unknown action {action}"));
        };
        let key = action.to_string();
        if started || !self.state.progress.contains_key(&key) {
            if let Some(unmet) = ground.pre.iter().find(|c| !self.check(c)) {
                return Step::Failure(format!("Precondition {unmet} of {action} not met"));
            }
            if let Some(Violation::Fail(error)) = self.violated(action).map(|r| &r.violation) {
                return Step::Failure(error.clone());
            }
            self.state.progress.insert(key.clone(), 0);
        }
        let done = self.state.progress.entry(key.clone()).or_insert(0);
        *done += 1;
        if *done < ground.ticks {
            return Step::Running;
        }
        self.state.progress.remove(&key);
        if matches!(
            self.violated(action).map(|r| &r.violation),
            Some(Violation::NoEffect)
        ) {
            return Step::Success;
        }
        self.state
            .facts
            .retain(|f| !ground.del.iter().any(|d| d.matches(f)));
        self.state.facts.extend(ground.add.iter().cloned());
        Step::Success
    }

    fn halt(&mut self, action: &ActionCall) {
        self.state.progress.remove(&action.to_string());
    }

    fn fork(&self) -> Box<dyn World> {
        Box::new(self.clone())
    }

    fn snapshot(&self) -> Snapshot {
        Snapshot::new(self.state.clone())
    }

    fn restore(&mut self, snapshot: &Snapshot) -> Result<(), WorldError> {
        let state = snapshot.get::<State>().ok_or(WorldError::ForeignSnapshot)?;
        self.state = state.clone();
        Ok(())
    }

    fn facts(&self) -> Vec<Condition> {
        self.state
            .facts
            .iter()
            .cloned()
            .map(Condition::pos)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::scenario::Scenario;

    const TEXT: &str = r#"
[scenario]
name = "t"
[objects]
item = ["Cup", "Mop"]
nothing = ["Nothing"]
furniture = ["Floor"]
[[predicates]]
name = "Holding"
args = ["item|nothing"]
description = "holds"
[[predicates]]
name = "IsClean"
args = ["furniture"]
description = "clean"
[[skills]]
name = "Grab"
params = ["i: item"]
pre = ["Holding_Nothing"]
add = ["Holding_{i}"]
del = ["Holding_Nothing"]
ticks = 3
[[skills]]
name = "Sweep"
params = ["f: furniture"]
add = ["IsClean_{f}"]
[world]
initial = ["Holding_Nothing"]
[[world.rules]]
action = 'Grab "Cup"'
requires = "~IsClean_Floor"
error = "Cup is stuck"
[[world.rules]]
action = "Sweep"
requires = "Holding_Mop"
otherwise = "no effect"
"#;

    fn world() -> SymbolicWorld {
        let s = Scenario::from_text(Path::new("t.toml"), TEXT).unwrap();
        SymbolicWorld::from_scenario(&s).unwrap()
    }

    fn c(text: &str) -> Condition {
        Condition::parse(text).unwrap()
    }

    #[test]
    fn actions_take_their_ticks_then_apply_effects() {
        let mut w = world();
        let grab = ActionCall::new("Grab", ["Mop"]);
        assert_eq!(w.step(&grab, true), Step::Running);
        assert_eq!(w.step(&grab, false), Step::Running);
        assert!(w.check(&c("Holding_Nothing")));
        assert_eq!(w.step(&grab, false), Step::Success);
        assert!(w.check(&c("Holding_Mop")) && w.check(&c("~Holding_Nothing")));
    }

    #[test]
    fn halting_restarts_the_count_and_forks_are_independent() {
        let mut w = world();
        let grab = ActionCall::new("Grab", ["Mop"]);
        let fork = w.fork();
        let snap = w.snapshot();
        w.step(&grab, true);
        w.step(&grab, false);
        w.halt(&grab);
        assert_eq!(w.step(&grab, true), Step::Running);
        w.step(&grab, false);
        assert_eq!(w.step(&grab, false), Step::Success);
        assert!(fork.check(&c("Holding_Nothing")));
        w.restore(&snap).unwrap();
        assert!(w.check(&c("Holding_Nothing")));
        assert_eq!(
            w.restore(&Snapshot::new(5u8)),
            Err(WorldError::ForeignSnapshot)
        );
    }

    #[test]
    fn hidden_rules_fail_with_their_text_or_remove_the_effect() {
        let mut w = world();
        let sweep = ActionCall::new("Sweep", ["Floor"]);
        assert_eq!(w.step(&sweep, true), Step::Success);
        assert!(w.check(&c("~IsClean_Floor")), "no mop, no effect");
        let mut w2 = world();
        w2.state.facts.insert(Atom::parse("IsClean_Floor").unwrap());
        assert_eq!(
            w2.step(&ActionCall::new("Grab", ["Cup"]), true),
            Step::Failure("Cup is stuck".into())
        );
    }

    #[test]
    fn undeclared_preconditions_and_unknown_actions_fail() {
        let mut w = world();
        w.state.facts.clear();
        assert_eq!(
            w.step(&ActionCall::new("Grab", ["Mop"]), true),
            Step::Failure("Precondition Holding_Nothing of Grab \"Mop\" not met".into())
        );
        assert!(
            matches!(w.step(&ActionCall::new("Fly", ["Mop"]), true), Step::Failure(e) if e.starts_with("Unknown action"))
        );
    }
}
