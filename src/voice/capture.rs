//! Push-to-talk recording from the default input device with `cpal`.
//!
//! [`Recorder::start`] opens the device on a thread of its own (so the recorder can live in
//! any front end's state, whatever the platform's stream type allows) and returns once the
//! stream runs, or with a clear error: no microphone, a busy device, no permission, no
//! usable format. While recording, the level callback receives the level of every 50 ms
//! of audio, for a meter. [`Recorder::stop`] ends the stream and returns the recording as
//! 16 kHz mono, refusing one that is empty or silent.

use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use cpal::traits::{DeviceTrait, HostTrait, StreamTrait};
use cpal::{FromSample, SampleFormat, SizedSample};

use super::{Audio16k, Level, VoiceError};

/// Receives the level of each 50 ms of audio while recording. It runs on the audio
/// thread: it must return quickly (send it on a channel, store it in an atomic).
pub type LevelCallback = Box<dyn FnMut(Level) + Send + 'static>;

/// A recording in progress. Dropping it stops and discards the recording.
pub struct Recorder {
    device: String,
    started: Instant,
    stop: Option<mpsc::Sender<()>>,
    thread: Option<JoinHandle<Captured>>,
}

/// What the capture thread hands back.
struct Captured {
    samples: Vec<f32>,
    rate: u32,
    channels: u16,
    stream_error: Option<String>,
}

impl Recorder {
    /// Start recording from the default input device.
    pub fn start(on_level: impl FnMut(Level) + Send + 'static) -> Result<Recorder, VoiceError> {
        let (ready_tx, ready_rx) = mpsc::sync_channel::<Result<String, VoiceError>>(1);
        let (stop_tx, stop_rx) = mpsc::channel::<()>();
        let on_level: LevelCallback = Box::new(on_level);
        let thread = std::thread::Builder::new()
            .name("betr-capture".into())
            .spawn(move || capture_thread(on_level, &ready_tx, &stop_rx))
            .map_err(|e| VoiceError::Capture {
                detail: format!("cannot start the recording thread: {e}"),
            })?;
        match ready_rx.recv() {
            Ok(Ok(device)) => Ok(Recorder {
                device,
                started: Instant::now(),
                stop: Some(stop_tx),
                thread: Some(thread),
            }),
            Ok(Err(e)) => {
                let _ = thread.join();
                Err(e)
            }
            Err(_) => {
                let _ = thread.join();
                Err(VoiceError::Capture {
                    detail: "the recording thread ended before the stream started".into(),
                })
            }
        }
    }

    /// The device's name.
    pub fn device(&self) -> &str {
        &self.device
    }

    /// Time since recording started.
    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// Stop recording; the audio at 16 kHz mono, or why there is nothing to transcribe.
    pub fn stop(mut self) -> Result<Audio16k, VoiceError> {
        let captured = self.finish().ok_or_else(|| VoiceError::Capture {
            detail: "the recording thread panicked".into(),
        })?;
        if captured.samples.is_empty()
            && let Some(detail) = captured.stream_error
        {
            return Err(VoiceError::Capture { detail });
        }
        let audio = Audio16k::from_interleaved(&captured.samples, captured.rate, captured.channels);
        audio.check_speech()?;
        Ok(audio)
    }

