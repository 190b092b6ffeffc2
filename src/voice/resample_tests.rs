//! The resampler against exact sines: the resampled signal must be the same sine sampled
//! at the new rate (frequency, amplitude and phase preserved), the length must follow the
//! ratio, and content above the new Nyquist frequency must be removed.

use std::f64::consts::PI;

use super::*;

fn sine(freq: f64, rate: u32, seconds: f64, amplitude: f64) -> Vec<f32> {
    let n = (seconds * f64::from(rate)).round() as usize;
    (0..n)
        .map(|i| (amplitude * (2.0 * PI * freq * i as f64 / f64::from(rate)).sin()) as f32)
        .collect()
}

/// Largest difference from the ideal sine at `rate`, away from the edges (where the
/// filter overlaps the silence outside the signal).
fn max_error(signal: &[f32], freq: f64, rate: u32, amplitude: f64) -> f64 {
    let margin = rate as usize / 20;
    signal[margin..signal.len() - margin]
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let t = (i + margin) as f64 / f64::from(rate);
            (f64::from(s) - amplitude * (2.0 * PI * freq * t).sin()).abs()
        })
        .fold(0.0, f64::max)
}

fn rms(signal: &[f32]) -> f64 {
    (signal.iter().map(|&s| f64::from(s).powi(2)).sum::<f64>() / signal.len() as f64).sqrt()
}

#[test]
fn lengths_follow_the_ratio() {
    assert_eq!(output_len(44_100, 44_100, 16_000), 16_000);
    assert_eq!(output_len(48_000, 48_000, 16_000), 16_000);
    assert_eq!(output_len(8_000, 8_000, 16_000), 16_000);
    assert_eq!(output_len(3, 48_000, 16_000), 1);
    for (from, len) in [
        (44_100, 44_100 * 2),
        (22_050, 11_025),
        (48_000, 4_801),
        (8_000, 99),
    ] {
        let out = resample(&vec![0.25; len], from, 16_000);
        assert_eq!(out.len(), output_len(len, from, 16_000), "{from} Hz, {len}");
        let expected = len as f64 * 16_000.0 / f64::from(from);
        assert!(
            (out.len() as f64 - expected).abs() <= 0.5,
            "{from}: {}",
            out.len()
        );
    }
}

#[test]
fn sines_keep_frequency_amplitude_and_phase() {
    for from in [48_000, 44_100, 22_050, 32_000, 8_000, 11_025] {
        for freq in [440.0, 1000.0, 3000.0] {
            if freq > 0.45 * f64::from(from) {
                continue;
            }
            let input = sine(freq, from, 1.0, 0.8);
            let out = resample(&input, from, 16_000);
            let err = max_error(&out, freq, 16_000, 0.8);
            assert!(err < 2e-3, "{freq} Hz from {from} Hz: error {err}");
        }
    }
}

#[test]
fn rates_without_a_phase_table_work_too() {
    // gcd(16001, 16000) = 1: 16000 phases, computed per sample.
    let input = sine(700.0, 16_001, 0.4, 0.5);
    let out = resample(&input, 16_001, 16_000);
    assert!(max_error(&out, 700.0, 16_000, 0.5) < 2e-3);
}

#[test]
fn content_above_the_new_nyquist_frequency_is_removed() {
    // 12 kHz at 48 kHz would alias to 4 kHz at 16 kHz without the low-pass filter.
    let input = sine(12_000.0, 48_000, 1.0, 0.8);
    let out = resample(&input, 48_000, 16_000);
    let interior = &out[800..out.len() - 800];
    assert!(rms(interior) < 0.8 * 1e-3, "rms {}", rms(interior));
}

#[test]
fn a_constant_keeps_its_level_and_the_same_rate_is_a_copy() {
    let out = resample(&vec![0.5; 44_100], 44_100, 16_000);
    assert!(out[1000..15_000].iter().all(|&s| (s - 0.5).abs() < 1e-5));
    let input = sine(440.0, 16_000, 0.1, 0.3);
    assert_eq!(resample(&input, 16_000, 16_000), input);
    assert!(resample(&[], 48_000, 16_000).is_empty());
}
