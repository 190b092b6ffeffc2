//! WAV files (`voice::Audio16k::from_wav_bytes`): headers of every format, rate, channel
//! count and sample size, and headers that lie about their sizes.
//!
//! Properties: reading allocates nothing near what a lying header claims (the process's
//! peak of reserved memory grows by less than 512 MiB, and the audio read is at most
//! twice as many samples as the file has bytes); the samples read are finite; audio read
//! is written (`to_wav_bytes`) and read back with as many samples, each what 16-bit
//! PCM keeps of it; every error says something.

use crate::fuzz::Material;
use std::path::Path;

use super::{Rng, Target, Violation, ensure, strings};
use crate::voice::Audio16k;

/// Growth of the peak of reserved memory that counts as a blow-up.
const PEAK_GROWTH_LIMIT_KB: u64 = 512 * 1024;

pub struct WavTarget {
    material: Material,
}

impl WavTarget {
    pub fn new() -> WavTarget {
        let specs = [
            (1, 16_000, 16, hound::SampleFormat::Int),
            (2, 44_100, 16, hound::SampleFormat::Int),
            (1, 8_000, 8, hound::SampleFormat::Int),
            (1, 48_000, 24, hound::SampleFormat::Int),
            (2, 22_050, 32, hound::SampleFormat::Int),
            (1, 16_000, 32, hound::SampleFormat::Float),
            (6, 96_000, 16, hound::SampleFormat::Int),
        ];
        let seeds = specs
            .iter()
            .enumerate()
            .map(|(k, &(channels, sample_rate, bits, format))| {
                written(
                    hound::WavSpec {
                        channels,
                        sample_rate,
                        bits_per_sample: bits,
                        sample_format: format,
                    },
                    40 + 30 * k,
                )
            })
            .collect();
        WavTarget {
            material: Material {
                seeds,
                tokens: strings(&[
                    "RIFF",
                    "WAVE",
                    "fmt ",
                    "data",
                    "fact",
                    "LIST",
                    "JUNK",
                    "\u{0}\u{0}\u{0}\u{0}",
                ]),
                brackets: Vec::new(),
            },
        }
    }
}

/// A short tone written by hound in `spec`.
fn written(spec: hound::WavSpec, frames: usize) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    if let Ok(mut w) = hound::WavWriter::new(&mut bytes, spec) {
        let amplitude = 2f64.powi(i32::from(spec.bits_per_sample) - 2);
        for i in 0..frames * usize::from(spec.channels) {
            let x = (i as f64 * 0.3).sin();
            let ok = match spec.sample_format {
                hound::SampleFormat::Float => w.write_sample(x as f32 * 0.5),
                hound::SampleFormat::Int => w.write_sample((x * amplitude) as i32),
            };
            if ok.is_err() {
                break;
            }
        }
        let _ = w.finalize();
    }
    bytes.into_inner()
}

