//! A stand-in microphone for the workbench's push-to-talk: its recording is given audio
//! (synthesised speech, or a tone), its levels are that audio's, 50 ms at a time; or it
//! fails to open the way a machine without a sound card does.

use std::sync::Arc;

use betr::tui::dictation::{Microphone, Recording};
use betr::voice::{Audio16k, Level, VoiceError};

pub struct AudioMicrophone {
    audio: Audio16k,
    fail: bool,
}

impl AudioMicrophone {
    pub fn playing(audio: Audio16k) -> Arc<AudioMicrophone> {
        Arc::new(AudioMicrophone { audio, fail: false })
    }

    /// A machine without an input device.
    pub fn missing() -> Arc<AudioMicrophone> {
        Arc::new(AudioMicrophone {
            audio: Audio16k::default(),
            fail: true,
        })
    }
}

struct Played(Audio16k);

impl Recording for Played {
    fn stop(self: Box<Self>) -> Result<Audio16k, VoiceError> {
        self.0.check_speech()?;
        Ok(self.0)
    }
}

impl Microphone for AudioMicrophone {
    fn start(
        &self,
        mut on_level: Box<dyn FnMut(Level) + Send>,
    ) -> Result<(String, Box<dyn Recording>), VoiceError> {
        if self.fail {
            return Err(VoiceError::NoInputDevice {
                detail: "\"Default Audio Device\" is not available".into(),
            });
        }
        let samples = self.audio.samples().to_vec();
        std::thread::spawn(move || {
            // As a device does, a moment after the stream starts.
            std::thread::sleep(std::time::Duration::from_millis(20));
            for chunk in samples.chunks(800) {
                on_level(Level::of(chunk));
            }
        });
        Ok((
            "test microphone".into(),
            Box::new(Played(self.audio.clone())),
        ))
    }
}

/// A tone loud enough to count as speech.
pub fn tone(seconds: f64) -> Audio16k {
    let n = (seconds * 16_000.0) as usize;
    Audio16k::new((0..n).map(|i| (i as f32 * 0.05).sin() * 0.4).collect())
}
