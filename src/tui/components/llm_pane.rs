//! The LLM pane: the call under way, the pending proposal (which action, what conditions
//! or value) with its keys first, so small terminals show it; then the goal, who
//! answered, the reasoning of the last call (why), and a log of what happened below them.
//!
//! The log follows its newest line unless the person scrolled it up (then a marker says
//! how many rows are below); a line said again right after itself is counted, not
//! repeated.

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};

use crate::session::Proposal;

use super::super::strings;
use super::super::theme::Theme;

const LOG_LINES: usize = 200;
const SPINNER: [&str; 4] = ["|", "/", "-", "\\"];

/// A proposal as the pane shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct ProposalView {
    /// The action it is for (`grasp "blue cube"`), or the skill and object of a value.
    pub target: String,
    /// One line per condition, or the value.
    pub lines: Vec<String>,
    /// The text the edit line starts with.
    pub edit_text: String,
}

impl ProposalView {
    pub fn of(proposal: &Proposal) -> ProposalView {
        match proposal {
            Proposal::Conditions {
                action, conditions, ..
            } => {
                let lines: Vec<String> = conditions.iter().map(ToString::to_string).collect();
                ProposalView {
                    target: format!("{action}!"),
                    edit_text: lines.join(" & "),
                    lines,
                }
            }
            Proposal::Value {
                skill,
                object,
                param,
                value,
            } => ProposalView {
                target: format!("{skill} \"{object}\""),
                lines: vec![format!("{param} = {value}")],
                edit_text: value.to_string(),
            },
        }
    }
}

#[derive(Default)]
pub struct LlmPane {
    pub asking: Option<String>,
    pub replied_by: Option<String>,
    pub goal: Option<String>,
    pub reasoning: Option<String>,
    pub proposal: Option<ProposalView>,
    /// An approved fix offered as a rule, with the keys that answer it.
    pub offer: Option<String>,
    pub error: Option<String>,
    /// Each line with how many times in a row it was said.
    log: Vec<(String, usize)>,
    /// Rows the log is scrolled up from its newest line (0: following it).
    log_scroll: usize,
    /// Rows of the log above the view when it last followed its newest line: how far it
    /// can be scrolled.
    log_hidden: std::cell::Cell<usize>,
    spin: usize,
}

/// Rows one log scroll key moves.
const SCROLL_ROWS: usize = 5;

impl LlmPane {
    pub fn log(&mut self, line: impl Into<String>) {
        let line = line.into();
        if let Some((last, count)) = self.log.last_mut()
            && *last == line
        {
            *count += 1;
            return;
        }
        self.log.push((line, 1));
        if self.log.len() > LOG_LINES {
            self.log.remove(0);
        }
        // A person reading older lines keeps them in view while new ones arrive.
        if self.log_scroll > 0 {
            self.log_scroll += 1;
        }
    }

    /// The log as shown: each line once, with its count when said more than once.
    pub fn log_lines(&self) -> Vec<String> {
        self.log
            .iter()
            .map(|(line, count)| match count {
                1 => line.clone(),
                n => strings::repeated(line, *n),
            })
            .collect()
    }

    /// Scroll the log towards older lines.
    pub fn scroll_log_up(&mut self) {
        self.log_scroll = (self.log_scroll + SCROLL_ROWS).min(self.log_hidden.get());
    }

    /// Scroll the log towards the newest line (following it again at the bottom).
    pub fn scroll_log_down(&mut self) {
        self.log_scroll = self.log_scroll.saturating_sub(SCROLL_ROWS);
    }

    /// Scroll the log as far up as `previous` was.
    pub fn adopt_scroll(&mut self, previous: &LlmPane) {
        self.log_scroll = previous.log_scroll;
        self.log_hidden.set(previous.log_hidden.get());
    }

    pub fn animate(&mut self) {
        self.spin = (self.spin + 1) % SPINNER.len();
    }

