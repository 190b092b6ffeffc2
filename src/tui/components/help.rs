//! Overlays: the help (generated from the key bindings), and lines in a titled box (a
//! verification report, the rules kept, the details of a proposal or a node, readings).

use ratatui::Frame;
use ratatui::layout::{Constraint, Flex, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Clear, Paragraph, Wrap};

use crate::verify::{Report, Verdict};

use super::super::keys::{KeyBindings, KeyMode};
use super::super::strings;
use super::super::theme::Theme;

/// A box in the middle of `area`, at most `width` × `height`.
fn centered(area: Rect, width: u16, height: u16) -> Rect {
    let [v] = Layout::vertical([Constraint::Length(height.min(area.height))])
        .flex(Flex::Center)
        .areas(area);
    let [h] = Layout::horizontal([Constraint::Length(width.min(area.width))])
        .flex(Flex::Center)
        .areas(v);
    h
}

/// The keys in a box over the screen: in two columns when one does not fit the height and
/// two fit the width, else in one; a list taller than the screen shows the rows from
/// `first` on, and says which rows show and how to scroll. The 3D view's web page, when
/// there is one, stands under the keys on a line of its own, to copy whole.
pub fn draw_help(
    frame: &mut Frame,
    area: Rect,
    (keys, mode): (&KeyBindings, KeyMode),
    viewer_page: Option<&str>,
    first: usize,
    theme: &Theme,
) {
    let entries = keys.help_lines(mode);
    // Borders, the blank line and the footer, and the viewer's page with its heading.
    let fixed = 4 + if viewer_page.is_some() { 2 } else { 0 };
    let two = if entries.len() + fixed > usize::from(area.height) {
        let columns = two_columns(&entries, theme);
        let wide = columns.iter().map(Line::width).max().unwrap_or(0) + 3;
        (wide <= usize::from(area.width)).then_some(columns)
    } else {
        None
    };
    let mut lines = two.unwrap_or_else(|| {
        let key_width = entries
            .iter()
            .map(|(k, _)| k.chars().count())
            .max()
            .unwrap_or(0);
        entries
            .iter()
            .map(|(k, what)| {
                Line::from(vec![
                    Span::styled(format!(" {k:>key_width$}  "), theme.key),
                    Span::raw(*what),
                ])
            })
            .collect()
    });
    let room = usize::from(area.height).saturating_sub(fixed).max(1);
    let total = lines.len();
    let footer = if total > room {
        let from = first.min(total - room);
        lines = lines.split_off(from);
        lines.truncate(room);
        strings::help_rows(from + 1, from + room, total)
    } else {
        strings::HELP_FOOTER.to_string()
    };
    lines.push(Line::from(""));
    if let Some(page) = viewer_page {
        lines.push(Line::from(Span::styled(
            format!(" {}", strings::VIEWER_PAGE),
            theme.title,
        )));
        lines.push(Line::from(format!(" {page}")));
    }
    lines.push(Line::from(Span::styled(format!(" {footer}"), theme.dim)));
    let width = lines.iter().map(Line::width).max().unwrap_or(20) + 3;
    let height = lines.len() + 2;
    let rect = centered(
        area,
        u16::try_from(width).unwrap_or(u16::MAX),
        u16::try_from(height).unwrap_or(u16::MAX),
    );
    frame.render_widget(Clear, rect);
    let block = Block::default()
        .borders(Borders::ALL)
        .border_style(theme.key)
        .title(Span::styled(strings::HELP_TITLE, theme.title));
    frame.render_widget(Paragraph::new(lines).block(block), rect);
}

