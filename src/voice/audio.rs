//! Audio as the speech-to-text models want it: 16 kHz mono `f32` in [-1, 1]. WAV files of
//! any common rate, channel count and sample format (8/16/24/32-bit integer, 32-bit float,
//! clipped to full scale) are read with `hound`, mixed down to mono and resampled with
//! [`super::resample`]; levels
//! (RMS and peak in dBFS) drive a meter and tell an empty or silent recording apart.

use std::path::Path;
use std::time::Duration;

use super::VoiceError;
use super::resample::resample;

/// The sample rate every backend gets.
pub const SAMPLE_RATE: u32 = 16_000;
/// Shorter recordings are "empty": a tap of the key, not an utterance.
pub const MIN_SECONDS: f64 = 0.3;
/// A recording whose loudest sample stays below this is "silent" (a muted or dead
/// microphone; speech peaks well above -30 dBFS, a quiet room's noise below -50).
pub const SILENCE_PEAK_DBFS: f64 = -45.0;
/// The floor reported for digital silence.
pub const FLOOR_DBFS: f64 = -120.0;
/// The sample rates a WAV file may declare: telephone speech to the fastest common
/// recording interfaces. Resampling from a lower rate makes more samples than the file
/// holds bytes (16,000 for each at 1 Hz), and from a far higher one needs a filter of
/// millions of taps per phase, so a header that claims such a rate is refused.
pub const MIN_WAV_RATE: u32 = 8_000;
pub const MAX_WAV_RATE: u32 = 384_000;

/// 16 kHz mono audio.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Audio16k {
    samples: Vec<f32>,
}

/// Loudness of a stretch of audio, in dB relative to full scale (0 dBFS = ±1.0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    pub rms_dbfs: f64,
    pub peak_dbfs: f64,
}

impl Level {
    /// The level of `samples` (the floor for none).
    pub fn of(samples: &[f32]) -> Level {
        if samples.is_empty() {
            return Level {
                rms_dbfs: FLOOR_DBFS,
                peak_dbfs: FLOOR_DBFS,
            };
        }
        let (mut sum, mut peak) = (0.0f64, 0.0f64);
        for &s in samples {
            let s = f64::from(s);
            sum += s * s;
            peak = peak.max(s.abs());
        }
        Level {
            rms_dbfs: dbfs((sum / samples.len() as f64).sqrt()),
            peak_dbfs: dbfs(peak),
        }
    }

    /// The RMS level mapped to 0.0 ..= 1.0 over -60 ..= 0 dBFS, for drawing a meter.
    pub fn meter(&self) -> f64 {
        ((self.rms_dbfs + 60.0) / 60.0).clamp(0.0, 1.0)
    }
}

fn dbfs(amplitude: f64) -> f64 {
    if amplitude <= 0.0 {
        FLOOR_DBFS
    } else {
        (20.0 * amplitude.log10()).max(FLOOR_DBFS)
    }
}

impl Audio16k {
    /// Samples already at 16 kHz mono.
    pub fn new(samples: Vec<f32>) -> Audio16k {
        Audio16k { samples }
    }

    /// Interleaved samples of `channels` channels at `rate` Hz: mixed down to mono (the
    /// mean of the channels) and resampled to 16 kHz.
    pub fn from_interleaved(samples: &[f32], rate: u32, channels: u16) -> Audio16k {
        let channels = usize::from(channels.max(1));
        let mono: Vec<f32> = if channels == 1 {
            samples.to_vec()
        } else {
            samples
                .chunks_exact(channels)
                .map(|frame| frame.iter().sum::<f32>() / channels as f32)
                .collect()
        };
        Audio16k {
            samples: resample(&mono, rate, SAMPLE_RATE),
        }
    }

    /// Read a WAV file.
    pub fn from_wav(path: &Path) -> Result<Audio16k, VoiceError> {
        let file = std::fs::File::open(path).map_err(|e| VoiceError::Wav {
            path: path.to_path_buf(),
            detail: format!("cannot read the file: {e}"),
        })?;
        Self::read_wav(std::io::BufReader::new(file), path)
    }

    /// Read a WAV file's bytes; `name` names them in errors.
    pub fn from_wav_bytes(bytes: &[u8], name: &Path) -> Result<Audio16k, VoiceError> {
        Self::read_wav(std::io::Cursor::new(bytes), name)
    }

