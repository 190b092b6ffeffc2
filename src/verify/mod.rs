//! Verifying a tree before it runs: the step the BETR-XP-LLM paper names as what makes an
//! LLM-modified policy safe to execute.
//!
//! Two layers. Structural checks (`structural.rs`) are fast rules over the tree's shape
//! and the skills' declarations. Model checking explores every state reachable from the
//! initial state in the planner's own abstraction (`abstraction.rs`: fact sets, declared
//! effects, optionally failing actions and declared disturbances, see `config.rs`) and
//! checks that the tree reaches Success from every reachable state, that every action
//! starts with its declared preconditions true, and the user's temporal properties
//! (`temporal.rs`); a violation comes with a shortest counterexample
//! (`counterexample.rs`). The same model can be exported to Promela (`promela.rs`) so the
//! SPIN model checker can confirm each verdict independently.
//!
//! This module knows nothing of any front end; the CLI and the TUI print its `Report`.

pub mod abstraction;
pub mod config;
pub mod counterexample;
pub mod explore;
pub mod model_plan;
pub mod promela;
pub mod structural;
pub mod temporal;

use std::time::{Duration, Instant};

use crate::bt::Tree;
use crate::bt::path_text;
use crate::domain::{Condition, Domain};

pub use abstraction::{Model, ModelError};
pub use config::{Disturbance, NamedProperty, VerifyConfig};
pub use counterexample::Counterexample;
pub use explore::Limits;
pub use model_plan::{Constraint, ModelPlan, model_world, plan_in_model};
pub use temporal::{Property, PropertyError, Temporal};

/// Which structural rule a finding breaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Rule {
    /// An action's declared precondition is neither checked on its path nor established
    /// by an earlier sibling.
    UnguardedPrecondition,
    /// A node no tick can reach.
    Unreachable,
    /// A condition outside the scenario's vocabulary.
    UnknownAtom,
    /// An action that names no skill of the scenario.
    UnknownAction,
    /// Two Sequence siblings whose actions undo each other's conditions.
    Oscillation,
}

impl Rule {
    pub fn name(self) -> &'static str {
        match self {
            Rule::UnguardedPrecondition => "unguarded-precondition",
            Rule::Unreachable => "unreachable-node",
            Rule::UnknownAtom => "unknown-atom",
            Rule::UnknownAction => "unknown-action",
            Rule::Oscillation => "oscillation",
        }
    }
}

/// One structural problem: where, which rule, what, and how to fix it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Finding {
    pub path: Vec<usize>,
    pub rule: Rule,
    pub message: String,
    pub hint: String,
}

impl Finding {
    /// The finding without where in the tree it is (a change moves nodes): its rule and
    /// message, as [`Report::failures`] lists it.
    pub fn key(&self) -> String {
        format!("[{}] {}", self.rule.name(), self.message)
    }
}

impl std::fmt::Display for Finding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "node {} [{}] {}",
            path_text(&self.path),
            self.rule.name(),
            self.message
        )
    }
}

/// Which property a result is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PropertyKind {
    /// The tree reaches Success from every reachable state within the tick bound.
    Success,
    /// Every action starts with its declared preconditions true.
    Preconditions,
    /// The user property with this index (into `VerifyInput::properties`).
    User(usize),
}

/// The outcome of checking one property.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Verdict {
    Holds,
    Violated(Box<Counterexample>),
    /// The state bound stopped the exploration after `states` states, before the property
    /// could be decided (front ends say how to raise the bound).
    Unknown {
        states: usize,
    },
}

impl Verdict {
    pub fn holds(&self) -> bool {
        matches!(self, Verdict::Holds)
    }
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PropertyResult {
    pub kind: PropertyKind,
    /// How the property reads (`reaches Success from every reachable state`, `never F`).
    pub name: String,
    /// A one-line detail when it holds (e.g. the worst number of ticks).
    pub detail: String,
    pub verdict: Verdict,
}

/// Statistics and results of model checking.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModelCheck {
    pub atoms: usize,
    pub states: usize,
    pub transitions: usize,
    pub complete: bool,
    pub elapsed: Duration,
    pub properties: Vec<PropertyResult>,
}

/// Everything `verify` found.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Report {
    pub findings: Vec<Finding>,
    /// Unguarded-precondition findings that model checking refuted: the tree's shape does
    /// not guard the precondition, but it holds at every start of the action in every
    /// reachable state (an invariant of the reachable states, e.g. one object in the hand
    /// at a time). Shown as warnings; they do not fail verification.
    pub notes: Vec<Finding>,
    /// `Err` when the tree cannot be model checked (an action names no skill).
    pub model: Result<ModelCheck, ModelError>,
}

impl Report {
    /// True when there are no findings and every property holds.
    pub fn holds(&self) -> bool {
        self.findings.is_empty()
            && self
                .model
                .as_ref()
                .is_ok_and(|m| m.properties.iter().all(|p| p.verdict.holds()))
    }