/// The keys in two columns side by side, each with its own key width.
fn two_columns(entries: &[(String, &'static str)], theme: &Theme) -> Vec<Line<'static>> {
    let rows = entries.len().div_ceil(2);
    let (left, right) = entries.split_at(rows.min(entries.len()));
    let width_of = |column: &[(String, &'static str)]| {
        column
            .iter()
            .map(|(k, _)| k.chars().count())
            .max()
            .unwrap_or(0)
    };
    let (left_keys, right_keys) = (width_of(left), width_of(right));
    let left_width = left
        .iter()
        .map(|(_, what)| left_keys + 3 + what.chars().count())
        .max()
        .unwrap_or(0);
    left.iter()
        .enumerate()
        .map(|(i, (k, what))| {
            let mut spans = vec![
                Span::styled(format!(" {k:>left_keys$}  "), theme.key),
                Span::raw(*what),
            ];
            if let Some((rk, rwhat)) = right.get(i) {
                let used = left_keys + 3 + what.chars().count();
                spans.push(Span::raw(" ".repeat(left_width - used + 2)));
                spans.push(Span::styled(format!("{rk:>right_keys$}  "), theme.key));
                spans.push(Span::raw(*rwhat));
            }
            Line::from(spans)
        })
        .collect()
}

/// The report as lines, in the words of `betr verify`.
pub fn report_lines(report: &Report, theme: &Theme) -> Vec<String> {
    let (ok, bad, unknown) = if theme.glyphs.success == "✓" {
        ("✓", "✕", "?")
    } else {
        ("ok", "FAIL", "??")
    };
    let mut lines = vec!["Structural checks".to_string()];
    if report.findings.is_empty() {
        lines.push(format!("  {ok} no findings"));
    }
    for f in &report.findings {
        lines.push(format!("  {bad} {f}"));
        lines.push(format!("      fix: {}", f.hint));
    }
    lines.push("Model checking".into());
    match &report.model {
        Err(e) => lines.push(format!("  {bad} not possible: {e}")),
        Ok(m) => {
            for p in &m.properties {
                match &p.verdict {
                    Verdict::Holds if p.detail.is_empty() => {
                        lines.push(format!("  {ok} {}", p.name))
                    }
                    Verdict::Holds => lines.push(format!("  {ok} {} ({})", p.name, p.detail)),
                    Verdict::Unknown { states } => lines.push(format!(
                        "  {unknown} {}: bound reached: stopped after {states} states",
                        p.name
                    )),
                    Verdict::Violated(cx) => {
                        lines.push(format!("  {bad} {}", p.name));
                        lines.push("    counterexample:".into());
                        lines.extend(cx.to_string().lines().map(|l| format!("      {l}")));
                    }
                }
            }
            lines.push(format!(
                "{} states, {} transitions, {} atoms",
                m.states, m.transitions, m.atoms
            ));
        }
    }
    lines.push(
        if report.holds() {
            "VERIFIED: every check and property holds"
        } else {
            "NOT VERIFIED"
        }
        .into(),
    );
    lines
}

/// Lines (a verification report, the rules kept, details) in a box over the screen.
pub fn draw_report(frame: &mut Frame, area: Rect, title: &str, lines: &[String], theme: &Theme) {
    draw_box(frame, area, lines, theme, title);
}

/// The readings of an instruction to choose among, each with its number, its words, its
/// goal and the first actions of its plan.
pub fn readings_lines(readings: &[crate::session::Reading], doubt: Option<&str>) -> Vec<String> {
    let mut lines = vec![match doubt {
        Some(why) => format!("{} {why}", strings::READING_DOUBTED),
        None => strings::READINGS_INTRO.to_string(),
    }];
    for (i, r) in readings.iter().enumerate() {
        lines.push(String::new());
        lines.push(format!("{}  {}", i + 1, r.words));
        lines.push(format!("   goal: {}", r.goal));
        if !r.first_actions.is_empty() {
            lines.push(format!("   first: {}", r.first_actions.join(", ")));
        }
    }
    lines
}

/// The readings to choose among in a box over the screen.
pub fn draw_readings(
    frame: &mut Frame,
    area: Rect,
    readings: &[crate::session::Reading],
    doubt: Option<&str>,
    theme: &Theme,
) {
    draw_box(
        frame,
        area,
        &readings_lines(readings, doubt),
        theme,
        strings::READINGS_TITLE,
    );
}

fn draw_box(frame: &mut Frame, area: Rect, lines: &[String], theme: &Theme, title: &str) {
    let width = area.width.saturating_sub(8).max(20);
    let inner = usize::from(width.saturating_sub(2)).max(1);
    // Wrapped lines take more than one row each.
    let rows: usize = lines
        .iter()
        .map(|l| l.chars().count().div_ceil(inner).max(1))
        .sum();
    let rect = centered(area, width, u16::try_from(rows + 2).unwrap_or(u16::MAX));
    frame.render_widget(Clear, rect);
    let block = Block::default()
        .borders(Borders::ALL)
        .border_style(theme.key)
        .title(Span::styled(title.to_string(), theme.title));
    let text: Vec<Line> = lines.iter().map(|l| Line::from(l.clone())).collect();
    frame.render_widget(
        Paragraph::new(text).wrap(Wrap { trim: false }).block(block),
        rect,
    );
}
