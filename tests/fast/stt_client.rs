//! The OpenAI-compatible transcription client against the fake server: the multipart
//! request's shape, retries, errors that name the problem and never the key, and
//! `betr transcribe` / `interpret --audio` through it.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::io::Write;
use std::process::Stdio;
use std::time::Duration;

use betr::voice::openai_stt::{OpenAiStt, OpenAiSttSettings, SttKey};
use betr::voice::{Audio16k, VoiceError, transcribe};
use support::cli::{KEY, KEY_VAR, betr, command, text, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;

fn client(base_url: &str, max_retries: u32, timeout: Duration) -> OpenAiStt {
    OpenAiStt::new(OpenAiSttSettings {
        base_url: base_url.to_string(),
        model: "whisper-1".into(),
        language: Some("en".into()),
        api_key_env: Some(KEY_VAR.into()),
        api_key: Some(SttKey::new(KEY)),
        timeout,
        connect_timeout: Duration::from_secs(2),
        retry: betr::http_retry::RetryPolicy {
            max_retries,
            initial_backoff: Duration::from_millis(10),
            max_backoff: Duration::from_millis(50),
        },
    })
    .unwrap()
}

/// One second of a tone: passes the empty/silence checks.
fn tone() -> Audio16k {
    Audio16k::new(
        (0..16_000)
            .map(|i| 0.3 * (i as f32 * 2.0 * std::f32::consts::PI * 300.0 / 16_000.0).sin())
            .collect(),
    )
}

fn block_on<T>(f: impl std::future::Future<Output = T>) -> T {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap()
        .block_on(f)
}

#[test]
fn the_request_is_a_multipart_form_with_model_language_and_a_16k_wav() {
    let server = FakeServer::start(
        vec![],
        Behavior::Reply(" Put the cup on the table. ".into()),
    );
    let stt = client(&server.base_url(), 0, Duration::from_secs(5));
    let t = block_on(transcribe(&stt, &tone())).unwrap();
    assert_eq!(t.text, "Put the cup on the table.");
    assert!((t.audio_seconds - 1.0).abs() < 1e-9);
    assert!(t.source.contains("whisper-1"));
    let got = server.received();
    assert_eq!(got.len(), 1);
    let r = &got[0];
    assert_eq!(r.path, "/v1/audio/transcriptions");
    assert!(
        r.header("content-type")
            .unwrap()
            .starts_with("multipart/form-data; boundary=")
    );
    assert_eq!(
        r.header("authorization"),
        Some(format!("Bearer {KEY}").as_str())
    );
    let names: Vec<&str> = r.form.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["model", "response_format", "file", "language"]);
    assert_eq!(r.field("model").unwrap().text(), "whisper-1");
    assert_eq!(r.field("response_format").unwrap().text(), "json");
    assert_eq!(r.field("language").unwrap().text(), "en");
    let file = r.field("file").unwrap();
    assert_eq!(file.file_name.as_deref(), Some("speech.wav"));
    assert_eq!(file.content_type.as_deref(), Some("audio/wav"));
    let wav = hound::WavReader::new(std::io::Cursor::new(file.data.clone())).unwrap();
    let spec = wav.spec();
    assert_eq!(
        (spec.sample_rate, spec.channels, spec.bits_per_sample),
        (16_000, 1, 16)
    );
    assert_eq!(wav.len(), 16_000);
}

