//! Recordings of format version 1, which wrote each event as its own record: plain text
//! for conditions, actions, goals and questions, and nodes by their position in the
//! current tree's pre-order (the tree's text keeps that order, so the tree read back from
//! it has the same shape and each position names the same node). Version 2 writes the
//! events themselves; this module reads version 1 into them, so the recordings written
//! then still replay. A version-1 record that cannot stand for an event is refused with
//! its line.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::Deserialize;

use crate::bt::{Forced, NodeId, Outcome, Status, TickRecord, Tree};
use crate::domain::action::parse_value;
use crate::domain::{ActionCall, Atom, Condition};
use crate::goal::Formula;
use crate::llm::usage::UsageTotals;
use crate::session::types::BreakReason;
use crate::session::{Event, Proposal, Question};

use super::{Entry, RecordError};

/// The version this module reads.
pub const VERSION: u32 = 1;

/// One line after the header.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
enum Line {
    Command { ms: u64, command: String },
    Event { ms: u64, event: Recorded },
}

/// A session event as version 1 recorded it.
#[derive(Debug, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
enum Recorded {
    Tree {
        text: String,
        new_nodes: Vec<usize>,
        why: String,
    },
    Tick {
        tick: u64,
        root: char,
        statuses: String,
        visited: Vec<usize>,
        failures: Vec<(usize, String)>,
        completed: Vec<usize>,
        halted: Vec<usize>,
        #[serde(default)]
        forced: Vec<usize>,
    },
    Asking {
        what: String,
    },
    Replied {
        attribution: String,
        prompt_tokens: u64,
        completion_tokens: u64,
        latency_ms: u64,
        text: String,
    },
    InvalidReply {
        error: String,
    },
    CandidateRejected {
        candidate: String,
        reason: String,
        author: Option<String>,
    },
    Goal {
        goal: String,
        reasoning: Option<String>,
        matches_expected: Option<bool>,
        /// Absent in the first recordings: the model.
        #[serde(default = "model_author")]
        author: String,
    },
    ActionFailed {
        action: String,
        node: usize,
        error: String,
    },
    Proposal {
        proposal: RecordedProposal,
        reasoning: Option<String>,
        author: String,
        #[serde(default)]
        evidence: Option<crate::session::Evidence>,
    },
    Approved,
    Rejected,
    Repaired {
        added_nodes: usize,
        valued_nodes: usize,
    },
    DidNotHelp {
        reason: String,
    },
    Success {
        ticks: u64,
    },
    GaveUp {
        reason: String,
    },
    RunState {
        running: bool,
    },
    WorldChanged {
        facts: Vec<String>,
        reset: bool,
    },
    Usage {
        totals: UsageTotals,
    },
    /// A verification's verdict in words (the report was not kept).
    Checked {
        summary: String,
    },
    PolicySaved {
        path: PathBuf,
        fixes: usize,
    },
    PolicyLoaded {
        path: PathBuf,
        fixes: usize,
    },
    Error {
        message: String,
    },
    Forced {
        forced: Vec<(usize, char)>,
    },
    Breakpoints {
        nodes: Vec<usize>,
        on_failure: bool,
    },
    BreakpointHit {
        node: usize,
        tick: u64,
        on_failure: bool,
    },
    /// Plans, rules, notices and exports, in words.
    Note {
        message: String,
    },
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
enum RecordedProposal {
    Conditions {
        action: String,
        node: usize,
        conditions: Vec<String>,
    },
    Value {
        skill: String,
        object: String,
        param: String,
        value: String,
    },
}

fn model_author() -> String {
    "model".into()
}

/// The entries of a version-1 recording's `text` (its header read already); `path` names
/// it in errors. A partial last line is left out and its number returned.
pub fn entries(path: &Path, text: &str) -> Result<crate::store::Lines<Entry>, RecordError> {
    let read = crate::store::read_lines(text, 2, |l| serde_json::from_str::<Line>(l)).map_err(
        |(line, e)| RecordError::Line {
            path: path.to_path_buf(),
            line,
            reason: format!("a version-{VERSION} entry: {e}"),
        },
    )?;
    let mut decoder = Decoder::default();
    let mut out = Vec::with_capacity(read.items.len());
    for (line, entry) in read.items {
        let entry = match entry {
            Line::Command { ms, command } => Entry::Command { ms, command },
            Line::Event { ms, event } => Entry::Event {
                ms,
                event: decoder.decode(&event).map_err(|reason| RecordError::Line {
                    path: path.to_path_buf(),
                    line,
                    reason: format!("a version-{VERSION} entry: {reason}"),
                })?,
            },
        };
        out.push((line, entry));
    }
    Ok(crate::store::Lines {
        items: out,
        cut_at: read.cut_at,
    })
}

/// Why a version-1 record stands for no event.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
struct Refused(String);

fn refused(reason: impl Into<String>) -> Refused {
    Refused(reason.into())
}

/// Follows the recorded trees, to turn pre-order positions into the nodes they name.
#[derive(Default)]
struct Decoder {
    tree: Option<Arc<Tree>>,
    order: Vec<NodeId>,
}

impl Decoder {
    fn node(&self, at: usize) -> Result<NodeId, Refused> {
        self.order.get(at).copied().ok_or_else(|| {
            refused(format!(
                "node {at} is past the end of the tree ({} nodes)",
                self.order.len()
            ))
        })
    }

