//! `betr transcribe` and the `--audio FILE.wav` of `interpret` / `resolve`: dictation
//! from a file. A dictated instruction is always printed, and used only after `--yes` or a
//! confirmation on the terminal (where it can also be corrected): never unseen.

use std::io::BufRead;
use std::path::Path;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Result, bail};
use clap::Args;

use betr::config_file::FileConfig;
use betr::voice::{self, Audio16k, SpeechToText, SttBackend, SttLayer, SttSettings, Transcript};

/// Speech-to-text flags. Each overrides the matching `BETR_STT*` variable, which overrides
/// the `[stt]` table of `betr.toml`.
#[derive(Args, Debug, Clone, Default)]
pub struct SttFlags {
    /// Speech-to-text backend: local (embedded Whisper) or openai (POST
    /// {base}/audio/transcriptions) [env: BETR_STT].
    #[arg(long = "stt", value_name = "local|openai")]
    pub stt_backend: Option<String>,
    /// Local: whisper-tiny.en (default) or whisper-base; openai: the server's model name
    /// (default whisper-1) [env: BETR_STT_MODEL].
    #[arg(long, value_name = "NAME")]
    pub stt_model: Option<String>,
    /// Transcription server base URL including /v1 [env: BETR_STT_BASE_URL].
    #[arg(long, value_name = "URL")]
    pub stt_base_url: Option<String>,
    /// NAME of the variable holding the transcription server's key (default
    /// OPENAI_API_KEY) [env: BETR_STT_API_KEY_ENV].
    #[arg(long, value_name = "VAR")]
    pub stt_api_key_env: Option<String>,
    /// Language spoken, for multilingual models and servers (default en)
    /// [env: BETR_STT_LANGUAGE].
    #[arg(long, value_name = "LANG")]
    pub language: Option<String>,
    /// Beam width of the embedded model (1: greedy, fastest; default 5).
    #[arg(value_parser = super::ranged(1, 64), long, value_name = "N")]
    pub beam_size: Option<usize>,
}

/// The layered settings: `config` (or the usual file), `BETR_STT*`, then `flags`.
pub fn settings(config: Option<&Path>, flags: &SttFlags) -> Result<SttSettings> {
    let var = |k: &str| std::env::var(k).ok();
    let file = match FileConfig::locate(config, &var) {
        Some(path) => Some(FileConfig::read(&path)?.stt),
        None => None,
    };
    let flag_layer = SttLayer {
        backend: flags
            .stt_backend
            .as_deref()
            .map(str::parse::<SttBackend>)
            .transpose()
            .map_err(|e| anyhow::anyhow!("--stt: {e}"))?,
        model: flags.stt_model.clone(),
        base_url: flags.stt_base_url.clone(),
        api_key_env: flags.stt_api_key_env.clone(),
        language: flags.language.clone(),
        beam_size: flags.beam_size,
        ..SttLayer::default()
    };
    Ok(SttSettings::resolve(
        file,
        SttLayer::from_env(&var)?,
        flag_layer,
    )?)
}

/// A ready backend and how long loading it took (the embedded model only).
pub struct Loaded {
    pub stt: Box<dyn SpeechToText>,
    pub load_time: Option<Duration>,
}

/// Build the backend; the embedded model is fetched first if it is not in the cache.
pub fn load(settings: &SttSettings) -> Result<Loaded> {
    match settings.backend {
        SttBackend::Local => {
            super::model_cmd::ensure_stt(Some(&settings.model))?;
            let local = settings.load_local()?;
            let load_time = Some(local.load_time());
            Ok(Loaded {
                stt: Box::new(local),
                load_time,
            })
        }
        SttBackend::Openai => Ok(Loaded {
            stt: Box::new(settings.remote(&|k| std::env::var(k).ok())?),
            load_time: None,
        }),
    }
}

fn run_transcription(stt: &dyn SpeechToText, audio: &Audio16k) -> Result<Transcript> {
    Ok(super::runtime()?.block_on(voice::transcribe(stt, audio))?)
}

fn read(file: &Path) -> Result<Audio16k> {
    Ok(Audio16k::from_wav(file)?)
}

fn timings(t: &Transcript, load_time: Option<Duration>) -> String {
    let load = load_time
        .map(|d| format!(" · model load {:.2} s", d.as_secs_f64()))
        .unwrap_or_default();
    format!(
        "audio {:.2} s{load} · transcription {:.2} s ({:.2}× real time) · {}",
        t.audio_seconds,
        t.elapsed.as_secs_f64(),
        t.real_time_factor(),
        t.source
    )
}

/// `betr transcribe FILE.wav`
pub fn transcribe(file: &Path, config: Option<&Path>, flags: &SttFlags) -> Result<ExitCode> {
    let audio = read(file)?;
    let loaded = load(&settings(config, flags)?)?;
    let transcript = run_transcription(loaded.stt.as_ref(), &audio)?;
    outln!("{}", transcript.text);
    errln!("{}", timings(&transcript, loaded.load_time));
    Ok(ExitCode::SUCCESS)
}

/// The instruction a command works on: dictated from `audio` when given (transcribed and
/// confirmed as `dictate` does), else the one typed (`None`: the scenario's).
pub fn instruction(
    typed: Option<String>,
    audio: Option<&Path>,
    config: Option<&Path>,
    flags: &SttFlags,
    yes: bool,
) -> Result<Option<String>> {
    match audio {
        Some(audio) => Ok(Some(dictate(audio, config, flags, yes)?)),
        None => Ok(typed),
    }
}

/// For `interpret` / `resolve --audio`: transcribe the file, print the transcript, and
/// return the instruction the user confirmed or corrected on the terminal (or, with
/// `yes`, the transcript as printed).
fn dictate(audio: &Path, config: Option<&Path>, flags: &SttFlags, yes: bool) -> Result<String> {
    let audio = read(audio)?;
    let loaded = load(&settings(config, flags)?)?;
    let transcript = run_transcription(loaded.stt.as_ref(), &audio)?;
    outln!("Dictated:    {}", transcript.text);
    outln!("             ({})", timings(&transcript, loaded.load_time));
    if yes {
        outln!("Using the transcript as the instruction (--yes).");
        return Ok(transcript.text);
    }
    out!("Enter to use it, or type the corrected instruction (n to cancel): ");
    super::out::flush();
    let mut line = String::new();
    match std::io::stdin().lock().read_line(&mut line) {
        Ok(0) | Err(_) => bail!(
            "the transcript was not confirmed (no answer on the terminal); pass --yes to use it as printed"
        ),
        Ok(_) => confirm(&transcript.text, &line),
    }
}

/// What the user's answer to the confirmation makes of the transcript.
pub fn confirm(transcript: &str, answer: &str) -> Result<String> {
    match answer.trim() {
        "" | "y" | "Y" | "yes" => Ok(transcript.to_string()),
        "n" | "N" | "no" => bail!("cancelled: the transcript was not used"),
        corrected => Ok(corrected.to_string()),
    }
}
