//! The push-to-talk service with a stand-in microphone (a recording of given audio) and a
//! stand-in model: the events a front end sees for a dictation, a failure of each kind, a
//! cancel, and a model that is loaded once and tried again after a failed load.

use std::sync::atomic::AtomicUsize;
use std::time::Duration;

use super::*;
use crate::voice::{SttFuture, Transcript};

/// Hands out a recording of `audio`, reporting two levels as the device would.
struct FakeMicrophone {
    audio: Audio16k,
    fail: Option<fn() -> VoiceError>,
    stopped: Arc<AtomicUsize>,
}

struct FakeRecording {
    audio: Audio16k,
    stopped: Arc<AtomicUsize>,
}

impl Recording for FakeRecording {
    fn stop(self: Box<Self>) -> Result<Audio16k, VoiceError> {
        self.stopped.fetch_add(1, Ordering::SeqCst);
        self.audio.check_speech()?;
        Ok(self.audio)
    }
}

impl Microphone for FakeMicrophone {
    fn start(
        &self,
        mut on_level: Box<dyn FnMut(Level) + Send>,
    ) -> Result<(String, Box<dyn Recording>), VoiceError> {
        if let Some(fail) = self.fail {
            return Err(fail());
        }
        let audio = self.audio.clone();
        let stopped = self.stopped.clone();
        // The device delivers audio at once; the levels only count once recording is
        // announced (as the service promises), so wait a little before sending them.
        on_level(Level::of(&[0.1; 800]));
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            on_level(Level::of(&[0.0; 800]));
            on_level(Level::of(&[0.5, -0.5, 0.5, -0.5]));
        });
        Ok((
            "fake mic".into(),
            Box::new(FakeRecording { audio, stopped }),
        ))
    }
}

struct Echo;

impl SpeechToText for Echo {
    fn describe(&self) -> String {
        "echo".into()
    }
    fn transcribe<'a>(&'a self, audio: &'a Audio16k) -> SttFuture<'a> {
        Box::pin(async move {
            Ok(Transcript {
                text: "  Put the blue cube   on the green cube. ".into(),
                audio_seconds: audio.seconds(),
                elapsed: Duration::from_millis(700),
                source: self.describe(),
            })
        })
    }
}

fn speech(seconds: f64) -> Audio16k {
    let n = (seconds * 16_000.0) as usize;
    Audio16k::new((0..n).map(|i| (i as f32 * 0.05).sin() * 0.4).collect())
}

fn microphone(audio: Audio16k) -> (Arc<FakeMicrophone>, Arc<AtomicUsize>) {
    let stopped = Arc::new(AtomicUsize::new(0));
    let mic = FakeMicrophone {
        audio,
        fail: None,
        stopped: stopped.clone(),
    };
    (Arc::new(mic), stopped)
}

/// A loader that fails `failures` times, then loads `Echo`; counts its calls.
fn loader(failures: usize, calls: Arc<AtomicUsize>) -> SttLoader {
    Arc::new(move |report: &mut dyn FnMut(&str)| {
        let n = calls.fetch_add(1, Ordering::SeqCst);
        report("loading echo");
        if n < failures {
            Err(VoiceError::ModelMissing {
                name: "echo".into(),
                path: PathBuf::from("/nowhere/echo"),
            }
            .into())
        } else {
            Ok(Arc::new(Echo) as Arc<dyn SpeechToText>)
        }
    })
}

/// Events until (and including) the first that ends a dictation.
async fn until_done(rx: &mut UnboundedReceiver<DictationEvent>) -> Vec<DictationEvent> {
    let mut seen = Vec::new();
    loop {
        let e = tokio::time::timeout(Duration::from_secs(10), rx.recv())
            .await
            .expect("the service went quiet")
            .expect("the channel closed");
        let done = matches!(
            e,
            DictationEvent::Heard(_) | DictationEvent::Failed(_) | DictationEvent::Cancelled
        );
        seen.push(e);
        if done {
            return seen;
        }
    }
}

fn rt() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap()
}

