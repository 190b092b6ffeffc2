//! A session followed into a recording: every event the engine reports and every command a
//! front end sends; or a watched BehaviorTree.CPP process: every event the watch reports
//! and every breakpoint command sent to it. A write that fails (a full disk) stops the recording, and what was
//! written stays readable; `stopped` says why, and the one-shot commands end with it as
//! an error, while the workbench shows it.

use std::path::Path;

use crate::monitor::{Address, WatchCommand, WatchEvent};
use crate::session::{Command, Event};

use super::{Entry, RecordError, Recorder, Source};

pub struct SessionRecorder {
    recorder: Option<Recorder>,
    /// Why the recording stopped, if a write failed.
    stopped: Option<String>,
}

impl SessionRecorder {
    /// Start recording a session on `scenario` into `path` (replaced if it exists).
    pub fn create(
        path: &Path,
        scenario: &Path,
        name: &str,
        variant: Option<&str>,
    ) -> Result<SessionRecorder, RecordError> {
        Ok(SessionRecorder {
            recorder: Some(Recorder::create(path, scenario, name, variant)?),
            stopped: None,
        })
    }

    /// Start recording the publisher watched at `address` into `path` (replaced if it
    /// exists).
    pub fn create_watched(path: &Path, address: &Address) -> Result<SessionRecorder, RecordError> {
        let source = Source::Watched {
            watched: address.clone(),
        };
        Ok(SessionRecorder {
            recorder: Some(Recorder::start(path, source)?),
            stopped: None,
        })
    }

    pub fn watched(&mut self, event: &WatchEvent) {
        self.write(|ms| Entry::Watched {
            ms,
            watched: event.clone(),
        });
    }

    /// A command sent to the watched publisher.
    pub fn asked(&mut self, command: WatchCommand) {
        let command = command.to_string();
        self.write(|ms| Entry::Command { ms, command });
    }

    pub fn event(&mut self, event: &Event) {
        // A replay re-simulates the cell's scenes from the recorded trees and ticks.
        if matches!(event, Event::Scene { .. }) {
            return;
        }
        self.write(|ms| Entry::Event {
            ms,
            event: event.clone(),
        });
    }

    pub fn command(&mut self, command: &Command) {
        let command = command_text(command);
        self.write(|ms| Entry::Command { ms, command });
    }

    fn write(&mut self, entry: impl FnOnce(u64) -> Entry) {
        let Some(recorder) = &mut self.recorder else {
            return;
        };
        let entry = entry(recorder.ms());
        if let Err(e) = recorder.write(&entry) {
            tracing::warn!(error = %e, "the recording stopped");
            self.stopped = Some(format!("the recording stopped: {e}"));
            self.recorder = None;
        }
    }

    /// Why the recording stopped, if a write failed (for a front end to tell).
    pub fn stopped(&self) -> Option<&str> {
        self.stopped.as_deref()
    }
}

/// A command in the words a person would use.
pub fn command_text(command: &Command) -> String {
    match command {
        Command::Submit(text) => format!("submit {text}"),
        Command::SubmitGoal { goal, .. } => format!("submit goal {goal}"),
        Command::Plan => "plan".into(),
        Command::PlanKeepingRefused => "plan, keeping the refused fixes".into(),
        Command::Tick => "tick".into(),
        Command::Run => "run".into(),
        Command::Pause => "pause".into(),
        Command::Approve => "approve".into(),
        Command::Reject => "reject".into(),
        Command::Cancel => "cancel the model call".into(),
        Command::Edit(edit) => format!("edit {edit}"),
        Command::SetValue(setting) => format!("set {}", setting.text),
        Command::Undo => "undo".into(),
        Command::Verify | Command::VerifyWith(_) => "verify".into(),
        Command::SavePolicy => "save policy".into(),
        Command::SavePolicyTo(path) => format!("save policy to {}", path.display()),
        Command::Export => "export".into(),
        Command::LoadPolicy(None) => "load policy".into(),
        Command::LoadPolicy(Some(path)) => format!("load policy {}", path.display()),
        Command::LoadTree { path, .. } => format!("load tree {}", path.display()),
        Command::Insert {
            conditions, before, ..
        } => {
            let names: Vec<String> = conditions.iter().map(ToString::to_string).collect();
            match before {
                Some(action) => format!("insert {} before {action}!", names.join(" & ")),
                None => format!("insert {}", names.join(" & ")),
            }
        }
        Command::ResetWorld => "reset world".into(),
        Command::RobotArrived => "robot description arrived".into(),
        // The events that follow name the nodes by their place in the tree.
        Command::Force { status: None, .. } => "clear a forced status".into(),
        Command::Force {
            status: Some(status),
            ..
        } => format!("force a node to {status}"),
        Command::CycleForce(_) => "force a node to its next status".into(),
        Command::ToggleBreakpoint(_) => "toggle a breakpoint".into(),
        Command::BreakOnFailure(on) => {
            format!("break on failure {}", if *on { "on" } else { "off" })
        }
        Command::KeepRule { only: false } => "keep rule".into(),
        Command::KeepRule { only: true } => "keep rule for these objects".into(),
        Command::DeclineRule => "decline rule".into(),
        Command::ShowKnowledge => "show knowledge".into(),
        Command::ChooseReading(index) => format!("choose reading {}", index + 1),
        Command::Shutdown => "quit".into(),
    }
}
