//! Changes to the tree: approving, rejecting and editing proposals, setting values. A
//! change is kept only when it helps (the failure is gone or has moved on); every kept
//! change can be undone, and the execution world starts afresh after each attempt so the
//! changed tree runs from the scenario's first state.

use crate::bt::Tree;
use crate::domain::{ActionCall, Condition, Value, ValueParam};
use crate::planner::Planner;

use super::super::policy::{Approval, now_rfc3339};
use super::super::repair::ask::{Tried, missing_value};
use super::super::repair::edit::Edit;
use super::super::repair::screen::{apply, helped};
use super::super::repair::values::{self, Setting, conform};
use super::super::types::{Event, Evidence, Proposal};
use super::Engine;
use super::phase::{AppliedProposal, Failure, Pending, Phase};
use super::task::AppliedFix;

/// Why what a person wrote does not fit the proposal it is for; each names the edit as
/// written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum Refused {
    #[error("no conditions for {action}")]
    NoConditions { action: ActionCall },
    #[error("'{edit}': {reason}")]
    Vocabulary {
        edit: String,
        reason: crate::domain::VocabularyError,
    },
    #[error("'{shown}': {reason}")]
    Value { shown: String, reason: Unfit },
    #[error("'{edit}': {action} calls for conditions ('A & ~B'), not a value")]
    ValueForConditions { edit: String, action: ActionCall },
    #[error("'{edit}': {skill} calls for a value of {param}, not conditions")]
    ConditionsForValue {
        edit: String,
        skill: String,
        param: String,
    },
}

/// Why a value does not fit the parameter it is for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum Unfit {
    #[error("{skill} declares no value {param}")]
    Undeclared { skill: String, param: String },
    #[error(transparent)]
    Conform(#[from] super::super::repair::values::ConformError),
}

/// What the model is told of a proposal a person rejected.
pub(super) const REJECTED: &str = "rejected by a person";

impl Engine {
    /// Take the pending proposal out of the phase; the failure it was for, if any, stays.
    fn take_pending(&mut self) -> Option<Pending> {
        let Phase::Proposed(pending) = &self.phase else {
            return None;
        };
        let pending = pending.clone();
        self.phase = match &pending.failure {
            Some(failure) => Phase::Failed {
                failure: failure.clone(),
            },
            None => self.settled(),
        };
        Some(pending)
    }

    /// Drop the pending proposal; the model is asked again with it told as rejected.
    pub(super) fn reject(&mut self) {
        let Some(pending) = self.take_pending() else {
            return self.error("no proposal to reject");
        };
        self.emit(Event::Rejected);
        let Some(failure) = pending.failure else {
            return;
        };
        // The model is asked again with what the person rejected told to it as tried (and
        // left out of the conditions it may choose from), a few times; then the person
        // types the fix.
        self.task.tried.push((
            failure.clone(),
            Tried {
                proposal: pending.proposal,
                why: REJECTED.to_string(),
            },
        ));
        let rejected = self
            .task
            .tried
            .iter()
            .filter(|(f, t)| *f == failure && t.why == REJECTED)
            .count();
        if rejected > self.settings.options.max_rejections || self.settings.model.is_err() {
            return self.wait_for_person(failure, format!("{rejected} proposal(s) rejected"));
        }
        self.ask_about(failure);
    }

    /// Apply the pending proposal; keep it only if it helps.
    pub(super) fn apply_pending(&mut self, approval: Approval) {
        let Some(pending) = self.take_pending() else {
            return;
        };
        let Some(tree) = self.task.tree.clone() else {
            return self.error("no tree to change");
        };
        self.emit(Event::Approved);
        let planner = Planner::new(&self.settings.scenario.domain);
        let before = pending.failure.clone();
        let result = apply(
            &planner,
            &tree,
            &pending.proposal,
            self.run.planning.as_ref(),
        );
        let (plan, valued_nodes) = match result {
            Ok(r) => r,
            Err(e) => return self.did_not_help(&pending, &tree, before.as_ref(), e.to_string()),
        };
        if let Err(reason) = helped(before.as_ref(), &plan.outcome) {
            return self.did_not_help(&pending, &tree, before.as_ref(), reason.to_string());
        }
        self.emit(Event::Repaired {
            added_nodes: plan.new_nodes.len(),
            valued_nodes,
        });
        self.task.push_undo(tree, Some(pending.proposal.clone()));
        let change = pending.proposal.to_string();
        self.task.fixes.push(AppliedFix {
            change: change.clone(),
            nodes: plan.new_nodes.clone(),
            author: pending.author.clone(),
            approval,
            at: now_rfc3339(),
        });
        let why = format!("{} ({})", change, approval_text(approval));
        self.set_tree(plan.tree, plan.new_nodes, why);
        self.check_change(Some(AppliedProposal {
            failure: before,
            proposal: pending.proposal.clone(),
        }));
        self.offer_rules(&pending.proposal, &pending.author);
    }

