//! The input line: an instruction (or a goal formula) to submit, or a proposal to edit.
//! Enter submits, Esc cancels; while it is open it takes every key. ↑ and ↓ go through
//! what was submitted before in the same kind of line (a refused goal is one ↑ away).
//! Tab completes the condition under the cursor from the scene's vocabulary, with or
//! without its opening quote: as far as the matches agree, then — pressed again — through
//! each match in turn (Shift-Tab back); the choices are listed under the line. A line that
//! could not be read stays open with the error under it, wrapped to the screen's width.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Frame;
use ratatui::layout::{Position, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};

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
    /// What was submitted, oldest first, with the kind of line it was submitted in.
    history: Vec<(Mode, String)>,
    /// Going through the history: the entry shown (an index into `history`) and the text
    /// that was being typed before, given back by ↓ past the newest entry.
    recalled: Option<(usize, String)>,
    /// Tab pressed again on a condition with several matches: which are being gone through.
    cycle: Option<Cycle>,
}

/// Several matches of a condition, gone through by repeated Tab.
struct Cycle {
    /// Where the condition starts, in bytes.
    start: usize,
    /// The matching words, as indices into the vocabulary.
    matches: Vec<usize>,
    /// The match in the line now.
    shown: usize,
}

/// What the line's lower border says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Note {
    Error(String),
    Choices(String),
}

/// Completions listed under the line at most.
const LISTED: usize = 4;

/// Entries the history keeps at most; the oldest go first.
const HISTORY: usize = 200;