    fn nodes(&self, at: &[usize]) -> Result<Vec<NodeId>, Refused> {
        at.iter().map(|a| self.node(*a)).collect()
    }

    /// The path of `node` in the current tree, as the events name it besides its id.
    fn path(&self, node: NodeId) -> Vec<usize> {
        self.tree
            .as_ref()
            .and_then(|t| t.path(node).ok())
            .unwrap_or_default()
    }

    fn decode(&mut self, recorded: &Recorded) -> Result<Event, Refused> {
        Ok(match recorded {
            Recorded::Tree {
                text,
                new_nodes,
                why,
            } => self.tree_changed(text, new_nodes, why)?,
            Recorded::Tick { .. } => Event::Ticked {
                record: Arc::new(self.tick(recorded)?),
            },
            Recorded::Asking { what } => Event::Asking {
                what: question(what)?,
            },
            Recorded::Goal {
                goal,
                reasoning,
                matches_expected,
                author,
            } => Event::Goal {
                author: author.clone(),
                goal: Formula::parse(goal)
                    .map_err(|e| refused(format!("the goal {goal:?}: {e}")))?,
                reasoning: reasoning.clone(),
                matches_expected: *matches_expected,
                first_answer: None,
                doubt: None,
            },
            Recorded::ActionFailed {
                action,
                node,
                error,
            } => {
                let node = self.node(*node)?;
                Event::ActionFailed {
                    action: action_call(action)?,
                    node,
                    node_path: self.path(node),
                    error: error.clone(),
                    executor: None,
                }
            }
            Recorded::Proposal {
                proposal,
                reasoning,
                author,
                evidence,
            } => Event::Proposal {
                proposal: self.proposal(proposal)?,
                reasoning: reasoning.clone(),
                author: author.clone(),
                evidence: evidence.clone().map(Box::new),
            },
            Recorded::WorldChanged { facts, reset } => Event::WorldChanged {
                facts: facts
                    .iter()
                    .map(|f| condition(f))
                    .collect::<Result<_, _>>()?,
                reset: *reset,
            },
            Recorded::Forced { forced } => Event::Forced {
                forced: forced
                    .iter()
                    .map(|(at, letter)| Ok((self.node(*at)?, forced_status(*letter)?)))
                    .collect::<Result<_, Refused>>()?,
            },
            Recorded::Breakpoints { nodes, on_failure } => Event::Breakpoints {
                nodes: self.nodes(nodes)?,
                on_failure: *on_failure,
            },
            Recorded::BreakpointHit {
                node,
                tick,
                on_failure,
            } => {
                let node = self.node(*node)?;
                Event::BreakpointHit {
                    node,
                    node_path: self.path(node),
                    tick: *tick,
                    reason: if *on_failure {
                        BreakReason::Failure
                    } else {
                        BreakReason::Breakpoint
                    },
                }
            }
            other => plain(other)?,
        })
    }

    /// A tree as written: it becomes the tree whose pre-order positions name nodes.
    fn tree_changed(
        &mut self,
        text: &str,
        new_nodes: &[usize],
        why: &str,
    ) -> Result<Event, Refused> {
        let tree = crate::bt::parse(text).map_err(|e| refused(format!("the tree: {e}")))?;
        self.order = tree.preorder();
        let tree = Arc::new(tree);
        self.tree = Some(tree.clone());
        Ok(Event::TreeChanged {
            tree,
            new_nodes: self.nodes(new_nodes)?,
            learned: Vec::new(),
            why: why.to_string(),
        })
    }

