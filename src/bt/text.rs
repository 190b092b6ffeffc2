//! The text form of a tree: one node per line, two spaces of indentation per level.
//!
//! ```text
//! sequence
//!   fallback
//!     "blue cube" on "green cube"?
//!     sequence
//!       grasp "blue cube"!
//!       place "blue cube" "green cube"!
//! ```
//!
//! `sequence` and `fallback` are the composites; a condition is its text followed by `?`
//! (`~On_Coffee_Table1?`), an action its text followed by `!` (`grasp "egg" {force = 5 N}!`).
//! Blank lines and lines whose first non-space character is `#` are ignored.
//! `parse(&to_text(&t)) == t` for every valid tree whose atoms are well formed.

use std::fmt::Write as _;

use super::tree::{NodeId, NodeKind, Tree};
use crate::domain::Condition;
use crate::domain::action::parse_action_prefix;
use crate::domain::condition::parse_atom_prefix;

/// Why a tree text could not be read. `line` and `column` are 1-based (columns count
/// characters); `text` is the offending line.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}: expected {expected}, found {found} in: {text}")]
pub struct ParseError {
    pub line: usize,
    pub column: usize,
    pub text: String,
    pub expected: String,
    pub found: String,
}

/// The text form of `tree` (one line per node, each ending in a newline).
pub fn to_text(tree: &Tree) -> String {
    let mut out = String::new();
    for (id, depth) in tree.subtree_with_depth(tree.root()).unwrap_or_default() {
        let Ok(kind) = tree.kind(id) else { continue };
        for _ in 0..depth {
            out.push_str("  ");
        }
        let _ = match kind {
            NodeKind::Sequence => writeln!(out, "sequence"),
            NodeKind::Fallback => writeln!(out, "fallback"),
            NodeKind::Condition(c) => writeln!(out, "{c}?"),
            NodeKind::Action(a) => writeln!(out, "{a}!"),
        };
    }
    out
}

/// One node line that has been read, kept until its children are known.
struct Open<'t> {
    id: NodeId,
    line: usize,
    text: &'t str,
    composite: bool,
    has_children: bool,
}

/// Read a tree from its text form.
pub fn parse(text: &str) -> Result<Tree, ParseError> {
    let mut tree: Option<Tree> = None;
    // `open[d]` is the most recent node at depth d.
    let mut open: Vec<Open> = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let trimmed = raw.trim_start();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let err = |at: usize, expected: &str, found: String| error(line, raw, at, expected, found);
        let (indent, depth) =
            indentation(raw).map_err(|(at, expected, found)| err(at, &expected, found))?;
        let kind =
            parse_node(raw, indent).map_err(|(at, expected, found)| err(at, &expected, found))?;
        if tree.is_some() && depth == 0 {
            return Err(err(
                0,
                "a single root (indent this node under the root)",
                "a second root".into(),
            ));
        }
        if depth > open.len() || (tree.is_none() && depth > 0) {
            let allowed = if tree.is_none() { 0 } else { 2 * open.len() };
            return Err(err(
                0,
                &format!(
                    "at most {allowed} spaces of indentation (one level deeper than the line above)"
                ),
                format!("{indent} spaces"),
            ));
        }
        for closed in open.drain(depth..).rev() {
            check_closed(&closed)?;
        }
        let composite = kind.is_composite();
        let id = match (&mut tree, open.last_mut()) {
            (None, _) => {
                let t = Tree::new(kind);
                let root = t.root();
                tree = Some(t);
                root
            }
            (Some(t), Some(parent)) => {
                if !parent.composite {
                    return Err(err(
                        indent,
                        &format!(
                            "no deeper indentation: `{}` is a leaf and cannot have children",
                            parent.text.trim()
                        ),
                        "a child".into(),
                    ));
                }
                parent.has_children = true;
                t.push_child(parent.id, kind)
            }
            (Some(_), None) => {
                return Err(err(0, "a single root", "a second root".into()));
            }
        };
        open.push(Open {
            id,
            line,
            text: raw,
            composite,
            has_children: false,
        });
    }
    for closed in open.drain(..).rev() {
        check_closed(&closed)?;
    }
    tree.ok_or_else(|| ParseError {
        line: text.lines().count().max(1),
        column: 1,
        text: String::new(),
        expected: "a tree (`sequence`, `fallback`, a condition `...?` or an action `...!`)".into(),
        found: "no nodes".into(),
    })
}

