//! Which pane keys and the mouse go to. A click focuses the pane under it (and on the
//! tree selects the row); the wheel scrolls the pane under it whatever has the focus; the
//! navigation keys no binding takes (arrows, PgUp PgDn, Home End, j k) move in the focused
//! pane. The LLM pane is two: the proposal (with the goal) above, the log below.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::{Position, Rect};

use super::App;

/// The panes that take the focus, in the order the focus key goes through them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Pane {
    #[default]
    Tree,
    Proposal,
    Log,
    World,
}

impl Pane {
    pub fn next(self) -> Pane {
        match self {
            Pane::Tree => Pane::Proposal,
            Pane::Proposal => Pane::Log,
            Pane::Log => Pane::World,
            Pane::World => Pane::Tree,
        }
    }
}

/// Where the panes were at the last draw, for the mouse.
#[derive(Debug, Clone, Copy, Default)]
pub struct PaneAreas {
    pub tree: Rect,
    pub llm: Rect,
    pub world: Rect,
}

/// Rows one wheel notch scrolls.
const WHEEL_ROWS: isize = 3;
/// Rows PgUp and PgDn scroll a pane other than the tree.
const PAGE_ROWS: isize = 10;

/// What a navigation key does in a pane that scrolls.
enum Scroll {
    /// Rows towards the end (negative: towards the start).
    By(isize),
    Start,
    End,
}

impl App {
    /// The pane at a screen cell, as drawn last.
    pub fn pane_at(&self, column: u16, row: u16) -> Option<Pane> {
        let at = Position::new(column, row);
        if self.areas.tree.contains(at) {
            Some(Pane::Tree)
        } else if self.areas.llm.contains(at) {
            if self.llm.log_area().contains(at) {
                Some(Pane::Log)
            } else {
                Some(Pane::Proposal)
            }
        } else if self.areas.world.contains(at) {
            Some(Pane::World)
        } else {
            None
        }
    }

    /// A mouse event: a click focuses the pane under it (on the tree it also selects or
    /// toggles the row); the wheel scrolls the pane under it; the horizontal wheel, or the
    /// wheel with Shift held, scrolls the tree sideways. Nothing happens under an overlay.
    pub fn on_mouse(&mut self, event: MouseEvent) {
        if self.overlay.is_some() {
            return;
        }
        let Some(pane) = self.pane_at(event.column, event.row) else {
            return;
        };
        let shift = event.modifiers.contains(KeyModifiers::SHIFT);
        match event.kind {
            MouseEventKind::Down(MouseButton::Left) => {
                self.focus = pane;
                if pane == Pane::Tree {
                    self.tree.mouse(&event);
                }
            }
            _ if pane == Pane::Tree => self.tree.mouse(&event),
            MouseEventKind::ScrollUp if !shift => self.scroll(pane, Scroll::By(-WHEEL_ROWS)),
            MouseEventKind::ScrollDown if !shift => self.scroll(pane, Scroll::By(WHEEL_ROWS)),
            _ => {}
        }
    }

    /// A key no binding takes: the focused pane's navigation.
    pub(super) fn on_navigation(&mut self, key: &KeyEvent) {
        if self.focus == Pane::Tree {
            self.tree.event(key);
            return;
        }
        let scroll = match key.code {
            KeyCode::Up | KeyCode::Char('k') => Scroll::By(-1),
            KeyCode::Down | KeyCode::Char('j') => Scroll::By(1),
            KeyCode::PageUp => Scroll::By(-PAGE_ROWS),
            KeyCode::PageDown => Scroll::By(PAGE_ROWS),
            KeyCode::Home => Scroll::Start,
            KeyCode::End => Scroll::End,
            _ => return,
        };
        self.scroll(self.focus, scroll);
    }

    /// Scroll a pane other than the tree: towards its end is down, for the log towards
    /// its newest line.
    fn scroll(&mut self, pane: Pane, scroll: Scroll) {
        match (pane, scroll) {
            (Pane::Tree, _) => {}
            (Pane::Proposal, Scroll::By(rows)) => self.llm.scroll_head(rows),
            (Pane::Proposal, Scroll::Start) => self.llm.scroll_head(isize::MIN),
            (Pane::Proposal, Scroll::End) => self.llm.scroll_head(isize::MAX),
            // The log counts rows up from its newest line.
            (Pane::Log, Scroll::By(rows)) => self.llm.scroll_log(-rows),
            (Pane::Log, Scroll::Start) => self.llm.scroll_log(isize::MAX),
            (Pane::Log, Scroll::End) => self.llm.scroll_log(isize::MIN),
            (Pane::World, Scroll::By(rows)) => self.world.scroll(rows),
            (Pane::World, Scroll::Start) => self.world.scroll(isize::MIN),
            (Pane::World, Scroll::End) => self.world.scroll(isize::MAX),
        }
    }

    /// Tell each pane whether it has the focus, and where they are drawn, before a draw.
    pub(crate) fn place_panes(&mut self, areas: PaneAreas) {
        self.areas = areas;
        self.tree.focused = self.focus == Pane::Tree;
        self.llm.focused = matches!(self.focus, Pane::Proposal | Pane::Log);
        self.llm.log_focused = self.focus == Pane::Log;
        self.world.focused = self.focus == Pane::World;
    }
}
