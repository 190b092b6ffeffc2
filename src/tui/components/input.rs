//! The input line: an instruction (or a goal formula) to submit, or a proposal to edit.
//! Enter submits, Esc cancels; while it is open it takes every key. Editing, Tab completes
//! the condition under the cursor from the scene's vocabulary (the choices left are listed
//! under the line), and a line that could not be read stays open with the error under it.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Frame;
use ratatui::layout::{Position, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph};

use super::super::strings;
use super::super::theme::Theme;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Instruction,
    Edit,
    /// Text to find in the tree's labels.
    Search,
    /// Text the world's facts listed must hold.
    Filter,
}

/// What the input line produced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Submitted {
    Instruction(String),
    Edit(String),
    Search(String),
    Filter(String),
}

#[derive(Default)]
pub struct InputLine {
    mode: Option<Mode>,
    text: String,
    /// Cursor position in characters.
    cursor: usize,
    /// The title and text while closed, when not the workbench's (a replay's keys).
    idle: Option<(&'static str, String)>,
    /// The conditions Tab completes from while editing.
    vocabulary: Vec<String>,
    /// Under the line: why it could not be read, or the completions left.
    note: Option<Note>,
}

/// What the line's lower border says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Note {
    Error(String),
    Choices(String),
}

/// Completions listed under the line at most.
const LISTED: usize = 4;

impl InputLine {
    /// What the line says while closed.
    pub fn set_idle(&mut self, title: &'static str, hint: String) {
        self.idle = Some((title, hint));
    }

    pub fn open(&mut self, mode: Mode, text: &str) {
        self.mode = Some(mode);
        self.text = text.to_string();
        self.cursor = self.text.chars().count();
        self.note = None;
    }

    /// Open the edit line again on `text` that could not be read, with why under it.
    pub fn reopen_with_error(&mut self, text: &str, error: String) {
        self.open(Mode::Edit, text);
        self.note = Some(Note::Error(error));
    }

    /// The conditions Tab completes from.
    pub fn set_vocabulary(&mut self, words: Vec<String>) {
        self.vocabulary = words;
    }

    /// What is under the line, if anything.
    pub fn note(&self) -> Option<&Note> {
        self.note.as_ref()
    }

    pub fn text(&self) -> &str {
        &self.text
    }

    /// Complete the condition before the cursor: to the one condition it begins, or as
    /// far as all it begins agree, listing them under the line.
    fn complete(&mut self) {
        let at = self.byte_at(self.cursor);
        // The condition under the cursor starts after the last operator before it.
        let start = self.text[..at]
            .rfind(['&', '|', '(', '~'])
            .map_or(0, |i| i + 1);
        let typed = self.text[start..at].trim_start();
        let start = at - typed.len();
        let lower = typed.to_lowercase();
        let matching: Vec<&String> = self
            .vocabulary
            .iter()
            .filter(|w| w.to_lowercase().starts_with(&lower))
            .collect();
        let Some(first) = matching.first() else {
            self.note = Some(Note::Choices(strings::NO_COMPLETION.to_string()));
            return;
        };
        let common = matching.iter().fold(first.as_str(), |acc, w| {
            let same = acc
                .char_indices()
                .zip(w.chars())
                .take_while(|((_, a), b)| a.eq_ignore_ascii_case(b))
                .last()
                .map_or(0, |((i, a), _)| i + a.len_utf8());
            &acc[..same]
        });
        let replacement = if common.len() >= typed.len() {
            common.to_string()
        } else {
            typed.to_string()
        };
        self.text.replace_range(start..at, &replacement);
        self.cursor = self.text[..start + replacement.len()].chars().count();
        self.note = if matching.len() == 1 {
            None
        } else {
            let listed: Vec<&str> = matching.iter().take(LISTED).map(|w| w.as_str()).collect();
            Some(Note::Choices(strings::completions(&listed, matching.len())))
        };
    }

    pub fn is_open(&self) -> bool {
        self.mode.is_some()
    }

