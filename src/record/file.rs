//! Writing a recording as it happens, and reading one back. Each entry is one line written
//! with one call and flushed, so the file only ever grows by whole entries; a crash can
//! leave at most a partial last line, which the reader reports and leaves out.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{Entry, FORMAT, Header, RecordError, Source, VERSION};
use crate::session::Event;

/// A recording being written.
pub struct Recorder {
    path: PathBuf,
    file: File,
    started: Instant,
}

impl Recorder {
    /// Create (or replace) `path` and write the header of a session on `scenario`.
    pub fn create(
        path: &Path,
        scenario: &Path,
        name: &str,
        variant: Option<&str>,
    ) -> Result<Recorder, RecordError> {
        let source = Source::Session {
            scenario: scenario.to_path_buf(),
            name: name.into(),
            variant: variant.map(str::to_string),
        };
        Recorder::start(path, source)
    }

    /// Create (or replace) `path` and write the header of what `source` records.
    pub fn start(path: &Path, source: Source) -> Result<Recorder, RecordError> {
        let io = |source| RecordError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = File::create(path).map_err(io)?;
        let mut recorder = Recorder {
            path: path.to_path_buf(),
            file,
            started: Instant::now(),
        };
        let header = Header {
            format: FORMAT.into(),
            version: VERSION,
            source,
            betr: env!("CARGO_PKG_VERSION").into(),
            started: crate::session::policy::now_rfc3339(),
        };
        recorder.line(&header)?;
        Ok(recorder)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Milliseconds since the recording started.
    pub fn ms(&self) -> u64 {
        u64::try_from(self.started.elapsed().as_millis()).unwrap_or(u64::MAX)
    }

    /// Append one entry.
    pub fn write(&mut self, entry: &Entry) -> Result<(), RecordError> {
        self.line(entry)
    }

    fn line(&mut self, value: &impl serde::Serialize) -> Result<(), RecordError> {
        let json = serde_json::to_string(value).map_err(|e| RecordError::Line {
            path: self.path.clone(),
            line: 0,
            reason: format!("cannot be written as JSON: {e}"),
        })?;
        let mut text = crate::http_text::without_secrets(&json).into_owned();
        text.push('\n');
        // One write per entry: a crash leaves whole entries and at most one partial line.
        self.file
            .write_all(text.as_bytes())
            .and_then(|()| self.file.flush())
            .map_err(|source| RecordError::Io {
                path: self.path.clone(),
                source,
            })
    }
}

/// A recording read back: its header, its entries with their line numbers, and whether
/// its last line was cut (the session ended without closing it, e.g. a crash).
#[derive(Debug, Clone)]
pub struct Recording {
    pub path: PathBuf,
    pub header: Header,
    pub entries: Vec<(usize, Entry)>,
    /// The line number of a partial last line that was left out.
    pub cut_at: Option<usize>,
}

/// Read the recording at `path`; a line that is not an entry is an error naming it,
/// except a partial last line (no newline), which is left out and reported in `cut_at`.
pub fn read(path: &Path) -> Result<Recording, RecordError> {
    let text = crate::store::read_text(path, crate::store::LOG_FILE_BYTES).map_err(|source| {
        RecordError::Io {
            path: path.to_path_buf(),
            source,
        }
    })?;
    parse(path, &text)
}

/// A recording from its text, as if read from `path` (which names it in errors).
pub fn parse(path: &Path, text: &str) -> Result<Recording, RecordError> {
    let Some(first) = text
        .split_inclusive('\n')
        .next()
        .map(|line| line.trim_end_matches(['\n', '\r']))
    else {
        return Err(RecordError::Empty {
            path: path.to_path_buf(),
        });
    };
    let header: Header = serde_json::from_str(first).map_err(|e| RecordError::NotARecording {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    if header.format != FORMAT {
        return Err(RecordError::NotARecording {
            path: path.to_path_buf(),
            reason: format!("its format is {:?}", header.format),
        });
    }
    let read = match header.version {
        VERSION => crate::store::read_lines(text, 2, |l| serde_json::from_str::<Entry>(l))
            .map_err(|(line, e)| RecordError::Line {
                path: path.to_path_buf(),
                line,
                reason: e.to_string(),
            })?,
        super::v1::VERSION => super::v1::entries(path, text)?,
        found => {
            return Err(RecordError::Version {
                path: path.to_path_buf(),
                found,
            });
        }
    };
    check_nodes(&read.items).map_err(|(line, reason)| RecordError::Line {
        path: path.to_path_buf(),
        line,
        reason,
    })?;
    Ok(Recording {
        path: path.to_path_buf(),
        header,
        entries: read.items,
        cut_at: read.cut_at,
    })
}

/// Every node an event names is a node of the tree before it, and every tick has a
/// status for each of its slots: a file edited by hand, or damaged, is refused at the
/// line that breaks this rather than shown with statuses on the wrong nodes.
fn check_nodes(entries: &[(usize, Entry)]) -> Result<(), (usize, String)> {
    let mut tree: Option<&crate::bt::Tree> = None;
    for (line, entry) in entries {
        let Entry::Event { event, .. } = entry else {
            continue;
        };
        if let Event::TreeChanged { tree: t, .. } = event {
            tree = Some(t);
        }
        let named = named_nodes(event);
        if named.is_empty() && !matches!(event, Event::Ticked { .. }) {
            continue;
        }
        let Some(tree) = tree else {
            return Err((*line, "an event that names nodes before any tree".into()));
        };
        if let Event::Ticked { record } = event
            && record.statuses.len() != tree.capacity()
        {
            return Err((
                *line,
                format!(
                    "{} statuses for a tree of {} slots",
                    record.statuses.len(),
                    tree.capacity()
                ),
            ));
        }
        if let Some(id) = named.into_iter().find(|id| !tree.contains(*id)) {
            return Err((*line, format!("node {id} is not in the tree")));
        }
    }
    Ok(())
}

/// The nodes `event` names (a tick's halted nodes may be removed ones, and are not).
fn named_nodes(event: &Event) -> Vec<crate::bt::NodeId> {
    use crate::session::Proposal;
    match event {
        Event::TreeChanged {
            new_nodes, learned, ..
        } => new_nodes
            .iter()
            .copied()
            .chain(learned.iter().map(|(id, _)| *id))
            .collect(),
        Event::Ticked { record } => record
            .visited
            .iter()
            .chain(&record.completed)
            .chain(&record.forced)
            .copied()
            .chain(record.failures.iter().map(|(id, _)| *id))
            .collect(),
        Event::ActionFailed { node, .. } | Event::BreakpointHit { node, .. } => vec![*node],
        Event::Proposal {
            proposal: Proposal::Conditions { node, .. },
            ..
        } => vec![*node],
        Event::Forced { forced } => forced.iter().map(|(id, _)| *id).collect(),
        Event::Breakpoints { nodes, .. } => nodes.clone(),
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("betr-record-{}-{name}", std::process::id()))
    }

    #[test]
    fn entries_are_read_back_in_order() {
        let path = temp("order.jsonl");
        let mut r = Recorder::create(&path, Path::new("s.toml"), "S", None).unwrap();
        r.write(&Entry::Command {
            ms: 1,
            command: "run".into(),
        })
        .unwrap();
        r.write(&Entry::Event {
            ms: 2,
            event: Event::Success {
                ticks: 3,
                executor: None,
            },
        })
        .unwrap();
        let back = read(&path).unwrap();
        assert_eq!(back.header.scenario_name(), Some("S"));
        assert_eq!(back.entries.len(), 2);
        assert_eq!(back.entries[1].0, 3, "line numbers count the header");
        assert!(matches!(
            back.entries[1].1,
            Entry::Event {
                ms: 2,
                event: Event::Success { ticks: 3, .. }
            }
        ));
        assert_eq!(back.cut_at, None);
    }

    #[test]
    fn a_partial_last_line_is_left_out_and_reported() {
        let path = temp("cut.jsonl");
        let mut r = Recorder::create(&path, Path::new("s.toml"), "S", None).unwrap();
        r.write(&Entry::Command {
            ms: 1,
            command: "run".into(),
        })
        .unwrap();
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        f.write_all(br#"{"kind":"event","ms":5,"event":{"ev"#)
            .unwrap();
        let back = read(&path).unwrap();
        assert_eq!(back.entries.len(), 1);
        assert_eq!(back.cut_at, Some(3));
    }

    #[test]
    fn a_broken_line_in_the_middle_is_an_error_naming_it() {
        let path = temp("broken.jsonl");
        Recorder::create(&path, Path::new("s.toml"), "S", None).unwrap();
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        f.write_all(b"not json\n{\"kind\":\"command\",\"ms\":1,\"command\":\"x\"}\n")
            .unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }

    #[test]
    fn an_event_naming_a_node_the_tree_lacks_is_an_error_naming_its_line() {
        let path = temp("nodes.jsonl");
        let mut r = Recorder::create(&path, Path::new("s.toml"), "S", None).unwrap();
        let tree = crate::bt::parse("sequence\n  Sweep!\n").unwrap();
        r.write(&Entry::Event {
            ms: 1,
            event: Event::TreeChanged {
                tree: std::sync::Arc::new(tree),
                new_nodes: Vec::new(),
                learned: Vec::new(),
                why: "planned".into(),
            },
        })
        .unwrap();
        r.write(&Entry::Event {
            ms: 2,
            event: Event::Breakpoints {
                nodes: vec![crate::bt::NodeId(7)],
                on_failure: false,
            },
        })
        .unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("#7"), "{e}");
    }

    #[test]
    fn another_file_or_version_is_refused() {
        let path = temp("other.jsonl");
        std::fs::write(&path, "{\"a\":1}\n").unwrap();
        assert!(
            read(&path)
                .unwrap_err()
                .to_string()
                .contains("not a betr recording")
        );
        std::fs::write(
            &path,
            format!(
                "{{\"format\":\"{FORMAT}\",\"version\":99,\"scenario\":\"s\",\"name\":\"S\",\"variant\":null,\"betr\":\"0\",\"started\":\"\"}}\n"
            ),
        )
        .unwrap();
        assert!(read(&path).unwrap_err().to_string().contains("version 99"));
        std::fs::write(&path, "").unwrap();
        assert!(read(&path).unwrap_err().to_string().contains("empty"));
    }
}
