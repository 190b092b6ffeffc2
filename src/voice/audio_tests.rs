//! WAV files of several formats, levels, and the refusal of empty and silent recordings.

use std::f64::consts::PI;
use std::path::PathBuf;

use super::*;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("betr-audio-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn tone(i: usize, rate: u32) -> f64 {
    0.5 * (2.0 * PI * 440.0 * i as f64 / f64::from(rate)).sin()
}

/// Write one second of a 440 Hz tone at amplitude 0.5 on every channel.
fn write_wav(path: &Path, rate: u32, channels: u16, bits: u16, float: bool) {
    let spec = hound::WavSpec {
        channels,
        sample_rate: rate,
        bits_per_sample: bits,
        sample_format: if float {
            hound::SampleFormat::Float
        } else {
            hound::SampleFormat::Int
        },
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    let full = 2f64.powi(i32::from(bits) - 1) - 1.0;
    for i in 0..rate as usize {
        for _ in 0..channels {
            let v = tone(i, rate);
            match (float, bits) {
                (true, _) => w.write_sample(v as f32).unwrap(),
                (false, 8) => w.write_sample((v * full).round() as i8).unwrap(),
                (false, 16) => w.write_sample((v * full).round() as i16).unwrap(),
                (false, _) => w.write_sample((v * full).round() as i32).unwrap(),
            }
        }
    }
    w.finalize().unwrap();
}

#[test]
fn wav_files_of_every_format_become_the_same_16k_mono_tone() {
    let dir = scratch("formats");
    let cases = [
        (16_000, 1, 16, false),
        (44_100, 2, 16, false),
        (48_000, 1, 24, false),
        (22_050, 2, 8, false),
        (8_000, 1, 32, false),
        (48_000, 2, 32, true),
    ];
    for (rate, channels, bits, float) in cases {
        let path = dir.join(format!("{rate}-{channels}-{bits}-{float}.wav"));
        write_wav(&path, rate, channels, bits, float);
        let audio = Audio16k::from_wav(&path).unwrap();
        let what = path.display();
        assert_eq!(audio.samples().len(), 16_000, "{what}");
        // 8-bit samples are quantised to 1/128.
        let bound = if bits == 8 { 1.5e-2 } else { 3e-3 };
        let err = audio.samples()[800..15_200]
            .iter()
            .enumerate()
            .map(|(i, &s)| (f64::from(s) - tone(i + 800, SAMPLE_RATE)).abs())
            .fold(0.0, f64::max);
        assert!(err < bound, "{what}: error {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn levels_are_in_dbfs() {
    let audio = Audio16k::new((0..16_000).map(|i| tone(i, SAMPLE_RATE) as f32).collect());
    let level = audio.level();
    assert!((level.rms_dbfs - (-9.03)).abs() < 0.05, "{level:?}");
    assert!((level.peak_dbfs - (-6.02)).abs() < 0.05, "{level:?}");
    assert!((level.meter() - (60.0 - 9.03) / 60.0).abs() < 0.01);
    assert_eq!(Level::of(&[]).peak_dbfs, FLOOR_DBFS);
    assert_eq!(Level::of(&[0.0; 10]).rms_dbfs, FLOOR_DBFS);
    assert_eq!(Level::of(&[1.0, -1.0]).peak_dbfs, 0.0);
    assert!(audio.check_speech().is_ok());
}

#[test]
fn empty_and_silent_recordings_are_refused_with_a_reason() {
    let short = Audio16k::new(vec![0.3; 1_600]);
    let err = short.check_speech().unwrap_err();
    assert!(matches!(err, VoiceError::EmptyRecording { .. }));
    assert!(err.to_string().contains("empty (0.10 s)"), "{err}");
    let err = Audio16k::new(vec![]).check_speech().unwrap_err();
    assert!(matches!(err, VoiceError::EmptyRecording { .. }));
    // A dead microphone: digital silence, or a faint hum at -60 dBFS.
    let err = Audio16k::new(vec![0.0; 32_000]).check_speech().unwrap_err();
    assert!(err.to_string().contains("silent (peak -120 dBFS)"), "{err}");
    let hum: Vec<f32> = (0..32_000)
        .map(|i| tone(i, SAMPLE_RATE) as f32 * 0.002)
        .collect();
    assert!(matches!(
        Audio16k::new(hum).check_speech(),
        Err(VoiceError::Silent { .. })
    ));
}

#[test]
fn unreadable_files_name_the_file_and_the_problem() {
    let dir = scratch("bad");
    let text = dir.join("notes.wav");
    std::fs::write(&text, "not audio").unwrap();
    let err = Audio16k::from_wav(&text).unwrap_err().to_string();
    assert!(
        err.contains("notes.wav") && err.contains("not a WAV file"),
        "{err}"
    );
    let err = Audio16k::from_wav(&dir.join("missing.wav"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("missing.wav") && err.contains("cannot read"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn wav_bytes_round_trip() {
    let audio = Audio16k::new((0..8_000).map(|i| tone(i, SAMPLE_RATE) as f32).collect());
    let bytes = audio.to_wav_bytes();
    assert_eq!(&bytes[..4], b"RIFF");
    assert_eq!(bytes.len(), 44 + 2 * 8_000);
    let dir = scratch("bytes");
    let path = dir.join("a.wav");
    std::fs::write(&path, &bytes).unwrap();
    let back = Audio16k::from_wav(&path).unwrap();
    assert_eq!(back.samples().len(), 8_000);
    let err = back
        .samples()
        .iter()
        .zip(audio.samples())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(err < 1e-4, "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A WAV file of 300 8-bit mono samples at `rate` Hz.
fn wav_at(rate: u32) -> Vec<u8> {
    let mut bytes = b"RIFF".to_vec();
    bytes.extend_from_slice(&(36u32 + 300).to_le_bytes());
    bytes.extend_from_slice(b"WAVEfmt ");
    bytes.extend_from_slice(&16u32.to_le_bytes());
    bytes.extend_from_slice(&1u16.to_le_bytes());
    bytes.extend_from_slice(&1u16.to_le_bytes());
    bytes.extend_from_slice(&rate.to_le_bytes());
    bytes.extend_from_slice(&rate.to_le_bytes());
    bytes.extend_from_slice(&1u16.to_le_bytes());
    bytes.extend_from_slice(&8u16.to_le_bytes());
    bytes.extend_from_slice(b"data");
    bytes.extend_from_slice(&300u32.to_le_bytes());
    bytes.extend((0..300u32).map(|i| (i * 37 % 256) as u8));
    bytes
}

#[test]
fn a_header_claiming_an_absurd_rate_is_refused_before_resampling() {
    // At 4,294,967,295 Hz the resampling filter would need about 400 GB; at 2 Hz three
    // bytes would become 24,000 samples.
    for rate in [u32::MAX, 3_999_999_996, 384_001, 7_999, 2, 1] {
        let err = Audio16k::from_wav_bytes(&wav_at(rate), Path::new("lying.wav"))
            .unwrap_err()
            .to_string();
        assert!(err.contains(&format!("declares {rate} Hz")), "{err}");
    }
    for rate in [MIN_WAV_RATE, 44_100, MAX_WAV_RATE] {
        let audio = Audio16k::from_wav_bytes(&wav_at(rate), Path::new("a.wav")).unwrap();
        assert!(audio.samples().len() <= 2 * 300, "{rate}");
    }
}

/// A 32-bit float WAV file of `samples` at 16 kHz mono.
fn float_wav(samples: &[f32]) -> Vec<u8> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: SAMPLE_RATE,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    let mut w = hound::WavWriter::new(&mut bytes, spec).unwrap();
    for &s in samples {
        w.write_sample(s).unwrap();
    }
    w.finalize().unwrap();
    bytes.into_inner()
}

#[test]
fn float_samples_that_are_not_numbers_are_damage_and_loud_ones_are_clipped() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let err = Audio16k::from_wav_bytes(&float_wav(&[0.1, bad, 0.2]), Path::new("f.wav"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("damaged sample data: sample 1 is"), "{err}");
    }
    let loud =
        Audio16k::from_wav_bytes(&float_wav(&[3e38, -3e38, 0.5]), Path::new("f.wav")).unwrap();
    assert_eq!(loud.samples(), &[1.0, -1.0, 0.5]);
}
