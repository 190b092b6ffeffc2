//! The widget's items: each node's row (status, label, marks) built children first, and
//! the copy of a wider drawing that scrolls the pane sideways.

use ratatui::buffer::Buffer;
use ratatui::layout::{Position, Rect};
use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use tui_tree_widget::TreeItem;

use crate::bt::{NodeId, NodeKind, Status, TickRecord, Tree};

use super::super::super::strings;
use super::super::super::theme::Theme;
use super::Marks;

/// Identifier paths of every composite, to open them all.
pub(super) fn composite_paths(tree: &Tree) -> Vec<Vec<u32>> {
    let mut out = Vec::new();
    let mut stack: Vec<(NodeId, Vec<u32>)> = vec![(tree.root(), vec![tree.root().0])];
    while let Some((node, path)) = stack.pop() {
        let children = tree.children(node).unwrap_or_default();
        if children.is_empty() {
            continue;
        }
        for c in children {
            let mut p = path.clone();
            p.push(c.0);
            stack.push((*c, p));
        }
        out.push(path);
    }
    out
}

/// The widget's items for `tree`, children before parents (no recursion); every label
/// holding `query` (any case) is underlined.
pub(super) fn build_items(
    tree: &Tree,
    record: Option<&TickRecord>,
    marks: &Marks,
    query: Option<&str>,
    theme: &Theme,
    widths: &mut [usize],
) -> TreeItem<'static, u32> {
    let query = query.map(str::to_lowercase);
    let mut built: Vec<Option<TreeItem<'static, u32>>> = vec![None; tree.capacity()];
    let order = tree.preorder();
    for &node in order.iter().rev() {
        let status = record.map_or(Status::Idle, |r| r.status(node));
        let mut line = decorated_line(tree, node, status, marks, theme);
        if let Some(query) = &query
            && node_label(tree, node, theme)
                .to_lowercase()
                .contains(query.as_str())
            && let Some(label) = line.spans.get_mut(2)
        {
            label.style = label
                .style
                .add_modifier(Modifier::UNDERLINED | Modifier::BOLD);
        }
        if let Some(w) = widths.get_mut(node.index()) {
            *w = line.width();
        }
        let children: Vec<TreeItem<'static, u32>> = tree
            .children(node)
            .unwrap_or_default()
            .iter()
            .filter_map(|c| built.get_mut(c.index()).and_then(Option::take))
            .collect();
        let item = if children.is_empty() {
            TreeItem::new_leaf(node.0, line)
        } else {
            match TreeItem::new(node.0, line.clone(), children) {
                Ok(item) => item,
                Err(_) => TreeItem::new_leaf(node.0, line),
            }
        };
        if let Some(slot) = built.get_mut(node.index()) {
            *slot = Some(item);
        }
    }
    built
        .get_mut(tree.root().index())
        .and_then(Option::take)
        .unwrap_or_else(|| TreeItem::new_leaf(tree.root().0, ""))
}

/// `[-] Sequence`, `grasp "blue cube"!`.
pub(super) fn node_label(tree: &Tree, node: NodeId, theme: &Theme) -> String {
    let g = theme.glyphs;
    match tree.kind(node) {
        Ok(NodeKind::Sequence) => format!("{} {}", g.sequence, g.sequence_name),
        Ok(NodeKind::Fallback) => format!("{} {}", g.fallback, g.fallback_name),
        Ok(NodeKind::Condition(c)) => format!("{c}{}", g.condition_suffix),
        Ok(NodeKind::Action(a)) => format!("{a}{}", g.action_suffix),
        Err(_) => String::new(),
    }
}

/// What a composite is for, so a collapsed one still says it: ` for "blue cube" on
/// "green cube"`, ` to grasp "blue cube"!`.
fn purpose(tree: &Tree, node: NodeId) -> Option<String> {
    tree.purpose(node).map(|p| format!(" {p}"))
}

/// The status in a row's first brackets: blank for a node not ticked, so that it never
/// reads as the sequence's own `[-]` beside it (`[ ] [-] Sequence`).
fn status_mark(status: Status, theme: &Theme) -> &'static str {
    match status {
        Status::Idle => " ",
        shown => theme.glyphs.status(shown),
    }
}

/// `[✓] [-] Sequence`, `[✕] grasp "blue cube"! ◀ failed`, with `+` before new nodes.
fn node_line(
    tree: &Tree,
    node: NodeId,
    status: Status,
    marks: &Marks,
    theme: &Theme,
) -> Line<'static> {
    let new = marks.new_nodes.contains(&node);
    let failing = marks.failing == Some(node);
    let label = node_label(tree, node, theme);
    let mut spans = vec![
        // Only a new node's column is coloured: a styled blank would put a block of the
        // new-node colour at the start of every row.
        if new {
            Span::styled(strings::NEW_MARK, theme.new_node)
        } else {
            Span::raw(" ")
        },
        Span::styled(
            format!("[{}] ", status_mark(status, theme)),
            theme.status(status),
        ),
    ];
    let style = if failing {
        theme.failing
    } else if marks.stopped == Some(node) {
        theme.stopped
    } else if new {
        theme.new_node.patch(theme.status(status))
    } else {
        theme.status(status)
    };
    spans.push(Span::styled(label, style));
    if let Some(purpose) = purpose(tree, node) {
        spans.push(Span::styled(purpose, theme.dim));
    }
    if failing {
        spans.push(Span::styled(
            format!(" {}", strings::FAILED_MARK),
            theme.error,
        ));
    }
    Line::from(spans)
}

/// `node`'s row: its line and the marks after it (rules, breakpoint, forced, stopped).
fn decorated_line(
    tree: &Tree,
    node: NodeId,
    status: Status,
    marks: &Marks,
    theme: &Theme,
) -> Line<'static> {
    let mut line = node_line(tree, node, status, marks, theme);
    if let Some((_, rules)) = marks.learned.iter().find(|(n, _)| *n == node) {
        line.spans
            .push(Span::styled(strings::learned_mark(rules), theme.dim));
    }
    if marks.breakpoints.contains(&node) {
        line.spans.push(Span::styled(
            format!(" {}", strings::BREAKPOINT_MARK),
            theme.breakpoint,
        ));
    }
    if let Some((_, forced)) = marks.forced.iter().find(|(n, _)| *n == node) {
        line.spans
            .push(Span::styled(strings::forced_mark(*forced), theme.forced));
    }
    if marks.stopped == Some(node) {
        line.spans.push(Span::styled(
            format!(" {}", strings::STOPPED_MARK),
            theme.key,
        ));
    }
    line
}

/// `area` of `to` filled from `from`, `column` cells further right; a wide character cut
/// at either edge becomes a blank.
pub(super) fn copy_columns(from: &Buffer, to: &mut Buffer, area: Rect, column: u16) {
    for y in area.top()..area.bottom() {
        for x in area.left()..area.right() {
            let Some(cell) = from.cell(Position::new(x.saturating_add(column), y)) else {
                continue;
            };
            let mut cell = cell.clone();
            let width = Span::raw(cell.symbol()).width();
            if x + 1 == area.right() && width > 1 {
                cell.set_symbol(" ");
            }
            if let Some(target) = to.cell_mut(Position::new(x, y)) {
                *target = cell;
            }
        }
    }
    // The cell right after a wide character is left blank by the widget; at the left
    // edge its character is out of view, so it shows as a blank.
}