/// Lines a wrapped error takes under the text at most.
const ERROR_LINES: u16 = 4;

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
        self.recalled = None;
        self.cycle = None;
    }

    /// Open the line again on `text` that could not be read, with why under it.
    pub fn reopen_with_error(&mut self, mode: Mode, text: &str, error: String) {
        self.open(mode, text);
        self.note = Some(Note::Error(error));
    }

    /// The conditions Tab completes from.
    pub fn set_vocabulary(&mut self, words: Vec<String>) {
        self.vocabulary = words;
    }

    pub fn has_vocabulary(&self) -> bool {
        !self.vocabulary.is_empty()
    }

    /// What is under the line, if anything.
    pub fn note(&self) -> Option<&Note> {
        self.note.as_ref()
    }

    pub fn text(&self) -> &str {
        &self.text
    }

    /// Complete the condition before the cursor: to the one condition it begins, or as
    /// far as all it begins agree, listing them under the line. The opening quote of an
    /// object's name may be left out. When the matches agree no further, Tab goes through
    /// them one by one (`forward`), and Shift-Tab back.
    fn complete(&mut self, forward: bool) {
        if let Some(cycle) = self.cycle.as_mut() {
            let count = cycle.matches.len();
            cycle.shown = if forward {
                (cycle.shown + 1) % count
            } else {
                (cycle.shown + count - 1) % count
            };
            return self.show_cycled();
        }
        let at = self.byte_at(self.cursor);
        // The condition under the cursor starts after the last operator before it.
        let start = self.text[..at]
            .rfind(['&', '|', '(', '~'])
            .map_or(0, |i| i + 1);
        let typed = self.text[start..at].trim_start();
        let start = at - typed.len();
        let lower = typed.trim_start_matches('"').to_lowercase();
        let matching: Vec<usize> = (0..self.vocabulary.len())
            .filter(|&i| {
                let word = self.vocabulary[i].trim_start_matches('"').to_lowercase();
                word.starts_with(&lower)
            })
            .collect();
        let Some(&first) = matching.first() else {
            self.note = Some(Note::Choices(strings::NO_COMPLETION.to_string()));
            return;
        };
        let first = self.vocabulary[first].as_str();
        let common = matching.iter().fold(first, |acc, &i| {
            let same = acc
                .char_indices()
                .zip(self.vocabulary[i].chars())
                .take_while(|((_, a), b)| a.eq_ignore_ascii_case(b))
                .last()
                .map_or(0, |((i, a), _)| i + a.len_utf8());
            &acc[..same]
        });
        let count = matching.len();
        if count > 1 && common.trim_start_matches('"').len() <= lower.len() {
            // Nothing more the matches agree on: go through them.
            self.cycle = Some(Cycle {
                start,
                matches: matching,
                // One step from here is the first match forward, the last back.
                shown: if forward { count - 1 } else { 0 },
            });
            return self.complete(forward);
        }
        let replacement = common.to_string();
        self.text.replace_range(start..at, &replacement);
        self.cursor = self.text[..start + replacement.len()].chars().count();
        self.note = if matching.len() == 1 {
            None
        } else {
            let listed: Vec<&str> = matching
                .iter()
                .take(LISTED)
                .map(|&i| self.vocabulary[i].as_str())
                .collect();
            Some(Note::Choices(strings::completions(&listed, matching.len())))
        };
    }

    /// Put the match the cycle is on in place of the condition, and say which it is.
    fn show_cycled(&mut self) {
        let Some(cycle) = &self.cycle else { return };
        let shown = cycle.shown % cycle.matches.len();
        let word = &self.vocabulary[cycle.matches[shown]];
        let at = self.byte_at(self.cursor);
        self.text.replace_range(cycle.start..at, word);
        self.cursor = self.text[..cycle.start + word.len()].chars().count();
        self.note = Some(Note::Choices(strings::cycling(
            shown + 1,
            cycle.matches.len(),
        )));
    }

    /// Show the submitted entry before (`back`) or after the one shown, the newest first;
    /// past the newest, the text that was being typed.
    fn recall(&mut self, back: bool) {
        let Some(mode) = self.mode else { return };
        let shown = self.recalled.as_ref().map(|(i, _)| *i);
        let same_mode = |(i, (m, _)): (usize, &(Mode, String))| (*m == mode).then_some(i);
        let next = if back {
            let before = shown.unwrap_or(self.history.len());
            self.history[..before]
                .iter()
                .enumerate()
                .filter_map(same_mode)
                .next_back()
        } else {
            let Some(shown) = shown else { return };
            self.history
                .iter()
                .enumerate()
                .skip(shown + 1)
                .find_map(same_mode)
        };
        let text = match next {
            Some(i) => {
                let draft = match self.recalled.take() {
                    Some((_, draft)) => draft,
                    None => self.text.clone(),
                };
                self.recalled = Some((i, draft));
                self.history[i].1.clone()
            }
            // ↓ past the newest entry: back to what was being typed.
            None if !back => match self.recalled.take() {
                Some((_, draft)) => draft,
                None => return,
            },
            None => return,
        };
        self.text = text;
        self.cursor = self.text.chars().count();
    }

    /// Keep a submitted line for ↑, unless it is empty or the same as the last of its kind.
    fn remember(&mut self, mode: Mode, text: &str) {
        if text.trim().is_empty() {
            return;
        }
        let last = self.history.iter().rev().find(|(m, _)| *m == mode);
        if last.is_some_and(|(_, t)| t == text) {
            return;
        }
        if self.history.len() >= HISTORY {
            self.history.remove(0);
        }
        self.history.push((mode, text.to_string()));
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
        if !matches!(key.code, KeyCode::Tab | KeyCode::BackTab) {
            // A key that changes the line makes what was said under it stale.
            self.note = None;
            self.cycle = None;
        }
        let completes = matches!(mode, Mode::Edit | Mode::Instruction);
        match key.code {
            KeyCode::Tab if completes => self.complete(true),
            KeyCode::BackTab if completes => self.complete(false),
            KeyCode::Up => self.recall(true),
            KeyCode::Down => self.recall(false),
            KeyCode::Enter => {
                let text = std::mem::take(&mut self.text);
                self.remember(mode, &text);
                self.mode = None;
                self.cursor = 0;
                self.recalled = None;
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
                self.recalled = None;
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

    /// Rows the line takes at `width` columns: the text between borders, and an error
    /// under it wrapped to a few rows.
    pub fn height(&self, width: u16) -> u16 {
        let error_rows = match (&self.note, self.mode) {
            (Some(Note::Error(e)), Some(_)) => {
                let rows = Paragraph::new(e.as_str())
                    .wrap(Wrap { trim: true })
                    .line_count(width.saturating_sub(2).max(1));
                u16::try_from(rows).unwrap_or(ERROR_LINES).min(ERROR_LINES)
            }
            _ => 0,
        };
        3 + error_rows
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
        let error = match (&self.note, self.mode) {
            (Some(Note::Error(e)), Some(_)) => Some(e.as_str()),
            _ => None,
        };
        let inner_width = usize::from(area.width.saturating_sub(4)).max(1);
        // Keep the cursor in view on long text.
        let scroll = self.cursor.saturating_sub(inner_width.saturating_sub(1));
        let block = Block::default()
            .borders(Borders::ALL)
            .border_style(theme.border)
            .title(Span::styled(title, theme.title));
        let block = match (&self.note, self.mode) {
            (Some(Note::Choices(c)), Some(_)) => {
                block.title_bottom(Span::styled(format!(" {c} "), theme.dim))
            }
            (None, Some(Mode::Edit | Mode::Instruction)) if !self.vocabulary.is_empty() => {
                block.title_bottom(Span::styled(strings::TAB_COMPLETES, theme.dim))
            }
            _ => block,
        };
        let scroll = u16::try_from(scroll).unwrap_or(u16::MAX);
        let inner = block.inner(area);
        frame.render_widget(block, area);
        let text_area = Rect { height: 1, ..inner };
        frame.render_widget(Paragraph::new(line).scroll((0, scroll)), text_area);
        if let Some(error) = error {
            // The whole error, wrapped under the text: cut at the border it could not be read.
            let below = Rect {
                y: inner.y.saturating_add(1),
                height: inner.height.saturating_sub(1),
                ..inner
            };
            frame.render_widget(
                Paragraph::new(Span::styled(error, theme.error)).wrap(Wrap { trim: true }),
                below,
            );
        }
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

    fn type_text(input: &mut InputLine, text: &str) {
        for c in text.chars() {
            input.event(&key(KeyCode::Char(c)));
        }
    }

    #[test]
    fn up_and_down_go_through_what_was_submitted_in_that_kind_of_line() {
        let mut input = InputLine::default();
        for (mode, text) in [
            (Mode::Instruction, "first"),
            (Mode::Edit, "an edit"),
            (Mode::Instruction, "On_Cofee_Table1"),
            (Mode::Instruction, "On_Cofee_Table1"),
        ] {
            input.open(mode, "");
            type_text(&mut input, text);
            input.event(&key(KeyCode::Enter));
        }
        input.open(Mode::Instruction, "");
        type_text(&mut input, "half typed");
        input.event(&key(KeyCode::Up));
        // The same line twice in a row is kept once.
        assert_eq!(input.text(), "On_Cofee_Table1");
        input.event(&key(KeyCode::Up));
        assert_eq!(input.text(), "first");
        input.event(&key(KeyCode::Up));
        assert_eq!(input.text(), "first", "the oldest stays");
        input.event(&key(KeyCode::Down));
        assert_eq!(input.text(), "On_Cofee_Table1");
        input.event(&key(KeyCode::Down));
        assert_eq!(
            input.text(),
            "half typed",
            "past the newest: what was typed"
        );
        input.event(&key(KeyCode::Down));
        assert_eq!(input.text(), "half typed");
        input.event(&key(KeyCode::Esc));
        // The edit line has its own.
        input.open(Mode::Edit, "");
        input.event(&key(KeyCode::Up));
        assert_eq!(input.text(), "an edit");
        input.event(&key(KeyCode::Up));
        assert_eq!(input.text(), "an edit");
    }

    #[test]
    fn tab_completes_without_the_quote_and_goes_through_the_matches() {
        let mut input = InputLine::default();
        input.set_vocabulary(vec![
            "\"red cube\" on \"blue cube\"".into(),
            "\"red cube\" on \"green cube\"".into(),
            "\"red cube\" on \"table\"".into(),
            "Active_AC".into(),
        ]);
        input.open(Mode::Instruction, "Active_AC & re");
        input.event(&key(KeyCode::Tab));
        assert_eq!(input.text(), "Active_AC & \"red cube\" on \"");
        assert!(matches!(input.note(), Some(Note::Choices(c)) if c.starts_with("3 match")));
        // Nothing more they agree on: each Tab shows the next, Shift-Tab the one before.
        input.event(&key(KeyCode::Tab));
        assert_eq!(input.text(), "Active_AC & \"red cube\" on \"blue cube\"");
        assert!(matches!(input.note(), Some(Note::Choices(c)) if c.starts_with("match 1 of 3")));
        input.event(&key(KeyCode::Tab));
        assert_eq!(input.text(), "Active_AC & \"red cube\" on \"green cube\"");
        input.event(&key(KeyCode::BackTab));
        input.event(&key(KeyCode::BackTab));
        assert_eq!(input.text(), "Active_AC & \"red cube\" on \"table\"");
        // Typing ends the round; the text stays as it was shown.
        type_text(&mut input, " & act");
        input.event(&key(KeyCode::Tab));
        assert_eq!(
            input.text(),
            "Active_AC & \"red cube\" on \"table\" & Active_AC"
        );
    }

    #[test]
    fn an_error_is_wrapped_under_the_text_in_a_taller_line() {
        let mut input = InputLine::default();
        assert_eq!(input.height(40), 3);
        input.reopen_with_error(Mode::Instruction, "x & y", "word ".repeat(20));
        // 100 characters in 38 columns: three rows under the text.
        assert_eq!(input.height(40), 6);
        input.reopen_with_error(Mode::Instruction, "x", "word ".repeat(200));
        assert_eq!(input.height(40), 3 + ERROR_LINES);
        input.event(&key(KeyCode::Char('z')));
        assert_eq!(input.height(40), 3, "a key makes the error stale");
    }
}
