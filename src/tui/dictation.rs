//! Push-to-talk for the workbench: the bridge between the app's key presses and the
//! `voice` module. The app asks ([`DictationRequest`]); this service owns the recording
//! and the speech-to-text model and answers with [`DictationEvent`]s through a sink (in the
//! workbench, into the event loop's queue), so the screen never waits on audio or on a
//! model.
//!
//! The microphone is a trait so tests (and machines without a sound card) can stand in a
//! recording; the model is loaded on first use (fetched first when it is not cached, with
//! progress), starting while the person is still speaking.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use tokio::sync::OnceCell;
use tokio::sync::mpsc::{UnboundedReceiver, unbounded_channel};

use crate::model::Progress;
use crate::voice::{
    self, Audio16k, Level, Recorder, SpeechToText, SttBackend, SttSettings, Transcript, VoiceError,
};

/// What the app asks of the service.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DictationRequest {
    /// Start recording from the microphone.
    Start,
    /// Stop recording and transcribe what was said.
    Stop,
    /// Stop recording and throw it away.
    Cancel,
}

/// What the service tells the app.
#[derive(Debug, Clone, PartialEq)]
pub enum DictationEvent {
    /// The microphone is recording.
    Recording { device: String },
    /// The level of the last 50 ms of audio.
    Level(Level),
    /// Getting the model ready (loading, or fetching it on first use).
    Preparing(String),
    /// The recording ended; this many seconds of audio are being transcribed.
    Transcribing { seconds: f64 },
    /// What was heard: for the input line, never submitted unseen.
    Heard(Transcript),
    /// Why nothing was heard (no microphone, a busy device, silence, no model…).
    Failed(String),
    /// The recording was thrown away.
    Cancelled,
}

/// A recording in progress.
pub trait Recording: Send {
    /// Stop and return the audio at 16 kHz mono (blocking: joins the audio thread).
    fn stop(self: Box<Self>) -> Result<Audio16k, VoiceError>;
}

/// Where recordings come from.
pub trait Microphone: Send + Sync {
    /// Start recording; `on_level` runs on the audio thread for every 50 ms of audio.
    /// Returns the device's name with the recording.
    fn start(
        &self,
        on_level: Box<dyn FnMut(Level) + Send>,
    ) -> Result<(String, Box<dyn Recording>), VoiceError>;
}

/// The default input device, through cpal.
pub struct DefaultMicrophone;

impl Recording for Recorder {
    fn stop(self: Box<Self>) -> Result<Audio16k, VoiceError> {
        Recorder::stop(*self)
    }
}

impl Microphone for DefaultMicrophone {
    fn start(
        &self,
        on_level: Box<dyn FnMut(Level) + Send>,
    ) -> Result<(String, Box<dyn Recording>), VoiceError> {
        let recorder = Recorder::start(on_level)?;
        Ok((recorder.device().to_string(), Box::new(recorder)))
    }
}

/// A WAV file played as the microphone (`BETR_PUSH_TO_TALK_WAV=FILE.wav betr tui`): for machines without
/// one, demonstrations and end-to-end tests. Its levels arrive in real time, 50 ms at a
/// time, while "recording"; stopping returns the whole file.
pub struct WavMicrophone {
    path: PathBuf,
}

impl WavMicrophone {
    pub fn new(path: PathBuf) -> WavMicrophone {
        WavMicrophone { path }
    }
}

/// A file being played: the level thread runs until stopped.
struct PlayedWav {
    audio: Audio16k,
    playing: Arc<AtomicBool>,
}

impl Recording for PlayedWav {
    fn stop(self: Box<Self>) -> Result<Audio16k, VoiceError> {
        self.playing.store(false, Ordering::SeqCst);
        self.audio.check_speech()?;
        Ok(self.audio)
    }
}

