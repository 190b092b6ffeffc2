//! The settings file, `betr.toml`: the language model's settings (`[llm]`), model prices
//! (`[prices]`) and speech-to-text's (`[stt]`). Each part is resolved by its own module
//! (`llm::config`, `voice::config`); this one finds the file and reads it whole.

use std::path::{Path, PathBuf};

use serde::Deserialize;

/// Why the settings file cannot be used; names the file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ConfigFileError(String);

/// The contents of `betr.toml`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileConfig {
    #[serde(default)]
    pub llm: crate::llm::config::Layer,
    #[serde(default)]
    pub prices: crate::llm::usage::PriceTable,
    #[serde(default)]
    pub stt: crate::voice::SttLayer,
}

impl FileConfig {
    pub fn read(path: &Path) -> Result<FileConfig, ConfigFileError> {
        let text = crate::store::read_text(path, crate::store::SMALL_FILE_BYTES)
            .map_err(|e| ConfigFileError(format!("cannot read {}: {e}", path.display())))?;
        let file: FileConfig = toml::from_str(&text)
            .map_err(|e| ConfigFileError(format!("{}: {e}", path.display())))?;
        if file.llm.api_key.is_some() {
            return Err(ConfigFileError(format!(
                "{}: `api_key` is not allowed in a file; put the key in an environment variable and name it with `api_key_env`",
                path.display()
            )));
        }
        if file.stt.api_key.is_some() {
            return Err(ConfigFileError(format!(
                "{}: `api_key` is not allowed under [stt]; put the key in an environment variable and name it with `api_key_env`",
                path.display()
            )));
        }
        Ok(file)
    }

    /// The file to read: `explicit`, else `$BETR_CONFIG`, else `./betr.toml`, else
    /// `$XDG_CONFIG_HOME/betr/betr.toml` (or `~/.config/betr/betr.toml`), if it exists.
    pub fn locate(
        explicit: Option<&Path>,
        var: &dyn Fn(&str) -> Option<String>,
    ) -> Option<PathBuf> {
        if let Some(p) = explicit {
            return Some(p.to_path_buf());
        }
        if let Some(p) = var("BETR_CONFIG").filter(|v| !v.is_empty()) {
            return Some(PathBuf::from(p));
        }
        let local = PathBuf::from("betr.toml");
        if local.is_file() {
            return Some(local);
        }
        let config_home = var("XDG_CONFIG_HOME")
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
            .or_else(|| var("HOME").map(|h| Path::new(&h).join(".config")))?;
        Some(config_home.join("betr").join("betr.toml")).filter(|p| p.is_file())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_example_is_valid() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("betr.example.toml");
        let file = FileConfig::read(&path).unwrap();
        assert!(file.llm.backend.is_some());
        assert_eq!(file.stt.backend, Some(crate::voice::SttBackend::Local));
    }

    #[test]
    fn keys_in_the_file_are_refused_without_repeating_them() {
        let dir = std::env::temp_dir().join(format!("betr-config-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("betr.toml");
        std::fs::write(&path, "[llm]\napi_key = \"sk-x\"\n").unwrap();
        let e = FileConfig::read(&path).unwrap_err().to_string();
        assert!(e.contains("api_key_env") && !e.contains("sk-x"), "{e}");
        std::fs::write(&path, "[stt]\napi_key = \"sk-y\"\n").unwrap();
        let e = FileConfig::read(&path).unwrap_err().to_string();
        assert!(e.contains("[stt]") && !e.contains("sk-y"), "{e}");
        std::fs::write(&path, "[llm]\nbackend = \"gpt\"\n").unwrap();
        let e = FileConfig::read(&path).unwrap_err().to_string();
        assert!(e.contains("betr.toml"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
