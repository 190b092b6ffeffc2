//! Where a scenario named on the command line is found, wherever betr runs from.
//!
//! The scenarios betr ships are built into the binary ([`SHIPPED`]) and written into the
//! data directory (`$XDG_DATA_HOME/betr/scenarios`) the first time a scenario is looked
//! for there. They stay files rather than being read from memory because they refer to
//! each other by relative path (`extends`, `example_pool`), because a person writes their
//! own domain by reading and copying them, and because a person's scenario placed beside
//! them can extend them (`extends = "../cell/cell.toml"`). A file betr wrote is replaced
//! when this build ships another version of it, unless the person changed it since: what
//! betr wrote last is remembered by SHA-256 in a manifest beside the files.
//!
//! A name is looked for as given, then under each folder searched (`scenarios/` of the
//! working directory, then the data directory), with `.toml` added when it has no
//! extension and a leading `scenarios/` taken off under the data directory.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

pub use super::shipped::SHIPPED;

/// The scenario the workbench opens when none is named: scenario 1 of BETR-XP-LLM.
pub const DEFAULT_SCENARIO: &str = "cell/red_on_blue.toml";

/// The manifest of what betr last wrote into the data directory: one `sha256  path` line
/// per file.
const MANIFEST: &str = ".shipped";

/// Where the shipped scenarios go: `$XDG_DATA_HOME/betr/scenarios`, else
/// `~/.local/share/betr/scenarios`.
pub fn data_dir(var: &dyn Fn(&str) -> Option<String>) -> Option<PathBuf> {
    let data = var("XDG_DATA_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| var("HOME").map(|h| Path::new(&h).join(".local/share")))?;
    Some(data.join("betr").join("scenarios"))
}

#[derive(Debug, thiserror::Error)]
pub enum CatalogError {
    #[error("cannot write the shipped scenarios into {}: {source}", dir.display())]
    Install {
        dir: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error(
        "scenario {} not found; looked for {}{}. Scenarios known: {}",
        arg.display(),
        list(searched),
        install_failure(install),
        if known.is_empty() { "none".to_string() } else { known.join(", ") }
    )]
    NotFound {
        arg: PathBuf,
        /// Every path tried, each once, in the order tried.
        searched: Vec<PathBuf>,
        /// The scenarios in the folders searched, by name (`cell/red_on_blue`).
        known: Vec<String>,
        /// Why the shipped scenarios are not in the data directory, when they could not be
        /// written.
        install: Option<String>,
    },
}

fn list(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

fn install_failure(why: &Option<String>) -> String {
    why.as_ref().map_or_else(String::new, |w| {
        format!(" (the shipped scenarios are missing: {w})")
    })
}

/// What [`install`] did.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Installed {
    /// Files written (new, or replaced by this build's version).
    pub written: Vec<String>,
    /// Files the person changed since betr wrote them, kept as they are although this
    /// build ships another version.
    pub kept: Vec<String>,
}

/// Write the shipped scenarios into `dir`: each file that is missing, or that betr wrote
/// and this build ships in another version, unless the person changed it since. Every
/// file is written atomically and the manifest last, so an interrupted install is taken
/// up again by the next.
pub fn install(dir: &Path) -> Result<Installed, CatalogError> {
    let failed = |source| CatalogError::Install {
        dir: dir.to_path_buf(),
        source,
    };
    let manifest_path = dir.join(MANIFEST);
    let before = read_manifest(&manifest_path);
    let mut after = BTreeMap::new();
    let mut done = Installed::default();
    for (rel, text) in SHIPPED {
        let path = dir.join(rel);
        let shipped = sha256(text.as_bytes());
        let current = std::fs::read(&path).ok().map(|bytes| sha256(&bytes));
        match current {
            Some(c) if c == shipped => {
                after.insert(rel.to_string(), shipped);
            }
            Some(c) if before.get(*rel) != Some(&c) => {
                // Changed by the person (or theirs from the start): theirs stays.
                done.kept.push(rel.to_string());
                if let Some(previous) = before.get(*rel) {
                    after.insert(rel.to_string(), previous.clone());
                }
            }
            _ => {
                crate::store::write_atomic(&path, text.as_bytes()).map_err(failed)?;
                after.insert(rel.to_string(), shipped);
                done.written.push(rel.to_string());
            }
        }
    }
    if after != before {
        let manifest: String = after
            .iter()
            .map(|(rel, hash)| format!("{hash}  {rel}\n"))
            .collect();
        crate::store::write_atomic(&manifest_path, manifest.as_bytes()).map_err(failed)?;
    }
    Ok(done)
}

fn read_manifest(path: &Path) -> BTreeMap<String, String> {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .lines()
        .filter_map(|l| l.split_once("  "))
        .map(|(hash, rel)| (rel.to_string(), hash.to_string()))
        .collect()
}

fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The folders a scenario name is looked for in, in order.
#[derive(Debug, Clone)]
pub struct Catalog {
    /// Searched first, as they are (`scenarios/` of the working directory).
    pub local: Vec<PathBuf>,
    /// Searched last, after the shipped scenarios were written into it.
    pub data: Option<PathBuf>,
}

impl Catalog {
    /// `scenarios/` of the working directory, then the data directory.
    pub fn standard(var: &dyn Fn(&str) -> Option<String>) -> Catalog {
        Catalog {
            local: vec![PathBuf::from("scenarios")],
            data: data_dir(var),
        }
    }

    /// The file `arg` names: as given, then under each folder; the shipped scenarios are
    /// written into the data directory before it is searched.
    pub fn find(&self, arg: &Path) -> Result<PathBuf, CatalogError> {
        let mut searched = Vec::new();
        add_new(&mut searched, [arg.to_path_buf()]);
        for root in &self.local {
            add_new(&mut searched, candidates(root, arg));
        }
        if let Some(found) = searched.iter().find(|p| p.is_file()) {
            return Ok(found.clone());
        }
        let mut install_error = None;
        if let Some(data) = &self.data {
            if let Err(e) = install(data) {
                tracing::warn!(error = %e, "shipped scenarios not installed");
                install_error = Some(e.to_string());
            }
            let before = searched.len();
            add_new(&mut searched, candidates(data, arg));
            if let Some(found) = searched[before..].iter().find(|p| p.is_file()) {
                return Ok(found.clone());
            }
        }
        Err(CatalogError::NotFound {
            arg: arg.to_path_buf(),
            searched,
            known: self.known(),
            install: install_error,
        })
    }

    /// The scenarios in the folders searched, by name under their folder (a file with a
    /// `[scenario]` table; bases and example pools are not scenarios), each once, sorted.
    pub fn known(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .local
            .iter()
            .chain(&self.data)
            .flat_map(|root| scenarios_under(root))
            .collect();
        names.sort();
        names.dedup();
        names
    }
}

/// Append the paths not listed yet.
fn add_new(list: &mut Vec<PathBuf>, paths: impl IntoIterator<Item = PathBuf>) {
    for p in paths {
        if !list.contains(&p) {
            list.push(p);
        }
    }
}

/// `root/arg` and, without an extension, `root/arg.toml`; a leading `scenarios/` is taken
/// off first, since `root` is such a folder.
fn candidates(root: &Path, arg: &Path) -> Vec<PathBuf> {
    let rel = arg.strip_prefix("scenarios").unwrap_or(arg);
    if arg.is_absolute() || rel.as_os_str().is_empty() {
        return Vec::new();
    }
    let mut out = vec![root.join(rel)];
    if rel.extension().is_none() {
        out.push(root.join(rel).with_extension("toml"));
    }
    out
}

/// Scenario names under `root`, at most four folders deep.
fn scenarios_under(root: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![(root.to_path_buf(), 0)];
    while let Some((dir, depth)) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() && depth < 4 {
                stack.push((path, depth + 1));
            } else if path.extension().is_some_and(|e| e == "toml") && is_scenario(&path) {
                let rel = path.strip_prefix(root).unwrap_or(&path).with_extension("");
                out.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    out
}

/// Whether the file has a `[scenario]` table (read as text: a file with errors is still
/// listed, and loading it says what is wrong).
fn is_scenario(path: &Path) -> bool {
    std::fs::read_to_string(path).is_ok_and(|text| {
        text.lines()
            .any(|l| l.trim_start().starts_with("[scenario]"))
    })
}

#[cfg(test)]
#[path = "catalog_tests.rs"]
mod tests;
