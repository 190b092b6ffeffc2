//! The world pane: the conditions true now in the execution world, the objects, and the
//! last error text.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};

use super::super::strings;
use super::super::theme::Theme;

#[derive(Default)]
pub struct WorldPane {
    pub facts: Vec<String>,
    pub objects: Vec<String>,
    pub last_error: Option<String>,
    /// The tree has succeeded since the last error.
    pub error_resolved: bool,
}

impl WorldPane {
    pub fn draw(&self, frame: &mut Frame, area: Rect, theme: &Theme) {
        let mut lines: Vec<Line> = Vec::new();
        if let Some(e) = &self.last_error {
            if self.error_resolved {
                lines.push(Line::from(Span::styled(
                    strings::LAST_ERROR_RESOLVED,
                    theme.dim,
                )));
                lines.push(Line::from(Span::styled(format!("  {e}"), theme.dim)));
            } else {
                lines.push(Line::from(Span::styled(strings::LAST_ERROR, theme.title)));
                lines.push(Line::from(Span::styled(format!("  {e}"), theme.error)));
            }
        }
        lines.push(Line::from(Span::styled(
            format!("{} {}", strings::OBJECTS, self.objects.join(", ")),
            theme.dim,
        )));
        lines.push(Line::from(Span::styled(strings::NOW_TRUE, theme.title)));
        if self.facts.is_empty() {
            lines.push(Line::from(strings::NOTHING_TRUE));
        }
        for f in &self.facts {
            lines.push(Line::from(format!("  {f}")));
        }
        let block = Block::default()
            .borders(Borders::ALL)
            .border_style(theme.border)
            .title(Span::styled(strings::WORLD_TITLE, theme.title));
        frame.render_widget(
            Paragraph::new(lines)
                .wrap(Wrap { trim: false })
                .block(block),
            area,
        );
    }
}
