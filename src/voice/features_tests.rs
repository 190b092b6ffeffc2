//! The features against their definition: the filter bank equals librosa's (as computed by
//! the mel_spec crate that ct2rs uses), a tone lights the mel band of its frequency, and
//! silence and padding take the value of silence.

use super::*;

#[test]
fn the_filter_bank_is_librosas() {
    let ours = mel_filters(16_000.0, N_FFT, 80);
    let reference = mel_spec::mel::mel(16_000.0, N_FFT, 80, None, None, false, true);
    assert_eq!(reference.shape(), [80, BINS]);
    let mut worst = 0.0f64;
    for m in 0..80 {
        for k in 0..BINS {
            let d = (f64::from(ours[m * BINS + k]) - reference[[m, k]]).abs();
            worst = worst.max(d);
        }
    }
    assert!(worst < 1e-6, "largest difference {worst}");
}

fn tone(freq: f64, seconds: f64) -> Vec<f32> {
    (0..(seconds * 16_000.0) as usize)
        .map(|i| (0.5 * (2.0 * PI * freq * i as f64 / 16_000.0).sin()) as f32)
        .collect()
}

#[test]
fn a_tone_lights_its_own_band_and_padding_is_silence() {
    let mel = MelExtractor::new(80);
    let features = mel.chunk(&tone(1_000.0, 2.0));
    assert_eq!(features.len(), 80 * CHUNK_FRAMES);
    // Frame 100 (1 s in): the loudest band is the one whose centre is nearest 1 kHz.
    let frame: Vec<f32> = (0..80).map(|m| features[m * CHUNK_FRAMES + 100]).collect();
    let loudest = (0..80)
        .max_by(|&a, &b| frame[a].total_cmp(&frame[b]))
        .unwrap();
    let lo = hz_to_mel(0.0);
    let hi = hz_to_mel(8_000.0);
    let centre = |m: usize| mel_to_hz(lo + (hi - lo) * (m + 1) as f64 / 81.0);
    let nearest = (0..80)
        .min_by(|&a, &b| {
            (centre(a) - 1_000.0)
                .abs()
                .total_cmp(&(centre(b) - 1_000.0).abs())
        })
        .unwrap();
    assert_eq!(loudest, nearest);
    // The scale: the maximum maps to (max + 4) / 4 and nothing is below max - 8.
    let max = features.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let min = features.iter().copied().fold(f32::INFINITY, f32::min);
    assert!((max - min - 2.0).abs() < 1e-5, "range {min}..{max}");
    // Past the audio (3 s in): every band is at the floor, the value of silence.
    assert!((0..80).all(|m| features[m * CHUNK_FRAMES + 300] == min));
}

#[test]
fn silence_is_flat_and_long_audio_is_cut_at_30_seconds() {
    let mel = MelExtractor::new(80);
    let silent = mel.chunk(&[]);
    assert!(
        silent
            .iter()
            .all(|&v| (v - (-10.0 + 4.0) / 4.0).abs() < 1e-6)
    );
    let long = mel.chunk(&tone(300.0, 31.0));
    assert_eq!(long.len(), 80 * CHUNK_FRAMES);
    assert_eq!(mel.n_mels(), 80);
}
