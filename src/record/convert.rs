//! Session events to recorded entries and back. Nodes are named by their position in the
//! tree's pre-order: the tree's text keeps that order, so the tree read back from it has
//! the same shape and each position names the same node.

use std::sync::Arc;

use crate::bt::{Forced, NodeId, Outcome, Status, TickRecord, Tree};
use crate::domain::action::parse_value;
use crate::domain::{ActionCall, Condition};
use crate::scenario::Scenario;
use crate::session::types::BreakReason;
use crate::session::{Event, Proposal};

use super::{RecordError, Recorded, RecordedProposal};

/// The nodes of `tree` in pre-order.
fn preorder(tree: &Tree) -> Vec<NodeId> {
    tree.preorder()
}

fn status_letter(status: Status) -> char {
    match status {
        Status::Idle => '-',
        Status::Running => 'R',
        Status::Success => 'S',
        Status::Failure => 'F',
        Status::Halted => 'H',
    }
}

fn outcome_letter(outcome: Outcome) -> char {
    match outcome {
        Outcome::Running => 'R',
        Outcome::Success => 'S',
        Outcome::Failure => 'F',
    }
}

/// Session events as entries, following the tree they refer to.
#[derive(Default)]
pub struct Encoder {
    /// Pre-order position of each node id of the current tree (by id index).
    position: Vec<Option<usize>>,
    order: Vec<NodeId>,
}

impl Encoder {
    pub fn new() -> Encoder {
        Encoder::default()
    }

    fn at(&self, id: NodeId) -> usize {
        // A node the current tree does not hold is named past its end, so it is read
        // back as no node rather than as another one.
        self.position
            .get(id.index())
            .copied()
            .flatten()
            .unwrap_or(self.order.len())
    }

    fn positions(&self, ids: &[NodeId]) -> Vec<usize> {
        ids.iter().map(|id| self.at(*id)).collect()
    }

