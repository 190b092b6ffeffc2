//! The push-to-talk panel: while recording it takes the input line's place with a level
//! meter, the elapsed time and the device; while transcribing it says how much audio is
//! being transcribed and what the model is doing.

use std::time::{Duration, Instant};

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph};

use crate::voice::Level;
use crate::voice::audio::SILENCE_PEAK_DBFS;

use super::super::strings;
use super::super::theme::Theme;

/// Where push-to-talk is.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Dictation {
    #[default]
    Idle,
    /// The key was pressed; the microphone is being opened.
    Starting,
    Recording {
        device: String,
        started: Instant,
        /// Shown; advanced by the animation ticker.
        elapsed: Duration,
        /// The last 50 ms of audio (none before the first arrives).
        level: Option<Level>,
        /// The loudest level so far: a meter that never moved means a muted microphone.
        peak: Option<Level>,
    },
    /// The recording is being stopped, or transcribed (`seconds` of audio, once known).
    Transcribing {
        seconds: Option<f64>,
        spinner: usize,
    },
}

/// The dictation panel's state: where push-to-talk is and what the model is doing.
#[derive(Debug, Clone, Default)]
pub struct DictationPanel {
    pub state: Dictation,
    /// Loading or fetching the model.
    pub preparing: Option<String>,
}

const METER_CELLS: usize = 20;
/// How long a recording may stay silent before the panel says so.
const QUIET_WARNING_AFTER: Duration = Duration::from_millis(1500);
const SPINNER: [&str; 4] = ["|", "/", "-", "\\"];

impl DictationPanel {
    /// Whether the panel replaces the input line.
    pub fn is_shown(&self) -> bool {
        !matches!(self.state, Dictation::Idle)
    }

    pub fn is_recording(&self) -> bool {
        matches!(
            self.state,
            Dictation::Recording { .. } | Dictation::Starting
        )
    }

    pub fn is_transcribing(&self) -> bool {
        matches!(self.state, Dictation::Transcribing { .. })
    }

    pub fn recording(&mut self, device: String) {
        self.state = Dictation::Recording {
            device,
            started: Instant::now(),
            elapsed: Duration::ZERO,
            level: None,
            peak: None,
        };
    }

    pub fn level(&mut self, new: Level) {
        if let Dictation::Recording { level, peak, .. } = &mut self.state {
            *level = Some(new);
            if peak.is_none_or(|p| new.rms_dbfs > p.rms_dbfs) {
                *peak = Some(new);
            }
        }
    }

    pub fn transcribing(&mut self, audio_seconds: Option<f64>) {
        let spinner = match self.state {
            Dictation::Transcribing { spinner, .. } => spinner,
            _ => 0,
        };
        self.state = Dictation::Transcribing {
            seconds: audio_seconds,
            spinner,
        };
    }

    pub fn idle(&mut self) {
        self.state = Dictation::Idle;
        self.preparing = None;
    }

    /// Advance the clock and the spinner.
    pub fn animate(&mut self) {
        match &mut self.state {
            Dictation::Recording {
                started, elapsed, ..
            } => *elapsed = started.elapsed(),
            Dictation::Transcribing { spinner, .. } => *spinner = (*spinner + 1) % SPINNER.len(),
            Dictation::Idle | Dictation::Starting => {}
        }
    }

    /// Draw in the input line's place; `key` is the push-to-talk key.
    pub fn draw(&self, frame: &mut Frame, area: Rect, theme: &Theme, key: &str) {
        let (title, line) = match &self.state {
            Dictation::Idle => return,
            Dictation::Starting => (
                strings::DICTATION_TITLE_STARTING.to_string(),
                Line::from(Span::styled(strings::OPENING_MICROPHONE, theme.dim)),
            ),
            Dictation::Recording {
                device,
                elapsed,
                level,
                peak,
                ..
            } => {
                let filled = level.map_or(0, |l| meter_cells(l.meter()));
                let (full, empty) = theme.meter;
                let dbfs = level.map_or_else(
                    || "   -- dBFS".to_string(),
                    |l| format!("{:>5.0} dBFS", l.rms_dbfs.max(-99.0)),
                );
                let mut spans = vec![
                    Span::styled(strings::REC_MARK, theme.error),
                    Span::raw(format!(" {}  ", clock(*elapsed))),
                    Span::styled(full.repeat(filled), theme.success),
                    Span::styled(empty.repeat(METER_CELLS - filled), theme.dim),
                    Span::raw(format!(" {dbfs}  ")),
                    Span::styled(device.clone(), theme.dim),
                ];
                // A meter that has not moved for a while: say so before the person has
                // spoken a whole instruction into a muted microphone.
                let silent = peak.is_none_or(|p| p.peak_dbfs < SILENCE_PEAK_DBFS);
                if silent && *elapsed >= QUIET_WARNING_AFTER {
                    spans.push(Span::styled(
                        format!("  {}", strings::NO_SOUND_YET),
                        theme.error,
                    ));
                } else if let Some(p) = &self.preparing {
                    spans.push(Span::styled(format!("  ({p})"), theme.dim));
                }
                (strings::dictation_title_recording(key), Line::from(spans))
            }
            Dictation::Transcribing { seconds, spinner } => {
                let what = self
                    .preparing
                    .clone()
                    .unwrap_or_else(|| strings::transcribing(*seconds));
                (
                    strings::DICTATION_TITLE_TRANSCRIBING.to_string(),
                    Line::from(vec![
                        Span::styled(SPINNER[*spinner % SPINNER.len()], theme.running),
                        Span::raw(" "),
                        Span::raw(what),
                    ]),
                )
            }
        };
        let block = Block::default()
            .borders(Borders::ALL)
            .border_style(theme.border)
            .title(Span::styled(title, theme.title));
        frame.render_widget(Paragraph::new(line).block(block), area);
    }
}

/// How many meter cells a 0..=1 level fills.
fn meter_cells(meter: f64) -> usize {
    let cells = (meter.clamp(0.0, 1.0) * METER_CELLS as f64).round();
    // A float in 0..=METER_CELLS, so the conversion is exact.
    (cells as usize).min(METER_CELLS)
}

/// `m:ss.d`
fn clock(elapsed: Duration) -> String {
    let tenths = elapsed.as_millis() / 100;
    format!("{}:{:02}.{}", tenths / 600, (tenths / 10) % 60, tenths % 10)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clock_and_the_meter() {
        assert_eq!(clock(Duration::from_millis(3_249)), "0:03.2");
        assert_eq!(clock(Duration::from_millis(75_000)), "1:15.0");
        assert_eq!(meter_cells(0.0), 0);
        assert_eq!(meter_cells(0.5), 10);
        assert_eq!(meter_cells(1.7), METER_CELLS);
        let mut panel = DictationPanel::default();
        panel.recording("mic".into());
        let quiet = Level {
            rms_dbfs: -50.0,
            peak_dbfs: -40.0,
        };
        let loud = Level {
            rms_dbfs: -12.0,
            peak_dbfs: -3.0,
        };
        panel.level(loud);
        panel.level(quiet);
        match &panel.state {
            Dictation::Recording { level, peak, .. } => {
                assert_eq!(*level, Some(quiet));
                assert_eq!(*peak, Some(loud));
            }
            other => panic!("{other:?}"),
        }
    }
}