#[test]
fn a_dictation_records_transcribes_and_loads_the_model_once() {
    rt().block_on(async {
        let calls = Arc::new(AtomicUsize::new(0));
        let (mic, stopped) = microphone(speech(2.0));
        let (mut service, mut rx) = DictationService::new(mic, Ok(loader(0, calls.clone())));
        for round in 0..2 {
            service.handle(DictationRequest::Start);
            assert_eq!(
                rx.recv().await,
                Some(DictationEvent::Recording {
                    device: "fake mic".into()
                })
            );
            // Let the levels and the early model load arrive, then stop.
            tokio::time::sleep(Duration::from_millis(100)).await;
            service.handle(DictationRequest::Stop);
            let events = until_done(&mut rx).await;
            let levels = events
                .iter()
                .filter(|e| matches!(e, DictationEvent::Level(_)))
                .count();
            assert_eq!(levels, 2, "round {round}: {events:?}");
            assert!(
                events.contains(&DictationEvent::Transcribing { seconds: 2.0 }),
                "{events:?}"
            );
            match events.last() {
                Some(DictationEvent::Heard(t)) => {
                    assert_eq!(t.text, "Put the blue cube on the green cube.");
                    assert_eq!(t.source, "echo");
                }
                other => panic!("round {round}: {other:?}"),
            }
        }
        assert_eq!(calls.load(Ordering::SeqCst), 1, "the model is loaded once");
        assert_eq!(stopped.load(Ordering::SeqCst), 2);
    });
}

#[test]
fn a_failed_load_is_reported_and_tried_again() {
    rt().block_on(async {
        let calls = Arc::new(AtomicUsize::new(0));
        let (mic, _) = microphone(speech(1.0));
        // Fails for the load started with the recording and for the one at the stop.
        let (mut service, mut rx) = DictationService::new(mic, Ok(loader(2, calls.clone())));
        service.handle(DictationRequest::Start);
        tokio::time::sleep(Duration::from_millis(100)).await;
        service.handle(DictationRequest::Stop);
        let events = until_done(&mut rx).await;
        assert!(
            events.contains(&DictationEvent::Preparing("loading echo".into())),
            "{events:?}"
        );
        match events.last() {
            Some(DictationEvent::Failed(why)) => assert!(why.contains("betr model fetch --stt")),
            other => panic!("{other:?}"),
        }
        service.handle(DictationRequest::Start);
        service.handle(DictationRequest::Stop);
        let events = until_done(&mut rx).await;
        assert!(
            matches!(events.last(), Some(DictationEvent::Heard(_))),
            "{events:?}"
        );
        assert_eq!(calls.load(Ordering::SeqCst), 3);
    });
}