    /// The entry for `event` (none for what a replay does not need: 3D scenes).
    pub fn encode(&mut self, event: &Event) -> Option<Recorded> {
        Some(match event {
            Event::TreeChanged {
                tree,
                new_nodes,
                why,
                ..
            } => {
                self.order = preorder(tree);
                self.position = vec![None; tree.capacity()];
                for (i, id) in self.order.iter().enumerate() {
                    if let Some(slot) = self.position.get_mut(id.index()) {
                        *slot = Some(i);
                    }
                }
                Recorded::Tree {
                    text: crate::bt::to_text(tree),
                    new_nodes: self.positions(new_nodes),
                    why: why.clone(),
                }
            }
            Event::Ticked { record } => Recorded::Tick {
                tick: record.tick,
                root: outcome_letter(record.root),
                statuses: self
                    .order
                    .iter()
                    .map(|id| status_letter(record.status(*id)))
                    .collect(),
                visited: self.positions(&record.visited),
                failures: record
                    .failures
                    .iter()
                    .map(|(id, e)| (self.at(*id), e.clone()))
                    .collect(),
                completed: self.positions(&record.completed),
                halted: self.positions(&record.halted),
                forced: self.positions(&record.forced),
            },
            Event::Asking { what } => Recorded::Asking { what: what.clone() },
            Event::Replied {
                attribution,
                prompt_tokens,
                completion_tokens,
                latency_ms,
                text,
            } => Recorded::Replied {
                attribution: attribution.clone(),
                prompt_tokens: *prompt_tokens,
                completion_tokens: *completion_tokens,
                latency_ms: *latency_ms,
                text: text.clone(),
            },
            Event::InvalidReply { error } => Recorded::InvalidReply {
                error: error.clone(),
            },
            Event::CandidateRejected {
                candidate,
                reason,
                author,
                ..
            } => Recorded::CandidateRejected {
                candidate: candidate.clone(),
                reason: reason.clone(),
                author: author.clone(),
            },
            Event::Goal {
                goal,
                reasoning,
                matches_expected,
                author,
            } => Recorded::Goal {
                goal: goal.to_string(),
                reasoning: reasoning.clone(),
                matches_expected: *matches_expected,
                author: author.clone(),
            },
            Event::ActionFailed {
                action,
                node,
                node_path,
                error,
            } => Recorded::ActionFailed {
                action: action.to_string(),
                node: self.at(*node),
                node_path: node_path.clone(),
                error: error.clone(),
            },
            Event::Proposal {
                proposal,
                reasoning,
                author,
                evidence,
            } => Recorded::Proposal {
                proposal: self.proposal(proposal),
                reasoning: reasoning.clone(),
                author: author.clone(),
                evidence: evidence.as_deref().cloned(),
            },
            Event::Approved => Recorded::Approved,
            Event::Rejected => Recorded::Rejected,
            Event::Repaired {
                added_nodes,
                valued_nodes,
            } => Recorded::Repaired {
                added_nodes: *added_nodes,
                valued_nodes: *valued_nodes,
            },
            Event::DidNotHelp { reason } => Recorded::DidNotHelp {
                reason: reason.clone(),
            },
            Event::Success { ticks } => Recorded::Success { ticks: *ticks },
            Event::GaveUp { reason } => Recorded::GaveUp {
                reason: reason.clone(),
            },
            Event::RunState { running } => Recorded::RunState { running: *running },
            Event::WorldChanged { facts, reset } => Recorded::WorldChanged {
                facts: facts.iter().map(ToString::to_string).collect(),
                reset: *reset,
            },
            Event::Usage { totals } => Recorded::Usage { totals: *totals },
            Event::Verified { report, origin } => Recorded::Checked {
                holds: report.holds(),
                summary: format!(
                    "{} ({origin})",
                    if report.holds() {
                        "verified"
                    } else {
                        "NOT verified"
                    }
                ),
            },
            Event::ChangeViolates { .. } => Recorded::Checked {
                holds: false,
                summary: "the changed tree fails verification in the model".into(),
            },
            Event::PolicySaved { path, fixes } => Recorded::PolicySaved {
                path: path.clone(),
                fixes: *fixes,
            },
            Event::PolicyLoaded { path, fixes } => Recorded::PolicyLoaded {
                path: path.clone(),
                fixes: *fixes,
            },
            Event::Error { message } => Recorded::Error {
                message: message.clone(),
            },
            Event::Failed { error } => Recorded::Error {
                message: error.to_string(),
            },
            Event::Notice { message } => Recorded::Note {
                message: message.clone(),
            },
            Event::Readings {
                readings, doubt, ..
            } => Recorded::Note {
                message: crate::session::interpret::readings::summary(readings, doubt.as_deref()),
            },
            Event::Exported { paths } => Recorded::Note {
                message: format!(
                    "exported to {}",
                    paths
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            },
            Event::RuleOffered { rule, .. } => Recorded::Note {
                message: format!("offered as a rule: {rule}"),
            },
            Event::RuleKept { id, rule, .. } => Recorded::Note {
                message: format!("kept as rule {id}: {rule}"),
            },
            Event::RuleRefused { rule, reason } => Recorded::Note {
                message: format!("not kept as a rule: {rule}: {reason}"),
            },
            Event::Forced { forced } => Recorded::Forced {
                forced: forced
                    .iter()
                    .map(|(id, f)| (self.at(*id), outcome_letter(f.outcome())))
                    .collect(),
            },
            Event::Breakpoints { nodes, on_failure } => Recorded::Breakpoints {
                nodes: self.positions(nodes),
                on_failure: *on_failure,
            },
            Event::BreakpointHit {
                node,
                node_path,
                tick,
                reason,
            } => Recorded::BreakpointHit {
                node: self.at(*node),
                node_path: node_path.clone(),
                tick: *tick,
                on_failure: matches!(reason, BreakReason::Failure),
            },
            // The engine's notice says what planning did; scenes and arm motions belong to
            // the simulation, not to the session's record.
            Event::Planned { .. }
            | Event::Verifying { .. }
            | Event::Knowledge { .. }
            | Event::ArmMotion { .. }
            | Event::Scene { .. } => {
                return None;
            }
        })
    }

    fn proposal(&self, proposal: &Proposal) -> RecordedProposal {
        match proposal {
            Proposal::Conditions {
                action,
                node,
                conditions,
            } => RecordedProposal::Conditions {
                action: action.to_string(),
                node: self.at(*node),
                conditions: conditions.iter().map(ToString::to_string).collect(),
            },
            Proposal::Value {
                skill,
                object,
                param,
                value,
            } => RecordedProposal::Value {
                skill: skill.clone(),
                object: object.clone(),
                param: param.clone(),
                value: value.to_string(),
            },
        }
    }
}

/// Recorded entries as session events again, over the recorded scenario.
pub struct Decoder {
    scenario: Arc<Scenario>,
    tree: Option<Arc<Tree>>,
    order: Vec<NodeId>,
}

impl Decoder {
    pub fn new(scenario: Arc<Scenario>) -> Decoder {
        Decoder {
            scenario,
            tree: None,
            order: Vec::new(),
        }
    }

