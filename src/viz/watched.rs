//! A watched BehaviorTree.CPP run (a `betr monitor --record` file) written as a rerun
//! recording: the tree as a graph and as text, its statuses after every read of the
//! publisher's changes, and every status change, connection and breakpoint stop in the
//! event log, all on the `watch` timeline (seconds since the watch began, each change at
//! the robot's own time). Its layout is the tree and the log: a watched process has no
//! cell to draw.

use std::path::Path;
use std::time::Duration;

use rerun::{
    Color, RecordingStream, RecordingStreamBuilder, RecordingStreamResult, TextDocument, TextLog,
    TextLogLevel,
};

use crate::http_text::printable;
use crate::monitor::{LiveTree, WatchEvent, WatchedTree, missed_some};

use super::blueprint::tree_and_log;
use super::tree::{Graph, TREE_TEXT, VIEWER_GLYPHS, status_colour, tidy};
use super::{APP_ID, EVENTS, VizError};

/// The timeline of a watched run: seconds since the watch began.
pub const WATCH: &str = "watch";

/// Writes the events of a watched run to `out`; how many status changes it holds.
pub fn write<'a>(
    out: &Path,
    events: impl Iterator<Item = &'a WatchEvent>,
) -> Result<u64, VizError> {
    let sink = rerun::sink::FileSink::new(out).map_err(|e| VizError::Rrd {
        path: out.to_path_buf(),
        message: e.to_string(),
    })?;
    let rec = RecordingStreamBuilder::new(APP_ID)
        .with_blueprint(tree_and_log(WATCH))
        .set_sinks((sink,))?;
    let mut writer = Writer {
        rec: &rec,
        live: None,
        since: Duration::ZERO,
        at: Duration::ZERO,
        changes: 0,
        boards: Vec::new(),
    };
    for event in events {
        if let Err(e) = writer.on(event) {
            return Err(VizError::Rrd {
                path: out.to_path_buf(),
                message: e.to_string(),
            });
        }
    }
    rec.flush_blocking().map_err(|e| VizError::Rrd {
        path: out.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(writer.changes)
}

struct Writer<'r> {
    rec: &'r RecordingStream,
    live: Option<LiveTree>,
    /// When the current connection began keeping changes.
    since: Duration,
    /// The latest time logged (the timeline never goes back).
    at: Duration,
    changes: u64,
    boards: Vec<crate::monitor::Blackboard>,
}

impl Writer<'_> {
    fn at(&mut self, time: Duration) {
        self.at = self.at.max(time);
        self.rec.set_duration_secs(WATCH, self.at.as_secs_f64());
    }

    fn line(&self, level: &str, text: String) -> RecordingStreamResult<()> {
        self.rec
            .log(EVENTS, &TextLog::new(text).with_level(level.to_string()))
    }

    fn on(&mut self, event: &WatchEvent) -> RecordingStreamResult<()> {
        match event {
            WatchEvent::Connected {
                address,
                tree,
                statuses,
                since,
                ..
            } => {
                self.since = *since;
                self.at(*since);
                let live = LiveTree::new((**tree).clone(), statuses);
                log_tree(self.rec, &live, true)?;
                self.live = Some(live);
                self.line(
                    TextLogLevel::INFO,
                    format!(
                        "watching {address}: tree {}, {} nodes",
                        printable(&tree.main),
                        tree.nodes.len()
                    ),
                )
            }
            WatchEvent::Changes(batch) => self.changes(batch),
            WatchEvent::Restarted => self.line(
                TextLogLevel::WARN,
                "the publisher runs a new tree (restarted)".into(),
            ),
            WatchEvent::Lost(reason) => {
                self.line(TextLogLevel::WARN, format!("connection lost: {reason}"))
            }
            WatchEvent::Waiting(reason) => self.line(TextLogLevel::WARN, reason.clone()),
            WatchEvent::Stopped(uid) => {
                let node = self
                    .live
                    .as_ref()
                    .and_then(|l| Some(l.tree.describe(l.tree.by_uid(*uid)?)))
                    .unwrap_or_else(|| format!("node {uid}"));
                self.line(
                    TextLogLevel::WARN,
                    format!("stopped at a breakpoint before {node}"),
                )
            }
            WatchEvent::Refused(reason) => self.line(TextLogLevel::ERROR, reason.clone()),
            WatchEvent::Blackboards(boards) => {
                for board in crate::monitor::changed_blackboards(&self.boards, boards) {
                    self.line(
                        TextLogLevel::INFO,
                        format!("blackboard {}", board.describe()),
                    )?;
                }
                self.boards.clone_from(boards);
                Ok(())
            }
        }
    }

    /// Each change in the log at its own time, then the tree's statuses after the batch.
    fn changes(&mut self, batch: &[crate::monitor::Transition]) -> RecordingStreamResult<()> {
        let Some(mut live) = self.live.take() else {
            return Ok(());
        };
        if missed_some(batch) {
            self.line(
                TextLogLevel::WARN,
                "the publisher kept only its last 1000 changes since the last read: some before these were missed".into(),
            )?;
        }
        for &transition in batch {
            self.at(self.since + Duration::from_micros(transition.micros));
            let Some(change) = live.apply(transition) else {
                continue;
            };
            self.changes += 1;
            let level = if change.new == crate::monitor::NodeStatus::Failure {
                TextLogLevel::ERROR
            } else {
                TextLogLevel::INFO
            };
            let text = live.describe_change(self.since, &change, "→");
            self.line(level, text.trim_start().to_string())?;
        }
        let logged = log_tree(self.rec, &live, false);
        self.live = Some(live);
        logged
    }
}