    /// A change that did not fix the failure: remember it for the next question about the
    /// same failure, and when it named several conditions, look in simulation (no model
    /// call) for a part of it that does fix the failure and offer that as a new proposal.
    fn did_not_help(
        &mut self,
        pending: &Pending,
        tree: &Tree,
        before: Option<&Failure>,
        reason: String,
    ) {
        if let Some(f) = before {
            self.task.tried.push((
                f.clone(),
                Tried {
                    proposal: pending.proposal.clone(),
                    why: reason.clone(),
                },
            ));
        }
        self.emit(Event::DidNotHelp { reason });
        let planner = Planner::new(&self.settings.scenario.domain);
        match narrowed(
            &planner,
            tree,
            &pending.proposal,
            before,
            self.run.planning.as_ref(),
        ) {
            Some((proposal, dropped)) => {
                let dropped: Vec<String> = dropped.iter().map(ToString::to_string).collect();
                let author = format!("simulation, narrowed from {}", pending.author);
                let mut findings: Vec<String> = before
                    .map(|f| format!("{}! failed: {}", f.action, f.error))
                    .into_iter()
                    .collect();
                findings.push(format!(
                    "{} was approved and did not fix the failure in the execution world",
                    pending.proposal
                ));
                findings.push(format!(
                    "in simulation, it works without {}: only the rest fixes the failure",
                    dropped.join(" & ")
                ));
                self.emit(Event::Proposal {
                    proposal: proposal.clone(),
                    reasoning: None,
                    author: author.clone(),
                    evidence: Some(Box::new(Evidence {
                        findings,
                        objects: before.map(|f| f.action.args.clone()).unwrap_or_default(),
                        doubt: None,
                    })),
                });
                self.enter(Phase::Proposed(Pending {
                    proposal,
                    author,
                    failure: before.cloned(),
                }));
                if self.settings.auto_approve {
                    self.apply_pending(Approval::Auto);
                } else {
                    self.reset_world(false);
                }
            }
            None => self.reset_world(false),
        }
    }

    /// What a person wrote for the pending proposal (or the current failure), read by the
    /// front end: checked against what is pending and the vocabulary, then applied. On an
    /// error nothing changes.
    pub(super) fn edit(&mut self, edit: Edit) {
        let base = match &self.phase {
            Phase::Proposed(p) => Some((p.proposal.clone(), p.failure.clone())),
            phase => phase
                .failure()
                .and_then(|f| self.blank_proposal(f).map(|p| (p, Some(f.clone())))),
        };
        let Some((base, failure)) = base else {
            return self.error("nothing to edit: no action has failed and nothing is proposed");
        };
        let edited = match self.edited(&base, edit) {
            Ok(p) => p,
            Err(e) => return self.error(e.to_string()),
        };
        self.emit(Event::Proposal {
            proposal: edited.clone(),
            reasoning: None,
            author: "a person".into(),
            evidence: None,
        });
        // What the person wrote answers the failure: a question still out about it is
        // dropped.
        self.enter(Phase::Proposed(Pending {
            proposal: edited,
            author: "a person".into(),
            failure,
        }));
        self.apply_pending(Approval::Edited);
    }

