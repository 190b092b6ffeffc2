//! What the workbench's background services report: the fetch of the robot description
//! and the embedded model, and push-to-talk.

use crate::session::Command;

use super::super::components::input::Mode;
use super::super::dictation::DictationEvent;
use super::super::strings;
use super::{App, AppEvent};

/// How a model fetched or loaded while the workbench is open comes along.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ModelArrival {
    /// Where the fetch stands, in a few words for the status bar.
    Progress(String),
    /// The model is there and answers from now on.
    Ready,
    /// It will not come: why.
    Failed(String),
    /// The robot description the cell's arms need arrived in the cache.
    RobotReady,
    /// The robot description will not come: why (the cell keeps its reach spheres and
    /// gripper sweep).
    RobotFailed(String),
}

impl App {
    /// What the background fetch reports.
    pub fn on_model(&mut self, arrival: ModelArrival) {
        match arrival {
            ModelArrival::Progress(text) => self.status.fetching = Some(text),
            ModelArrival::Ready => {
                self.status.fetching = None;
                self.llm.log(strings::MODEL_READY);
            }
            ModelArrival::Failed(why) => {
                self.status.fetching = None;
                self.llm.error = Some(strings::no_model(&why));
            }
            // The session says what the arms' arrival changes.
            ModelArrival::RobotReady => {
                self.status.fetching = None;
                self.queue.push(AppEvent::Command(Command::RobotArrived));
            }
            ModelArrival::RobotFailed(why) => {
                self.status.fetching = None;
                self.llm.log(strings::no_robot(&why));
            }
        }
    }

    /// What the push-to-talk service reports.
    pub fn on_dictation(&mut self, event: DictationEvent) {
        match event {
            DictationEvent::Recording { device } => {
                // A cancel that arrived before the microphone opened wins.
                if self.dictation.is_recording() {
                    self.dictation.recording(device);
                }
            }
            DictationEvent::Level(level) => self.dictation.level(level),
            DictationEvent::Preparing(what) => self.dictation.preparing = Some(what),
            DictationEvent::Transcribing { seconds } => {
                self.dictation.preparing = None;
                self.dictation.transcribing(Some(seconds));
            }
            DictationEvent::Heard(transcript) => {
                self.dictation.idle();
                self.llm.log(format!("dictated: {}", transcript.text));
                // Into the input line, for the person to read and correct: never submitted
                // from here.
                if !self.input.is_open() {
                    self.input.open(Mode::Instruction, &transcript.text);
                } else if !self.input.insert_dictation(&transcript.text) {
                    let text = strings::transcript_not_placed(&transcript.text);
                    self.llm.log(text.clone());
                    return self.message(text, true);
                }
                self.message(
                    strings::dictated(
                        transcript.audio_seconds,
                        transcript.elapsed.as_secs_f64(),
                        &transcript.source,
                    ),
                    false,
                );
            }
            DictationEvent::Failed(why) => {
                self.dictation.idle();
                let text = strings::dictation_failed(&why);
                self.llm.log(text.clone());
                self.message(text, true);
            }
            DictationEvent::Cancelled => {
                self.dictation.idle();
                self.message(strings::RECORDING_DISCARDED.to_string(), false);
            }
        }
    }
}