#[test]
fn rate_limits_and_server_errors_are_retried() {
    let server = FakeServer::start(
        vec![
            Behavior::TooMany {
                retry_after: "0.01".into(),
            },
            Behavior::ServerError,
        ],
        Behavior::Reply("hello robot".into()),
    );
    let stt = client(&server.base_url(), 3, Duration::from_secs(5));
    assert_eq!(
        block_on(transcribe(&stt, &tone())).unwrap().text,
        "hello robot"
    );
    assert_eq!(server.received().len(), 3);

    let failing = FakeServer::start(vec![], Behavior::ServerError);
    let stt = client(&failing.base_url(), 2, Duration::from_secs(5));
    let e = block_on(transcribe(&stt, &tone())).unwrap_err();
    assert!(
        matches!(
            e,
            VoiceError::Http {
                status: 500,
                attempts: 3,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn errors_name_the_problem_and_never_the_key() {
    let server = FakeServer::start(vec![], Behavior::Unauthorized);
    let stt = client(&server.base_url(), 0, Duration::from_secs(5));
    let e = block_on(transcribe(&stt, &tone())).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, VoiceError::Unauthorized { .. }), "{msg}");
    assert!(msg.contains(KEY_VAR) && !msg.contains(KEY), "{msg}");
    assert!(!format!("{stt:?}", stt = SttKey::new(KEY)).contains(KEY));

    let server = FakeServer::start(vec![], Behavior::Malformed);
    let stt = client(&server.base_url(), 0, Duration::from_secs(5));
    let e = block_on(transcribe(&stt, &tone())).unwrap_err();
    assert!(matches!(e, VoiceError::MalformedReply { .. }), "{e}");

    let server = FakeServer::start(
        vec![],
        Behavior::Slow(Duration::from_secs(3), "late".into()),
    );
    let stt = client(&server.base_url(), 0, Duration::from_millis(300));
    let e = block_on(transcribe(&stt, &tone())).unwrap_err();
    assert!(matches!(e, VoiceError::Timeout { .. }), "{e}");

    // Nothing listens on port 9 of localhost.
    let stt = client("http://127.0.0.1:9/v1", 0, Duration::from_secs(2));
    let e = block_on(transcribe(&stt, &tone())).unwrap_err();
    assert!(matches!(e, VoiceError::Connect { .. }), "{e}");
    assert!(
        OpenAiStt::new(OpenAiSttSettings {
            base_url: "localhost:8080".into(),
            ..client_settings()
        })
        .is_err()
    );
}

fn client_settings() -> OpenAiSttSettings {
    OpenAiSttSettings {
        base_url: String::new(),
        model: "m".into(),
        language: None,
        api_key_env: None,
        api_key: None,
        timeout: Duration::from_secs(1),
        connect_timeout: Duration::from_secs(1),
        retry: betr::http_retry::RetryPolicy {
            max_retries: 0,
            initial_backoff: Duration::from_millis(1),
            max_backoff: Duration::from_millis(1),
        },
    }
}

#[test]
fn silence_is_refused_before_any_request() {
    let server = FakeServer::start(vec![], Behavior::Reply("ghost words".into()));
    let stt = client(&server.base_url(), 0, Duration::from_secs(5));
    let e = block_on(transcribe(&stt, &Audio16k::new(vec![0.0; 32_000]))).unwrap_err();
    assert!(matches!(e, VoiceError::Silent { .. }), "{e}");
    assert!(server.received().is_empty());
}

#[test]
fn the_cli_transcribes_and_dictates_through_a_server() {
    let dir = tmp("stt-cli");
    let wav = dir.join("speech.wav");
    std::fs::write(&wav, tone().to_wav_bytes()).unwrap();
    let wav_s = wav.to_string_lossy().to_string();
    let stt_server = FakeServer::start(
        vec![],
        Behavior::Reply("Put the blue cube on the green cube.".into()),
    );
    let stt_base = stt_server.base_url();
    let remote = [
        "--stt",
        "openai",
        "--stt-base-url",
        &stt_base,
        "--stt-api-key-env",
        KEY_VAR,
    ];
    let mut args = vec!["transcribe", &wav_s];
    args.extend(remote);
    let out = betr(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.trim(), "Put the blue cube on the green cube.");
    assert!(String::from_utf8_lossy(&out.stderr).contains("transcription"));

    // interpret --audio: printed, then used with --yes; without --yes and no terminal
    // answer it is refused before any language model is asked.
    let llm = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let llm_base = llm.base_url();
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let scenario_s = scenario.to_string_lossy().to_string();
    let mut args = vec![
        "interpret",
        &scenario_s,
        "--audio",
        &wav_s,
        "--base-url",
        &llm_base,
    ];
    args.extend(["--model", "fake-model", "--api-key-env", KEY_VAR]);
    args.extend(remote);
    let refused = betr(&dir, &args);
    assert_eq!(refused.status.code(), Some(2), "{}", text(&refused));
    assert!(text(&refused).contains("Dictated:    Put the blue cube on the green cube."));
    assert!(text(&refused).contains("--yes"), "{}", text(&refused));
    assert!(llm.received().is_empty());
    args.push("--yes");
    let out = betr(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let t = text(&out);
    assert!(
        t.contains("Instruction: Put the blue cube on the green cube."),
        "{t}"
    );
    assert!(t.contains("(equivalent to the scenario's goal)"), "{t}");

    // On a terminal the person confirms with Enter, corrects by typing, or cancels.
    args.pop();
    let answered = |answer: &str| {
        let mut child = command(&dir, &args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(answer.as_bytes())
            .unwrap();
        child.wait_with_output().unwrap()
    };
    let confirmed = answered("\n");
    assert!(
        text(&confirmed).contains("Instruction: Put the blue cube on the green cube."),
        "{}",
        text(&confirmed)
    );
    let corrected = answered("Put the red cube on the green cube\n");
    assert!(
        text(&corrected).contains("Instruction: Put the red cube on the green cube"),
        "{}",
        text(&corrected)
    );
    let calls = llm.received().len();
    let cancelled = answered("n\n");
    assert_eq!(cancelled.status.code(), Some(2), "{}", text(&cancelled));
    assert!(
        text(&cancelled).contains("cancelled"),
        "{}",
        text(&cancelled)
    );
    assert_eq!(llm.received().len(), calls, "no model call after a cancel");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_key_inside_the_transcription_url_is_sent_as_the_key_and_printed_nowhere() {
    let dir = tmp("stt-url-key");
    let wav = dir.join("speech.wav");
    std::fs::write(&wav, tone().to_wav_bytes()).unwrap();
    let server = FakeServer::start(vec![], Behavior::Reply("Put the cup away.".into()));
    let with_key = server
        .base_url()
        .replacen("http://", "http://user:sk-IN-URL-123@", 1);
    let out = betr(
        &dir,
        &[
            "transcribe",
            &wav.to_string_lossy(),
            "--stt",
            "openai",
            "--stt-base-url",
            &with_key,
            "--stt-api-key-env",
            "BETR_TEST_NO_SUCH_KEY",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(!text(&out).contains("sk-IN-URL-123"), "{}", text(&out));
    let got = server.received();
    assert_eq!(got.len(), 1);
    assert_eq!(got[0].header("authorization"), Some("Bearer sk-IN-URL-123"));
    std::fs::remove_dir_all(&dir).unwrap();
}
