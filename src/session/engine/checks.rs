//! Verification in the engine. `Verify` checks the tree as it is, except before the first
//! tick of a freshly planned tree, when the whole tree is planned in the planner's model
//! (no simulation, the scenario's safety properties as constraints) and that tree is
//! shown and checked. Every applied change is checked the same way before it can run:
//! while the check is under way the tree is not ticked (a `Run` waits for it), and when
//! the changed tree fails, it does not run until a person approves the change again with
//! the counterexample in view, or undoes it. Automatic approval never approves a change
//! past a failed check.

use std::sync::Arc;

use crate::bt::{Tree, to_text};
use crate::verify::{self, Checks, Limits, Report, VerifyConfig, plan_in_model};

use super::super::planned::Prediction;
use super::super::types::{Event, VerifyRequest, VerifyScope};
use super::Engine;
use super::phase::{AppliedProposal, Phase};
use super::requests::Internal;
use super::task::Origin;

/// Why the Promela model could not be written.
#[derive(Debug, thiserror::Error)]
enum PromelaError {
    #[error("cannot build the Promela model: {0}")]
    Build(#[from] verify::ModelError),
    #[error("cannot write the Promela model to {}: {source}", path.display())]
    Write {
        path: std::path::PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// What a request asks checked: the scenario's properties and disturbances with what the
/// request added or left out, within its bounds.
fn requested(config: VerifyConfig, request: &VerifyRequest) -> Checks {
    let mut checks = Checks::declared(config);
    checks.properties.extend(request.properties.iter().cloned());
    if request.no_disturbances {
        checks.disturbances.clear();
    }
    let defaults = Limits::default();
    checks.limits.max_states = request.max_states.unwrap_or(defaults.max_states);
    checks.limits.max_ticks = request.max_ticks.unwrap_or(defaults.max_ticks);
    checks.limits.action_failures |= request.action_failures;
    checks
}

/// What failed in a report, in one line: the first finding or violated property, with the
/// counterexample's last words.
fn violation_summary(report: &Report, inherited: &[String]) -> String {
    if let Some(f) = report
        .findings
        .iter()
        .find(|f| !inherited.contains(&f.key()))
    {
        return f.to_string();
    }
    let Ok(model) = &report.model else {
        return "it could not be checked".to_string();
    };
    model
        .properties
        .iter()
        .find(|p| !p.verdict.holds() && !inherited.contains(&p.name))
        .map_or_else(
            || "it could not be checked".to_string(),
            |p| match &p.verdict {
                verify::Verdict::Violated(cx) => {
                    format!("{} is violated ({})", p.name, cx.violation)
                }
                other => format!("{}: {other:?}", p.name),
            },
        )
}

impl Engine {
    /// What a change that breaks nothing is told with: what the tree before it fails too,
    /// and, for a property of the scenario's, that it was declared with the scenario's own
    /// goal when the goal worked on is another.
    fn inherited_notice(&self, report: &Report, inherited: &[String]) -> String {
        let declared_goal = self.settings.scenario.goal.as_ref();
        let other_goal = match (declared_goal, &self.task.goal) {
            (Some(declared), Some(goal)) => !crate::goal::equivalent(declared, &goal.formula)
                .unwrap_or(declared == &goal.formula),
            _ => false,
        };
        let described: Vec<String> = inherited
            .iter()
            .map(|failure| {
                if other_goal && report.is_declared_property(failure) {
                    format!("{failure} (declared for the scenario's goal; this goal differs)")
                } else {
                    failure.clone()
                }
            })
            .collect();
        format!(
            "the change breaks nothing: the tree fails verification without it in the same way, \
             not because of it: {}",
            described.join("; ")
        )
    }

    /// Where the current tree came from, for the verification report.
    fn origin(&self) -> String {
        match (&self.task.origin, self.task.fixes.len()) {
            (Origin::File(path), 0) => format!("loaded from {}", path.display()),
            (Origin::File(path), n) => format!("loaded from {} with {n} fix(es)", path.display()),
            (Origin::Model, 0) => "planned in the planner's model".to_string(),
            (Origin::Simulation, 0) => "planned in simulation".to_string(),
            (_, n) => format!("repaired: planned, then changed by {n} approved fix(es)"),
        }
    }

    /// Structural checks and model checking, off the engine's thread.
    pub(super) fn verify(&mut self, request: VerifyRequest) {
        let Some(tree) = self.task.tree.clone() else {
            return self.error("nothing to verify: submit an instruction or plan first");
        };
        let config = match VerifyConfig::from_scenario(&self.settings.scenario) {
            Ok(c) => c,
            Err(e) => return self.error(format!("cannot verify: {e}")),
        };
        let left_out = request.no_disturbances && !config.disturbances.is_empty();
        let checks = requested(config, &request);
        let fresh = self.run.last.is_none()
            && self.task.fixes.is_empty()
            && !matches!(self.task.origin, Origin::File(_));
        let current = tree;
        let mut added = Vec::new();
        let mut planned_note = None;
        let (tree, origin) = match (&self.task.goal, fresh) {
            (Some(goal), true) => {
                let initial = self.run.planning.facts();
                let planned = match plan_in_model(
                    &self.settings.scenario.domain,
                    &initial,
                    &goal.formula.to_dnf(),
                    &checks.properties,
                    &checks.disturbances,
                ) {
                    Ok(p) => p,
                    Err(e) => return self.error(format!("cannot plan in the model: {e}")),
                };
                let prediction = Prediction::of(&planned.plan.outcome, &planned.plan.tree);
                planned_note = (!prediction.is_success()).then_some(prediction);
                added.clone_from(&planned.constraints);
                let guards: Vec<String> = planned
                    .constraints
                    .iter()
                    .map(|c| format!("{}? before {}! ({})", c.condition, c.action, c.property))
                    .collect();
                let mut origin = "planned in the planner's model (no simulation)".to_string();
                if !guards.is_empty() {
                    origin.push_str(&format!("; the properties added {}", guards.join(", ")));
                }
                let tree = planned.plan.tree;
                if to_text(&tree) != to_text(&current) {
                    self.replace_tree(tree.clone(), planned.plan.new_nodes, origin.clone());
                }
                self.task.origin = Origin::Model;
                (tree, origin)
            }
            _ => (current, self.origin()),
        };
        let promela = match &request.promela {
            Some(path) => match self.write_promela(&tree, &checks, path) {
                Ok(claims) => Some((path.clone(), claims)),
                Err(e) => return self.error(e.to_string()),
            },
            None => None,
        };
        self.emit(Event::Verifying {
            scope: Arc::new(VerifyScope {
                nodes: tree.len(),
                added,
                planned: planned_note,
                action_failures: checks.limits.action_failures,
                disturbances: checks.disturbances.len(),
                disturbances_left_out: left_out,
                promela,
            }),
        });
        self.calls.verifications += 1;
        self.notice("verifying the tree …");
        self.spawn_check(tree, None, checks, None, origin);
    }

    /// Write the model `checks` would check as Promela; its LTL claims' names.
    fn write_promela(
        &self,
        tree: &Tree,
        checks: &Checks,
        path: &std::path::Path,
    ) -> Result<Vec<String>, PromelaError> {
        let initial = self.run.planning.facts();
        let domain = &self.settings.scenario.domain;
        let model = verify::export_promela(&checks.input(domain, tree, &initial))?;
        crate::store::write_atomic(path, model.text.as_bytes()).map_err(|source| {
            PromelaError::Write {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Ok(model.claims.into_iter().map(|(name, _)| name).collect())
    }

    /// Check the tree an applied change produced before it may run (`change`: the
    /// proposal applied, told to the model as tried if the change is rejected).
    pub(super) fn check_change(&mut self, change: Option<AppliedProposal>) {
        let Some(tree) = self.task.tree.clone() else {
            return;
        };
        let config = match VerifyConfig::from_scenario(&self.settings.scenario) {
            Ok(c) => c,
            Err(e) => return self.error(format!("cannot verify the change: {e}")),
        };
        let id = self.calls.next_id();
        self.enter(Phase::Checking {
            id,
            run_after: false,
            change,
        });
        self.notice("verifying the changed tree in the model before it runs …");
        let origin = self.origin();
        let checks = requested(config, &VerifyRequest::default());
        // The tree before the change is checked the same way, so that what it fails too is
        // told apart from what the change did.
        let before = self.task.undo.last().map(|entry| entry.tree.clone());
        self.spawn_check(tree, before, checks, Some(id), origin);
    }

    fn spawn_check(
        &self,
        tree: Tree,
        before: Option<Tree>,
        checks: Checks,
        gate: Option<u64>,
        origin: String,
    ) {
        let scenario = self.settings.scenario.clone();
        let initial = self.run.planning.facts();
        let tx = self.internal_tx.clone();
        tokio::task::spawn_blocking(move || {
            let check = |tree: &Tree| {
                Arc::new(verify::verify(&checks.input(
                    &scenario.domain,
                    tree,
                    &initial,
                )))
            };
            let report = check(&tree);
            let before = before.filter(|_| !report.holds()).map(|tree| check(&tree));
            let _ = tx.send(Internal::Verified {
                report,
                origin,
                gate,
                before,
            });
        });
    }

    /// A verification finished: a report for the person, or the verdict on a change.
    pub(super) fn on_verified(
        &mut self,
        report: Arc<Report>,
        origin: String,
        gate: Option<u64>,
        before: Option<Arc<Report>>,
    ) {
        let Some(id) = gate else {
            self.calls.verifications = self.calls.verifications.saturating_sub(1);
            return self.emit(Event::Verified { report, origin });
        };
        let Phase::Checking {
            id: current,
            run_after,
            change,
        } = &self.phase
        else {
            return;
        };
        if id != *current {
            return;
        }
        let (run_after, change) = (*run_after, change.clone());
        let inherited = before
            .map(|before| report.failures_shared_with(&before))
            .unwrap_or_default();
        let caused: Vec<String> = report
            .failures()
            .into_iter()
            .filter(|f| !inherited.contains(f))
            .collect();
        if caused.is_empty() {
            self.enter(Phase::Ready);
            if inherited.is_empty() {
                self.notice("the changed tree verifies in the model");
            } else {
                let message = self.inherited_notice(&report, &inherited);
                self.notice(message);
            }
            if run_after {
                self.start_running();
            }
        } else {
            self.enter(Phase::Violated {
                summary: violation_summary(&report, &inherited),
                change,
            });
            self.emit(Event::ChangeViolates { report, inherited });
            self.notice(
                "the changed tree fails verification: it does not run until the change is approved again with the counterexample in view, rejected (the model is told why), or undone",
            );
        }
    }

    /// A change that failed verification is rejected: undone, and remembered as tried for
    /// its failure with what verification found, so the next question tells the model.
    pub(super) fn reject_violation(&mut self) {
        let Phase::Violated { summary, change } = &self.phase else {
            return self.error("no change fails verification");
        };
        let why = format!(
            "it fixes the failure in simulation, but the changed tree fails verification in the model: {summary}"
        );
        let refused = change.clone();
        self.emit(Event::DidNotHelp {
            reason: why.clone(),
        });
        // Undone first: undoing makes the undone change a candidate again, and this one is
        // refused, so it is remembered as tried after.
        self.undo();
        if let Some(AppliedProposal {
            failure: Some(failure),
            proposal,
        }) = refused
        {
            self.task
                .tried
                .push((failure, super::super::repair::ask::Tried { proposal, why }));
        }
    }

    /// A person approves a change that failed verification, having seen why.
    pub(super) fn approve_violation(&mut self) {
        self.enter(Phase::Ready);
        self.notice(
            "the change was approved again with the counterexample in view: the tree may run",
        );
    }
}
