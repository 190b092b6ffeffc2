//! Dictation: audio capture and speech-to-text. This module knows nothing of trees,
//! scenarios, language models or user interfaces: it turns a microphone or a WAV file into
//! 16 kHz mono audio and the audio into text.
//!
//! For a push-to-talk front end:
//!
//! ```no_run
//! # async fn demo(stt: &dyn betr::voice::SpeechToText) -> Result<(), betr::voice::VoiceError> {
//! use betr::voice::{Recorder, transcribe};
//! let recorder = Recorder::start(|level| { /* update the meter with level.meter() */ })?;
//! // ... the key is pressed again; recorder.elapsed() shows the time meanwhile ...
//! let audio = recorder.stop()?; // Err: empty or silent recording
//! let transcript = transcribe(stt, &audio).await?;
//! // put transcript.text in the input line for the user to correct; never submit it unseen
//! # Ok(()) }
//! ```

pub mod audio;
pub mod capture;
pub mod config;
mod error;
pub mod features;
pub mod openai_stt;
pub mod resample;
pub mod stt;
pub mod wer;
pub mod whisper_local;

pub use audio::{Audio16k, Level, SAMPLE_RATE};
pub use capture::Recorder;
pub use config::{SttBackend, SttLayer, SttSettings};
pub use error::VoiceError;
pub use openai_stt::OpenAiStt;
pub use stt::{SpeechToText, SttFuture, Transcript, transcribe};
pub use wer::word_error_rate;
pub use whisper_local::{LocalSettings, LocalWhisper};