    fn read_wav(source: impl std::io::Read, path: &Path) -> Result<Audio16k, VoiceError> {
        let wav_error = |detail: String| VoiceError::Wav {
            path: path.to_path_buf(),
            detail,
        };
        let mut reader = hound::WavReader::new(source).map_err(|e| match e {
            hound::Error::IoError(io) => wav_error(format!("cannot read the file: {io}")),
            other => wav_error(format!("not a WAV file betr can read: {other}")),
        })?;
        let spec = reader.spec();
        if spec.channels == 0 || spec.sample_rate == 0 {
            return Err(wav_error(
                "the header declares no channels or a zero rate".into(),
            ));
        }
        if !(MIN_WAV_RATE..=MAX_WAV_RATE).contains(&spec.sample_rate) {
            return Err(wav_error(format!(
                "the header declares {} Hz; betr reads {MIN_WAV_RATE} to {MAX_WAV_RATE} Hz",
                spec.sample_rate
            )));
        }
        let samples: Vec<f32> = match (spec.sample_format, spec.bits_per_sample) {
            (hound::SampleFormat::Float, 32) => {
                // Full scale is ±1: louder samples are clipped (so mixing channels cannot
                // overflow), and a sample that is not a number is damage.
                let mut out = Vec::new();
                for (i, s) in reader.samples::<f32>().enumerate() {
                    let s = s.map_err(|e| wav_error(format!("damaged sample data: {e}")))?;
                    if !s.is_finite() {
                        return Err(wav_error(format!(
                            "damaged sample data: sample {i} is {s}, not a number of the waveform"
                        )));
                    }
                    out.push(s.clamp(-1.0, 1.0));
                }
                out
            }
            (hound::SampleFormat::Int, bits @ 1..=32) => {
                let scale = 2f64.powi(i32::from(bits) - 1);
                reader
                    .samples::<i32>()
                    .map(|s| s.map(|v| (f64::from(v) / scale) as f32))
                    .collect::<Result<_, _>>()
                    .map_err(|e| wav_error(format!("damaged sample data: {e}")))?
            }
            (format, bits) => {
                return Err(wav_error(format!(
                    "unsupported sample format: {bits}-bit {format:?} (use 8/16/24/32-bit PCM or 32-bit float)"
                )));
            }
        };
        Ok(Audio16k::from_interleaved(
            &samples,
            spec.sample_rate,
            spec.channels,
        ))
    }

    /// Write as a 16-bit PCM WAV (for an HTTP upload, or to keep a recording).
    pub fn to_wav_bytes(&self) -> Vec<u8> {
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate: SAMPLE_RATE,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let mut bytes = std::io::Cursor::new(Vec::with_capacity(44 + 2 * self.samples.len()));
        // Writing into memory cannot fail for lack of space; a failure would mean a bug in
        // hound, and an empty body is then reported by the server.
        if let Ok(mut writer) = hound::WavWriter::new(&mut bytes, spec) {
            for &s in &self.samples {
                let v = (f64::from(s).clamp(-1.0, 1.0) * f64::from(i16::MAX)).round() as i16;
                if writer.write_sample(v).is_err() {
                    break;
                }
            }
            let _ = writer.finalize();
        }
        bytes.into_inner()
    }

    pub fn samples(&self) -> &[f32] {
        &self.samples
    }

    pub fn into_samples(self) -> Vec<f32> {
        self.samples
    }

    pub fn seconds(&self) -> f64 {
        self.samples.len() as f64 / f64::from(SAMPLE_RATE)
    }

    pub fn duration(&self) -> Duration {
        Duration::from_secs_f64(self.seconds())
    }

    pub fn level(&self) -> Level {
        Level::of(&self.samples)
    }

    /// Refuse a recording with nothing to transcribe: too short to hold a word, or silent.
    pub fn check_speech(&self) -> Result<(), VoiceError> {
        if self.seconds() < MIN_SECONDS {
            return Err(VoiceError::EmptyRecording {
                seconds: self.seconds(),
            });
        }
        let level = self.level();
        if level.peak_dbfs < SILENCE_PEAK_DBFS {
            return Err(VoiceError::Silent {
                peak_dbfs: level.peak_dbfs,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "audio_tests.rs"]
mod tests;
