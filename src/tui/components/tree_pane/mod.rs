//! The live behavior tree (tui-tree-widget): each node with its status symbol and
//! colour, collapsible; nodes added by the last expansion highlighted, the failing action
//! marked, and the debugger's marks: breakpoints, forced statuses and the node a run
//! stopped at. Items are rebuilt only when the tree or the statuses change, iteratively (no
//! recursion, so deep trees are fine); the widget draws only the visible rows.
//!
//! Long labels deep in a tree scroll sideways. tui-tree-widget 0.24 has no horizontal
//! offset (its rows always start at the pane's left edge), so a scrolled pane draws the
//! widget into a buffer as much wider as it is scrolled and copies the columns in view:
//! indentation, fold symbols and highlight move together, and clicks still find their
//! row (the widget matches them by row only).

use std::sync::Arc;

use crossterm::event::{KeyCode, KeyEvent};
use ratatui::Frame;
use ratatui::buffer::Buffer;
use ratatui::layout::{Position, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};
use tui_tree_widget::{Tree as TreeWidget, TreeItem, TreeState};

use crate::bt::{Forced, NodeId, Status, TickRecord, Tree};

mod items;

use items::{build_items, composite_paths, copy_columns, node_label};

use super::super::strings;
use super::super::theme::Theme;

#[derive(Default)]
pub struct TreePane {
    /// What the pane says with no tree, when not the workbench's hint.
    pub empty_text: Option<&'static str>,
    tree: Option<Arc<Tree>>,
    record: Option<Arc<TickRecord>>,
    marks: Marks,
    items: Vec<TreeItem<'static, u32>>,
    state: TreeState<u32>,
    dirty: bool,
    /// Select the running node after every tick.
    pub follow: bool,
    /// The last search, for next and previous.
    pub query: Option<String>,
    /// Whether keys go to this pane (its border says so).
    pub focused: bool,
    /// Columns scrolled past on the left.
    column: usize,
    /// Each node's label width in cells, by node index (rebuilt with the items).
    widths: Vec<usize>,
    /// The widest shown row and the pane's inner width at the last draw: how far the
    /// pane can scroll sideways.
    extent: (usize, usize),
}

/// Columns one sideways key or wheel notch moves the tree.
const SIDEWAYS_STEP: usize = 8;

/// Where a search stands: the match selected (from 1) of how many.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Found {
    pub at: usize,
    pub of: usize,
}

/// What the pane marks on nodes besides their status.
#[derive(Default)]
struct Marks {
    /// Added by the last change.
    new_nodes: Vec<NodeId>,
    /// Conditions learned rules put there, with the rules' ids.
    learned: Vec<(NodeId, Vec<String>)>,
    failing: Option<NodeId>,
    breakpoints: Vec<NodeId>,
    forced: Vec<(NodeId, Forced)>,
    /// Where a run stopped (a breakpoint, or a failure with break-on-failure), until the
    /// next tick.
    stopped: Option<NodeId>,
}

impl TreePane {
    pub fn set_tree(
        &mut self,
        tree: Arc<Tree>,
        new_nodes: Vec<NodeId>,
        learned: Vec<(NodeId, Vec<String>)>,
    ) {
        self.state = TreeState::default();
        for path in composite_paths(&tree) {
            self.state.open(path);
        }
        let focus = new_nodes.first().copied();
        self.tree = Some(tree);
        self.marks.new_nodes = new_nodes;
        self.marks.learned = learned;
        self.record = None;
        self.marks.failing = None;
        self.marks.stopped = None;
        self.dirty = true;
        if let Some(n) = focus {
            self.select(n);
        }
    }

    /// Whether the last tick ended with the root failed.
    pub fn root_failed(&self) -> bool {
        self.record
            .as_ref()
            .is_some_and(|r| r.root == crate::bt::Outcome::Failure)
    }

    pub fn set_record(&mut self, record: Arc<TickRecord>) {
        self.record = Some(record);
        self.marks.stopped = None;
        self.dirty = true;
        if self.follow {
            self.show_running(false);
        }
    }

    /// The node the last tick is at: the deepest running node, else the last failing
    /// action.
    pub fn running(&self) -> Option<NodeId> {
        let tree = self.tree.as_ref()?;
        let record = self.record.as_ref()?;
        tree.preorder()
            .into_iter()
            .rev()
            .find(|n| record.status(*n) == Status::Running)
            .or(self.marks.failing)
    }