    fn finish(&mut self) -> Option<Captured> {
        drop(self.stop.take());
        self.thread.take().and_then(|t| t.join().ok())
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

/// Open the device, run the stream until told to stop (or the recorder is dropped).
fn capture_thread(
    on_level: LevelCallback,
    ready: &mpsc::SyncSender<Result<String, VoiceError>>,
    stop: &mpsc::Receiver<()>,
) -> Captured {
    let errors: Arc<Mutex<Option<String>>> = Arc::default();
    let mut captured = Captured {
        samples: Vec::new(),
        rate: 48_000,
        channels: 1,
        stream_error: None,
    };
    match open(on_level, &errors) {
        Ok(opened) => {
            let _ = ready.send(Ok(opened.device));
            // Blocks until stop() sends or the Recorder (holding the sender) is dropped.
            let _ = stop.recv();
            drop(opened.stream);
            captured.rate = opened.rate;
            captured.channels = opened.channels;
            captured.samples = opened
                .collector
                .lock()
                .map(|mut c| std::mem::take(&mut c.samples))
                .unwrap_or_default();
        }
        Err(e) => {
            let _ = ready.send(Err(e));
        }
    }
    captured.stream_error = errors.lock().ok().and_then(|mut e| e.take());
    captured
}

struct Opened {
    stream: cpal::Stream,
    device: String,
    rate: u32,
    channels: u16,
    collector: Arc<Mutex<Collector>>,
}

fn open(
    on_level: LevelCallback,
    errors: &Arc<Mutex<Option<String>>>,
) -> Result<Opened, VoiceError> {
    let host = cpal::default_host();
    let device = host
        .default_input_device()
        .ok_or_else(|| VoiceError::NoInputDevice {
            detail: format!("{} has no default input device", host.id().name()),
        })?;
    let name = device
        .description()
        .map_or_else(|_| "default".to_string(), |d| d.name().to_string());
    let supported = device
        .default_input_config()
        .map_err(|e| classify(&e, &name))?;
    let (rate, channels) = (supported.sample_rate(), supported.channels());
    let collector = Arc::new(Mutex::new(Collector::new(rate, channels, on_level)));
    let config: cpal::StreamConfig = supported.config();
    let c = &collector;
    let stream = match supported.sample_format() {
        SampleFormat::F32 => build::<f32>(&device, &config, c, errors),
        SampleFormat::I16 => build::<i16>(&device, &config, c, errors),
        SampleFormat::U16 => build::<u16>(&device, &config, c, errors),
        SampleFormat::I32 => build::<i32>(&device, &config, c, errors),
        SampleFormat::I8 => build::<i8>(&device, &config, c, errors),
        SampleFormat::U8 => build::<u8>(&device, &config, c, errors),
        other => {
            return Err(VoiceError::UnsupportedConfig {
                device: name,
                detail: format!("sample format {other}"),
            });
        }
    }
    .map_err(|e| classify(&e, &name))?;
    stream.play().map_err(|e| classify(&e, &name))?;
    Ok(Opened {
        stream,
        device: name,
        rate,
        channels,
        collector,
    })
}

fn build<T>(
    device: &cpal::Device,
    config: &cpal::StreamConfig,
    collector: &Arc<Mutex<Collector>>,
    errors: &Arc<Mutex<Option<String>>>,
) -> Result<cpal::Stream, cpal::Error>
where
    T: SizedSample,
    f32: FromSample<T>,
{
    let collector = Arc::clone(collector);
    let errors = Arc::clone(errors);
    device.build_input_stream::<T, _, _>(
        *config,
        move |data: &[T], _: &cpal::InputCallbackInfo| {
            if let Ok(mut c) = collector.lock() {
                c.push(data.iter().map(|&s| s.to_sample::<f32>()));
            }
        },
        move |err: cpal::Error| {
            if let Ok(mut e) = errors.lock() {
                e.get_or_insert_with(|| err.to_string());
            }
        },
        None,
    )
}

/// A cpal error as what a person can do about it.
pub(crate) fn classify(err: &cpal::Error, device: &str) -> VoiceError {
    let device = device.to_string();
    let detail = err.to_string();
    match err.kind() {
        cpal::ErrorKind::DeviceBusy => VoiceError::DeviceBusy { device, detail },
        cpal::ErrorKind::PermissionDenied => VoiceError::PermissionDenied { device, detail },
        cpal::ErrorKind::UnsupportedConfig => VoiceError::UnsupportedConfig { device, detail },
        cpal::ErrorKind::DeviceNotAvailable | cpal::ErrorKind::HostUnavailable => {
            VoiceError::NoInputDevice {
                detail: format!("{device:?} is not available ({detail})"),
            }
        }
        _ => VoiceError::Capture {
            detail: format!("{device}: {detail}"),
        },
    }
}

/// Gathers interleaved samples and reports the level of every 50 ms.
pub(crate) struct Collector {
    pub(crate) samples: Vec<f32>,
    on_level: LevelCallback,
    /// Samples (all channels) per level report.
    window: usize,
    pending: Vec<f32>,
}

impl Collector {
    pub(crate) fn new(rate: u32, channels: u16, on_level: LevelCallback) -> Collector {
        let window = (rate as usize / 20).max(1) * usize::from(channels.max(1));
        Collector {
            samples: Vec::new(),
            on_level,
            window,
            pending: Vec::with_capacity(window),
        }
    }

    pub(crate) fn push(&mut self, data: impl Iterator<Item = f32>) {
        for s in data {
            self.samples.push(s);
            self.pending.push(s);
            if self.pending.len() == self.window {
                (self.on_level)(Level::of(&self.pending));
                self.pending.clear();
            }
        }
    }
}

#[cfg(test)]
#[path = "capture_tests.rs"]
mod tests;