    /// Put dictated text at the cursor of an open instruction (spaced from the words
    /// around it). False when the line is editing a proposal: that text is not touched.
    pub fn insert_dictation(&mut self, dictated: &str) -> bool {
        if self.mode != Some(Mode::Instruction) {
            return false;
        }
        let at = self.byte_at(self.cursor);
        let before = self.text[..at].chars().next_back();
        let after = self.text[at..].chars().next();
        let mut piece = String::new();
        if before.is_some_and(|c| !c.is_whitespace()) {
            piece.push(' ');
        }
        piece.push_str(dictated);
        if after.is_some_and(|c| !c.is_whitespace()) {
            piece.push(' ');
        }
        self.text.insert_str(at, &piece);
        self.cursor += piece.chars().count();
        true
    }

    /// Handle a key while open: `Some` when Enter submitted the text.
    pub fn event(&mut self, key: &KeyEvent) -> Option<Submitted> {
        let mode = self.mode?;
        if key.code != KeyCode::Tab {
            // A key that changes the line makes what was said under it stale.
            self.note = None;
        }
        match key.code {
            KeyCode::Tab if mode == Mode::Edit => self.complete(),
            KeyCode::Enter => {
                let text = std::mem::take(&mut self.text);
                self.mode = None;
                self.cursor = 0;
                return Some(match mode {
                    Mode::Instruction => Submitted::Instruction(text),
                    Mode::Edit => Submitted::Edit(text),
                    Mode::Search => Submitted::Search(text),
                    Mode::Filter => Submitted::Filter(text),
                });
            }
            KeyCode::Esc => {
                self.mode = None;
                self.text.clear();
                self.cursor = 0;
            }
            KeyCode::Char('u') if key.modifiers.contains(KeyModifiers::CONTROL) => {
                self.text.clear();
                self.cursor = 0;
            }
            KeyCode::Char(c) => {
                let at = self.byte_at(self.cursor);
                self.text.insert(at, c);
                self.cursor += 1;
            }
            KeyCode::Backspace if self.cursor > 0 => {
                self.cursor -= 1;
                let at = self.byte_at(self.cursor);
                self.text.remove(at);
            }
            KeyCode::Delete if self.cursor < self.text.chars().count() => {
                let at = self.byte_at(self.cursor);
                self.text.remove(at);
            }
            KeyCode::Left => self.cursor = self.cursor.saturating_sub(1),
            KeyCode::Right => self.cursor = (self.cursor + 1).min(self.text.chars().count()),
            KeyCode::Home => self.cursor = 0,
            KeyCode::End => self.cursor = self.text.chars().count(),
            _ => {}
        }
        None
    }

    fn byte_at(&self, chars: usize) -> usize {
        self.text
            .char_indices()
            .nth(chars)
            .map_or(self.text.len(), |(i, _)| i)
    }

