//! Whisper's input features, computed exactly as OpenAI's reference implementation does
//! (`whisper/audio.py`, also faster-whisper's): the audio padded with silence to 30 s, a
//! short-time Fourier transform (400-sample periodic Hann window, hop 160, reflect-padded
//! centre frames, the last frame dropped), power spectra through 80 Slaney-normalised mel
//! filters, `log10` (floored at 1e-10), clamped to 8 below the chunk's maximum, and scaled
//! as `(x + 4) / 4`.
//!
//! `ct2rs`'s own pipeline normalises every frame by its own maximum and leaves the padding
//! at 0 instead of the value of silence, which the model never saw in training; with
//! synthetic speech that turned "Put the blue cube ..." into "Well, it's the blue cube ...".
//! Only frames that overlap the audio are transformed: the rest are silence.

use std::f64::consts::PI;
use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

/// Samples per FFT window.
pub const N_FFT: usize = 400;
/// Samples between frames.
pub const HOP: usize = 160;
/// Samples in one 30-second chunk at 16 kHz.
pub const CHUNK_SAMPLES: usize = 480_000;
/// Frames in one chunk.
pub const CHUNK_FRAMES: usize = CHUNK_SAMPLES / HOP;
const BINS: usize = N_FFT / 2 + 1;

/// Computes log-mel features for one model (80 or 128 mel bins).
pub struct MelExtractor {
    n_mels: usize,
    /// `n_mels` rows of `BINS` weights.
    filters: Vec<f32>,
    window: Vec<f32>,
    fft: Arc<dyn Fft<f32>>,
}

impl MelExtractor {
    pub fn new(n_mels: usize) -> MelExtractor {
        let window = (0..N_FFT)
            .map(|i| (0.5 - 0.5 * (2.0 * PI * i as f64 / N_FFT as f64).cos()) as f32)
            .collect();
        MelExtractor {
            n_mels,
            filters: mel_filters(16_000.0, N_FFT, n_mels),
            window,
            fft: FftPlanner::new().plan_fft_forward(N_FFT),
        }
    }

    pub fn n_mels(&self) -> usize {
        self.n_mels
    }

    /// Features of one chunk of at most 30 s: `n_mels` rows of `CHUNK_FRAMES` values,
    /// row-major (the `[n_mels, 3000]` layout the encoder takes).
    pub fn chunk(&self, samples: &[f32]) -> Vec<f32> {
        let samples = &samples[..samples.len().min(CHUNK_SAMPLES)];
        // Frame t is centred on sample t·HOP; frames whose window reaches no audio are
        // silence (their power is 0, their log the floor).
        let active = samples.len().div_ceil(HOP) + N_FFT / HOP + 1;
        let active = active.min(CHUNK_FRAMES);
        let mut log_mel = vec![-10.0f32; self.n_mels * CHUNK_FRAMES];
        let mut buffer = vec![Complex::new(0.0f32, 0.0); N_FFT];
        let mut power = vec![0.0f32; BINS];
        let half = (N_FFT / 2) as isize;
        for t in 0..active {
            let start = (t * HOP) as isize - half;
            for (i, slot) in buffer.iter_mut().enumerate() {
                *slot = Complex::new(padded(samples, start + i as isize) * self.window[i], 0.0);
            }
            self.fft.process(&mut buffer);
            for (p, c) in power.iter_mut().zip(&buffer) {
                *p = c.norm_sqr();
            }
            for m in 0..self.n_mels {
                let row = &self.filters[m * BINS..(m + 1) * BINS];
                let energy: f32 = row.iter().zip(&power).map(|(w, p)| w * p).sum();
                log_mel[m * CHUNK_FRAMES + t] = energy.max(1e-10).log10();
            }
        }
        let max = log_mel.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        for v in &mut log_mel {
            *v = (v.max(max - 8.0) + 4.0) / 4.0;
        }
        log_mel
    }
}

/// The sample at `i` of the audio padded with silence to 30 s and reflect-padded by half a
/// window at both ends (torch.stft's `center=True, pad_mode="reflect"`).
fn padded(samples: &[f32], i: isize) -> f32 {
    let n = CHUNK_SAMPLES as isize;
    let j = if i < 0 {
        -i
    } else if i >= n {
        2 * (n - 1) - i
    } else {
        i
    };
    samples.get(j as usize).copied().unwrap_or(0.0)
}

/// Slaney mel scale (librosa's default, as Whisper's filters use).
fn hz_to_mel(hz: f64) -> f64 {
    let f_sp = 200.0 / 3.0;
    let min_log_hz = 1000.0;
    let logstep = 6.4f64.ln() / 27.0;
    if hz < min_log_hz {
        hz / f_sp
    } else {
        min_log_hz / f_sp + (hz / min_log_hz).ln() / logstep
    }
}

fn mel_to_hz(mel: f64) -> f64 {
    let f_sp = 200.0 / 3.0;
    let min_log_mel = 1000.0 / f_sp;
    let logstep = 6.4f64.ln() / 27.0;
    if mel < min_log_mel {
        mel * f_sp
    } else {
        1000.0 * (logstep * (mel - min_log_mel)).exp()
    }
}

/// librosa.filters.mel(sr, n_fft, n_mels) with Slaney normalisation, row-major.
pub fn mel_filters(sample_rate: f64, n_fft: usize, n_mels: usize) -> Vec<f32> {
    let bins = n_fft / 2 + 1;
    let fft_hz: Vec<f64> = (0..bins)
        .map(|k| k as f64 * sample_rate / n_fft as f64)
        .collect();
    let (lo, hi) = (hz_to_mel(0.0), hz_to_mel(sample_rate / 2.0));
    let points: Vec<f64> = (0..n_mels + 2)
        .map(|i| mel_to_hz(lo + (hi - lo) * i as f64 / (n_mels + 1) as f64))
        .collect();
    let mut filters = Vec::with_capacity(n_mels * bins);
    for m in 0..n_mels {
        let (left, centre, right) = (points[m], points[m + 1], points[m + 2]);
        let norm = 2.0 / (right - left);
        for &f in &fft_hz {
            let rising = (f - left) / (centre - left);
            let falling = (right - f) / (right - centre);
            filters.push((rising.min(falling).max(0.0) * norm) as f32);
        }
    }
    filters
}

#[cfg(test)]
#[path = "features_tests.rs"]
mod tests;