    /// The node at pre-order position `at` of the current tree.
    fn node(&self, at: usize, line: usize) -> Result<NodeId, RecordError> {
        self.order.get(at).copied().ok_or(RecordError::Decode {
            line,
            reason: format!(
                "node {at} is past the end of the tree ({} nodes)",
                self.order.len()
            ),
        })
    }

    fn nodes(&self, at: &[usize], line: usize) -> Result<Vec<NodeId>, RecordError> {
        at.iter().map(|a| self.node(*a, line)).collect()
    }

    /// The event `recorded` stands for (`line`: where it was read, for errors).
    pub fn decode(&mut self, recorded: &Recorded, line: usize) -> Result<Event, RecordError> {
        let bad = |reason: String| RecordError::Decode { line, reason };
        Ok(match recorded {
            Recorded::Tree {
                text,
                new_nodes,
                why,
            } => {
                let tree = crate::bt::parse(text).map_err(|e| bad(format!("the tree: {e}")))?;
                self.order = preorder(&tree);
                let tree = Arc::new(tree);
                self.tree = Some(tree.clone());
                Event::TreeChanged {
                    tree,
                    new_nodes: self.nodes(new_nodes, line)?,
                    learned: Vec::new(),
                    why: why.clone(),
                }
            }
            Recorded::Tick {
                tick,
                root,
                statuses,
                visited,
                failures,
                completed,
                halted,
                forced,
            } => {
                let mut record = self.tick(
                    *tick, *root, statuses, visited, failures, completed, halted, line,
                )?;
                record.forced = self.nodes(forced, line)?;
                Event::Ticked {
                    record: Arc::new(record),
                }
            }
            Recorded::Asking { what } => Event::Asking { what: what.clone() },
            Recorded::Replied {
                attribution,
                prompt_tokens,
                completion_tokens,
                latency_ms,
                text,
            } => Event::Replied {
                attribution: attribution.clone(),
                prompt_tokens: *prompt_tokens,
                completion_tokens: *completion_tokens,
                latency_ms: *latency_ms,
                text: text.clone(),
            },
            Recorded::InvalidReply { error } => Event::InvalidReply {
                error: error.clone(),
            },
            Recorded::CandidateRejected {
                candidate,
                reason,
                author,
            } => Event::CandidateRejected {
                candidate: candidate.clone(),
                proposal: None,
                reason: reason.clone(),
                author: author.clone(),
            },
            Recorded::Goal {
                goal,
                reasoning,
                matches_expected,
                author,
            } => Event::Goal {
                author: author.clone(),
                goal: self
                    .scenario
                    .parse_goal(goal)
                    .map_err(|e| bad(format!("the goal {goal:?}: {e}")))?,
                reasoning: reasoning.clone(),
                matches_expected: *matches_expected,
            },
            Recorded::ActionFailed {
                action,
                node,
                node_path,
                error,
            } => Event::ActionFailed {
                action: ActionCall::parse(action)
                    .map_err(|e| bad(format!("the action {action:?}: {e}")))?,
                node: self.node(*node, line)?,
                node_path: node_path.clone(),
                error: error.clone(),
            },
            Recorded::Proposal {
                proposal,
                reasoning,
                author,
                evidence,
            } => Event::Proposal {
                proposal: self.proposal(proposal, line)?,
                reasoning: reasoning.clone(),
                author: author.clone(),
                evidence: evidence.clone().map(Box::new),
            },
            Recorded::Approved => Event::Approved,
            Recorded::Rejected => Event::Rejected,
            Recorded::Repaired {
                added_nodes,
                valued_nodes,
            } => Event::Repaired {
                added_nodes: *added_nodes,
                valued_nodes: *valued_nodes,
            },
            Recorded::DidNotHelp { reason } => Event::DidNotHelp {
                reason: reason.clone(),
            },
            Recorded::Success { ticks } => Event::Success { ticks: *ticks },
            Recorded::GaveUp { reason } => Event::GaveUp {
                reason: reason.clone(),
            },
            Recorded::RunState { running } => Event::RunState { running: *running },
            Recorded::WorldChanged { facts, reset } => Event::WorldChanged {
                facts: facts
                    .iter()
                    .map(|f| Condition::parse(f).map_err(|e| bad(format!("the fact {f:?}: {e}"))))
                    .collect::<Result<_, _>>()?,
                reset: *reset,
            },
            Recorded::Usage { totals } => Event::Usage { totals: *totals },
            Recorded::Checked { summary, .. } => Event::Notice {
                message: summary.clone(),
            },
            Recorded::PolicySaved { path, fixes } => Event::PolicySaved {
                path: path.clone(),
                fixes: *fixes,
            },
            Recorded::PolicyLoaded { path, fixes } => Event::PolicyLoaded {
                path: path.clone(),
                fixes: *fixes,
            },
            Recorded::Error { message } => Event::Error {
                message: message.clone(),
            },
            Recorded::Note { message } => Event::Notice {
                message: message.clone(),
            },
            Recorded::Forced { forced } => Event::Forced {
                forced: forced
                    .iter()
                    .map(|(at, letter)| {
                        let status = match letter {
                            'S' => Forced::Success,
                            'F' => Forced::Failure,
                            'R' => Forced::Running,
                            other => return Err(bad(format!("{other:?} is not a forced status"))),
                        };
                        Ok((self.node(*at, line)?, status))
                    })
                    .collect::<Result<_, RecordError>>()?,
            },
            Recorded::Breakpoints { nodes, on_failure } => Event::Breakpoints {
                nodes: self.nodes(nodes, line)?,
                on_failure: *on_failure,
            },
            Recorded::BreakpointHit {
                node,
                node_path,
                tick,
                on_failure,
            } => Event::BreakpointHit {
                node: self.node(*node, line)?,
                node_path: node_path.clone(),
                tick: *tick,
                reason: if *on_failure {
                    BreakReason::Failure
                } else {
                    BreakReason::Breakpoint
                },
            },
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn tick(
        &self,
        tick: u64,
        root: char,
        statuses: &str,
        visited: &[usize],
        failures: &[(usize, String)],
        completed: &[usize],
        halted: &[usize],
        line: usize,
    ) -> Result<TickRecord, RecordError> {
        let bad = |reason: String| RecordError::Decode { line, reason };
        let Some(tree) = &self.tree else {
            return Err(bad("a tick before any tree".into()));
        };
        if statuses.chars().count() != self.order.len() {
            return Err(bad(format!(
                "{} statuses for a tree of {} nodes",
                statuses.chars().count(),
                self.order.len()
            )));
        }
        let mut all = vec![Status::Idle; tree.capacity()];
        for (id, letter) in self.order.iter().zip(statuses.chars()) {
            all[id.index()] = match letter {
                '-' => Status::Idle,
                'R' => Status::Running,
                'S' => Status::Success,
                'F' => Status::Failure,
                'H' => Status::Halted,
                other => return Err(bad(format!("{other:?} is not a status"))),
            };
        }
        Ok(TickRecord {
            tick,
            root: match root {
                'R' => Outcome::Running,
                'S' => Outcome::Success,
                'F' => Outcome::Failure,
                other => return Err(bad(format!("{other:?} is not an outcome"))),
            },
            statuses: all,
            visited: self.nodes(visited, line)?,
            halted: self.nodes(halted, line)?,
            failures: failures
                .iter()
                .map(|(at, e)| Ok((self.node(*at, line)?, e.clone())))
                .collect::<Result<_, RecordError>>()?,
            completed: self.nodes(completed, line)?,
            forced: Vec::new(),
        })
    }

    fn proposal(&self, p: &RecordedProposal, line: usize) -> Result<Proposal, RecordError> {
        let bad = |reason: String| RecordError::Decode { line, reason };
        Ok(match p {
            RecordedProposal::Conditions {
                action,
                node,
                conditions,
            } => Proposal::Conditions {
                action: ActionCall::parse(action)
                    .map_err(|e| bad(format!("the action {action:?}: {e}")))?,
                node: self.node(*node, line)?,
                conditions: conditions
                    .iter()
                    .map(|c| {
                        Condition::parse(c).map_err(|e| bad(format!("the condition {c:?}: {e}")))
                    })
                    .collect::<Result<_, _>>()?,
            },
            RecordedProposal::Value {
                skill,
                object,
                param,
                value,
            } => Proposal::Value {
                skill: skill.clone(),
                object: object.clone(),
                param: param.clone(),
                value: parse_value(value).map_err(|e| bad(format!("the value {value:?}: {e}")))?,
            },
        })
    }
}
