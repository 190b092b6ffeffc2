//! Speech-to-text timing: model load time and the latency of transcribing a 3-second
//! utterance (spoken by espeak-ng as clear dictation, 140 words per minute with 30 ms
//! between words, padded with silence to exactly 3.00 s) with each embedded Whisper
//! model in the cache (whisper-tiny.en is fetched if missing), greedy and with beam
//! search. Each latency is the median of several runs after a warm-up; the process's CPU
//! time per run is printed too, as wall-clock times depend on what else the machine runs
//! (the load average is printed before and after).
//!
//! Run: `cargo bench --bench stt` (needs `espeak-ng`; scripts/test.sh installs it)

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use betr::model::{self, Progress, STT_MODELS, WHISPER_TINY_EN};
use betr::voice::{Audio16k, LocalSettings, LocalWhisper, SAMPLE_RATE, word_error_rate};

const UTTERANCE: &str = "Put the green cube in the red cup";
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

fn speak(text: &str, wav: &Path) -> Result<Audio16k, Box<dyn std::error::Error>> {
    let status = Command::new("espeak-ng")
        .args(["-g", "3", "-s", "140", "-w"])
        .arg(wav)
        .arg(text)
        .status()?;
    if !status.success() {
        return Err(format!("espeak-ng failed: {status}").into());
    }
    Ok(Audio16k::from_wav(wav)?)
}

/// The utterance, padded with silence to (or cut at) exactly `SECONDS`.
fn utterance(dir: &Path) -> Result<(Audio16k, f64), Box<dyn std::error::Error>> {
    let wav = dir.join("utterance.wav");
    let mut samples = speak(UTTERANCE, &wav)?.into_samples();
    let spoken = samples.len() as f64 / f64::from(SAMPLE_RATE);
    samples.resize((SECONDS * f64::from(SAMPLE_RATE)) as usize, 0.0);
    Ok((Audio16k::new(samples), spoken))
}

/// CPU time of this process so far (user + system, all threads), from /proc (Linux).
fn cpu_time() -> Duration {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which is in parentheses): utime is the 12th, stime the 13th.
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<u64> = after
        .split_whitespace()
        .map(|f| f.parse().unwrap_or(0))
        .collect();
    let ticks = fields.get(11).copied().unwrap_or(0) + fields.get(12).copied().unwrap_or(0);
    Duration::from_millis(ticks * 10)
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
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
        "utterance: {UTTERANCE:?}, {spoken:.2} s of speech padded to {:.2} s; {threads} thread(s); load average {}",
        audio.seconds(),
        load_average()
    );
    println!(
        "\n{:<16} {:>9} {:>9} {:>5} {:>9} {:>9} {:>9} {:>9}  transcript",
        "model", "load 1st", "load med", "beam", "median", "min", "max", "CPU/run"
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
            let cpu_before = cpu_time();
            for _ in 0..RUNS {
                let started = Instant::now();
                whisper.transcribe_blocking(&audio)?;
                times.push(started.elapsed());
            }
            let cpu = (cpu_time() - cpu_before) / RUNS as u32;
            let min = times.iter().copied().min().unwrap_or_default();
            let max = times.iter().copied().max().unwrap_or_default();
            println!(
                "{:<16} {:>9} {:>9} {:>5} {:>9} {:>9} {:>9} {:>9}  {:?} (WER {:.2})",
                spec.name,
                ms(first),
                ms(load_median),
                beam,
                ms(median(times)),
                ms(min),
                ms(max),
                ms(cpu),
                warm.text,
                word_error_rate(UTTERANCE, &warm.text)
            );
        }
    }
    println!("\nload average after: {}", load_average());
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