/// A WAV header assembled field by field, any field possibly a lie, then sample bytes.
fn header(rng: &mut Rng) -> Vec<u8> {
    let mut out = Vec::new();
    // Each size field lies now and then; a header whose fields agree reaches the samples.
    let u32_field = |rng: &mut Rng, usual: u32| -> u32 {
        match rng.below(20) {
            0 => u32::MAX,
            1 => 0,
            2 => (rng.next_u64() & 0xffff_ffff) as u32,
            3 => 0x7fff_ffff,
            _ => usual,
        }
    };
    let payload = rng.small(600);
    out.extend_from_slice(b"RIFF");
    out.extend_from_slice(&u32_field(rng, 36 + payload as u32).to_le_bytes());
    out.extend_from_slice(b"WAVE");
    if rng.chance(20) {
        let tag: &[u8] = rng
            .pick(&[&b"LIST"[..], b"fact", b"JUNK"])
            .copied()
            .unwrap_or(b"JUNK");
        out.extend_from_slice(tag);
        out.extend_from_slice(&u32_field(rng, 4).to_le_bytes());
        out.extend_from_slice(&[0, 0, 0, 0]);
    }
    let format: u16 = *rng.pick(&[1u16, 1, 3, 0xFFFE, 2, 0, 0xFFFF]).unwrap_or(&1);
    let channels: u16 = *rng.pick(&[1u16, 1, 2, 0, 3, 8, 65535]).unwrap_or(&1);
    let rate: u32 = *rng
        .pick(&[
            16_000u32,
            44_100,
            8_000,
            1,
            0,
            2,
            7_999,
            768_000,
            4_000_000_000,
            u32::MAX,
            3_999_999_996,
            1_000_003,
        ])
        .unwrap_or(&16_000);
    let bits: u16 = *rng
        .pick(&[16u16, 8, 8, 24, 32, 0, 1, 4, 12, 64, 65535])
        .unwrap_or(&16);
    let extensible = format == 0xFFFE;
    let fmt_len: u32 = if extensible {
        40
    } else {
        *rng.pick(&[16u32, 16, 16, 18, 14, 0, 1000]).unwrap_or(&16)
    };
    out.extend_from_slice(b"fmt ");
    out.extend_from_slice(&fmt_len.to_le_bytes());
    out.extend_from_slice(&format.to_le_bytes());
    out.extend_from_slice(&channels.to_le_bytes());
    out.extend_from_slice(&rate.to_le_bytes());
    let align = u32::from(channels) * u32::from(bits).div_ceil(8);
    out.extend_from_slice(&u32_field(rng, rate.wrapping_mul(align)).to_le_bytes());
    out.extend_from_slice(&(u32_field(rng, align) as u16).to_le_bytes());
    out.extend_from_slice(&bits.to_le_bytes());
    if extensible {
        out.extend_from_slice(&22u16.to_le_bytes());
        out.extend_from_slice(&(*rng.pick(&[bits, 0, 8, 33]).unwrap_or(&bits)).to_le_bytes());
        out.extend_from_slice(&(rng.next_u64() as u32).to_le_bytes());
        // The PCM or IEEE-float sub-format GUID.
        let sub: u8 = *rng.pick(&[1u8, 3, 2]).unwrap_or(&1);
        out.extend_from_slice(&[
            sub, 0, 0, 0, 0, 0, 0x10, 0, 0x80, 0, 0, 0xAA, 0, 0x38, 0x9B, 0x71,
        ]);
    } else if fmt_len > 16 {
        out.extend(std::iter::repeat_n(0u8, (fmt_len - 16).min(64) as usize));
    }
    out.extend_from_slice(b"data");
    out.extend_from_slice(&u32_field(rng, payload as u32).to_le_bytes());
    for _ in 0..payload {
        out.push((rng.next_u64() & 0xff) as u8);
    }
    out
}

/// The peak of the process's reserved memory in kB (`VmPeak`), where Linux tells it.
fn peak_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmPeak:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

impl Target for WavTarget {
    fn name(&self) -> &'static str {
        "wav"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn is_text(&self) -> bool {
        false
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        header(rng)
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let before = peak_kb();
        let read = Audio16k::from_wav_bytes(input, Path::new("fuzz.wav"));
        if let (Some(before), Some(after)) = (before, peak_kb()) {
            ensure(
                after.saturating_sub(before) < PEAK_GROWTH_LIMIT_KB,
                "reading a WAV reserves no memory its size does not justify",
                || {
                    format!(
                        "the peak grew by {} MiB for {} bytes",
                        (after - before) / 1024,
                        input.len()
                    )
                },
            )?;
        }
        let audio = match read {
            Ok(a) => a,
            Err(e) => {
                return ensure(
                    !e.to_string().is_empty(),
                    "a WAV error says something",
                    || format!("{e:?}"),
                );
            }
        };
        let samples = audio.samples();
        ensure(
            samples.len() <= 2 * input.len() + 16,
            "WAV audio is at most twice as many samples as the file has bytes",
            || format!("{} samples from {} bytes", samples.len(), input.len()),
        )?;
        if let Some(i) = samples.iter().position(|s| !s.is_finite()) {
            return Err(super::broken(
                "WAV samples are finite",
                format!("sample {i} of {} is {}", samples.len(), samples[i]),
            ));
        }
        let again = Audio16k::from_wav_bytes(&audio.to_wav_bytes(), Path::new("written.wav"));
        let Ok(again) = again else {
            return ensure(false, "audio written as WAV reads back", || {
                format!("{again:?}")
            });
        };
        // What 16-bit PCM keeps of a sample: clipped, scaled by 32767 and rounded when
        // written, divided by 32768 when read.
        let kept = |a: f32| (f64::from(a).clamp(-1.0, 1.0) * 32767.0).round() / 32768.0;
        ensure(
            again.samples().len() == samples.len()
                && again
                    .samples()
                    .iter()
                    .zip(samples)
                    .all(|(b, a)| (f64::from(*b) - kept(*a)).abs() <= 1e-7),
            "audio written as WAV reads back as 16-bit PCM keeps it",
            || format!("{} samples, then {}", samples.len(), again.samples().len()),
        )
    }
}