    /// Open the way to the running node and select it; `alone`: close everything else.
    pub fn show_running(&mut self, alone: bool) -> bool {
        let Some(node) = self.running() else {
            return false;
        };
        if alone {
            self.state.close_all();
        }
        self.open_to(node);
        self.select(node);
        true
    }

    /// Close every node but the root, and select it.
    pub fn collapse_all(&mut self) {
        self.state.close_all();
        if let Some(tree) = &self.tree {
            let root = tree.root();
            self.state.open(vec![root.0]);
            self.select(root);
        }
    }

    /// Open every node.
    pub fn expand_all(&mut self) {
        if let Some(tree) = &self.tree {
            for path in composite_paths(tree) {
                self.state.open(path);
            }
        }
    }

    /// Select the next (or previous) node whose label holds `query` (any case), after
    /// the selected one in the tree's order, wrapping; its ancestors are opened.
    pub fn search(&mut self, query: &str, forward: bool, theme: &Theme) -> Option<Found> {
        let tree = self.tree.clone()?;
        let query = query.to_lowercase();
        // Every match is marked at the next drawing.
        self.dirty = true;
        let order = tree.preorder();
        let matches: Vec<NodeId> = order
            .iter()
            .copied()
            .filter(|n| node_label(&tree, *n, theme).to_lowercase().contains(&query))
            .collect();
        if matches.is_empty() {
            return None;
        }
        let position = |n: NodeId| order.iter().position(|m| *m == n).unwrap_or(0);
        let here = self.selected().map(position);
        let next = match (here, forward) {
            (None, true) => 0,
            (None, false) => matches.len() - 1,
            (Some(h), true) => matches.iter().position(|m| position(*m) > h).unwrap_or(0),
            (Some(h), false) => matches
                .iter()
                .rposition(|m| position(*m) < h)
                .unwrap_or(matches.len() - 1),
        };
        let node = matches[next];
        self.open_to(node);
        self.select(node);
        Some(Found {
            at: next + 1,
            of: matches.len(),
        })
    }

    /// Open every ancestor of `node`.
    fn open_to(&mut self, node: NodeId) {
        let Some(tree) = &self.tree else {
            return;
        };
        let mut path: Vec<u32> = Vec::new();
        let mut at = tree.parent(node).ok().flatten();
        while let Some(n) = at {
            path.push(n.0);
            at = tree.parent(n).ok().flatten();
        }
        path.reverse();
        for depth in 1..=path.len() {
            self.state.open(path[..depth].to_vec());
        }
    }

    /// A mouse click on the pane selects (and toggles) the row; the wheel scrolls, and
    /// the horizontal wheel (or the wheel with Shift held) scrolls sideways.
    pub fn mouse(&mut self, event: &crossterm::event::MouseEvent) {
        use crossterm::event::{KeyModifiers, MouseButton, MouseEventKind};
        let at = Position::new(event.column, event.row);
        let shift = event.modifiers.contains(KeyModifiers::SHIFT);
        match event.kind {
            MouseEventKind::Down(MouseButton::Left) => {
                self.state.click_at(at);
            }
            MouseEventKind::ScrollLeft => self.scroll_left(),
            MouseEventKind::ScrollRight => self.scroll_right(),
            MouseEventKind::ScrollUp if shift => self.scroll_left(),
            MouseEventKind::ScrollDown if shift => self.scroll_right(),
            MouseEventKind::ScrollDown => {
                self.state.scroll_down(3);
            }
            MouseEventKind::ScrollUp => {
                self.state.scroll_up(3);
            }
            _ => {}
        }
    }

    /// Scroll towards the labels' starts.
    pub fn scroll_left(&mut self) {
        self.column = self.column.saturating_sub(SIDEWAYS_STEP);
    }

    /// Scroll towards the labels' ends, no further than the widest row shown needs.
    pub fn scroll_right(&mut self) {
        self.column = (self.column + SIDEWAYS_STEP).min(self.max_column());
    }

    /// Columns scrolled past on the left.
    pub fn column(&self) -> usize {
        self.column
    }

    fn max_column(&self) -> usize {
        let (widest, width) = self.extent;
        widest.saturating_sub(width)
    }

    /// Statuses back to "not ticked" (the world was reset).
    pub fn clear_statuses(&mut self) {
        self.record = None;
        self.marks.failing = None;
        self.marks.stopped = None;
        self.dirty = true;
    }

    pub fn set_failing(&mut self, node: NodeId) {
        self.marks.failing = Some(node);
        self.dirty = true;
        self.select(node);
    }

    pub fn set_breakpoints(&mut self, nodes: Vec<NodeId>) {
        self.marks.breakpoints = nodes;
        self.dirty = true;
    }