#[test]
fn no_microphone_silence_and_bad_settings_are_clear_failures() {
    rt().block_on(async {
        let calls = Arc::new(AtomicUsize::new(0));
        let no_mic = FakeMicrophone {
            audio: speech(1.0),
            fail: Some(|| VoiceError::NoInputDevice {
                detail: "ALSA has no default input device".into(),
            }),
            stopped: Arc::default(),
        };
        let (mut service, mut rx) =
            DictationService::new(Arc::new(no_mic), Ok(loader(0, calls.clone())));
        service.handle(DictationRequest::Start);
        match until_done(&mut rx).await.last() {
            Some(DictationEvent::Failed(why)) => assert!(why.starts_with("no microphone"), "{why}"),
            other => panic!("{other:?}"),
        }
        // Stop without a recording does nothing; the session goes on.
        service.handle(DictationRequest::Stop);
        assert!(rx.try_recv().is_err());

        let (mic, _) = microphone(Audio16k::new(vec![0.0; 32_000]));
        let (mut service, mut rx) = DictationService::new(mic, Ok(loader(0, calls.clone())));
        service.handle(DictationRequest::Start);
        service.handle(DictationRequest::Stop);
        match until_done(&mut rx).await.last() {
            Some(DictationEvent::Failed(why)) => assert!(why.contains("silent"), "{why}"),
            other => panic!("{other:?}"),
        }

        let (mic, _) = microphone(speech(0.1));
        let (mut service, mut rx) = DictationService::new(mic, Ok(loader(0, calls.clone())));
        service.handle(DictationRequest::Start);
        service.handle(DictationRequest::Stop);
        match until_done(&mut rx).await.last() {
            Some(DictationEvent::Failed(why)) => assert!(why.contains("empty"), "{why}"),
            other => panic!("{other:?}"),
        }

        let (mic, stopped) = microphone(speech(1.0));
        let (mut service, mut rx) = DictationService::new(
            mic,
            Err(DictationError::Settings {
                reason: "BETR_STT: unknown backend \"cloud\"".into(),
            }),
        );
        service.handle(DictationRequest::Start);
        match until_done(&mut rx).await.last() {
            Some(DictationEvent::Failed(why)) => {
                assert!(
                    why.contains("not available") && why.contains("cloud"),
                    "{why}"
                );
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            stopped.load(Ordering::SeqCst),
            0,
            "no recording was started"
        );
    });
}

#[test]
fn cancel_discards_and_busy_refuses_a_second_recording() {
    rt().block_on(async {
        let calls = Arc::new(AtomicUsize::new(0));
        let (mic, stopped) = microphone(speech(1.0));
        let (mut service, mut rx) = DictationService::new(mic, Ok(loader(0, calls.clone())));
        service.handle(DictationRequest::Start);
        service.handle(DictationRequest::Cancel);
        let events = until_done(&mut rx).await;
        assert_eq!(events.last(), Some(&DictationEvent::Cancelled));
        assert!(
            !events
                .iter()
                .any(|e| matches!(e, DictationEvent::Heard(_) | DictationEvent::Transcribing { .. })),
            "{events:?}"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
        assert_eq!(stopped.load(Ordering::SeqCst), 1, "the device was released");

        // A slow model: a second recording while the first is transcribed is refused.
        let slow: SttLoader = Arc::new(|_: &mut dyn FnMut(&str)| {
            std::thread::sleep(Duration::from_millis(500));
            Ok(Arc::new(Echo) as Arc<dyn SpeechToText>)
        });
        let (mic, _) = microphone(speech(1.0));
        let (mut service, mut rx) = DictationService::new(mic, Ok(slow));
        service.handle(DictationRequest::Start);
        service.handle(DictationRequest::Stop);
        tokio::time::sleep(Duration::from_millis(50)).await;
        service.handle(DictationRequest::Start);
        let events = until_done(&mut rx).await;
        assert!(
            matches!(events.last(), Some(DictationEvent::Failed(why)) if why.contains("still transcribing")),
            "{events:?}"
        );
        let events = until_done(&mut rx).await;
        assert!(
            matches!(events.last(), Some(DictationEvent::Heard(_))),
            "{events:?}"
        );
    });
}

#[test]
fn a_wav_file_plays_as_the_microphone() {
    let dir = std::env::temp_dir().join(format!("betr-wav-mic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let wav = dir.join("said.wav");
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 16_000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut writer = hound::WavWriter::create(&wav, spec).unwrap();
    for s in speech(0.5).samples() {
        writer.write_sample((s * 32_767.0) as i16).unwrap();
    }
    writer.finalize().unwrap();

    let (tx, rx) = std::sync::mpsc::channel();
    let mic = WavMicrophone::new(wav.clone());
    let (device, recording) = mic
        .start(Box::new(move |l: Level| {
            let _ = tx.send(l);
        }))
        .unwrap();
    assert_eq!(device, "said.wav (file)");
    // The level of the speech first, in real time, then the silence after the file's end.
    let first = rx.recv_timeout(Duration::from_secs(2)).unwrap();
    assert!(first.rms_dbfs > -12.0, "{first:?}");
    let audio = recording.stop().unwrap();
    assert_eq!(audio.samples().len(), 8_000);

    let missing = WavMicrophone::new(dir.join("missing.wav"));
    let e = missing.start(Box::new(|_| {})).err().unwrap();
    assert!(e.to_string().contains("missing.wav"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fetch_progress_is_one_line_per_percent() {
    let mut lines = Vec::new();
    let mut report = |l: &str| lines.push(l.to_string());
    let mut progress = ReportedProgress {
        name: "whisper-tiny.en",
        report: &mut report,
        percent: None,
    };
    progress.stage("downloading part 1 of 1");
    for done in [0, 10, 11, 500, 999, 1000] {
        progress.bytes(done, 1000);
    }
    progress.bytes(5, 0);
    assert_eq!(
        lines,
        [
            "whisper-tiny.en: downloading part 1 of 1",
            "fetching whisper-tiny.en: 0%",
            "fetching whisper-tiny.en: 1%",
            "fetching whisper-tiny.en: 50%",
            "fetching whisper-tiny.en: 99%",
            "fetching whisper-tiny.en: 100%",
            "fetching whisper-tiny.en: 0%",
        ]
    );
}

#[test]
fn the_settings_loader_builds_the_configured_backend() {
    use crate::voice::SttLayer;
    let settings = SttSettings::resolve(
        None,
        SttLayer::default(),
        SttLayer {
            backend: Some(SttBackend::Openai),
            base_url: Some("http://127.0.0.1:9/v1".into()),
            model: Some("whisper-large".into()),
            ..SttLayer::default()
        },
    )
    .expect("remote settings");
    let mut lines = Vec::new();
    let stt = loader_of(settings)(&mut |l: &str| lines.push(l.to_string())).expect("a backend");
    assert_eq!(stt.describe(), "whisper-large at http://127.0.0.1:9/v1");
    assert!(lines.is_empty(), "nothing to fetch or load: {lines:?}");
    // An unknown embedded model is an error naming the known ones, not a fetch.
    let settings = SttSettings::resolve(
        None,
        SttLayer::default(),
        SttLayer {
            model: Some("whisper-huge".into()),
            ..SttLayer::default()
        },
    )
    .expect("local settings");
    let e = loader_of(settings)(&mut |_: &str| {})
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("whisper-huge") && e.contains("whisper-tiny.en"),
        "{e}"
    );
}
