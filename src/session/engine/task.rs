//! The task: the goal worked on and the instruction it came from, the tree, where it came
//! from, the changes applied to it (each undoable), and what was tried for its failures.

use std::path::PathBuf;

use crate::bt::{NodeId, Tree};
use crate::goal::Formula;
use crate::session::policy::Approval;
use crate::session::repair::ask::Tried;
use crate::session::types::{FixCounts, Proposal};

use super::phase::Failure;

/// The goal being worked on, and the instruction it came from.
#[derive(Debug, Clone)]
pub(super) struct Goal {
    pub(super) formula: Formula,
    pub(super) instruction: Option<String>,
}

/// Where the tree came from, for the verification report.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) enum Origin {
    /// Grown by the planner ticking it in simulation.
    #[default]
    Simulation,
    /// Planned in the planner's model (by `Verify` before the first tick).
    Model,
    /// Loaded from a tree file.
    File(PathBuf),
}

/// A change that is in the tree, for the policy header.
#[derive(Debug, Clone)]
pub(super) struct AppliedFix {
    pub(super) change: String,
    /// The nodes it added (ids are stable; a later change may remove some).
    pub(super) nodes: Vec<NodeId>,
    pub(super) author: String,
    pub(super) approval: Approval,
    pub(super) at: String,
}

/// The tree before an applied change.
#[derive(Debug, Clone)]
pub(super) struct UndoEntry {
    pub(super) tree: Tree,
    pub(super) fixes: usize,
    /// The change this entry undoes, when it was a proposal: undone, it is a candidate
    /// for its failure again, whatever was said of it before.
    pub(super) proposal: Option<Proposal>,
}

#[derive(Debug, Clone, Default)]
pub(super) struct Task {
    /// None until an instruction, a goal or the scenario's goal is worked on (a tree file
    /// that names no goal may be loaded without one).
    pub(super) goal: Option<Goal>,
    pub(super) tree: Option<Tree>,
    pub(super) origin: Origin,
    pub(super) undo: Vec<UndoEntry>,
    pub(super) fixes: Vec<AppliedFix>,
    /// Changes tried for a failure that did not fix it, told to the model when it is asked
    /// about the same failure again.
    pub(super) tried: Vec<(Failure, Tried)>,
    /// Questions asked about failures of this tree.
    pub(super) rounds: usize,
    /// How many of `fixes` a saved policy holds (the first ones).
    pub(super) saved: usize,
    /// The counts the front end was last told (`Event::FixCounts`).
    pub(super) told: FixCounts,
    /// The instruction and the model's reading of it, while the goal worked on is that
    /// reading and nothing has run: a goal typed now corrects it.
    pub(super) reading: Option<(String, Formula)>,
}

impl Task {
    /// Start the history afresh for a tree that does not grow out of the current one (a
    /// plan, a load): nothing applied, nothing tried, no round asked.
    pub(super) fn restart(&mut self, origin: Origin) {
        self.origin = origin;
        self.rounds = 0;
        self.tried.clear();
        self.undo.clear();
        self.fixes.clear();
        self.saved = 0;
    }

    /// The fixes refused for the goal's failures, and those applied that no saved policy
    /// holds.
    pub(super) fn counts(&self) -> FixCounts {
        FixCounts {
            refused: self.tried.len(),
            unsaved: self.fixes.len().saturating_sub(self.saved),
        }
    }

    /// Record the tree before a change, to undo it.
    pub(super) fn push_undo(&mut self, tree: Tree, proposal: Option<Proposal>) {
        self.undo.push(UndoEntry {
            tree,
            fixes: self.fixes.len(),
            proposal,
        });
    }

    /// What was tried for `failure`.
    pub(super) fn tried_for(&self, failure: &Failure) -> Vec<Tried> {
        self.tried
            .iter()
            .filter(|(f, _)| f == failure)
            .map(|(_, t)| t.clone())
            .collect()
    }

    /// The instruction, else the goal in words: what the question about a failure quotes.
    pub(super) fn request_text(&self) -> String {
        self.goal
            .as_ref()
            .map(|g| {
                g.instruction
                    .clone()
                    .unwrap_or_else(|| g.formula.to_string())
            })
            .unwrap_or_default()
    }
}