/// A composite whose children have all been read must have at least one.
fn check_closed(node: &Open) -> Result<(), ParseError> {
    if node.composite && !node.has_children {
        let indent = node.text.len() - node.text.trim_start().len();
        return Err(error(
            node.line,
            node.text,
            indent,
            &format!("at least one child indented under `{}`", node.text.trim()),
            "no children".into(),
        ));
    }
    Ok(())
}

fn error(line: usize, raw: &str, at: usize, expected: &str, found: String) -> ParseError {
    ParseError {
        line,
        column: raw.get(..at).map_or(1, |s| s.chars().count() + 1),
        text: raw.to_string(),
        expected: expected.to_string(),
        found,
    }
}

type NodeError = (usize, String, String);

/// A line's indentation in spaces and the depth it stands for: two spaces per level, no
/// tabs, at most [`super::MAX_DEPTH`] levels.
fn indentation(raw: &str) -> Result<(usize, usize), NodeError> {
    let indent = raw.len() - raw.trim_start_matches(' ').len();
    if raw[indent..].starts_with(char::is_whitespace) {
        return Err((
            indent,
            "indentation made of spaces".into(),
            "a tab or other blank".into(),
        ));
    }
    if !indent.is_multiple_of(2) {
        return Err((
            indent,
            "indentation of two spaces per level".into(),
            format!("{indent} spaces"),
        ));
    }
    let depth = indent / 2;
    if depth > super::MAX_DEPTH {
        return Err((
            indent,
            format!("at most {} levels of nesting", super::MAX_DEPTH),
            format!("level {depth}"),
        ));
    }
    Ok((indent, depth))
}

/// Read the node written at byte `start` of `raw`; errors carry a byte offset.
fn parse_node(raw: &str, start: usize) -> Result<NodeKind, NodeError> {
    let content = raw[start..].trim_end();
    match content {
        "sequence" => return Ok(NodeKind::Sequence),
        "fallback" => return Ok(NodeKind::Fallback),
        _ => {}
    }
    let word_end = content
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(content.len());
    if word_end == content.len() && word_end > 0 {
        return Err((
            start,
            "`sequence`, `fallback`, a condition ending in `?` or an action ending in `!`".into(),
            format!("{content:?}"),
        ));
    }
    let (negated, atom_at) = match content.strip_prefix('~') {
        Some(_) => (true, start + 1),
        None => (false, start),
    };
    let condition = parse_atom_prefix(raw, atom_at);
    if let Ok((atom, end)) = &condition
        && let Some(after) = expect_mark(raw, *end, '?')
    {
        finish(raw, after)?;
        return Ok(NodeKind::Condition(Condition {
            atom: atom.clone(),
            negated,
        }));
    }
    if negated || content.starts_with('"') {
        return match condition {
            Ok((_, end)) => Err(mark_error(raw, end, "`?` after the condition")),
            Err(e) => Err((e.at, e.expected.into(), e.found)),
        };
    }
    match parse_action_prefix(raw, start) {
        Ok((action, end)) => match expect_mark(raw, end, '!') {
            Some(after) => {
                finish(raw, after)?;
                Ok(NodeKind::Action(action))
            }
            None => Err(mark_error(
                raw,
                end,
                "`!` after the action (or `?` after a condition)",
            )),
        },
        Err(e) => Err((e.at, e.expected.into(), e.found)),
    }
}

/// If the next non-blank character after byte `at` is `mark`, the offset just after it.
fn expect_mark(raw: &str, at: usize, mark: char) -> Option<usize> {
    let rest = raw.get(at..)?;
    let skipped = rest.len() - rest.trim_start_matches([' ', '\t']).len();
    rest[skipped..]
        .starts_with(mark)
        .then_some(at + skipped + mark.len_utf8())
}

fn mark_error(raw: &str, at: usize, expected: &str) -> NodeError {
    let rest = raw.get(at..).unwrap_or_default();
    let at = at + (rest.len() - rest.trim_start().len());
    (at, expected.into(), found_at(raw, at))
}

/// Nothing but blanks may follow the `?` or `!`.
fn finish(raw: &str, at: usize) -> Result<(), NodeError> {
    let rest = raw.get(at..).unwrap_or_default();
    let junk = rest.trim_start();
    if junk.is_empty() {
        return Ok(());
    }
    let at = at + (rest.len() - junk.len());
    Err((at, "end of line after `?` or `!`".into(), found_at(raw, at)))
}

fn found_at(raw: &str, at: usize) -> String {
    match raw.get(at..).and_then(|s| s.chars().next()) {
        Some(c) => format!("{c:?}"),
        None => "end of line".into(),
    }
}

#[cfg(test)]
#[path = "text_tests.rs"]
mod tests;
