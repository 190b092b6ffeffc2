//! Drawing the monitor screen: the tree with statuses, the selected node, the latest
//! changes and the connection.

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};
use tui_tree_widget::{Tree as TreeWidget, TreeItem};

use crate::http_text::printable;
use crate::monitor::{LiveTree, NodeKind, NodeStatus};

use super::{Connection, Mode, MonitorScreen};

pub fn draw(frame: &mut Frame, screen: &mut MonitorScreen) {
    let [main, bar] =
        Layout::vertical([Constraint::Min(3), Constraint::Length(1)]).areas(frame.area());
    let [tree_area, side] =
        Layout::horizontal([Constraint::Percentage(60), Constraint::Percentage(40)]).areas(main);
    let [details, recent] =
        Layout::vertical([Constraint::Percentage(45), Constraint::Percentage(55)]).areas(side);
    draw_tree(frame, screen, tree_area);
    draw_details(frame, screen, details);
    draw_recent(frame, screen, recent);
    draw_bar(frame, screen, bar);
}

fn block(screen: &MonitorScreen, title: String) -> Block<'static> {
    Block::default()
        .borders(Borders::ALL)
        .border_style(screen.theme.border)
        .title(Span::styled(title, screen.theme.title))
}

fn draw_tree(frame: &mut Frame, screen: &mut MonitorScreen, area: Rect) {
    let Some(live) = &screen.live else {
        let text = match &screen.connection {
            Connection::Waiting(Some(reason)) => format!("{reason}\n\ntrying again…"),
            _ => format!("connecting to {}…", screen.address),
        };
        let pane = Paragraph::new(text)
            .wrap(Wrap { trim: false })
            .block(block(screen, " tree ".into()));
        frame.render_widget(pane, area);
        return;
    };
    let items = items(live, screen);
    let title = format!(" {} ", printable(&live.tree.main));
    match TreeWidget::new(&items) {
        Ok(widget) => {
            let widget = widget
                .block(block(screen, title))
                .highlight_style(screen.theme.selected);
            frame.render_stateful_widget(widget, area, &mut screen.state);
        }
        Err(e) => {
            // Uids are unique in a read tree (`WatchedTree::parse` refuses repeats).
            tracing::warn!(error = %e, "the watched tree's rows cannot be drawn");
        }
    }
}

/// The widget's rows, children before parents (no recursion: nodes are in depth-first
/// order, so every node comes after its parent).
fn items(live: &LiveTree, screen: &MonitorScreen) -> Vec<TreeItem<'static, u16>> {
    let ascii = screen.glyphs.success.is_ascii();
    let mut built: Vec<Option<TreeItem<'static, u16>>> = vec![None; live.tree.nodes.len()];
    for (i, node) in live.tree.nodes.iter().enumerate().rev() {
        let status = live.statuses[i];
        let style = screen.theme.status(status.as_status());
        let label = if screen.matches(i) {
            style.add_modifier(Modifier::UNDERLINED | Modifier::BOLD)
        } else {
            style
        };
        let stop = if screen.stopped == Some(node.uid) {
            Span::styled(if ascii { "> " } else { "▶ " }, screen.theme.error)
        } else if screen.breakpoints.contains(&node.uid) {
            Span::styled(if ascii { "o " } else { "● " }, screen.theme.error)
        } else {
            Span::raw("")
        };
        let line = Line::from(vec![
            stop,
            Span::styled(format!("[{}] ", mark(screen, status)), style),
            Span::styled(live.tree.describe(node), label),
        ]);
        let children: Vec<TreeItem<'static, u16>> = node
            .children
            .iter()
            .filter_map(|&c| built[c].take())
            .collect();
        let item = if children.is_empty() {
            TreeItem::new_leaf(node.uid, line)
        } else {
            TreeItem::new(node.uid, line.clone(), children)
                .unwrap_or_else(|_| TreeItem::new_leaf(node.uid, line))
        };
        built[i] = Some(item);
    }
    built
        .first_mut()
        .and_then(Option::take)
        .into_iter()
        .collect()
}

fn mark(screen: &MonitorScreen, status: NodeStatus) -> &'static str {
    let g = screen.glyphs;
    match status {
        NodeStatus::Idle => " ",
        NodeStatus::Skipped => g.idle,
        NodeStatus::Running => g.running,
        NodeStatus::Success => g.success,
        NodeStatus::Failure => g.failure,
    }
}