    /// The kind of proposal a failure calls for, with nothing filled in.
    fn blank_proposal(&self, f: &Failure) -> Option<Proposal> {
        Some(
            match missing_value(&self.settings.scenario, &f.action, &f.error) {
                Some(param) => Proposal::Value {
                    skill: f.action.skill.clone(),
                    object: f.action.args.first().cloned().unwrap_or_default(),
                    param: param.name.clone(),
                    value: crate::domain::Value::Category(String::new()),
                },
                None => Proposal::Conditions {
                    action: f.action.clone(),
                    node: f.node,
                    conditions: Vec::new(),
                },
            },
        )
    }

    /// `base` with the edit in it: conditions for an action, a value for a parameter.
    fn edited(&self, base: &Proposal, edit: Edit) -> Result<Proposal, Refused> {
        match (base, edit) {
            (Proposal::Conditions { action, node, .. }, Edit::Conditions(conditions)) => {
                // The front end read them over the same vocabulary; a sender that did not
                // is refused here.
                if conditions.is_empty() {
                    return Err(Refused::NoConditions {
                        action: action.clone(),
                    });
                }
                for c in &conditions {
                    self.settings
                        .scenario
                        .domain
                        .vocabulary
                        .check_atom(&c.atom)
                        .map_err(|reason| Refused::Vocabulary {
                            edit: Edit::Conditions(conditions.clone()).to_string(),
                            reason,
                        })?;
                }
                Ok(Proposal::Conditions {
                    action: action.clone(),
                    node: *node,
                    conditions,
                })
            }
            (
                Proposal::Value {
                    skill,
                    object,
                    param,
                    ..
                },
                Edit::Value(value),
            ) => {
                let shown = value_text(&value);
                let value = self
                    .fit_value(skill, param, value)
                    .map_err(|reason| Refused::Value { shown, reason })?;
                Ok(Proposal::Value {
                    skill: skill.clone(),
                    object: object.clone(),
                    param: param.clone(),
                    value,
                })
            }
            (Proposal::Conditions { action, .. }, edit @ Edit::Value(_)) => {
                Err(Refused::ValueForConditions {
                    edit: edit.to_string(),
                    action: action.clone(),
                })
            }
            (Proposal::Value { skill, param, .. }, edit @ Edit::Conditions(_)) => {
                Err(Refused::ConditionsForValue {
                    edit: edit.to_string(),
                    skill: skill.clone(),
                    param: param.clone(),
                })
            }
        }
    }

    /// `value` as `skill` declares its parameter `param`.
    fn fit_value(&self, skill: &str, param: &str, value: Value) -> Result<Value, Unfit> {
        let declared = self
            .declared_value(skill, param)
            .ok_or_else(|| Unfit::Undeclared {
                skill: skill.to_string(),
                param: param.to_string(),
            })?;
        Ok(conform(declared, value)?)
    }

    /// The declaration of `skill`'s value `param`.
    fn declared_value(&self, skill: &str, param: &str) -> Option<&ValueParam> {
        self.settings
            .scenario
            .domain
            .skills
            .iter()
            .find(|s| s.name == skill)
            .and_then(|s| s.values.iter().find(|v| v.name == param))
    }

    /// `force of egg = 5 N`, read by the front end: checked against the skills' declared
    /// values, set on every action that uses it, then re-plan.
    pub(super) fn set_value(&mut self, setting: &Setting) {
        let Some(tree) = self.task.tree.clone() else {
            return self.error("no tree: plan first");
        };
        for (skill, param) in &setting.targets {
            if let Err(e) = self.fit_value(skill, param, setting.value.clone()) {
                return self.error(format!("{:?}: {e}", setting.text));
            }
        }
        let mut changed = tree.clone();
        let valued = values::apply(&mut changed, setting);
        if valued == 0 {
            return self.error(format!(
                "{:?}: no action of the tree uses that value with {:?}",
                setting.text, setting.object
            ));
        }
        let plan =
            Planner::new(&self.settings.scenario.domain).grow(changed, self.run.planning.as_ref());
        self.emit(Event::Repaired {
            added_nodes: plan.new_nodes.len(),
            valued_nodes: valued,
        });
        self.task.push_undo(tree, None);
        let change = format!("set {} ({valued} action(s))", setting.text);
        self.task.fixes.push(AppliedFix {
            change: change.clone(),
            nodes: plan.new_nodes.clone(),
            author: "a person".into(),
            approval: Approval::Edited,
            at: now_rfc3339(),
        });
        self.set_tree(plan.tree, plan.new_nodes, change);
        self.check_change(None);
    }
}

