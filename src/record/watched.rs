//! A watched BehaviorTree.CPP process read back from its recording: the publisher's
//! address and every event the watch reported (each tree as the publisher described it,
//! every status change, losses and restarts, breakpoint stops) with the commands sent to
//! it, in order, with their times. A front end replays them as it showed them live.

use std::path::PathBuf;

use crate::monitor::{Address, WatchEvent};

use super::{Entry, Header, Recording, Source};

/// One step of a watched run.
#[derive(Debug, Clone)]
pub enum WatchStep {
    /// A command sent to the publisher, in words.
    Asked(String),
    Watched(WatchEvent),
}

/// A watched run read back.
pub struct WatchedRun {
    pub path: PathBuf,
    pub header: Header,
    pub address: Address,
    /// The steps with their times (milliseconds since the watch began).
    pub steps: Vec<(u64, WatchStep)>,
    /// The line of a partial last entry that was left out (the watch did not end
    /// cleanly).
    pub cut_at: Option<usize>,
}

/// Why a recording is not a watched run.
#[derive(Debug, thiserror::Error)]
pub enum WatchedRunError {
    #[error("{path}: a session on the scenario {scenario}, not a watched BehaviorTree.CPP process")]
    Session { path: PathBuf, scenario: PathBuf },
    #[error("{path}, line {line}: a session's event in the recording of a watched process")]
    SessionEvent { path: PathBuf, line: usize },
}

impl WatchedRun {
    pub fn of(recording: Recording) -> Result<WatchedRun, WatchedRunError> {
        let address = match &recording.header.source {
            Source::Watched { watched } => watched.clone(),
            Source::Session { scenario, .. } => {
                return Err(WatchedRunError::Session {
                    path: recording.path,
                    scenario: scenario.clone(),
                });
            }
        };
        let mut steps = Vec::with_capacity(recording.entries.len());
        for (line, entry) in recording.entries {
            steps.push(match entry {
                Entry::Command { ms, command } => (ms, WatchStep::Asked(command)),
                Entry::Watched { ms, watched } => (ms, WatchStep::Watched(watched)),
                Entry::Event { .. } => {
                    return Err(WatchedRunError::SessionEvent {
                        path: recording.path,
                        line,
                    });
                }
            });
        }
        Ok(WatchedRun {
            path: recording.path,
            header: recording.header,
            address,
            steps,
            cut_at: recording.cut_at,
        })
    }

    /// The watch's events, in order.
    pub fn events(&self) -> impl Iterator<Item = &WatchEvent> {
        self.steps.iter().filter_map(|(_, step)| match step {
            WatchStep::Watched(event) => Some(event),
            WatchStep::Asked(_) => None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::file::parse;
    use crate::record::{Replay, ReplayError};
    use std::path::Path;

    const HEADER: &str = r#"{"format":"betr-recording","version":2,"watched":"127.0.0.1:1667","betr":"0.1.0","started":"2026-11-28T00:00:00Z"}"#;
    const TREE: &str = r#"{"kind":"watched","ms":3,"watched":{"connected":{"address":"127.0.0.1:1667","tree":"<root><BehaviorTree ID=\"Main\"><Sequence _uid=\"1\"><AlwaysSuccess _uid=\"2\"/></Sequence></BehaviorTree></root>","statuses":[],"since":{"secs":0,"nanos":3000000},"started":null}}}"#;
    const CHANGES: &str = r#"{"kind":"watched","ms":9,"watched":{"changes":[{"micros":10,"uid":2,"status":"Success"}]}}"#;

    fn text(lines: &[&str]) -> String {
        lines.iter().map(|l| format!("{l}\n")).collect()
    }

    #[test]
    fn a_watched_run_reads_back_with_its_tree_and_changes() {
        let recording = parse(Path::new("w.jsonl"), &text(&[HEADER, TREE, CHANGES])).unwrap();
        let run = WatchedRun::of(recording).unwrap();
        assert_eq!(run.address.to_string(), "127.0.0.1:1667");
        let events: Vec<&WatchEvent> = run.events().collect();
        assert!(matches!(events[0], WatchEvent::Connected { tree, .. } if tree.nodes.len() == 2));
        assert!(matches!(events[1], WatchEvent::Changes(c) if c.len() == 1));
    }

    #[test]
    fn a_damaged_tree_is_refused_at_its_line() {
        let broken = TREE.replace("_uid=\\\"2\\\"", "_uid=\\\"1\\\"");
        let e = parse(Path::new("w.jsonl"), &text(&[HEADER, &broken])).unwrap_err();
        let said = e.to_string();
        assert!(
            said.starts_with("w.jsonl, line 2:") && said.contains("_uid 1 of another node"),
            "{said}"
        );
    }

    #[test]
    fn the_two_kinds_are_not_mixed() {
        let session = r#"{"format":"betr-recording","version":2,"scenario":"s.toml","name":"S","variant":null,"betr":"0.1.0","started":"2026-11-28T00:00:00Z"}"#;
        let recording = parse(Path::new("s.jsonl"), &text(&[session, TREE])).unwrap();
        let e = Replay::of(recording.clone(), None).err().unwrap();
        assert!(
            matches!(&e, ReplayError::Record(_)) && e.to_string().contains("line 2"),
            "{e}"
        );
        let e = WatchedRun::of(recording).err().unwrap();
        assert!(
            e.to_string().contains("a session on the scenario s.toml"),
            "{e}"
        );

        let tick = r#"{"kind":"command","ms":1,"command":"tick"}"#;
        let recording = parse(Path::new("w.jsonl"), &text(&[HEADER, tick])).unwrap();
        assert!(
            WatchedRun::of(recording.clone()).is_ok(),
            "commands are words in both"
        );
        let e = Replay::of(recording, None).err().unwrap();
        assert!(matches!(e, ReplayError::Watched { .. }), "{e}");
    }
}
