//! The embedded backend: Whisper in CTranslate2 format through the `ct2rs` crate's
//! low-level binding, fed with betr's own features ([`super::features`], the reference
//! log-mel computation) and the reference prompt (`<|startoftranscript|>` and
//! `<|notimestamps|>`, with `<|lang|><|transcribe|>` between them for multilingual
//! models). The model is loaded once (the load time is kept for status lines and
//! benchmarks); each transcription runs on a thread of its own so an async caller never
//! blocks.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use ct2rs::Tokenizer as _;
use ct2rs::sys::{ComputeType, Config, Device, StorageView, Whisper, WhisperOptions};
use ct2rs::tokenizers::hf;

use super::features::{CHUNK_FRAMES, CHUNK_SAMPLES, MelExtractor};
use super::{Audio16k, SpeechToText, SttFuture, Transcript, VoiceError};

/// How the embedded model decodes.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalSettings {
    /// The language spoken, for multilingual models (`en`, `de`, ...; `None`: English).
    /// English-only models ignore it.
    pub language: Option<String>,
    /// Beam search width (1 is greedy decoding: fastest).
    pub beam_size: usize,
    /// CPU threads for inference (0: CTranslate2's default).
    pub threads: usize,
}

impl Default for LocalSettings {
    fn default() -> Self {
        LocalSettings {
            language: Some("en".into()),
            beam_size: 5,
            threads: std::thread::available_parallelism().map_or(0, usize::from),
        }
    }
}

/// The model with its tokenizer and feature extractor.
struct Engine {
    whisper: Whisper,
    tokenizer: hf::Tokenizer,
    mel: MelExtractor,
}

/// A loaded Whisper model.
pub struct LocalWhisper {
    engine: Arc<Engine>,
    name: String,
    dir: PathBuf,
    settings: LocalSettings,
    load_time: Duration,
}

impl LocalWhisper {
    /// Load a model of the catalogue from the cache (`betr model fetch --stt` puts it there).
    pub fn load_named(name: &str, settings: LocalSettings) -> Result<LocalWhisper, VoiceError> {
        let Some(spec) = crate::model::find_stt(name) else {
            let known: Vec<&str> = crate::model::STT_MODELS.iter().map(|m| m.name).collect();
            return Err(VoiceError::UnknownModel {
                name: name.to_string(),
                known: known.join(", "),
            });
        };
        if !spec.is_present() {
            return Err(VoiceError::ModelMissing {
                name: name.to_string(),
                path: spec.path(),
            });
        }
        LocalWhisper::load(&spec.path(), name, settings)
    }

    /// Load the model in `dir` (model.bin, config.json, tokenizer.json,
    /// preprocessor_config.json).
    pub fn load(
        dir: &Path,
        name: &str,
        settings: LocalSettings,
    ) -> Result<LocalWhisper, VoiceError> {
        if !dir.join("model.bin").is_file() {
            return Err(VoiceError::ModelMissing {
                name: name.to_string(),
                path: dir.to_path_buf(),
            });
        }
        let started = Instant::now();
        let config = Config {
            num_threads_per_replica: settings.threads,
            // The published weights are float16, which CPUs compute as float32 anyway
            // (CTranslate2 would convert them with a warning on stderr).
            compute_type: ComputeType::FLOAT32,
            ..Config::default()
        };
        let load_error = |e: anyhow::Error| VoiceError::ModelLoad {
            path: dir.to_path_buf(),
            detail: format!("{e:#}"),
        };
        let whisper = Whisper::new(dir, config).map_err(load_error)?;
        let tokenizer = hf::Tokenizer::new(dir).map_err(load_error)?;
        let mel = MelExtractor::new(whisper.n_mels());
        Ok(LocalWhisper {
            engine: Arc::new(Engine {
                whisper,
                tokenizer,
                mel,
            }),
            name: name.to_string(),
            dir: dir.to_path_buf(),
            settings,
            load_time: started.elapsed(),
        })
    }

