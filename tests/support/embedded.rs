//! The embedded models, fetched into the cache first when missing (like `betr model
//! fetch`), each loaded once per test binary.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use betr::llm::local::{EngineOptions, LocalModel};
use betr::model::{self, DEFAULT_MODEL, Progress, WHISPER_TINY_EN};

/// Fetch progress as plain lines on stderr (test output).
pub struct Lines;

impl Progress for Lines {
    fn stage(&mut self, message: &str) {
        eprintln!("{message}");
    }
    fn bytes(&mut self, _: u64, _: u64) {}
}

/// The default language model's file, fetched when missing.
pub fn default_model_file() -> PathBuf {
    if !DEFAULT_MODEL.is_present() {
        model::fetch(DEFAULT_MODEL, &model::cache_dir(), "python3", &mut Lines).unwrap();
    }
    DEFAULT_MODEL.path()
}

/// The default language model in llama.cpp, on `threads` threads (the first call of a
/// test binary decides). One thread where other tests of the binary keep the machine
/// busy, since two threads stall waiting for each other there; every core where the
/// binary's tests are all model calls, which its one worker answers one at a time.
pub fn language_model(threads: u32) -> &'static Arc<LocalModel> {
    static MODEL: OnceLock<Arc<LocalModel>> = OnceLock::new();
    MODEL.get_or_init(|| {
        let path = default_model_file();
        Arc::new(
            LocalModel::load(
                DEFAULT_MODEL.name,
                EngineOptions {
                    model_path: path,
                    threads,
                    context: 4096,
                    prompt_states: None,
                },
            )
            .unwrap(),
        )
    })
}

/// A test's turn with the model. Its one worker answers one call at a time anyway, but
/// tests that interleave their calls evict each other's prompt from the worker's cache,
/// and a test simulating between calls takes a core from the threads answering another
/// test's call, which then stall. Tests holding the turn for their whole body run one
/// after another at full speed.
pub async fn turn() -> tokio::sync::MutexGuard<'static, ()> {
    static TURN: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());
    TURN.lock().await
}

/// Threads for a test binary whose only work is the model's: the machine's cores, at most
/// four.
pub fn every_core() -> u32 {
    std::thread::available_parallelism().map_or(1, |n| n.get().min(4)) as u32
}

/// The directory of the default speech-to-text model (Whisper tiny.en).
pub fn whisper_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        if WHISPER_TINY_EN.is_present() {
            WHISPER_TINY_EN.path()
        } else {
            model::fetch_dir(&WHISPER_TINY_EN, &model::cache_dir(), "python3", &mut Lines).unwrap()
        }
    })
}