impl Microphone for WavMicrophone {
    fn start(
        &self,
        mut on_level: Box<dyn FnMut(Level) + Send>,
    ) -> Result<(String, Box<dyn Recording>), VoiceError> {
        // Read at each press, so a file rewritten between dictations is heard anew.
        let audio = Audio16k::from_wav(&self.path)?;
        let playing = Arc::new(AtomicBool::new(true));
        let (samples, still) = (audio.samples().to_vec(), playing.clone());
        std::thread::Builder::new()
            .name("betr-wav-mic".into())
            .spawn(move || {
                let window = voice::SAMPLE_RATE as usize / 20;
                let mut chunks = samples.chunks(window);
                while still.load(Ordering::SeqCst) {
                    // After the file's end, the room is silent.
                    on_level(chunks.next().map_or_else(|| Level::of(&[]), Level::of));
                    std::thread::sleep(Duration::from_millis(50));
                }
            })
            .map_err(|e| VoiceError::Capture {
                detail: format!("cannot start the playback thread: {e}"),
            })?;
        let name = self.path.file_name().map_or_else(
            || self.path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        Ok((
            format!("{name} (file)"),
            Box::new(PlayedWav { audio, playing }),
        ))
    }
}

/// Where the service's events go: called from the audio thread and from tasks, so it
/// must not block (a send on an unbounded channel).
pub type DictationSink = Arc<dyn Fn(DictationEvent) + Send + Sync>;

/// Why dictation gave no transcript, or cannot work at all.
#[derive(Debug, thiserror::Error)]
pub enum DictationError {
    /// The speech-to-text settings cannot work, in the words of the front end that read
    /// them (it knows where they came from).
    #[error("{reason}")]
    Settings { reason: String },
    /// The embedded model could not be fetched.
    #[error(transparent)]
    Fetch(#[from] crate::model::FetchError),
    /// Recording, loading the model or transcribing failed.
    #[error(transparent)]
    Voice(#[from] VoiceError),
    /// The task stopping the recording ended without an answer.
    #[error("the recording could not be stopped: {0}")]
    Stop(tokio::task::JoinError),
    /// The task loading the model ended without an answer.
    #[error("the speech-to-text model could not be loaded: {0}")]
    Load(tokio::task::JoinError),
}

/// Builds the speech-to-text backend (blocking: it may fetch and load a model), reporting
/// progress through the callback; the error says what to do.
pub type SttLoader = Arc<
    dyn Fn(&mut dyn FnMut(&str)) -> Result<Arc<dyn SpeechToText>, DictationError> + Send + Sync,
>;

/// The workbench's push-to-talk model: built on first use, the embedded model fetched
/// first when it is not in the cache, with progress reported as short lines (the screen
/// is up, so nothing is printed).
pub fn loader_of(settings: SttSettings) -> SttLoader {
    Arc::new(move |report: &mut dyn FnMut(&str)| {
        if settings.backend == SttBackend::Local
            && let Some(spec) = crate::model::find_stt(&settings.model)
            && !spec.is_present()
        {
            report(&format!(
                "fetching {} ({:.0} MB, once only)",
                spec.name,
                spec.size() as f64 / 1e6
            ));
            let mut progress = ReportedProgress {
                name: spec.name,
                report: &mut *report,
                percent: None,
            };
            crate::model::fetch_dir(spec, &crate::model::cache_dir(), "python3", &mut progress)?;
        }
        if settings.backend == SttBackend::Local {
            report(&format!("loading {}", settings.model));
        }
        settings
            .build(&|k| std::env::var(k).ok())
            .map(Arc::from)
            .map_err(DictationError::from)
    })
}

/// A fetch's progress as "fetching NAME: 42%" lines, one per percent.
struct ReportedProgress<'a> {
    name: &'static str,
    report: &'a mut dyn FnMut(&str),
    percent: Option<u64>,
}

impl Progress for ReportedProgress<'_> {
    fn stage(&mut self, message: &str) {
        (self.report)(&format!("{}: {message}", self.name));
    }

    fn bytes(&mut self, done: u64, total: u64) {
        let percent = (done * 100).checked_div(total).unwrap_or(0);
        if self.percent != Some(percent) {
            self.percent = Some(percent);
            (self.report)(&format!("fetching {}: {percent}%", self.name));
        }
    }
}

/// Owns the recording in progress and the speech-to-text model.
pub struct DictationService {
    microphone: Arc<dyn Microphone>,
    /// `Err`: why dictation cannot work at all (bad `[stt]` settings).
    loader: Result<SttLoader, DictationError>,
    stt: Arc<OnceCell<Arc<dyn SpeechToText>>>,
    recording: Option<Box<dyn Recording>>,
    /// A recording is being stopped or transcribed.
    busy: Arc<AtomicBool>,
    events: DictationSink,
}

impl DictationService {
    /// A service whose events arrive on a channel of their own.
    pub fn new(
        microphone: Arc<dyn Microphone>,
        loader: Result<SttLoader, DictationError>,
    ) -> (DictationService, UnboundedReceiver<DictationEvent>) {
        let (tx, rx) = unbounded_channel();
        // The app is gone only when the workbench is closing: nothing is left to tell.
        let sink: DictationSink = Arc::new(move |event| {
            let _ = tx.send(event);
        });
        (DictationService::reporting_to(microphone, loader, sink), rx)
    }

    /// A service whose events go to `events`.
    pub fn reporting_to(
        microphone: Arc<dyn Microphone>,
        loader: Result<SttLoader, DictationError>,
        events: DictationSink,
    ) -> DictationService {
        DictationService {
            microphone,
            loader,
            stt: Arc::new(OnceCell::new()),
            recording: None,
            busy: Arc::new(AtomicBool::new(false)),
            events,
        }
    }