    fn tick(&self, recorded: &Recorded) -> Result<TickRecord, Refused> {
        let Recorded::Tick {
            tick,
            root,
            statuses,
            visited,
            failures,
            completed,
            halted,
            forced,
        } = recorded
        else {
            return Err(refused("not a tick"));
        };
        let Some(tree) = &self.tree else {
            return Err(refused("a tick before any tree"));
        };
        if statuses.chars().count() != self.order.len() {
            return Err(refused(format!(
                "{} statuses for a tree of {} nodes",
                statuses.chars().count(),
                self.order.len()
            )));
        }
        let mut all = vec![Status::Idle; tree.capacity()];
        for (id, letter) in self.order.iter().zip(statuses.chars()) {
            all[id.index()] = Status::from_letter(letter)
                .ok_or_else(|| refused(format!("{letter:?} is not a status")))?;
        }
        Ok(TickRecord {
            tick: *tick,
            root: match root {
                'R' => Outcome::Running,
                'S' => Outcome::Success,
                'F' => Outcome::Failure,
                other => return Err(refused(format!("{other:?} is not an outcome"))),
            },
            statuses: all,
            visited: self.nodes(visited)?,
            halted: self.nodes(halted)?,
            failures: failures
                .iter()
                .map(|(at, e)| Ok((self.node(*at)?, e.clone())))
                .collect::<Result<_, Refused>>()?,
            completed: self.nodes(completed)?,
            forced: self.nodes(forced)?,
        })
    }

    fn proposal(&self, p: &RecordedProposal) -> Result<Proposal, Refused> {
        Ok(match p {
            RecordedProposal::Conditions {
                action,
                node,
                conditions,
            } => Proposal::Conditions {
                action: action_call(action)?,
                node: self.node(*node)?,
                conditions: conditions
                    .iter()
                    .map(|c| condition(c))
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
                value: parse_value(value)
                    .map_err(|e| refused(format!("the value {value:?}: {e}")))?,
            },
        })
    }
}

/// The events whose record names no node and holds no text to parse.
fn plain(recorded: &Recorded) -> Result<Event, Refused> {
    Ok(match recorded {
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
        Recorded::Success { ticks } => Event::Success {
            ticks: *ticks,
            executor: None,
        },
        Recorded::GaveUp { reason } => Event::GaveUp {
            reason: reason.clone(),
        },
        Recorded::RunState { running } => Event::RunState { running: *running },
        Recorded::Usage { totals } => Event::Usage { totals: *totals },
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
        // Version 1 kept a verification's verdict and the other notes in words only.
        Recorded::Checked { summary: message } | Recorded::Note { message } => Event::Notice {
            message: message.clone(),
        },
        // `Decoder::decode` reads these, which name nodes or hold text to parse.
        Recorded::Tree { .. }
        | Recorded::Tick { .. }
        | Recorded::Asking { .. }
        | Recorded::Goal { .. }
        | Recorded::ActionFailed { .. }
        | Recorded::Proposal { .. }
        | Recorded::WorldChanged { .. }
        | Recorded::Forced { .. }
        | Recorded::Breakpoints { .. }
        | Recorded::BreakpointHit { .. } => {
            return Err(refused("a record that names nodes, read without the tree"));
        }
    })
}

fn action_call(text: &str) -> Result<ActionCall, Refused> {
    ActionCall::parse(text).map_err(|e| refused(format!("the action {text:?}: {e}")))
}

fn condition(text: &str) -> Result<Condition, Refused> {
    Condition::parse(text).map_err(|e| refused(format!("the condition {text:?}: {e}")))
}

fn forced_status(letter: char) -> Result<Forced, Refused> {
    match letter {
        'S' => Ok(Forced::Success),
        'F' => Ok(Forced::Failure),
        'R' => Ok(Forced::Running),
        other => Err(refused(format!("{other:?} is not a forced status"))),
    }
}

/// The question version 1 wrote in words, read back from the words each kind of question
/// was written in (`Question`'s `Display`, which keeps them).
fn question(what: &str) -> Result<Question, Refused> {
    if what == "the goal of the instruction" {
        return Ok(Question::Goal { draw: 0, draws: 1 });
    }
    if what == "the objects and places the instruction names" {
        return Ok(Question::NamedObjects);
    }
    if let Some(rest) = what
        .strip_prefix("another candidate goal (")
        .and_then(|r| r.strip_suffix(')'))
        && let Some((draw, draws)) = rest.split_once(" of ")
        && let (Ok(draw), Ok(draws)) = (draw.parse::<usize>(), draws.parse::<usize>())
        && draw > 0
    {
        return Ok(Question::Goal {
            draw: draw - 1,
            draws,
        });
    }
    if let Some(action) = what
        .strip_prefix("missing preconditions of ")
        .and_then(|r| r.strip_suffix('!'))
    {
        return Ok(Question::Preconditions {
            action: action_call(action)?,
        });
    }
    if let Some((param, action)) = what
        .strip_prefix("a value for ")
        .and_then(|r| r.strip_suffix('!'))
        .and_then(|r| r.split_once(" of "))
    {
        return Ok(Question::Value {
            param: param.to_string(),
            action: action_call(action)?,
        });
    }
    if let Some(atom) = what.strip_prefix("whether the instruction asks for ") {
        return Ok(Question::Confirm {
            atom: Atom::parse(atom).map_err(|e| refused(format!("the atom {atom:?}: {e}")))?,
        });
    }
    Err(refused(format!(
        "the question {what:?} is none that betr asks"
    )))
}