impl Engine {
    /// Conditions a person inserts by name: before `before`, or as the first
    /// preconditions of the action that failed. Made as written, whether or not it fixes
    /// the failure: the next run shows what it did.
    pub(super) fn insert(
        &mut self,
        conditions: &[Condition],
        before: Option<&ActionCall>,
        author: String,
    ) {
        let Some(tree) = self.task.tree.clone() else {
            return self.error("no tree: plan first");
        };
        if conditions.is_empty() {
            return self.error("nothing to insert: no condition given");
        }
        let names = conditions
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(" & ");
        let planner = Planner::new(&self.settings.scenario.domain);
        let planning = self.run.planning.as_ref();
        let started = std::time::Instant::now();
        let (result, change) = match (before, self.phase.failure()) {
            (Some(action), _) => (
                planner.repair_at(tree.clone(), action, conditions, planning),
                format!("insert {names} before {action}!"),
            ),
            (None, Some(failure)) => (
                planner.repair(tree.clone(), failure.node, conditions, planning),
                format!(
                    "insert {names} as the first precondition(s) of {}!",
                    failure.action
                ),
            ),
            (None, None) => {
                return self.error(format!(
                    "nowhere to insert {names}: no action has failed (run the tree first, or name the action to insert it before)"
                ));
            }
        };
        let plan = match result {
            Ok(plan) => plan,
            Err(e) => return self.error(format!("cannot insert {names}: {e}")),
        };
        self.planned(&plan, started.elapsed());
        self.emit(Event::Repaired {
            added_nodes: plan.new_nodes.len(),
            valued_nodes: 0,
        });
        self.task.push_undo(tree, None);
        self.task.fixes.push(AppliedFix {
            change: change.clone(),
            nodes: plan.new_nodes.clone(),
            author,
            approval: Approval::Edited,
            at: now_rfc3339(),
        });
        self.drop_offers();
        self.set_tree(plan.tree, plan.new_nodes, change);
        self.check_change(None);
    }
}

/// A value as a person would type it (a category without its quotes).
fn value_text(value: &Value) -> String {
    match value {
        Value::Category(c) => c.clone(),
        number => number.to_string(),
    }
}

fn approval_text(approval: Approval) -> &'static str {
    match approval {
        Approval::Person => "approved",
        Approval::Auto => "auto-approved",
        Approval::Edited => "written by a person",
    }
}

/// The largest part of a multi-condition proposal that fixes the failure in simulation,
/// and the conditions it leaves out.
fn narrowed(
    planner: &Planner,
    tree: &Tree,
    proposal: &Proposal,
    before: Option<&Failure>,
    world: &dyn crate::world::World,
) -> Option<(Proposal, Vec<crate::domain::Condition>)> {
    let Proposal::Conditions {
        action,
        node,
        conditions,
    } = proposal
    else {
        return None;
    };
    // Proposals hold a few conditions (the grammar allows two); larger ones are not split.
    let n = conditions.len();
    if !(2..=4).contains(&n) {
        return None;
    }
    for size in (1..n).rev() {
        for mask in 1u32..(1 << n) {
            if mask.count_ones() as usize != size {
                continue;
            }
            let (kept, dropped): (Vec<_>, Vec<_>) = conditions
                .iter()
                .enumerate()
                .partition(|(i, _)| mask & (1 << i) != 0);
            let kept: Vec<_> = kept.into_iter().map(|(_, c)| c.clone()).collect();
            let Ok(plan) = planner.repair(tree.clone(), *node, &kept, world) else {
                continue;
            };
            if helped(before, &plan.outcome).is_ok() {
                let candidate = Proposal::Conditions {
                    action: action.clone(),
                    node: *node,
                    conditions: kept,
                };
                return Some((
                    candidate,
                    dropped.into_iter().map(|(_, c)| c.clone()).collect(),
                ));
            }
        }
    }
    None
}
