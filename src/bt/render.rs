//! Drawing a tree (and, optionally, what one tick did to it) as lines of text, in the style
//! of py_trees' `display.unicode_tree`:
//!
//! ```text
//! [-] Sequence [✓]
//!     [o] Fallback [✓]
//!         --> "blue cube" on "green cube"? [✕]
//!         [-] Sequence [*]
//!             --> grasp "blue cube"! [*]
//! ```
//!
//! What is drawn for each node kind and status is data (`Glyphs`), so a front end can pick
//! `UNICODE`, `ASCII` or its own set without touching the layout code.

use super::status::Status;
use super::tick::TickRecord;
use super::tree::{NodeKind, Tree};

/// The strings a rendering is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Glyphs {
    /// Prepended once per depth level.
    pub indent: &'static str,
    /// Marker before a sequence.
    pub sequence: &'static str,
    /// Marker before a fallback.
    pub fallback: &'static str,
    /// Marker before a condition.
    pub condition: &'static str,
    /// Marker before an action.
    pub action: &'static str,
    /// Name printed after the sequence marker.
    pub sequence_name: &'static str,
    /// Name printed after the fallback marker.
    pub fallback_name: &'static str,
    /// Written after a condition's text (as in the text format).
    pub condition_suffix: &'static str,
    /// Written after an action's text (as in the text format).
    pub action_suffix: &'static str,
    /// Status marks, shown in brackets after the node when a tick record is given.
    pub idle: &'static str,
    pub running: &'static str,
    pub success: &'static str,
    pub failure: &'static str,
    pub halted: &'static str,
}

/// py_trees-like Unicode glyphs.
pub const UNICODE: Glyphs = Glyphs {
    indent: "    ",
    sequence: "[-]",
    fallback: "[o]",
    condition: "-->",
    action: "-->",
    sequence_name: "Sequence",
    fallback_name: "Fallback",
    condition_suffix: "?",
    action_suffix: "!",
    idle: "-",
    running: "*",
    success: "✓",
    failure: "✕",
    halted: "‖",
};

/// Plain ASCII glyphs, for logs and terminals without Unicode.
pub const ASCII: Glyphs = Glyphs {
    indent: "    ",
    sequence: "[-]",
    fallback: "[o]",
    condition: "-->",
    action: "-->",
    sequence_name: "Sequence",
    fallback_name: "Fallback",
    condition_suffix: "?",
    action_suffix: "!",
    idle: "-",
    running: "*",
    success: "+",
    failure: "x",
    halted: "=",
};

impl Glyphs {
    /// The mark for `status`.
    pub fn status(&self, status: Status) -> &'static str {
        match status {
            Status::Idle => self.idle,
            Status::Running => self.running,
            Status::Success => self.success,
            Status::Failure => self.failure,
            Status::Halted => self.halted,
        }
    }
}

/// One line per live node in preorder; with a record, each line ends in ` [mark]` for the
/// status the node showed in that tick (nodes the record does not cover show as idle).
pub fn render(tree: &Tree, statuses: Option<&TickRecord>, glyphs: &Glyphs) -> Vec<String> {
    let nodes = tree.subtree_with_depth(tree.root()).unwrap_or_default();
    let mut lines = Vec::with_capacity(nodes.len());
    for (id, depth) in nodes {
        let Ok(kind) = tree.kind(id) else { continue };
        let mut line = glyphs.indent.repeat(depth);
        let (marker, label, suffix) = match kind {
            NodeKind::Sequence => (glyphs.sequence, glyphs.sequence_name.to_string(), ""),
            NodeKind::Fallback => (glyphs.fallback, glyphs.fallback_name.to_string(), ""),
            NodeKind::Condition(c) => (glyphs.condition, c.to_string(), glyphs.condition_suffix),
            NodeKind::Action(a) => (glyphs.action, a.to_string(), glyphs.action_suffix),
        };
        line.push_str(marker);
        line.push(' ');
        line.push_str(&label);
        line.push_str(suffix);
        if let Some(record) = statuses {
            line.push_str(" [");
            line.push_str(glyphs.status(record.status(id)));
            line.push(']');
        }
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bt::status::Outcome;
    use crate::bt::test_util::{act, cond};
    use crate::bt::tree::NodeId;

    /// Sequence(Fallback(c, Sequence(grasp)), place)
    fn sample() -> Tree {
        let mut t = Tree::new(NodeKind::Sequence);
        let f = t.add_child(t.root(), NodeKind::Fallback).unwrap();
        t.add_child(f, cond("\"blue cube\" on \"green cube\""))
            .unwrap();
        let s = t.add_child(f, NodeKind::Sequence).unwrap();
        t.add_child(s, act("grasp \"blue cube\"")).unwrap();
        t.add_child(t.root(), act("place \"blue cube\" \"green cube\""))
            .unwrap();
        t
    }

    fn record(statuses: Vec<Status>) -> TickRecord {
        TickRecord {
            tick: 1,
            root: Outcome::Running,
            statuses,
            visited: Vec::new(),
            halted: Vec::new(),
            failures: Vec::new(),
            completed: Vec::new(),
            forced: Vec::new(),
        }
    }

    #[test]
    fn plain_tree() {
        assert_eq!(
            render(&sample(), None, &UNICODE),
            [
                "[-] Sequence",
                "    [o] Fallback",
                "        --> \"blue cube\" on \"green cube\"?",
                "        [-] Sequence",
                "            --> grasp \"blue cube\"!",
                "    --> place \"blue cube\" \"green cube\"!",
            ]
        );
    }

    #[test]
    fn unicode_statuses() {
        use Status::*;
        let r = record(vec![Running, Running, Failure, Running, Running, Idle]);
        assert_eq!(
            render(&sample(), Some(&r), &UNICODE),
            [
                "[-] Sequence [*]",
                "    [o] Fallback [*]",
                "        --> \"blue cube\" on \"green cube\"? [✕]",
                "        [-] Sequence [*]",
                "            --> grasp \"blue cube\"! [*]",
                "    --> place \"blue cube\" \"green cube\"! [-]",
            ]
        );
    }

    #[test]
    fn ascii_statuses_and_short_records() {
        use Status::*;
        let mut t = sample();
        // A node added after the tick is not covered by the record: idle.
        let extra = t.add_child(t.root(), cond("Clean_Floor")).unwrap();
        assert_eq!(extra, NodeId(6));
        let r = record(vec![Failure, Success, Success, Idle, Halted, Failure]);
        assert_eq!(
            render(&t, Some(&r), &ASCII),
            [
                "[-] Sequence [x]",
                "    [o] Fallback [+]",
                "        --> \"blue cube\" on \"green cube\"? [+]",
                "        [-] Sequence [-]",
                "            --> grasp \"blue cube\"! [=]",
                "    --> place \"blue cube\" \"green cube\"! [x]",
                "    --> Clean_Floor? [-]",
            ]
        );
        assert_eq!(UNICODE.status(Halted), "‖");
    }
}