    /// Act on a request. Must run inside a tokio runtime: stopping and transcribing run as
    /// tasks whose outcome arrives as events.
    pub fn handle(&mut self, request: DictationRequest) {
        match request {
            DictationRequest::Start => self.start(),
            DictationRequest::Stop => self.stop(),
            DictationRequest::Cancel => self.cancel(),
        }
    }

    fn send(&self, event: DictationEvent) {
        (self.events)(event);
    }

    fn start(&mut self) {
        if self.recording.is_some() {
            return;
        }
        if self.busy.load(Ordering::SeqCst) {
            return self.send(DictationEvent::Failed(
                super::strings::DICTATION_BUSY.to_string(),
            ));
        }
        let loader = match &self.loader {
            Ok(l) => l.clone(),
            Err(why) => {
                return self.send(DictationEvent::Failed(
                    super::strings::dictation_unavailable(&why.to_string()),
                ));
            }
        };
        // Levels are forwarded once `Recording` is sent, so they never arrive before it
        // (the device may deliver its first 50 ms before `start` returns).
        let open = Arc::new(AtomicBool::new(false));
        let (levels, forwarding) = (self.events.clone(), open.clone());
        let on_level = Box::new(move |level: Level| {
            if forwarding.load(Ordering::Acquire) {
                levels(DictationEvent::Level(level));
            }
        });
        // Opening the device is quick (the stream starts on its own thread); doing it here
        // keeps "recording" and the first level in order.
        match self.microphone.start(on_level) {
            Ok((device, recording)) => {
                self.recording = Some(recording);
                self.send(DictationEvent::Recording { device });
                open.store(true, Ordering::Release);
                // Load the model while the person speaks; a failure here is reported when
                // the recording is transcribed (the load is tried again then).
                let (stt, events) = (self.stt.clone(), self.events.clone());
                tokio::spawn(async move {
                    if let Err(e) = ready_model(&stt, &loader, &events).await {
                        tracing::warn!(error = %e, "speech-to-text model not ready");
                    }
                });
            }
            Err(e) => self.send(DictationEvent::Failed(e.to_string())),
        }
    }

    fn stop(&mut self) {
        let Some(recording) = self.recording.take() else {
            return;
        };
        // `start` refuses to record without a loader, so this holds; if it ever did not,
        // the person hears why rather than nothing.
        let loader = match &self.loader {
            Ok(l) => l.clone(),
            Err(why) => {
                return self.send(DictationEvent::Failed(
                    super::strings::dictation_unavailable(&why.to_string()),
                ));
            }
        };
        self.busy.store(true, Ordering::SeqCst);
        let (stt, events, busy) = (self.stt.clone(), self.events.clone(), self.busy.clone());
        tokio::spawn(async move {
            let outcome = stop_and_transcribe(recording, &stt, &loader, &events).await;
            busy.store(false, Ordering::SeqCst);
            events(match outcome {
                Ok(transcript) => DictationEvent::Heard(transcript),
                Err(e) => DictationEvent::Failed(e.to_string()),
            });
        });
    }

    fn cancel(&mut self) {
        if let Some(recording) = self.recording.take() {
            // Joining the audio thread blocks briefly: not on the event loop.
            tokio::task::spawn_blocking(move || drop(recording.stop()));
            self.send(DictationEvent::Cancelled);
        }
    }
}

async fn stop_and_transcribe(
    recording: Box<dyn Recording>,
    stt: &OnceCell<Arc<dyn SpeechToText>>,
    loader: &SttLoader,
    events: &DictationSink,
) -> Result<Transcript, DictationError> {
    let audio = tokio::task::spawn_blocking(move || recording.stop())
        .await
        .map_err(DictationError::Stop)??;
    events(DictationEvent::Transcribing {
        seconds: audio.seconds(),
    });
    let model = ready_model(stt, loader, events).await?;
    Ok(voice::transcribe(model.as_ref(), &audio).await?)
}

/// The model, loaded once (concurrent callers wait for the same load; a failed load is
/// tried again by the next caller).
async fn ready_model(
    stt: &OnceCell<Arc<dyn SpeechToText>>,
    loader: &SttLoader,
    events: &DictationSink,
) -> Result<Arc<dyn SpeechToText>, DictationError> {
    stt.get_or_try_init(|| {
        let (loader, events) = (loader.clone(), events.clone());
        async move {
            tokio::task::spawn_blocking(move || {
                loader(&mut |message: &str| {
                    events(DictationEvent::Preparing(message.to_string()));
                })
            })
            .await
            .map_err(DictationError::Load)?
        }
    })
    .await
    .cloned()
}

#[cfg(test)]
#[path = "dictation_tests.rs"]
mod tests;
