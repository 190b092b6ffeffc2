//! Dictation end to end with the embedded model: the instructions of cell scenarios 1, 3
//! and 4 are spoken by `espeak-ng`, transcribed by Whisper tiny.en (fetched into the model
//! cache like `betr model fetch --stt` when missing), scored by word error rate, and the
//! transcript is interpreted into the scenario's goal.
//!
//! The speech is "clear dictation": 140 words per minute with 30 ms between words
//! (`espeak-ng -s 140 -g 3`). At espeak's default 175 words per minute its robotic voice
//! is much harder for the tiny model; those word error rates are printed too, not
//! asserted.
//!
//! The interpretation goes through the fake OpenAI server answering with the hand-written
//! fixture replies (keyed on the instruction's words): it checks that the transcript
//! carries the instruction's wording into the prompt, not what a model would answer. The
//! same check with the embedded language model comes with that model.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

mod support;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use betr::domain::Scenario;
use betr::llm::openai::{AuthHeader, OpenAiClient, OpenAiSettings, RetryPolicy};
use betr::model::{self, Progress, WHISPER_TINY_EN};
use betr::session::{self, Event, Options};
use betr::voice::{self, Audio16k, LocalSettings, LocalWhisper, VoiceError, word_error_rate};
use support::cli::{betr_with, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

/// The highest word error rate accepted for a clearly synthesised short instruction.
const MAX_WER: f64 = 0.25;

const SCENARIOS: [&str; 3] = [
    "scenarios/cell/red_on_blue.toml",
    "scenarios/cell/flip_cup.toml",
    "scenarios/cell/centrifuge.toml",
];

struct Quiet;
impl Progress for Quiet {
    fn stage(&mut self, message: &str) {
        eprintln!("{message}");
    }
    fn bytes(&mut self, _: u64, _: u64) {}
}

/// The model, fetched once if it is not in the cache.
fn model_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        if WHISPER_TINY_EN.is_present() {
            WHISPER_TINY_EN.path()
        } else {
            model::fetch_dir(&WHISPER_TINY_EN, &model::cache_dir(), "python3", &mut Quiet).unwrap()
        }
    })
}

/// Clear dictation.
const DICTATION: &[&str] = &["-s", "140", "-g", "3"];
/// espeak-ng's defaults (175 words per minute, no gaps).
const FAST: &[&str] = &[];

fn speak(text: &str, voice: &[&str], wav: &Path) {
    let out = Command::new("espeak-ng")
        .args(voice)
        .arg("-w")
        .arg(wav)
        .arg(text)
        .output()
        .unwrap_or_else(|e| panic!("cannot run espeak-ng ({e}); scripts/test.sh installs it"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn llm(base_url: String) -> OpenAiClient {
    OpenAiClient::new(OpenAiSettings {
        base_url,
        model: "fake-model".into(),
        api_key_env: None,
        api_key: None,
        auth_header: AuthHeader::Bearer,
        timeout: std::time::Duration::from_secs(5),
        connect_timeout: std::time::Duration::from_secs(1),
        retry: RetryPolicy::default(),
        structured: false,
        max_tokens_field: "max_tokens".into(),
    })
    .unwrap()
}

#[test]
fn dictated_instructions_of_scenarios_1_3_4_give_their_goals() {
    let whisper =
        LocalWhisper::load(model_dir(), WHISPER_TINY_EN.name, LocalSettings::default()).unwrap();
    eprintln!("model load: {:.2} s", whisper.load_time().as_secs_f64());
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let client = llm(server.base_url());
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let dir = tmp("dictation");
    for rel in SCENARIOS {
        let scenario = Scenario::load(&fixtures::root().join(rel)).unwrap();
        let instruction = scenario.instruction.clone().unwrap();
        let wav = dir.join(format!("{}.wav", scenario.name.replace(' ', "_")));
        speak(&instruction, FAST, &wav);
        let fast = whisper
            .transcribe_blocking(&Audio16k::from_wav(&wav).unwrap())
            .unwrap();
        eprintln!(
            "{rel} at 175 wpm: heard {:?}: WER {:.3} (not asserted)",
            fast.text,
            word_error_rate(&instruction, &fast.text)
        );
        speak(&instruction, DICTATION, &wav);
        let audio = Audio16k::from_wav(&wav).unwrap();
        let transcript = rt.block_on(voice::transcribe(&whisper, &audio)).unwrap();
        let wer = word_error_rate(&instruction, &transcript.text);
        eprintln!(
            "{rel}: said {instruction:?}, heard {:?}: WER {wer:.3}; {:.2} s of audio in {:.2} s",
            transcript.text,
            transcript.audio_seconds,
            transcript.elapsed.as_secs_f64()
        );
        assert!(
            wer <= MAX_WER,
            "{rel}: WER {wer:.3} for {:?}",
            transcript.text
        );

        let world = betr::world::load(&scenario).unwrap();
        let mut events = Vec::new();
        let answer = rt
            .block_on(session::interpret(
                &scenario,
                &world.facts(),
                &transcript.text,
                &client,
                &Options::default(),
                &mut |e| events.push(e.clone()),
            ))
            .unwrap_or_else(|e| panic!("{rel}: {e} (transcript {:?})", transcript.text));
        let matches = events.iter().any(|e| {
            matches!(
                e,
                Event::Goal {
                    matches_expected: Some(true),
                    ..
                }
            )
        });
        assert!(
            matches,
            "{rel}: goal {} differs from the scenario's",
            answer.goal
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_cli_transcribes_a_file_with_the_embedded_model() {
    let dir = tmp("dictation-cli");
    let wav = dir.join("cup.wav");
    speak("Put the green cube in the red cup", DICTATION, &wav);
    let models = model_dir().parent().unwrap().to_string_lossy().to_string();
    let wav_s = wav.to_string_lossy().to_string();
    let out = betr_with(
        &dir,
        &["transcribe", &wav_s],
        &[("BETR_MODEL_DIR", &models)],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let heard = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        word_error_rate("Put the green cube in the red cup", &heard) <= MAX_WER,
        "{heard}"
    );
    let timings = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        timings.contains("model load") && timings.contains("whisper-tiny.en"),
        "{timings}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn silence_never_reaches_the_model() {
    let whisper =
        LocalWhisper::load(model_dir(), WHISPER_TINY_EN.name, LocalSettings::default()).unwrap();
    let rt = tokio::runtime::Builder::new_current_thread()
        .build()
        .unwrap();
    let e = rt
        .block_on(voice::transcribe(
            &whisper,
            &Audio16k::new(vec![0.0; 48_000]),
        ))
        .unwrap_err();
    assert!(matches!(e, VoiceError::Silent { .. }), "{e}");
}
