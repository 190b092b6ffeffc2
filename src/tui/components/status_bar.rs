//! The status bar: scenario, backend and model (and its fetch's progress), calls, tokens and cost so far, tick
//! count, run/pause state, the last outcome, and the auto-approve warning. In a replay,
//! the timeline instead: the step it stands on of how many, the tick, the step's time and
//! what the step was.

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;

use crate::llm::usage::UsageTotals;
use crate::session::PhaseKind;

use super::super::strings;
use super::super::theme::Theme;

/// Characters a model's name keeps where the status bar is tight.
const TIGHT_MODEL_NAME: usize = 14;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ending {
    Success,
    Failed,
    /// A run stopped at a breakpoint (or a failure, with break-on-failure).
    Stopped,
}

/// A passing message (dictation's outcome), shown until the next key.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Message {
    pub text: String,
    pub error: bool,
}

/// Where a replay stands.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Timeline {
    /// Steps applied (0: none yet).
    pub step: usize,
    pub steps: usize,
    /// Milliseconds since the session started, at the last step applied.
    pub ms: u64,
    /// The last step applied, in one line.
    pub what: String,
}

#[derive(Default)]
pub struct StatusBar {
    pub scenario: String,
    pub backend: String,
    pub model: String,
    pub auto_approve: bool,
    pub usage: UsageTotals,
    pub ticks: u64,
    /// What the engine does or waits for, as it last said.
    pub phase: PhaseKind,
    pub ending: Option<Ending>,
    /// Whether running stops after a node fails.
    pub break_on_failure: bool,
    /// Where the model's fetch stands while the workbench is open without it.
    pub fetching: Option<String>,
    /// Said once when a 3D viewer was asked for and is not there.
    pub viewer: Option<String>,
    /// Takes the bar's middle while it is there.
    pub message: Option<Message>,
    /// In a replay: where it stands (drawn instead of the session's state).
    pub replay: Option<Timeline>,
}

impl StatusBar {
    pub fn draw(&self, frame: &mut Frame, area: Rect, theme: &Theme, help_key: &str) {
        // Narrow terminals: the model without its backend, the help key without its word,
        // tighter separators.
        let narrow = area.width < 100;
        let sep = Span::styled(if narrow { "│" } else { " │ " }, theme.status_bar);
        let help = if narrow {
            help_key.to_string()
        } else {
            format!("{help_key} {}", strings::HELP_WORD)
        };
        if let Some(timeline) = &self.replay {
            return self.draw_replay(frame, area, theme, timeline, (&sep, help));
        }
        if let Some(message) = &self.message {
            return self.draw_message(frame, area, theme, message, (&sep, help));
        }
        // The help key keeps its place at the right edge; the state left of it says the
        // calls and the model shorter before anything is cut.
        let help = Line::from(vec![sep.clone(), Span::styled(help, theme.status_bar)]);
        let help_width = u16::try_from(help.width()).unwrap_or(u16::MAX);
        let [state_area, help_area] =
            Layout::horizontal([Constraint::Fill(1), Constraint::Length(help_width)]).areas(area);
        let state = |tight: bool| {
            let mut spans = self.session_spans(theme, narrow, tight, &sep);
            self.push_flags(&mut spans, theme, &sep);
            Line::from(spans)
        };
        let mut line = state(false);
        if line.width() > usize::from(state_area.width) {
            line = state(true);
        }
        frame.render_widget(Paragraph::new(line).style(theme.status_bar), state_area);
        frame.render_widget(Paragraph::new(help).style(theme.status_bar), help_area);
    }

    /// `scenario │ message │ ? help`: the message gets the width; the help key stays at
    /// the right edge.
    fn draw_message(
        &self,
        frame: &mut Frame,
        area: Rect,
        theme: &Theme,
        message: &Message,
        (sep, help): (&Span<'static>, String),
    ) {
        let style = if message.error {
            theme.status_bar.patch(theme.error)
        } else {
            theme.status_bar
        };
        let scenario = format!(" {}", self.scenario);
        let fixed =
            scenario.chars().count() + 2 * sep.content.chars().count() + help.chars().count();
        let room = usize::from(area.width).saturating_sub(fixed);
        let spans = vec![
            Span::styled(scenario, theme.status_bar),
            sep.clone(),
            Span::styled(
                format!("{:<room$}", crate::excerpt::shortened(&message.text, room)),
                style,
            ),
            sep.clone(),
            Span::styled(help, theme.status_bar),
        ];
        frame.render_widget(
            Paragraph::new(Line::from(spans)).style(theme.status_bar),
            area,
        );
    }

    /// The session's state, each part followed by `sep` but the last: scenario, backend
    /// and model, the model's fetch, calls, tick, and whether it runs. `tight`: the calls
    /// counted without tokens and price, and a long model name shortened.
    fn session_spans(
        &self,
        theme: &Theme,
        narrow: bool,
        tight: bool,
        sep: &Span<'static>,
    ) -> Vec<Span<'static>> {
        let who = match (narrow, tight) {
            (_, true) => crate::excerpt::shortened(&self.model, TIGHT_MODEL_NAME),
            (true, false) => self.model.clone(),
            (false, false) => format!("{} {}", self.backend, self.model),
        };
        let calls = if tight {
            strings::calls_short(self.usage.calls)
        } else {
            strings::calls(
                self.usage.calls,
                self.usage.prompt_tokens + self.usage.completion_tokens,
                self.usage.price_usd,
            )
        };
        let mut spans = vec![
            Span::styled(format!(" {}", self.scenario), theme.status_bar),
            sep.clone(),
            Span::styled(who, theme.status_bar),
            sep.clone(),
        ];
        if let Some(fetching) = &self.fetching {
            spans.push(Span::styled(
                fetching.clone(),
                theme.status_bar.patch(theme.running),
            ));
            spans.push(sep.clone());
        }
        spans.extend([
            Span::styled(calls, theme.status_bar),
            sep.clone(),
            Span::styled(strings::tick(self.ticks), theme.status_bar),
            sep.clone(),
            // What the engine waits for (the model, approval, a person) stands where the
            // run state does: the tree does not tick meanwhile.
            match strings::waiting_for(self.phase) {
                Some(what) => Span::styled(
                    if narrow { what.short } else { what.long },
                    theme.status_bar.patch(theme.running),
                ),
                None if self.phase == PhaseKind::Running => {
                    Span::styled(strings::RUNNING, theme.status_bar)
                }
                None => Span::styled(strings::PAUSED, theme.status_bar),
            },
        ]);
        spans
    }

