//! The LLM pane: the call under way, the pending proposal (which action, what conditions
//! or value) with its keys first, so small terminals show it; then the goal, who
//! answered, the reasoning of the last call (why), and a short log of what happened.

use ratatui::Frame;
use ratatui::layout::Rect;
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
    pub error: Option<String>,
    log: Vec<String>,
    spin: usize,
}

impl LlmPane {
    pub fn log(&mut self, line: impl Into<String>) {
        self.log.push(line.into());
        if self.log.len() > LOG_LINES {
            self.log.remove(0);
        }
    }

    pub fn log_lines(&self) -> &[String] {
        &self.log
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
            None => lines.push(Line::from(Span::styled(strings::NO_PROPOSAL, theme.dim))),
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
        // The newest log lines that fit below the rest.
        let inner_height = usize::from(area.height.saturating_sub(2));
        let width = usize::from(area.width.saturating_sub(2)).max(1);
        let used: usize = lines.iter().map(|l| rows(l.width(), width)).sum();
        let mut room = inner_height.saturating_sub(used);
        let mut tail: Vec<Line> = Vec::new();
        for entry in self.log.iter().rev() {
            let need = rows(entry.chars().count(), width);
            if need > room {
                break;
            }
            room -= need;
            tail.push(Line::from(entry.clone()));
        }
        tail.reverse();
        lines.extend(tail);
        let block = Block::default()
            .borders(Borders::ALL)
            .border_style(theme.border)
            .title(Span::styled(strings::LLM_TITLE, theme.title));
        frame.render_widget(
            Paragraph::new(lines)
                .wrap(Wrap { trim: false })
                .block(block),
            area,
        );
    }
}

/// Rows a line of `len` characters takes when wrapped at `width`.
fn rows(len: usize, width: usize) -> usize {
    len.div_ceil(width).max(1)
}