    pub fn draw(&self, frame: &mut Frame, area: Rect, theme: &Theme, keys_hint: &str) {
        let mut lines: Vec<Line> = Vec::new();
        if let Some(what) = &self.asking {
            lines.push(Line::from(Span::styled(
                format!("{} {} {what} …", SPINNER[self.spin], strings::ASKING),
                theme.running,
            )));
        }
        match &self.proposal {
            Some(p) => {
                lines.push(Line::from(Span::styled(
                    format!("{} {}:", strings::PROPOSAL_FOR, p.target),
                    theme.proposal,
                )));
                for l in &p.lines {
                    lines.push(Line::from(Span::styled(format!("  {l}"), theme.proposal)));
                }
                lines.push(Line::from(Span::styled(keys_hint.to_string(), theme.key)));
            }
            None => match &self.offer {
                Some(offer) => lines.push(Line::from(Span::styled(offer.clone(), theme.proposal))),
                None => lines.push(Line::from(Span::styled(strings::NO_PROPOSAL, theme.dim))),
            },
        }
        if let Some(goal) = &self.goal {
            lines.push(Line::from(vec![
                Span::styled(format!("{} ", strings::GOAL), theme.title),
                Span::raw(goal.clone()),
            ]));
        }
        if let Some(who) = &self.replied_by {
            lines.push(Line::from(Span::styled(
                format!("{} {who}", strings::REPLY_FROM),
                theme.dim,
            )));
        }
        if let Some(r) = &self.reasoning {
            lines.push(Line::from(vec![
                Span::styled(format!("{} ", strings::REASONING), theme.title),
                Span::raw(r.replace('\n', " ")),
            ]));
        }
        if let Some(e) = &self.error {
            lines.push(Line::from(Span::styled(e.clone(), theme.error)));
        }
        lines.push(Line::from(Span::styled(
            format!("── {} ──", strings::LOG),
            theme.dim,
        )));
        let block = Block::default()
            .borders(Borders::ALL)
            .border_style(theme.border)
            .title(Span::styled(strings::LLM_TITLE, theme.title));
        let inner = block.inner(area);
        frame.render_widget(block, area);
        // The parts above the log take the rows they wrap to; the log gets the rest.
        let head = Paragraph::new(lines).wrap(Wrap { trim: false });
        let head_rows = u16::try_from(head.line_count(inner.width)).unwrap_or(u16::MAX);
        let [head_area, log_area] =
            Layout::vertical([Constraint::Length(head_rows), Constraint::Fill(1)]).areas(inner);
        frame.render_widget(head, head_area);
        self.draw_log(frame, log_area, theme);
    }

    /// The log's rows that fit in `area`: the newest, or those the person scrolled to,
    /// with a marker of the rows below them.
    fn draw_log(&self, frame: &mut Frame, area: Rect, theme: &Theme) {
        if area.height == 0 {
            return;
        }
        let log = Paragraph::new(
            self.log_lines()
                .into_iter()
                .map(Line::from)
                .collect::<Vec<_>>(),
        )
        .wrap(Wrap { trim: false });
        let total = log.line_count(area.width);
        let height = usize::from(area.height);
        let hidden = total.saturating_sub(height);
        self.log_hidden.set(hidden);
        let below = self.log_scroll.min(hidden);
        let (log_area, marker_area) = if below > 0 {
            let [log_area, marker_area] =
                Layout::vertical([Constraint::Fill(1), Constraint::Length(1)]).areas(area);
            (log_area, Some(marker_area))
        } else {
            (area, None)
        };
        // Rows above the view: everything but what fits and what is scrolled below.
        let top = total.saturating_sub(usize::from(log_area.height) + below);
        let top = u16::try_from(top).unwrap_or(u16::MAX);
        frame.render_widget(log.scroll((top, 0)), log_area);
        if let Some(marker_area) = marker_area {
            frame.render_widget(
                Paragraph::new(Span::styled(strings::log_below(below), theme.key)),
                marker_area,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    fn screen(pane: &LlmPane) -> String {
        let mut terminal = Terminal::new(TestBackend::new(40, 12)).unwrap();
        terminal
            .draw(|f| pane.draw(f, f.area(), &Theme::default(), ""))
            .unwrap();
        terminal.backend().to_string()
    }

    #[test]
    fn a_repeated_line_is_counted_not_repeated() {
        let mut pane = LlmPane::default();
        pane.log("ticked");
        for _ in 0..15 {
            pane.log("grasp failed");
        }
        pane.log("ticked");
        assert_eq!(pane.log_lines(), ["ticked", "grasp failed (×15)", "ticked"]);
    }

    #[test]
    fn the_log_follows_its_newest_line_unless_scrolled_up() {
        let mut pane = LlmPane::default();
        for n in 1..=30 {
            pane.log(format!("line {n}"));
        }
        let s = screen(&pane);
        assert!(s.contains("line 30"), "{s}");
        assert!(!s.contains("line 20 "), "{s}");
        assert!(!s.contains("below"), "{s}");

        pane.scroll_log_up();
        let s = screen(&pane);
        assert!(!s.contains("line 30"), "{s}");
        assert!(s.contains("↓ 5 more row(s) below"), "{s}");
        // New lines keep the view where the person scrolled to.
        pane.log("line 31");
        let s = screen(&pane);
        assert!(s.contains("↓ 6 more row(s) below"), "{s}");

        pane.scroll_log_down();
        pane.scroll_log_down();
        let s = screen(&pane);
        assert!(s.contains("line 31"), "{s}");
        assert!(!s.contains("below"), "{s}");
    }
}
