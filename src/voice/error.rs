//! Everything that can go wrong between a microphone (or a WAV file) and a transcript,
//! each with what a person can do about it. Texts are short enough for a status bar.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum VoiceError {
    #[error(
        "no microphone: connect one, or dictate a WAV file with --audio on interpret/resolve ({detail})"
    )]
    NoInputDevice { detail: String },
    #[error(
        "the microphone {device:?} is busy ({detail}); close the program using it and try again"
    )]
    DeviceBusy { device: String, detail: String },
    #[error(
        "not allowed to use the microphone {device:?} ({detail}); on Linux, check membership of the `audio` group"
    )]
    PermissionDenied { device: String, detail: String },
    #[error("the microphone {device:?} offers no recording format betr can use ({detail})")]
    UnsupportedConfig { device: String, detail: String },
    #[error("recording failed: {detail}")]
    Capture { detail: String },
    #[error("{path}: {detail}")]
    Wav { path: PathBuf, detail: String },
    #[error("the recording is empty ({seconds:.2} s); hold the key while speaking")]
    EmptyRecording { seconds: f64 },
    #[error(
        "the recording is silent (peak {peak_dbfs:.0} dBFS); check that the microphone is on and not muted"
    )]
    Silent { peak_dbfs: f64 },
    #[error(
        "the speech-to-text model {name} is not in the cache ({path}); run `betr model fetch --stt --model {name}`"
    )]
    ModelMissing { name: String, path: PathBuf },
    #[error("unknown speech-to-text model {name:?} (known: {known})")]
    UnknownModel { name: String, known: String },
    #[error("cannot load the speech-to-text model from {path}: {detail}")]
    ModelLoad { path: PathBuf, detail: String },
    #[error("transcription failed: {detail}")]
    Transcribe { detail: String },
    #[error(
        "nothing intelligible was heard ({seconds:.1} s of audio); speak closer to the microphone and try again"
    )]
    EmptyTranscript { seconds: f64 },
    #[error("speech-to-text settings: {0}")]
    Config(String),
    #[error("cannot reach the transcription server at {url}: {detail}")]
    Connect { url: String, detail: String },
    #[error("the transcription server at {url} did not answer within {seconds:.0} s")]
    Timeout { url: String, seconds: f64 },
    #[error(
        "the transcription server at {url} refused the key (HTTP {status}); check the variable {env_var}: {detail}"
    )]
    Unauthorized {
        url: String,
        status: u16,
        env_var: String,
        detail: String,
    },
    #[error(
        "the transcription server at {url} answered HTTP {status} after {attempts} attempt(s): {detail}"
    )]
    Http {
        url: String,
        status: u16,
        attempts: u32,
        detail: String,
    },
    #[error("the transcription server at {url} sent a reply betr cannot read: {detail}")]
    MalformedReply { url: String, detail: String },
}
