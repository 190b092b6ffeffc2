//! Colours and glyphs. Status symbols come from `bt::render`'s glyph sets, so the
//! workbench and the command line agree.

use ratatui::style::{Color, Modifier, Style};

use crate::bt::{Glyphs, Status, UNICODE};

#[derive(Debug, Clone, Copy)]
pub struct Theme {
    pub glyphs: &'static Glyphs,
    pub success: Style,
    pub failure: Style,
    pub running: Style,
    pub idle: Style,
    pub halted: Style,
    /// Nodes added by the last expansion.
    pub new_node: Style,
    /// The action that failed.
    pub failing: Style,
    /// The mark of a breakpoint.
    pub breakpoint: Style,
    /// The mark of a forced status.
    pub forced: Style,
    /// The node a run stopped at.
    pub stopped: Style,
    pub selected: Style,
    pub title: Style,
    pub border: Style,
    /// The border of the pane keys go to.
    pub focused: Style,
    pub status_bar: Style,
    pub proposal: Style,
    pub error: Style,
    pub dim: Style,
    pub key: Style,
    /// The filled and empty cells of the dictation level meter.
    pub meter: (&'static str, &'static str),
}

impl Theme {
    /// The theme with ASCII marks (`--ascii`) or Unicode ones.
    pub fn of(ascii: bool) -> Theme {
        Theme::new(if ascii {
            &crate::bt::ASCII
        } else {
            &crate::bt::UNICODE
        })
    }

    pub fn new(glyphs: &'static Glyphs) -> Theme {
        Theme {
            glyphs,
            success: Style::new().fg(Color::Green),
            failure: Style::new().fg(Color::Red),
            running: Style::new().fg(Color::Yellow),
            idle: Style::new().fg(Color::Gray),
            halted: Style::new().fg(Color::Magenta),
            new_node: Style::new().bg(Color::Blue).add_modifier(Modifier::BOLD),
            failing: Style::new()
                .fg(Color::White)
                .bg(Color::Red)
                .add_modifier(Modifier::BOLD),
            breakpoint: Style::new()
                .fg(Color::LightRed)
                .add_modifier(Modifier::BOLD),
            forced: Style::new()
                .fg(Color::LightBlue)
                .add_modifier(Modifier::BOLD),
            stopped: Style::new()
                .fg(Color::Black)
                .bg(Color::Yellow)
                .add_modifier(Modifier::BOLD),
            selected: Style::new().add_modifier(Modifier::REVERSED),
            title: Style::new().add_modifier(Modifier::BOLD),
            border: Style::new().fg(Color::DarkGray),
            focused: Style::new().fg(Color::Yellow),
            status_bar: Style::new().fg(Color::Black).bg(Color::Cyan),
            proposal: Style::new().fg(Color::Cyan).add_modifier(Modifier::BOLD),
            error: Style::new().fg(Color::Red).add_modifier(Modifier::BOLD),
            dim: Style::new().fg(Color::DarkGray),
            key: Style::new().fg(Color::Yellow).add_modifier(Modifier::BOLD),
            // Block characters only where the tree glyphs are not plain ASCII either.
            meter: if glyphs.success.is_ascii() {
                ("#", "-")
            } else {
                ("█", "░")
            },
        }
    }

    pub fn status(&self, status: Status) -> Style {
        match status {
            Status::Idle => self.idle,
            Status::Running => self.running,
            Status::Success => self.success,
            Status::Failure => self.failure,
            Status::Halted => self.halted,
        }
    }
}

impl Default for Theme {
    fn default() -> Self {
        Theme::new(&UNICODE)
    }
}