    /// What the run came to, and the flags that are on (break on failure, the missing
    /// viewer, auto-approve), each after `sep`.
    fn push_flags(&self, spans: &mut Vec<Span<'static>>, theme: &Theme, sep: &Span<'static>) {
        match self.ending {
            Some(Ending::Success) => {
                spans.push(sep.clone());
                spans.push(Span::styled(
                    strings::SUCCESS,
                    theme.success.patch(theme.title),
                ));
            }
            Some(Ending::Failed) => {
                spans.push(sep.clone());
                spans.push(Span::styled(strings::FAILED, theme.error));
            }
            Some(Ending::Stopped) => {
                spans.push(sep.clone());
                spans.push(Span::styled(strings::STOPPED, theme.stopped));
            }
            None => {}
        }
        if self.break_on_failure {
            spans.push(sep.clone());
            spans.push(Span::styled(strings::BREAK_ON_FAILURE, theme.status_bar));
        }
        if let Some(viewer) = &self.viewer {
            spans.push(sep.clone());
            spans.push(Span::styled(viewer.clone(), theme.error));
        }
        if self.auto_approve {
            spans.push(sep.clone());
            spans.push(Span::styled(strings::AUTO_APPROVE, theme.error));
        }
    }

    /// `REPLAY  step 123/4567  tick 42  0:12.345 │ what the step was │ SUCCESS │ ? help`;
    /// a message (a move that found nothing) stands where the step's words do.
    fn draw_replay(
        &self,
        frame: &mut Frame,
        area: Rect,
        theme: &Theme,
        timeline: &Timeline,
        (sep, help): (&Span<'static>, String),
    ) {
        let position = format!(
            " {}",
            strings::replay_position(timeline.step, timeline.steps, self.ticks, timeline.ms)
        );
        let ending = match self.ending {
            Some(Ending::Success) => Some((strings::SUCCESS, theme.success.patch(theme.title))),
            Some(Ending::Failed) => Some((strings::FAILED, theme.error)),
            Some(Ending::Stopped) => Some((strings::STOPPED, theme.stopped)),
            None => None,
        };
        let sep_width = sep.content.chars().count();
        let fixed = position.chars().count()
            + 2 * sep_width
            + help.chars().count()
            + ending.map_or(0, |(e, _)| e.chars().count() + sep_width);
        let room = usize::from(area.width).saturating_sub(fixed);
        let (what, style) = match &self.message {
            Some(m) if m.error => (m.text.as_str(), theme.status_bar.patch(theme.error)),
            Some(m) => (m.text.as_str(), theme.status_bar),
            None => (timeline.what.as_str(), theme.status_bar),
        };
        let mut spans = vec![
            Span::styled(position, theme.status_bar.patch(theme.title)),
            sep.clone(),
            Span::styled(
                format!("{:<room$}", crate::excerpt::shortened(what, room)),
                style,
            ),
        ];
        if let Some((text, style)) = ending {
            spans.push(sep.clone());
            spans.push(Span::styled(text, style));
        }
        spans.push(sep.clone());
        spans.push(Span::styled(help, theme.status_bar));
        frame.render_widget(
            Paragraph::new(Line::from(spans)).style(theme.status_bar),
            area,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    fn drawn(bar: &StatusBar, width: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, 1)).unwrap();
        terminal
            .draw(|f| bar.draw(f, f.area(), &Theme::default(), "?"))
            .unwrap();
        terminal.backend().to_string()
    }

    /// At 80 columns a long model name and the calls' tokens and price give way before
    /// anything is cut; the help key stays at the right edge.
    #[test]
    fn a_tight_bar_abbreviates_before_it_cuts() {
        let bar = StatusBar {
            scenario: "cafe/no_coffee".into(),
            backend: "local".into(),
            model: "qwen2.5-coder-1.5b-instruct-q4_k_m".into(),
            usage: UsageTotals {
                calls: 12,
                prompt_tokens: 48_000,
                completion_tokens: 1_200,
                price_usd: 0.0,
                ..UsageTotals::default()
            },
            ticks: 120,
            ending: Some(Ending::Failed),
            break_on_failure: true,
            ..StatusBar::default()
        };
        let wide = drawn(&bar, 160);
        assert!(
            wide.contains("qwen2.5-coder-1.5b-instruct-q4_k_m"),
            "{wide}"
        );
        assert!(wide.contains("49200 tok"), "{wide}");
        let tight = drawn(&bar, 80);
        assert!(tight.contains("qwen2.5-coder…"), "{tight}");
        assert!(
            tight.contains("12 call(s)│") && !tight.contains("tok"),
            "{tight}"
        );
        assert!(tight.contains("FAILED"), "{tight}");
        assert!(tight.trim_end().ends_with("│?\""), "{tight}");
    }
}
