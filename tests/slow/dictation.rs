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
//! The interpretation is the embedded language model's (the default
//! backend), asked exactly as `betr interpret` asks it.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::Path;
use std::process::Command;

use betr::model::WHISPER_TINY_EN;
use betr::scenario::Scenario;
use betr::session::{self, Event, Options};
use betr::voice::{self, Audio16k, LocalSettings, LocalWhisper, VoiceError, word_error_rate};
use support::cli::{betr_with, text, tmp};
use support::fixtures;
use support::spread;

/// The highest word error rate accepted for a clearly synthesised short instruction.
const MAX_WER: f64 = 0.25;

const SCENARIOS: [&str; 3] = [
    "scenarios/cell/red_on_blue.toml",
    "scenarios/cell/flip_cup.toml",
    "scenarios/cell/centrifuge.toml",
];

fn model_dir() -> &'static Path {
    support::embedded::whisper_dir()
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

#[test]
fn dictated_instructions_of_scenarios_1_3_4_give_their_goals() {
    let whisper =
        LocalWhisper::load(model_dir(), WHISPER_TINY_EN.name, LocalSettings::default()).unwrap();
    eprintln!("model load: {:.2} s", whisper.load_time().as_secs_f64());
    // The model's answers do not depend on its threads; every core reads the three
    // transcripts sooner.
    let llm = support::embedded::language_model(support::embedded::every_core());
    let dir = tmp("dictation");
    // Each scenario is spoken, heard and read on its own, so they run side by side.
    spread::each(
        &SCENARIOS,
        |rel| (*rel).to_string(),
        |rel| {
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .unwrap();
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
                    world,
                    &transcript.text,
                    llm.as_ref(),
                    &Options::default(),
                    &mut |e| events.push(e.clone()),
                ))
                .unwrap_or_else(|e| panic!("{rel}: {e} (transcript {:?})", transcript.text))
                .answer;
            let matches = events.iter().any(|e| {
                matches!(
                    e,
                    Event::Goal {
                        matches_expected: Some(true),
                        ..
                    }
                )
            });
            eprintln!("{rel}: the embedded language model's goal: {}", answer.goal);
            assert!(
                matches,
                "{rel}: goal {} differs from the scenario's",
                answer.goal
            );
        },
    );
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

/// Push-to-talk in the workbench with real speech and the real embedded model: the
/// microphone plays scenario 1's spoken instruction, the app's key presses go to the
/// dictation service as the event loop sends them, and the transcript lands in the input
/// line, unsubmitted, close to what was said.
#[test]
fn push_to_talk_puts_the_embedded_models_transcript_in_the_input_line() {
    use betr::tui::dictation::{DictationError, DictationEvent, DictationService, SttLoader};
    use betr::tui::{App, Info, KeyBindings, Request, Theme};
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use std::sync::Arc;
    use support::microphone::AudioMicrophone;

    let dir = tmp("dictation-tui");
    let wav = dir.join("scenario1.wav");
    let said = "Put the blue cube on the green cube";
    speak(said, DICTATION, &wav);
    let audio = Audio16k::from_wav(&wav).unwrap();
    let loader: SttLoader = Arc::new(|report: &mut dyn FnMut(&str)| {
        report("loading whisper-tiny.en");
        LocalWhisper::load(model_dir(), WHISPER_TINY_EN.name, LocalSettings::default())
            .map(|w| Arc::new(w) as Arc<dyn voice::SpeechToText>)
            .map_err(DictationError::from)
    });
    let (mut service, mut heard) =
        DictationService::new(AudioMicrophone::playing(audio), Ok(loader));
    let scenario =
        Scenario::load(&fixtures::root().join("scenarios/cell/red_on_blue.toml")).unwrap();
    let mut app = App::new(
        Arc::new(scenario),
        Info::default(),
        KeyBindings::default(),
        Theme::default(),
    );
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    rt.block_on(async {
        let mut press = |app: &mut App, c: char| {
            app.on_key(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE));
            for request in app.take_requests() {
                match request {
                    Request::Dictation(r) => service.handle(r),
                    Request::Session(c) => panic!("a dictation key sent {c:?} to the session"),
                    Request::Replay(m) => panic!("a dictation key asked for a replay's {m:?}"),
                }
            }
        };
        press(&mut app, 'd');
        let mut stopped = false;
        let transcript = loop {
            let event = tokio::time::timeout(std::time::Duration::from_secs(60), heard.recv())
                .await
                .expect("no word from the dictation service")
                .unwrap();
            let recording = matches!(event, DictationEvent::Recording { .. });
            let outcome = match &event {
                DictationEvent::Heard(t) => Some(Ok(t.clone())),
                DictationEvent::Failed(why) => Some(Err(why.clone())),
                _ => None,
            };
            app.on_dictation(event);
            if recording && !stopped {
                stopped = true;
                press(&mut app, 'd');
            }
            if let Some(outcome) = outcome {
                break outcome.unwrap();
            }
        };
        assert!(app.input.is_open(), "the transcript opens the input line");
        let wer = word_error_rate(said, &transcript.text);
        eprintln!(
            "push-to-talk heard {:?} (WER {wer:.3}) in {:.2} s",
            transcript.text,
            transcript.elapsed.as_secs_f64()
        );
        assert!(wer <= MAX_WER, "{:?}", transcript.text);
        // Enter submits exactly what the input line shows.
        app.on_key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert_eq!(
            app.take_requests(),
            [Request::Session(betr::session::Command::Submit(
                transcript.text.clone()
            ))]
        );
    });
    std::fs::remove_dir_all(&dir).unwrap();
}