fn draw_details(frame: &mut Frame, screen: &MonitorScreen, area: Rect) {
    let mut lines = Vec::new();
    if let (Some(live), Some(i)) = (&screen.live, screen.selected()) {
        let node = &live.tree.nodes[i];
        let kind = match node.kind {
            NodeKind::Unknown => "a node the publisher's model does not describe",
            kind => kind.name(),
        };
        lines.push(Line::from(vec![
            Span::styled(printable(&node.id).into_owned(), screen.theme.title),
            Span::raw(format!("  {:?}", printable(&node.name))),
        ]));
        lines.push(Line::raw(format!(
            "{kind} · path {} · uid {}",
            node.path, node.uid
        )));
        lines.push(Line::from(vec![
            Span::raw("status "),
            Span::styled(
                live.statuses[i].name(),
                screen.theme.status(live.statuses[i].as_status()),
            ),
        ]));
        if node.ports.is_empty() {
            lines.push(Line::styled("no ports", screen.theme.dim));
        }
        let board = screen
            .blackboards
            .iter()
            .find(|b| b.name == node.blackboard);
        for (port, value) in &node.ports {
            let entry = value
                .strip_prefix('{')
                .and_then(|v| v.strip_suffix('}'))
                .map(|name| match board.and_then(|b| b.get(name)) {
                    Some(now) => format!(
                        "  (blackboard entry {}: {})",
                        printable(name),
                        printable(now)
                    ),
                    None => format!("  (blackboard entry {})", printable(name)),
                })
                .unwrap_or_default();
            lines.push(Line::raw(format!(
                "{} = {}{entry}",
                printable(port),
                printable(value)
            )));
        }
        if let Some(board) = board {
            lines.push(Line::styled(
                format!("blackboard {}", printable(&board.name)),
                screen.theme.title,
            ));
            if board.entries.is_empty() {
                lines.push(Line::styled("no entries", screen.theme.dim));
            }
            for (key, value) in &board.entries {
                lines.push(Line::raw(format!(
                    "{} = {}",
                    printable(key),
                    printable(value)
                )));
            }
        }
    }
    let pane = Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(block(screen, " node ".into()));
    frame.render_widget(pane, area);
}

fn draw_recent(frame: &mut Frame, screen: &MonitorScreen, area: Rect) {
    if let Some(why) = &screen.not_run {
        let pane = Paragraph::new(printable(why).into_owned())
            .wrap(Wrap { trim: false })
            .block(block(screen, " not run by betr's engine ".into()));
        frame.render_widget(pane, area);
        return;
    }
    let rows = usize::from(area.height.saturating_sub(2));
    let skip = screen.recent.len().saturating_sub(rows);
    let arrow = if screen.glyphs.success.is_ascii() {
        "->"
    } else {
        "→"
    };
    let lines: Vec<Line> = match &screen.live {
        Some(live) => screen
            .recent
            .iter()
            .skip(skip)
            .map(|(since, change)| {
                Line::raw(
                    live.describe_change(*since, change, arrow)
                        .trim_start()
                        .to_string(),
                )
            })
            .collect(),
        None => Vec::new(),
    };
    let title = if screen.missed == 0 {
        format!(" status changes ({}) ", screen.changes)
    } else {
        format!(
            " status changes ({}; some missed {} times: the publisher keeps 1000) ",
            screen.changes, screen.missed
        )
    };
    frame.render_widget(Paragraph::new(lines).block(block(screen, title)), area);
}