    /// What fails, one line each: a structural finding, a property violated or left
    /// undecided by the state bound, or a tree that could not be model checked.
    pub fn failures(&self) -> Vec<String> {
        let mut out: Vec<String> = self.findings.iter().map(Finding::key).collect();
        match &self.model {
            Err(e) => out.push(format!("not model checked: {e}")),
            Ok(m) => out.extend(
                m.properties
                    .iter()
                    .filter(|p| !p.verdict.holds())
                    .map(|p| p.name.clone()),
            ),
        }
        out
    }

    /// Of this report's failures, those `before` has too: what a changed tree inherits
    /// from the tree it was changed from, not what the change did.
    pub fn failures_shared_with(&self, before: &Report) -> Vec<String> {
        let earlier = before.failures();
        self.failures()
            .into_iter()
            .filter(|f| earlier.contains(f))
            .collect()
    }

    /// Whether `failure` (one of [`Report::failures`]) is a violated property of the
    /// scenario's own, not one of the checks every tree gets.
    pub fn is_declared_property(&self, failure: &str) -> bool {
        self.model.as_ref().is_ok_and(|m| {
            m.properties
                .iter()
                .any(|p| matches!(p.kind, PropertyKind::User(_)) && p.name == failure)
        })
    }

    /// The result for one property kind, if it was checked.
    pub fn property(&self, kind: PropertyKind) -> Option<&PropertyResult> {
        self.model
            .as_ref()
            .ok()?
            .properties
            .iter()
            .find(|p| p.kind == kind)
    }
}

/// What one verification checks: properties and disturbances, within bounds.
#[derive(Debug, Clone)]
pub struct Checks {
    pub properties: Vec<NamedProperty>,
    pub disturbances: Vec<Disturbance>,
    pub limits: Limits,
}

impl Checks {
    /// What the scenario declares, within the default bounds.
    pub fn declared(config: VerifyConfig) -> Checks {
        Checks {
            limits: Limits {
                action_failures: config.action_failures,
                ..Limits::default()
            },
            properties: config.properties,
            disturbances: config.disturbances,
        }
    }

    /// These checks on `tree`, started from `initial`.
    pub fn input<'a>(
        &'a self,
        domain: &'a Domain,
        tree: &'a Tree,
        initial: &'a [Condition],
    ) -> VerifyInput<'a> {
        VerifyInput {
            domain,
            tree,
            initial,
            disturbances: &self.disturbances,
            properties: &self.properties,
            limits: self.limits,
        }
    }
}

/// What to verify and how.
pub struct VerifyInput<'a> {
    pub domain: &'a Domain,
    pub tree: &'a Tree,
    /// The facts true at the start (`World::facts()` of the scenario's world).
    pub initial: &'a [Condition],
    /// Disturbances to explore under (empty: none).
    pub disturbances: &'a [Disturbance],
    pub properties: &'a [NamedProperty],
    pub limits: Limits,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_states: 200_000,
            max_ticks: crate::planner::RunLimits::DEFAULT.run_ticks,
            action_failures: false,
        }
    }
}

/// Run the structural checks and model checking.
pub fn verify(input: &VerifyInput) -> Report {
    let findings = structural::check(input.domain, input.tree);
    let model = build_model(input).map(|m| model_check(&m, input));
    // The structural rules are local and conservative; the exploration is exact over the
    // abstraction. When it proves every action starts with its preconditions true, an
    // unguarded precondition is guarded by reachability, not by the tree's shape; when
    // it proves the tree reaches success from every reachable state, siblings that could
    // undo each other never do so in a state the tree can reach.
    let proves = |kind: PropertyKind| {
        model.as_ref().is_ok_and(|m| {
            m.complete
                && m.properties
                    .iter()
                    .any(|p| p.kind == kind && p.verdict.holds())
        })
    };
    let refuted = |rule: Rule| match rule {
        Rule::UnguardedPrecondition => proves(PropertyKind::Preconditions),
        Rule::Oscillation => proves(PropertyKind::Success),
        _ => false,
    };
    let (notes, findings) = findings.into_iter().partition(|f| refuted(f.rule));
    Report {
        findings,
        notes,
        model,
    }
}

/// Compile the input's tree, disturbances and properties.
pub fn build_model(input: &VerifyInput) -> Result<Model, ModelError> {
    let formulas: Vec<&crate::goal::Formula> = input
        .properties
        .iter()
        .map(|p| &p.property.formula)
        .collect();
    Model::build(
        input.domain,
        input.tree,
        input.initial,
        input.disturbances,
        &formulas,
    )
}

/// Export the input as Promela (see `promela.rs`).
pub fn export_promela(input: &VerifyInput) -> Result<promela::PromelaModel, ModelError> {
    let model = build_model(input)?;
    let temporal: Vec<Temporal> = input
        .properties
        .iter()
        .map(|p| p.property.temporal)
        .collect();
    Ok(promela::export(
        &model,
        &temporal,
        input.limits.action_failures,
    ))
}

