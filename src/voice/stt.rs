//! The speech-to-text seam: a backend turns 16 kHz mono audio into text and says how long
//! it took. [`transcribe`] is what front ends call: it refuses empty or silent audio
//! before any model runs and an empty transcript after.

use std::future::Future;
use std::pin::Pin;
use std::time::Duration;

use super::{Audio16k, VoiceError};

/// What a backend heard.
#[derive(Debug, Clone, PartialEq)]
pub struct Transcript {
    /// The text, trimmed, with runs of white space collapsed.
    pub text: String,
    /// Seconds of audio transcribed.
    pub audio_seconds: f64,
    /// Time spent transcribing (inference, or the HTTP round trip).
    pub elapsed: Duration,
    /// Which model produced it, e.g. `whisper-tiny.en (embedded)`.
    pub source: String,
}

impl Transcript {
    /// Transcription time over audio time: below 1 is faster than real time.
    pub fn real_time_factor(&self) -> f64 {
        if self.audio_seconds > 0.0 {
            self.elapsed.as_secs_f64() / self.audio_seconds
        } else {
            0.0
        }
    }
}

pub type SttFuture<'a> = Pin<Box<dyn Future<Output = Result<Transcript, VoiceError>> + Send + 'a>>;

/// A speech-to-text backend. Implementations never block the calling thread: local
/// inference runs on a thread of its own, HTTP is asynchronous.
pub trait SpeechToText: Send + Sync {
    /// The model and where it runs, for status lines.
    fn describe(&self) -> String;
    /// Transcribe `audio` as it is (no checks; see [`transcribe`]).
    fn transcribe<'a>(&'a self, audio: &'a Audio16k) -> SttFuture<'a>;
}

/// Transcribe dictated audio: refuse an empty or silent recording with a clear error,
/// run the backend, and refuse a transcript with no words.
pub async fn transcribe(
    stt: &dyn SpeechToText,
    audio: &Audio16k,
) -> Result<Transcript, VoiceError> {
    audio.check_speech()?;
    let mut transcript = stt.transcribe(audio).await?;
    transcript.text = tidy(&transcript.text);
    if !transcript.text.chars().any(char::is_alphanumeric) {
        return Err(VoiceError::EmptyTranscript {
            seconds: audio.seconds(),
        });
    }
    Ok(transcript)
}

/// Trim and collapse white space.
pub fn tidy(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Fixed(&'static str);

    impl SpeechToText for Fixed {
        fn describe(&self) -> String {
            "fixed".into()
        }
        fn transcribe<'a>(&'a self, audio: &'a Audio16k) -> SttFuture<'a> {
            Box::pin(async move {
                Ok(Transcript {
                    text: self.0.to_string(),
                    audio_seconds: audio.seconds(),
                    elapsed: Duration::from_millis(300),
                    source: self.describe(),
                })
            })
        }
    }

    fn speech() -> Audio16k {
        Audio16k::new((0..16_000).map(|i| (i as f32 * 0.1).sin() * 0.3).collect())
    }

    fn block_on<T>(f: impl Future<Output = T>) -> T {
        tokio::runtime::Builder::new_current_thread()
            .build()
            .unwrap()
            .block_on(f)
    }

    #[test]
    fn transcripts_are_tidied_and_timed() {
        let t = block_on(transcribe(
            &Fixed("  Put the cup\n on  the table. "),
            &speech(),
        ))
        .unwrap();
        assert_eq!(t.text, "Put the cup on the table.");
        assert!((t.real_time_factor() - 0.3).abs() < 1e-9);
    }

    #[test]
    fn silence_and_empty_transcripts_are_errors() {
        let silent = Audio16k::new(vec![0.0; 16_000]);
        let e = block_on(transcribe(&Fixed("hello"), &silent)).unwrap_err();
        assert!(matches!(e, VoiceError::Silent { .. }));
        let e = block_on(transcribe(&Fixed(" . "), &speech())).unwrap_err();
        assert!(matches!(e, VoiceError::EmptyTranscript { .. }), "{e}");
    }
}