    pub fn set_forced(&mut self, forced: Vec<(NodeId, Forced)>) {
        self.marks.forced = forced;
        self.dirty = true;
    }

    /// Mark and select the node a run stopped at.
    pub fn set_stopped(&mut self, node: NodeId) {
        self.marks.stopped = Some(node);
        self.dirty = true;
        self.select(node);
    }

    /// The selected node, if any.
    pub fn selected(&self) -> Option<NodeId> {
        let node = NodeId(*self.state.selected().last()?);
        self.tree.as_ref()?.contains(node).then_some(node)
    }

    /// The selected node whole: its label, where it is, its status and its marks.
    pub fn selected_details(&self, theme: &Theme) -> Option<Vec<String>> {
        let node = self.selected()?;
        let tree = self.tree.as_ref()?;
        let status = self
            .record
            .as_ref()
            .map_or(Status::Idle, |r| r.status(node));
        let mut lines = vec![
            node_label(tree, node, theme),
            format!(
                "node {}",
                tree.path(node)
                    .map(|p| crate::bt::path_text(&p))
                    .unwrap_or_default()
            ),
            format!("status: {}", strings::status_word(status)),
        ];
        if self.marks.new_nodes.contains(&node) {
            lines.push(strings::ADDED_BY_LAST_CHANGE.to_string());
        }
        if self.marks.failing == Some(node) {
            lines.push(strings::FAILED_MARK.to_string());
        }
        if let Some((_, rules)) = self.marks.learned.iter().find(|(n, _)| *n == node) {
            lines.push(strings::learned_mark(rules).trim().to_string());
        }
        if self.marks.breakpoints.contains(&node) {
            lines.push(strings::BREAKPOINT_MARK.to_string());
        }
        if let Some((_, forced)) = self.marks.forced.iter().find(|(n, _)| *n == node) {
            lines.push(strings::forced_mark(*forced).trim().to_string());
        }
        Some(lines)
    }

    /// The nodes with a breakpoint.
    pub fn breakpoints(&self) -> &[NodeId] {
        &self.marks.breakpoints
    }

    /// `node` as the pane shows it (`grasp "blue cube"!`, `[-] Sequence`).
    pub fn label(&self, node: NodeId, theme: &Theme) -> String {
        self.tree
            .as_ref()
            .map(|t| node_label(t, node, theme))
            .unwrap_or_default()
    }

    pub fn has_tree(&self) -> bool {
        self.tree.is_some()
    }