fn draw_bar(frame: &mut Frame, screen: &MonitorScreen, area: Rect) {
    let ascii = screen.glyphs.success.is_ascii();
    let dot = if ascii { " | " } else { " · " };
    if let Some(typed) = &screen.typing {
        let text = format!(" find: {typed}_{dot}Enter find{dot}Esc cancel");
        frame.render_widget(
            Paragraph::new(Span::styled(text, screen.theme.status_bar)),
            area,
        );
        return;
    }
    let stopped = screen.stopped.and_then(|uid| {
        let live = screen.live.as_ref()?;
        Some(live.tree.describe(live.tree.by_uid(uid)?))
    });
    if let Some(node) = stopped {
        let text = if screen.mode == Mode::Live {
            format!(
                " stopped before {node}{dot}c go on{dot}s succeed it{dot}x fail it{dot}b remove the breakpoint"
            )
        } else {
            let playback = screen.playback.as_deref().unwrap_or_default();
            format!("{playback}{dot}stopped at a breakpoint before {node}")
        };
        frame.render_widget(
            Paragraph::new(Span::styled(text, screen.theme.stopped)),
            area,
        );
        return;
    }
    if let Some(reason) = &screen.said {
        frame.render_widget(
            Paragraph::new(Span::styled(format!(" {reason}"), screen.theme.error)),
            area,
        );
        return;
    }
    let (mut state, style) = match (&screen.playback, &screen.connection) {
        (Some(playback), Connection::Lost(reason)) => (
            format!("{playback}{dot}the connection was lost: {reason}"),
            screen.theme.error,
        ),
        (Some(playback), _) => (playback.clone(), screen.theme.status_bar),
        (None, connection) => connection_state(screen, connection, dot),
    };
    if let Some(query) = &screen.not_found {
        state.push_str(&format!("{dot}no node matches {:?}", printable(query)));
    }
    let keys = match screen.mode {
        Mode::Live => watch_keys(dot, ascii),
        Mode::Replay => replay_keys(dot),
        Mode::File => file_keys(dot, ascii),
    };
    let width = usize::from(area.width);
    let text = match keys
        .iter()
        .find(|k| state.chars().count() + k.chars().count() <= width)
    {
        Some(keys) => format!("{state}{keys}"),
        // A long reason is cut rather than the way out.
        None => {
            let room = width.saturating_sub(keys[3].chars().count() + 1);
            let cut: String = state.chars().take(room).collect();
            format!("{cut}…{}", keys[3])
        }
    };
    frame.render_widget(Paragraph::new(Span::styled(text, style)), area);
}

/// The status bar's state of a live watch.
fn connection_state(
    screen: &MonitorScreen,
    connection: &Connection,
    dot: &str,
) -> (String, ratatui::style::Style) {
    match connection {
        Connection::Watching => {
            let nodes = screen.live.as_ref().map_or(0, |l| l.tree.nodes.len());
            let follow = if screen.follow {
                "following"
            } else {
                "not following"
            };
            (
                format!(
                    " watching {}{dot}{nodes} nodes{dot}{follow}",
                    screen.address
                ),
                screen.theme.status_bar,
            )
        }
        Connection::Lost(reason) | Connection::Waiting(Some(reason)) => {
            (format!(" {reason}; trying again"), screen.theme.error)
        }
        Connection::Waiting(None) => (
            format!(" connecting to {}", screen.address),
            screen.theme.status_bar,
        ),
    }
}

/// The keys said after the state, fewer of them when the terminal is narrow; quitting is
/// always said.
fn watch_keys(dot: &str, ascii: bool) -> [String; 4] {
    let fold = if ascii { "h/l fold" } else { "←→ fold" };
    [
        format!(
            "{dot}f follow{dot}{fold}{dot}E/C open/close all{dot}/ find{dot}b breakpoint{dot}q quit"
        ),
        format!("{dot}f follow{dot}/ find{dot}b breakpoint{dot}q quit"),
        format!("{dot}f follow{dot}q quit"),
        format!("{dot}q quit"),
    ]
}

fn file_keys(dot: &str, ascii: bool) -> [String; 4] {
    let fold = if ascii { "h/l fold" } else { "←→ fold" };
    [
        format!("{dot}{fold}{dot}E/C open/close all{dot}/ find{dot}n next{dot}q quit"),
        format!("{dot}{fold}{dot}/ find{dot}q quit"),
        format!("{dot}/ find{dot}q quit"),
        format!("{dot}q quit"),
    ]
}

fn replay_keys(dot: &str) -> [String; 4] {
    [
        format!(
            "{dot}space play{dot}. , step{dot}] [ failure{dot}g G start/end{dot}/ find{dot}q quit"
        ),
        format!("{dot}space play{dot}. , step{dot}q quit"),
        format!("{dot}space play{dot}q quit"),
        format!("{dot}q quit"),
    ]
}