    /// How long loading took.
    pub fn load_time(&self) -> Duration {
        self.load_time
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Transcribe on the calling thread.
    pub fn transcribe_blocking(&self, audio: &Audio16k) -> Result<Transcript, VoiceError> {
        run(
            &self.engine,
            audio.samples(),
            &self.settings,
            self.describe(),
        )
    }
}

fn run(
    engine: &Engine,
    samples: &[f32],
    settings: &LocalSettings,
    source: String,
) -> Result<Transcript, VoiceError> {
    let started = Instant::now();
    let failed = |e: anyhow::Error| VoiceError::Transcribe {
        detail: format!("{e:#}"),
    };
    let chunks: Vec<&[f32]> = samples.chunks(CHUNK_SAMPLES).collect();
    let mut features: Vec<f32> = chunks.iter().flat_map(|c| engine.mel.chunk(c)).collect();
    let mut texts = Vec::new();
    if !chunks.is_empty() {
        let shape = [chunks.len(), engine.mel.n_mels(), CHUNK_FRAMES];
        let view = StorageView::new(&shape, &mut features, Device::CPU).map_err(failed)?;
        let prompt = prompt(
            engine.whisper.is_multilingual(),
            settings.language.as_deref(),
        );
        let options = WhisperOptions {
            beam_size: settings.beam_size.max(1),
            ..WhisperOptions::default()
        };
        let results = engine
            .whisper
            .generate(&view, &vec![prompt; chunks.len()], &options)
            .map_err(failed)?;
        for result in results {
            let tokens: Vec<String> = result
                .sequences
                .into_iter()
                .next()
                .unwrap_or_default()
                .into_iter()
                .filter(|t| !(t.starts_with("<|") && t.ends_with("|>")))
                .collect();
            texts.push(engine.tokenizer.decode(tokens).map_err(failed)?);
        }
    }
    Ok(Transcript {
        text: super::stt::tidy(&texts.join(" ")),
        audio_seconds: samples.len() as f64 / f64::from(super::SAMPLE_RATE),
        elapsed: started.elapsed(),
        source,
    })
}

/// The decoder's first tokens, as OpenAI's reference decoder builds them.
fn prompt(multilingual: bool, language: Option<&str>) -> Vec<String> {
    let mut prompt = vec!["<|startoftranscript|>".to_string()];
    if multilingual {
        prompt.push(format!("<|{}|>", language.unwrap_or("en")));
        prompt.push("<|transcribe|>".into());
    }
    prompt.push("<|notimestamps|>".into());
    prompt
}

impl SpeechToText for LocalWhisper {
    fn describe(&self) -> String {
        format!("{} (embedded)", self.name)
    }

    fn transcribe<'a>(&'a self, audio: &'a Audio16k) -> SttFuture<'a> {
        let engine = Arc::clone(&self.engine);
        let samples = audio.samples().to_vec();
        let settings = self.settings.clone();
        let source = self.describe();
        let (tx, rx) = tokio::sync::oneshot::channel();
        let spawned = std::thread::Builder::new()
            .name("betr-whisper".into())
            .spawn(move || {
                let _ = tx.send(run(&engine, &samples, &settings, source));
            });
        Box::pin(async move {
            if let Err(e) = spawned {
                return Err(VoiceError::Transcribe {
                    detail: format!("cannot start the transcription thread: {e}"),
                });
            }
            rx.await.unwrap_or_else(|_| {
                Err(VoiceError::Transcribe {
                    detail: "the transcription thread stopped without an answer".into(),
                })
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prompts_follow_the_reference_decoder() {
        assert_eq!(
            prompt(false, Some("de")),
            ["<|startoftranscript|>", "<|notimestamps|>"]
        );
        assert_eq!(
            prompt(true, Some("de")),
            [
                "<|startoftranscript|>",
                "<|de|>",
                "<|transcribe|>",
                "<|notimestamps|>"
            ]
        );
        assert_eq!(prompt(true, None)[1], "<|en|>");
    }
}
