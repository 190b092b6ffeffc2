//! Speech-to-text timing: model load time and the latency of transcribing a 3-second
//! utterance (spoken by espeak-ng, padded with silence to exactly 3.00 s) with each
//! embedded Whisper model in the cache (whisper-tiny.en is fetched if missing), greedy
//! and with beam search. Each latency is the median of several runs after a warm-up.
//!
//! Run: `cargo bench --bench stt` (needs `espeak-ng`; scripts/test.sh installs it)

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use betr::model::{self, Progress, STT_MODELS, WHISPER_TINY_EN};
use betr::voice::{Audio16k, LocalSettings, LocalWhisper, SAMPLE_RATE, word_error_rate};

const UTTERANCE: &str = "Put the blue cube on the green cube, then open the centrifuge";
const SECONDS: f64 = 3.0;
const LOADS: usize = 3;
const RUNS: usize = 5;

struct Log;
impl Progress for Log {
    fn stage(&mut self, message: &str) {
        eprintln!("{message}");
    }
    fn bytes(&mut self, _: u64, _: u64) {}
}

fn speak(text: &str, speed: u32, wav: &Path) -> Result<Audio16k, Box<dyn std::error::Error>> {
    let status = Command::new("espeak-ng")
        .args(["-s", &speed.to_string(), "-w"])
        .arg(wav)
        .arg(text)
        .status()?;
    if !status.success() {
        return Err(format!("espeak-ng failed: {status}").into());
    }
    Ok(Audio16k::from_wav(wav)?)
}

/// The utterance spoken to last just under `SECONDS`, padded with silence to exactly that.
fn utterance(dir: &Path) -> Result<(Audio16k, f64), Box<dyn std::error::Error>> {
    let wav = dir.join("utterance.wav");
    let natural = speak(UTTERANCE, 175, &wav)?.seconds();
    let speed = (175.0 * natural / (SECONDS - 0.2)).round() as u32;
    let mut samples = speak(UTTERANCE, speed, &wav)?.into_samples();
    let spoken = samples.len() as f64 / f64::from(SAMPLE_RATE);
    samples.resize((SECONDS * f64::from(SAMPLE_RATE)) as usize, 0.0);
    Ok((Audio16k::new(samples), spoken))
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn ms(d: Duration) -> String {
    format!("{:.0} ms", d.as_secs_f64() * 1000.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    if !WHISPER_TINY_EN.is_present() {
        model::fetch_dir(&WHISPER_TINY_EN, &model::cache_dir(), "python3", &mut Log)?;
    }
    let dir = std::env::temp_dir().join(format!("betr-bench-stt-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let (audio, spoken) = utterance(&dir)?;
    let threads = LocalSettings::default().threads;
    println!(
        "utterance: {UTTERANCE:?}, {spoken:.2} s of speech padded to {:.2} s; {threads} thread(s)",
        audio.seconds()
    );
    println!(
        "\n{:<16} {:>10} {:>10} {:>6} {:>12} {:>12} {:>12}  transcript",
        "model", "load 1st", "load med", "beam", "median", "min", "max"
    );
    for spec in STT_MODELS.iter().filter(|m| m.is_present()) {
        let mut loads = Vec::new();
        for _ in 0..LOADS {
            let m = LocalWhisper::load(&spec.path(), spec.name, LocalSettings::default())?;
            loads.push(m.load_time());
        }
        let first = loads[0];
        let load_median = median(loads);
        for beam in [1, 5] {
            let settings = LocalSettings {
                beam_size: beam,
                ..LocalSettings::default()
            };
            let whisper = LocalWhisper::load(&spec.path(), spec.name, settings)?;
            let warm = whisper.transcribe_blocking(&audio)?;
            let mut times = Vec::new();
            for _ in 0..RUNS {
                let started = Instant::now();
                whisper.transcribe_blocking(&audio)?;
                times.push(started.elapsed());
            }
            let min = times.iter().copied().min().unwrap_or_default();
            let max = times.iter().copied().max().unwrap_or_default();
            println!(
                "{:<16} {:>10} {:>10} {:>6} {:>12} {:>12} {:>12}  {:?} (WER {:.2})",
                spec.name,
                ms(first),
                ms(load_median),
                beam,
                ms(median(times)),
                ms(min),
                ms(max),
                warm.text,
                word_error_rate(UTTERANCE, &warm.text)
            );
        }
    }
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
