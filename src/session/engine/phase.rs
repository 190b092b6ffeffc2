//! What the engine is doing: one phase at a time, each holding the data that belongs to it
//! alone (the call under way, the failure asked about, the proposal waiting, the check of
//! a change). Leaving a phase drops its data: a call it started is aborted, so its late
//! answer finds no phase waiting for it.

use crate::session::types::{Event, PhaseKind, Proposal, Reading};

use super::Engine;

/// An action that failed in the execution world.
pub(super) use crate::session::repair::screen::FailureAt as Failure;

/// A model call under way.
pub(super) struct Call {
    pub(super) id: u64,
    pub(super) handle: tokio::task::JoinHandle<()>,
}

/// A proposal waiting for approval, with who made it.
#[derive(Debug, Clone)]
pub(super) struct Pending {
    pub(super) proposal: Proposal,
    /// Who answered (`model gpt-4o`, a fixture's label, or `a person`).
    pub(super) author: String,
    pub(super) failure: Option<Failure>,
}

/// A proposal that was applied, and the failure it was for: when the changed tree fails
/// verification and the change is rejected, the model is told it was tried.
#[derive(Debug, Clone)]
pub(super) struct AppliedProposal {
    pub(super) failure: Option<Failure>,
    pub(super) proposal: Proposal,
}

pub(super) enum Phase {
    /// No tree yet.
    Idle,
    /// The model reads an instruction (the current tree, if any, can still be stepped).
    Reading { call: Call },
    /// The readings of an instruction that would make the robot do different things wait
    /// for the person's choice.
    Choosing {
        instruction: String,
        readings: Vec<Reading>,
    },
    /// A tree, stepped by hand.
    Ready,
    /// The tree ticks on its own.
    Running,
    /// An action failed and nothing is asked about it (no model, the rounds used up, the
    /// proposals rejected, or the model's answer unusable): a person writes the fix, or
    /// ticks again, which asks again while rounds remain.
    Failed { failure: Failure },
    /// The model is asked what the failure misses.
    Asking { failure: Failure, call: Call },
    /// A proposal waits for approval.
    Proposed(Pending),
    /// An applied change is verified before the changed tree may run; `run_after`: a run
    /// was asked for meanwhile and starts when the check passes.
    Checking {
        id: u64,
        run_after: bool,
        change: Option<AppliedProposal>,
    },
    /// The changed tree fails verification (`summary`: what failed, in one line); it does
    /// not run until the change is approved again, rejected or undone.
    Violated {
        summary: String,
        change: Option<AppliedProposal>,
    },
}

impl Phase {
    /// The phase as front ends are told it, without its data.
    pub(super) fn kind(&self) -> PhaseKind {
        match self {
            Phase::Idle => PhaseKind::Idle,
            Phase::Reading { .. } => PhaseKind::Reading,
            Phase::Choosing { .. } => PhaseKind::Choosing,
            Phase::Ready => PhaseKind::Ready,
            Phase::Running => PhaseKind::Running,
            Phase::Failed { .. } => PhaseKind::Failed,
            Phase::Asking { .. } => PhaseKind::Asking,
            Phase::Proposed(_) => PhaseKind::Proposed,
            Phase::Checking { .. } => PhaseKind::Checking,
            Phase::Violated { .. } => PhaseKind::Violated,
        }
    }

    pub(super) fn has_call(&self) -> bool {
        matches!(self, Phase::Reading { .. } | Phase::Asking { .. })
    }

    /// The id of the model call under way.
    pub(super) fn call_id(&self) -> Option<u64> {
        match self {
            Phase::Reading { call } | Phase::Asking { call, .. } => Some(call.id),
            _ => None,
        }
    }

    /// Abort the model call under way; true if there was one.
    pub(super) fn abort_call(&self) -> bool {
        match self {
            Phase::Reading { call } | Phase::Asking { call, .. } => {
                call.handle.abort();
                true
            }
            _ => false,
        }
    }

    /// The failure this phase is about.
    pub(super) fn failure(&self) -> Option<&Failure> {
        match self {
            Phase::Failed { failure } | Phase::Asking { failure, .. } => Some(failure),
            Phase::Proposed(pending) => pending.failure.as_ref(),
            _ => None,
        }
    }

    /// Why the tree is not ticked in this phase, if it is not: ticking a tree that waits
    /// for a change would only fail again.
    pub(super) fn why_not_ticked(&self) -> Option<String> {
        const FAILED: &str = "the failed tree would only fail again";
        Some(match self {
            Phase::Checking { .. } => {
                "not ticked: the changed tree waits for the verification of the change".into()
            }
            Phase::Violated { .. } => "not ticked: the changed tree waits for approval of the change that fails verification (approve again, reject, or undo)".into(),
            Phase::Proposed(_) => {
                format!("not ticked: the failure waits for approval of the proposal; {FAILED}")
            }
            Phase::Asking { .. } => {
                format!("not ticked: the failure waits for the model's proposal; {FAILED}")
            }
            _ => return None,
        })
    }
}

impl Engine {
    /// Leave the current phase for `next`: a model call under way is aborted (its answer
    /// would be ignored), and front ends hear when running starts or stops and what the
    /// phase is now.
    pub(super) fn enter(&mut self, next: Phase) {
        let was = std::mem::replace(&mut self.phase, next);
        if was.abort_call() {
            self.notice("the model call under way was cancelled");
        }
        let (was_running, running) = (
            matches!(was, Phase::Running),
            matches!(self.phase, Phase::Running),
        );
        if was_running != running {
            self.emit(Event::RunState { running });
        }
        self.tell_phase();
    }

    /// The phase's model call has answered: on to `next` without [`Engine::enter`]'s
    /// cancelling (the call's task is ending by itself). The answer usually moves the
    /// phase on again, so front ends are told the phase once it is taken in (`tell_state`).
    pub(super) fn call_answered(&mut self, next: Phase) {
        self.phase = next;
    }

    /// The phase with nothing under way: ready when there is a tree, else idle.
    pub(super) fn settled(&self) -> Phase {
        if self.task.tree.is_some() {
            Phase::Ready
        } else {
            Phase::Idle
        }
    }

    /// Stop running, if running.
    pub(super) fn stop_running(&mut self) {
        if matches!(self.phase, Phase::Running) {
            self.enter(self.settled());
        }
    }

    /// Drop what the phase waits for (a call, a failure, a proposal, a check, a choice of
    /// readings); a run goes on.
    pub(super) fn drop_waiting(&mut self) {
        if !matches!(self.phase, Phase::Running) {
            self.enter(self.settled());
        }
    }
}