    pub fn draw(&self, frame: &mut Frame, area: Rect, theme: &Theme) {
        let (title, line) = match self.mode {
            None => match &self.idle {
                Some((title, hint)) => (*title, Line::from(Span::styled(hint.clone(), theme.dim))),
                None => (
                    strings::INPUT_TITLE_IDLE,
                    Line::from(Span::styled(strings::INPUT_HINT, theme.dim)),
                ),
            },
            Some(mode) => (
                match mode {
                    Mode::Instruction => strings::INPUT_TITLE_INSTRUCTION,
                    Mode::Edit => strings::INPUT_TITLE_EDIT,
                    Mode::Search => strings::SEARCH_TITLE,
                    Mode::Filter => strings::FILTER_TITLE,
                },
                Line::from(vec![
                    Span::styled("> ", theme.key),
                    Span::raw(self.text.clone()),
                ]),
            ),
        };
        let inner_width = usize::from(area.width.saturating_sub(4)).max(1);
        // Keep the cursor in view on long text.
        let scroll = self.cursor.saturating_sub(inner_width.saturating_sub(1));
        let block = Block::default()
            .borders(Borders::ALL)
            .border_style(theme.border)
            .title(Span::styled(title, theme.title));
        let block = match (&self.note, self.mode) {
            (Some(Note::Error(e)), Some(_)) => {
                block.title_bottom(Span::styled(format!(" {e} "), theme.error))
            }
            (Some(Note::Choices(c)), Some(_)) => {
                block.title_bottom(Span::styled(format!(" {c} "), theme.dim))
            }
            (None, Some(Mode::Edit)) if !self.vocabulary.is_empty() => {
                block.title_bottom(Span::styled(strings::TAB_COMPLETES, theme.dim))
            }
            _ => block,
        };
        let scroll = u16::try_from(scroll).unwrap_or(u16::MAX);
        frame.render_widget(Paragraph::new(line).block(block).scroll((0, scroll)), area);
        if self.mode.is_some() {
            let x = area.x.saturating_add(3).saturating_add(
                u16::try_from(self.cursor)
                    .unwrap_or(0)
                    .saturating_sub(scroll),
            );
            frame.set_cursor_position(Position::new(
                x.min(area.right().saturating_sub(2)),
                area.y + 1,
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    #[test]
    fn typing_editing_and_submitting() {
        let mut input = InputLine::default();
        assert_eq!(input.event(&key(KeyCode::Char('x'))), None);
        input.open(Mode::Instruction, "");
        for c in "gräsp".chars() {
            input.event(&key(KeyCode::Char(c)));
        }
        input.event(&key(KeyCode::Left));
        input.event(&key(KeyCode::Backspace));
        input.event(&key(KeyCode::Home));
        input.event(&key(KeyCode::Char('>')));
        assert_eq!(
            input.event(&key(KeyCode::Enter)),
            Some(Submitted::Instruction(">gräp".into()))
        );
        assert!(!input.is_open());
        input.open(Mode::Edit, "A & B");
        assert!(!input.insert_dictation("put the cup"));
        input.event(&key(KeyCode::Esc));
        assert!(!input.is_open());
    }

    #[test]
    fn tab_completes_a_condition_from_the_vocabulary() {
        let mut input = InputLine::default();
        input.set_vocabulary(vec![
            "\"any object\" on \"blue cube\"".into(),
            "\"red cube\" on \"blue cube\"".into(),
            "\"red cube\" on \"green cube\"".into(),
        ]);
        input.open(Mode::Edit, "~\"re");
        input.event(&key(KeyCode::Tab));
        // Both conditions it begins agree up to the object's name: completed that far,
        // the two listed.
        assert_eq!(input.text(), "~\"red cube\" on \"");
        assert!(
            matches!(input.note(), Some(Note::Choices(c)) if c.contains("2 match")),
            "{:?}",
            input.note()
        );
        input.event(&key(KeyCode::Char('b')));
        input.event(&key(KeyCode::Tab));
        assert_eq!(input.text(), "~\"red cube\" on \"blue cube\"");
        assert_eq!(input.note(), None);
        // After an operator the next condition completes alone.
        for c in " & \"AN".chars() {
            input.event(&key(KeyCode::Char(c)));
        }
        input.event(&key(KeyCode::Tab));
        assert_eq!(
            input.text(),
            "~\"red cube\" on \"blue cube\" & \"any object\" on \"blue cube\""
        );
        input.event(&key(KeyCode::Char('x')));
        input.event(&key(KeyCode::Tab));
        assert!(matches!(input.note(), Some(Note::Choices(c)) if c == strings::NO_COMPLETION));
    }

    #[test]
    fn dictation_is_inserted_at_the_cursor_with_spaces() {
        let mut input = InputLine::default();
        assert!(!input.insert_dictation("x"));
        input.open(Mode::Instruction, "Carefully then");
        input.event(&key(KeyCode::Home));
        for _ in 0.."Carefully".len() {
            input.event(&key(KeyCode::Right));
        }
        assert!(input.insert_dictation("put the cup on the table"));
        input.event(&key(KeyCode::Char('!')));
        assert_eq!(
            input.event(&key(KeyCode::Enter)),
            Some(Submitted::Instruction(
                "Carefully put the cup on the table! then".into()
            ))
        );
    }
}