    /// Take `previous`'s folds, selection and scroll when it shows the same tree; a node
    /// this pane marks as failing or stopped that `previous` did not is selected still.
    pub fn adopt_view(&mut self, previous: &mut TreePane) {
        let same = match (&self.tree, &previous.tree) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        };
        if !same {
            return;
        }
        self.state = std::mem::take(&mut previous.state);
        let focus = [
            (self.marks.stopped, previous.marks.stopped),
            (self.marks.failing, previous.marks.failing),
        ]
        .into_iter()
        .find_map(|(now, before)| now.filter(|n| Some(*n) != before));
        if let Some(node) = focus {
            self.select(node);
        }
    }

    fn select(&mut self, node: NodeId) {
        if let Some(tree) = &self.tree {
            let mut path: Vec<u32> = Vec::new();
            let mut at = Some(node);
            while let Some(n) = at {
                path.push(n.0);
                at = tree.parent(n).ok().flatten();
            }
            path.reverse();
            self.state.select(path);
        }
    }

    /// Navigation keys; true when consumed.
    pub fn event(&mut self, key: &KeyEvent) -> bool {
        match key.code {
            KeyCode::Up | KeyCode::Char('k') => self.state.key_up(),
            KeyCode::Down | KeyCode::Char('j') => self.state.key_down(),
            KeyCode::Left => self.state.key_left(),
            KeyCode::Right => self.state.key_right(),
            KeyCode::Enter => self.state.toggle_selected(),
            KeyCode::Home => self.state.select_first(),
            KeyCode::End => self.state.select_last(),
            KeyCode::PageDown => self.state.scroll_down(10),
            KeyCode::PageUp => self.state.scroll_up(10),
            _ => return false,
        };
        true
    }

    fn rebuild(&mut self, theme: &Theme) {
        if !self.dirty {
            return;
        }
        self.dirty = false;
        self.widths = vec![0; self.tree.as_ref().map_or(0, |t| t.capacity())];
        self.items = match &self.tree {
            Some(tree) => vec![build_items(
                tree,
                self.record.as_deref(),
                &self.marks,
                self.query.as_deref(),
                theme,
                &mut self.widths,
            )],
            None => Vec::new(),
        };
    }

    pub fn draw(&mut self, frame: &mut Frame, area: Rect, theme: &Theme) {
        self.rebuild(theme);
        let border = if self.focused {
            theme.focused
        } else {
            theme.border
        };
        let mut block = Block::default()
            .borders(Borders::ALL)
            .border_style(border)
            .title(Span::styled(strings::TREE_TITLE, theme.title));
        if self.follow {
            block = block.title(Span::styled(strings::FOLLOWING, theme.key));
        }
        if let Some(q) = &self.query {
            block = block.title_bottom(Span::styled(strings::searching(q), theme.dim));
        }
        if self.items.is_empty() {
            self.column = 0;
            let text = Paragraph::new(self.empty_text.unwrap_or(strings::TREE_EMPTY))
                .style(theme.dim)
                .wrap(Wrap { trim: true })
                .block(block);
            frame.render_widget(text, area);
            return;
        }
        let inner = block.inner(area);
        self.extent = (self.widest_row(), usize::from(inner.width));
        self.column = self.column.min(self.max_column());
        if let Some(mark) = strings::sideways(self.column, self.column < self.max_column()) {
            block = block.title(Line::from(Span::styled(mark, theme.key)).right_aligned());
        }
        let widget = match TreeWidget::new(&self.items) {
            Ok(widget) => widget
                .highlight_style(theme.selected)
                .node_closed_symbol("▸ ")
                .node_open_symbol("▾ ")
                .node_no_children_symbol("  "),
            Err(e) => {
                tracing::warn!(error = %e, "cannot draw the tree");
                return;
            }
        };
        frame.render_widget(block, area);
        if self.column == 0 {
            frame.render_stateful_widget(widget, inner, &mut self.state);
            return;
        }
        // Drawn as wide as the scrolled-past columns plus the pane, then the part in view
        // copied over.
        let column = u16::try_from(self.column).unwrap_or(u16::MAX);
        let wide = Rect {
            width: inner.width.saturating_add(column),
            ..inner
        };
        let mut drawn = Buffer::empty(wide);
        ratatui::widgets::StatefulWidget::render(widget, wide, &mut drawn, &mut self.state);
        copy_columns(&drawn, frame.buffer_mut(), inner, column);
    }

    /// The widest row the widget shows now: indentation, fold symbol and label.
    fn widest_row(&self) -> usize {
        self.state
            .flatten(&self.items)
            .iter()
            .map(|row| {
                let label = row
                    .identifier
                    .last()
                    .and_then(|id| self.widths.get(NodeId(*id).index()))
                    .copied()
                    .unwrap_or(0);
                row.depth() * 2 + 2 + label
            })
            .max()
            .unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bt::NodeKind;
    use crate::domain::{ActionCall, Condition};
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;
    use ratatui::style::Modifier;

    /// A tree of `n` nodes: a fallback of sequences, each a condition and an action.
    fn big(n: usize) -> Tree {
        let mut t = Tree::new(NodeKind::Fallback);
        let mut count = 1;
        let mut parent = t.root();
        while count < n {
            let seq = t.add_child(parent, NodeKind::Sequence).unwrap();
            let c = Condition::parse(&format!("Done_{count}")).unwrap();
            t.add_child(seq, NodeKind::Condition(c)).unwrap();
            let a = ActionCall::parse(&format!("Do \"thing {count}\"")).unwrap();
            t.add_child(seq, NodeKind::Action(a)).unwrap();
            count += 3;
            if count % 300 == 1 {
                parent = seq;
            }
        }
        t
    }

    #[test]
    fn search_finds_next_and_previous_and_opens_the_way() {
        let tree = Arc::new(big(300));
        let theme = Theme::default();
        let mut pane = TreePane::default();
        pane.set_tree(tree.clone(), Vec::new(), Vec::new());
        pane.collapse_all();
        let found = pane.search("thing 1", true, &theme).unwrap();
        // The actions are numbered 1, 4, 7, …: those whose number starts with a 1.
        let expected = (1..300)
            .step_by(3)
            .filter(|n: &usize| n.to_string().starts_with('1'))
            .count();
        assert_eq!(found.of, expected);
        let first = pane.selected().unwrap();
        assert!(pane.label(first, &theme).contains("\"thing 1\""));
        let second = pane.search("thing 1", true, &theme).unwrap();
        assert_eq!(second.at, 2);
        let back = pane.search("thing 1", false, &theme).unwrap();
        assert_eq!(back.at, 1);
        assert_eq!(pane.selected(), Some(first));
        // Previous from the first wraps to the last.
        let last = pane.search("thing 1", false, &theme).unwrap();
        assert_eq!(last.at, last.of);
        assert!(pane.search("no such node", true, &theme).is_none());
        // The match is drawn: its ancestors were opened.
        let mut terminal = Terminal::new(TestBackend::new(80, 24)).unwrap();
        terminal.draw(|f| pane.draw(f, f.area(), &theme)).unwrap();
        let label = pane.label(pane.selected().unwrap(), &theme);
        assert!(terminal.backend().to_string().contains(&label));
        pane.query = Some("thing 1".into());
        pane.follow = true;
        terminal.draw(|f| pane.draw(f, f.area(), &theme)).unwrap();
        insta::assert_snapshot!("searched_300_nodes_80x24", terminal.backend().to_string());
    }

    /// Every row whose label holds the search is underlined, not only the selected one;
    /// `+` opens again what `C` closed.
    #[test]
    fn every_match_is_marked_and_expand_all_opens_everything() {
        let tree = Arc::new(big(40));
        let theme = Theme::default();
        let mut pane = TreePane::default();
        pane.set_tree(tree.clone(), Vec::new(), Vec::new());
        pane.collapse_all();
        pane.expand_all();
        pane.query = Some("THING 1".into());
        pane.search("THING 1", true, &theme).unwrap();
        let mut terminal = Terminal::new(TestBackend::new(60, 45)).unwrap();
        terminal.draw(|f| pane.draw(f, f.area(), &theme)).unwrap();
        let buffer = terminal.backend().buffer().clone();
        let mut marked = 0;
        for y in 1..buffer.area.height - 1 {
            let row: String = (0..buffer.area.width)
                .map(|x| buffer[(x, y)].symbol().to_string())
                .collect();
            let underlined = (0..buffer.area.width)
                .any(|x| buffer[(x, y)].modifier.contains(Modifier::UNDERLINED));
            // The label, not what a sequence is said to be for (" to Do …!").
            let label = row.split(" to ").next().unwrap_or_default();
            assert_eq!(label.contains("\"thing 1"), underlined, "row {y}: {row}");
            marked += usize::from(underlined);
        }
        // Actions 1, 10, 13, 16, 19 (numbered 1, 4, 7, …): all open, all marked.
        assert_eq!(marked, 5);
    }

    /// The new-node colour marks the rows of new nodes only.
    #[test]
    fn only_the_new_nodes_rows_carry_the_new_node_colour() {
        let tree = Arc::new(big(13));
        let theme = Theme::default();
        let mut pane = TreePane::default();
        pane.set_tree(tree.clone(), Vec::new(), Vec::new());
        pane.search("thing 4", true, &theme).unwrap();
        let new = pane.selected().unwrap();
        pane.set_tree(tree, vec![new], Vec::new());
        let mut terminal = Terminal::new(TestBackend::new(60, 20)).unwrap();
        terminal.draw(|f| pane.draw(f, f.area(), &theme)).unwrap();
        let buffer = terminal.backend().buffer();
        let coloured = |y: u16| {
            (0..buffer.area.width).any(|x| buffer[(x, y)].bg == theme.new_node.bg.unwrap())
        };
        let text = |y: u16| -> String {
            (0..buffer.area.width)
                .map(|x| buffer[(x, y)].symbol())
                .collect()
        };
        let marked: Vec<String> = (0..buffer.area.height)
            .filter(|y| coloured(*y))
            .map(text)
            .collect();
        assert_eq!(marked.len(), 1, "{marked:#?}");
        assert!(marked[0].contains("thing 4"), "{marked:#?}");
    }

    #[test]
    fn five_thousand_nodes_render() {
        // How fast is measured by `cargo bench --bench tree_render`; here only that a large tree draws,
        // and draws the same again.
        let tree = Arc::new(big(5000));
        assert!(tree.len() >= 5000);
        let mut pane = TreePane::default();
        let theme = Theme::default();
        let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
        pane.set_tree(tree.clone(), vec![tree.root()], Vec::new());
        terminal.draw(|f| pane.draw(f, f.area(), &theme)).unwrap();
        let first = terminal.backend().to_string();
        assert!(first.contains("Fallback"), "{first}");
        terminal.draw(|f| pane.draw(f, f.area(), &theme)).unwrap();
        assert_eq!(terminal.backend().to_string(), first);
    }
}