/// The tree's nodes with their statuses' colours and marks at their tidy positions, the
/// edges when `edges`, and the tree as text.
fn log_tree(rec: &RecordingStream, live: &LiveTree, edges: bool) -> RecordingStreamResult<()> {
    let tree = &live.tree;
    let ids: Vec<String> = tree.nodes.iter().map(|n| n.uid.to_string()).collect();
    let labels: Vec<String> = tree
        .nodes
        .iter()
        .zip(&live.statuses)
        .map(|(node, status)| match status.as_status() {
            crate::bt::Status::Idle => label(tree, node),
            shown => format!("{} {}", VIEWER_GLYPHS.status(shown), label(tree, node)),
        })
        .collect();
    let colours: Vec<Color> = live
        .statuses
        .iter()
        .map(|s| {
            let [r, g, b] = status_colour(s.as_status());
            Color::from_rgb(r, g, b)
        })
        .collect();
    let layout: Vec<(Vec<usize>, usize)> = tree
        .nodes
        .iter()
        .map(|n| (n.children.clone(), label(tree, n).chars().count()))
        .collect();
    let edges = edges.then(|| {
        tree.nodes
            .iter()
            .flat_map(|n| {
                n.children
                    .iter()
                    .map(move |&c| (n.uid.to_string(), tree.nodes[c].uid.to_string()))
            })
            .collect()
    });
    let graph = Graph {
        ids,
        labels,
        colours,
        positions: tidy(&layout),
    };
    graph.log(rec, edges)?;
    rec.log(TREE_TEXT, &TextDocument::new(text(live)))
}

fn label(tree: &WatchedTree, node: &crate::monitor::WatchedNode) -> String {
    printable(&tree.describe(node)).into_owned()
}

/// The tree as indented lines with each node's status mark.
fn text(live: &LiveTree) -> String {
    let mut lines = Vec::with_capacity(live.tree.nodes.len());
    for (node, status) in live.tree.nodes.iter().zip(&live.statuses) {
        lines.push(format!(
            "{}[{}] {}",
            "  ".repeat(node.depth),
            VIEWER_GLYPHS.status(status.as_status()),
            label(&live.tree, node)
        ));
    }
    lines.join("\n")
}