/// Explore every state reachable in `model`, then check each property over them.
fn model_check(model: &Model, input: &VerifyInput) -> ModelCheck {
    let started = Instant::now();
    let g = explore::explore(model, &input.limits);
    let explored = Explored { model, g: &g };
    let mut properties = vec![
        explored.success(input.limits.max_ticks),
        explored.preconditions(),
    ];
    properties.extend(
        input
            .properties
            .iter()
            .zip(&model.properties)
            .enumerate()
            .map(|(i, (p, e))| explored.user_property(i, p, e)),
    );
    ModelCheck {
        atoms: model.atoms.len(),
        states: g.states.len(),
        transitions: g.transitions,
        complete: g.complete,
        elapsed: started.elapsed(),
        properties,
    }
}

/// A model with the graph of its reachable states: what each property check reads.
struct Explored<'a> {
    model: &'a Model,
    g: &'a explore::Graph,
}

impl Explored<'_> {
    /// The verdict when the state bound stopped the exploration before it was decided.
    fn unknown(&self) -> Verdict {
        Verdict::Unknown {
            states: self.g.states.len(),
        }
    }

    /// A violation shown along `transitions` from the initial state; from `loop_from` on,
    /// the steps repeat forever.
    fn violated(
        &self,
        transitions: Vec<(u32, explore::Edge)>,
        loop_from: Option<usize>,
        violation: String,
    ) -> Verdict {
        Verdict::Violated(Box::new(Counterexample::build(
            self.model,
            &self.g.states,
            &transitions,
            loop_from,
            violation,
        )))
    }

    /// Whether the tree reaches Success from every reachable state within `max_ticks`.
    fn success(&self, max_ticks: u64) -> PropertyResult {
        use explore::{Edge, Liveness};
        let g = self.g;
        let mut detail = String::new();
        let verdict = match explore::check_liveness(g, max_ticks) {
            Liveness::Holds { worst } => {
                detail = format!("at most {worst} tick(s) from any reachable state");
                Verdict::Holds
            }
            Liveness::DeadEnd(s) => {
                let mut path = g.path_to(s);
                path.push((s, Edge::Tick { fail: 0 }));
                self.violated(
                    path,
                    None,
                    "dead end: the root returns Failure and no action can run".into(),
                )
            }
            Liveness::Livelock { entry, cycle } => {
                let mut path = g.path_to(entry);
                let from = path.len();
                let mut at = entry;
                for next in &cycle {
                    path.push((at, Edge::Tick { fail: 0 }));
                    at = *next;
                }
                self.violated(
                    path,
                    Some(from),
                    format!(
                        "livelock: the tree keeps acting ({} tick(s) repeat) and never succeeds",
                        cycle.len()
                    ),
                )
            }
            Liveness::TooSlow { state, ticks } => self.violated(
                g.path_to(state),
                None,
                format!(
                    "from this state the tree needs {ticks} ticks to succeed, more than the bound of {max_ticks}"
                ),
            ),
            Liveness::Unknown => self.unknown(),
        };
        PropertyResult {
            kind: PropertyKind::Success,
            name: "reaches Success from every reachable state".into(),
            detail,
            verdict,
        }
    }

    /// Whether every action starts with its declared preconditions true.
    fn preconditions(&self) -> PropertyResult {
        let (model, g) = (self.model, self.g);
        let verdict = match g.first_unmet {
            Some((s, fail, action, condition)) => {
                let mut path = g.path_to(s);
                path.push((s, explore::Edge::Tick { fail }));
                self.violated(
                    path,
                    None,
                    format!(
                        "{}! starts while its declared precondition {} does not hold",
                        model.actions[action].call, model.conditions[condition].condition
                    ),
                )
            }
            None if g.complete => Verdict::Holds,
            None => self.unknown(),
        };
        PropertyResult {
            kind: PropertyKind::Preconditions,
            name: "every action starts with its declared preconditions true".into(),
            detail: String::new(),
            verdict,
        }
    }

    /// The user property `index` (`property`, compiled into the model as `expr`).
    fn user_property(
        &self,
        index: usize,
        property: &NamedProperty,
        expr: &abstraction::Expr,
    ) -> PropertyResult {
        use explore::Eventually;
        let (model, g) = (self.model, self.g);
        let f = &property.property.formula;
        let verdict = match property.property.temporal {
            Temporal::Always | Temporal::Never => {
                let always = property.property.temporal == Temporal::Always;
                match explore::first_state_where(model, g, expr, !always) {
                    Some(s) => self.violated(
                        g.path_to(s),
                        None,
                        if always {
                            format!("{f} does not hold in this state")
                        } else {
                            format!("{f} holds in this state")
                        },
                    ),
                    None if g.complete => Verdict::Holds,
                    None => self.unknown(),
                }
            }
            Temporal::Eventually => match explore::check_eventually(model, g, expr) {
                Eventually::Holds => Verdict::Holds,
                Eventually::Unknown => self.unknown(),
                Eventually::Lasso { mut prefix, cycle } => {
                    let from = prefix.len();
                    let len = cycle.len();
                    prefix.extend(cycle);
                    self.violated(
                        prefix,
                        Some(from),
                        format!("{f} never holds: the last {len} step(s) can repeat forever"),
                    )
                }
            },
        };
        PropertyResult {
            kind: PropertyKind::User(index),
            name: property.text.clone(),
            detail: String::new(),
            verdict,
        }
    }
}

#[cfg(test)]
mod tests;
