//! `betr model fetch`, `list` and `verify`, for the language model, (with `--stt`) the
//! speech-to-text models and (with `--robot`) the robot descriptions the cell's arms need.

use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Subcommand;
use indicatif::{ProgressBar, ProgressStyle};

use betr::model::{self, DirModelSpec, ModelSpec, Progress};

#[derive(Subcommand)]
pub enum ModelAction {
    /// Download, verify and install a model (the default LLM unless --model; with --stt
    /// the default speech-to-text model, whisper-tiny.en), or with --robot a robot
    /// description (the workbench also fetches the one its scenario needs on first use).
    Fetch {
        #[arg(long)]
        model: Option<String>,
        /// A speech-to-text model.
        #[arg(long)]
        stt: bool,
        /// A robot description by name (`yumi`: the ABB YuMi's URDF and meshes).
        #[arg(long, value_name = "NAME", conflicts_with_all = ["model", "stt"])]
        robot: Option<String>,
    },
    /// Known models, their sizes and whether they are in the cache.
    List,
    /// Check the cached files' SHA-256 against the expected ones.
    Verify {
        #[arg(long)]
        model: Option<String>,
        /// A speech-to-text model.
        #[arg(long)]
        stt: bool,
    },
}

pub fn run(action: ModelAction) -> Result<ExitCode> {
    match action {
        ModelAction::Fetch {
            robot: Some(robot), ..
        } => fetch_robot(&robot),
        ModelAction::Fetch { model, stt, .. } => fetch(model.as_deref(), stt),
        ModelAction::List => list(),
        ModelAction::Verify { model, stt } => verify(model.as_deref(), stt),
    }
}

/// Progress on the terminal: a spinner per step, a byte bar while the file is assembled.
pub struct TerminalProgress {
    bar: ProgressBar,
}

impl TerminalProgress {
    pub fn new() -> Self {
        let bar = ProgressBar::new_spinner();
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        TerminalProgress { bar }
    }

    pub fn finish(&self, message: String) {
        self.bar.finish_with_message(message);
    }
}

impl Progress for TerminalProgress {
    fn stage(&mut self, message: &str) {
        self.bar.set_message(message.to_string());
    }

    fn bytes(&mut self, done: u64, total: u64) {
        if self.bar.length() != Some(total) {
            self.bar.set_length(total);
            if let Ok(style) = ProgressStyle::with_template(
                "{msg}\n{wide_bar} {bytes}/{total_bytes} ({bytes_per_sec})",
            ) {
                self.bar.set_style(style);
            }
        }
        self.bar.set_position(done);
    }
}

fn spec(name: Option<&str>) -> Result<&'static ModelSpec> {
    match name {
        None => Ok(model::DEFAULT_MODEL),
        Some(n) => model::find(n).with_context(|| {
            let known: Vec<&str> = model::MODELS.iter().map(|m| m.name).collect();
            format!("unknown model {n:?} (known: {})", known.join(", "))
        }),
    }
}

/// Fetch a model unless it is already cached; returns its path.
pub fn ensure(name: Option<&str>) -> Result<std::path::PathBuf> {
    let spec = spec(name)?;
    if spec.is_present() {
        return Ok(spec.path());
    }
    fetch_once(spec.description, spec.size, |progress| {
        model::fetch(spec, &model::cache_dir(), "python3", progress)
    })
}

/// Fetch something into the cache with a progress bar on the terminal, saying first what
/// and how big, and at the end where it went; with `--offline` (or `BETR_OFFLINE`),
/// nothing is fetched and the command fails saying what is missing.
fn fetch_once(
    description: &str,
    size: u64,
    fetch: impl FnOnce(&mut TerminalProgress) -> Result<std::path::PathBuf, model::FetchError>,
) -> Result<std::path::PathBuf> {
    if super::offline() {
        anyhow::bail!(
            "{description} ({:.0} MB) is not in {} and --offline (or BETR_OFFLINE) fetches nothing; \
             `betr model fetch` fetches it where the network can be reached",
            size as f64 / 1e6,
            model::cache_dir().display()
        );
    }
    errln!(
        "Fetching {} ({:.0} MB) into {} — once only",
        description,
        size as f64 / 1e6,
        model::cache_dir().display()
    );
    let mut progress = TerminalProgress::new();
    let path = fetch(&mut progress)?;
    progress.finish(format!("verified and installed {}", path.display()));
    Ok(path)
}

fn stt_spec(name: Option<&str>) -> Result<&'static DirModelSpec> {
    match name {
        None => Ok(&model::WHISPER_TINY_EN),
        Some(n) => model::find_stt(n).with_context(|| {
            let known: Vec<&str> = model::STT_MODELS.iter().map(|m| m.name).collect();
            format!(
                "unknown speech-to-text model {n:?} (known: {})",
                known.join(", ")
            )
        }),
    }
}

/// Fetch a speech-to-text model unless it is already cached; returns its directory.
pub fn ensure_stt(name: Option<&str>) -> Result<std::path::PathBuf> {
    let spec = stt_spec(name)?;
    if spec.is_present() {
        return Ok(spec.path());
    }
    fetch_once(spec.description, spec.size(), |progress| {
        model::fetch_dir(spec, &model::cache_dir(), "python3", progress)
    })
}

/// The robot description `scenario`'s cell moves its arms with, fetched now with its
/// progress on standard error when it is not in the cache yet (as the workbench fetches
/// it in the background), unless `offline`: then the world says what is missing and keeps
/// its reach spheres and gripper sweep.
pub fn ensure_scenario_robot(scenario: &betr::scenario::Scenario, offline: bool) -> Result<()> {
    let Some(spec) = betr::session::missing_description(scenario) else {
        return Ok(());
    };
    if offline {
        return Ok(());
    }
    fetch_once(spec.description, spec.size, |progress| {
        model::ensure_description(spec, &model::cache_dir(), model::Pip::DEFAULT, progress)
    })
    .with_context(|| {
        format!(
            "fetching the robot description {} that {} names (--offline or BETR_OFFLINE=1 runs without it)",
            spec.name, scenario.name
        )
    })?;
    Ok(())
}

/// Fetch a robot description unless it is already cached, and say where it is.
fn fetch_robot(name: &str) -> Result<ExitCode> {
    let spec = model::find_description(name).with_context(|| {
        let known: Vec<&str> = model::DESCRIPTIONS.iter().map(|d| d.name).collect();
        format!(
            "unknown robot description {name:?} (known: {})",
            known.join(", ")
        )
    })?;
    let path = spec.path();
    if !spec.urdf_in(&path).is_file() {
        fetch_once(spec.description, spec.size, |progress| {
            model::ensure_description(spec, &model::cache_dir(), model::Pip::DEFAULT, progress)
        })?;
    }
    outln!("{}", path.display());
    Ok(ExitCode::SUCCESS)
}

pub fn fetch(name: Option<&str>, stt: bool) -> Result<ExitCode> {
    let path = if stt {
        ensure_stt(name)?
    } else {
        ensure(name)?
    };
    outln!("{}", path.display());
    Ok(ExitCode::SUCCESS)
}

pub fn list() -> Result<ExitCode> {
    outln!("{:<22} {:>9}  {:<8} description", "name", "size", "present");
    for m in model::MODELS {
        outln!(
            "{:<22} {:>6.0} MB  {:<8} {}",
            m.name,
            m.size as f64 / 1e6,
            if m.is_present() { "yes" } else { "no" },
            m.description
        );
    }
    for m in model::STT_MODELS {
        outln!(
            "{:<22} {:>6.0} MB  {:<8} {} [--stt]",
            m.name,
            m.size() as f64 / 1e6,
            if m.is_present() { "yes" } else { "no" },
            m.description
        );
    }
    for d in model::DESCRIPTIONS {
        outln!(
            "{:<22} {:>6.0} MB  {:<8} {} [--robot]",
            d.name,
            d.size as f64 / 1e6,
            if d.urdf_in(&d.path()).is_file() {
                "yes"
            } else {
                "no"
            },
            d.description
        );
    }
    outln!("\ncache: {}", model::cache_dir().display());
    Ok(ExitCode::SUCCESS)
}

pub fn verify(name: Option<&str>, stt: bool) -> Result<ExitCode> {
    if stt {
        return verify_stt(stt_spec(name)?);
    }
    let spec = spec(name)?;
    let path = spec.path();
    if !path.is_file() {
        anyhow::bail!(
            "{} is not in the cache ({}); run `betr model fetch`",
            spec.name,
            path.display()
        );
    }
    let digest = model::sha256_file(&path)?;
    if digest == spec.sha256 {
        outln!("{}: SHA-256 matches ({digest})", path.display());
        Ok(ExitCode::SUCCESS)
    } else {
        outln!(
            "{}: SHA-256 is {digest}, expected {}; delete it and run `betr model fetch`",
            path.display(),
            spec.sha256
        );
        Ok(ExitCode::from(1))
    }
}

fn verify_stt(spec: &DirModelSpec) -> Result<ExitCode> {
    if !spec.path().is_dir() {
        anyhow::bail!(
            "{} is not in the cache ({}); run `betr model fetch --stt --model {}`",
            spec.name,
            spec.path().display(),
            spec.name
        );
    }
    let mut ok = true;
    for check in spec.verify()? {
        match &check.found {
            Some(found) if check.matches() => {
                outln!("{}: SHA-256 matches ({found})", check.path.display());
            }
            Some(found) => {
                ok = false;
                outln!(
                    "{}: SHA-256 is {found}, expected {}",
                    check.path.display(),
                    check.expected
                );
            }
            None => {
                ok = false;
                outln!("{}: missing", check.path.display());
            }
        }
    }
    if ok {
        Ok(ExitCode::SUCCESS)
    } else {
        outln!(
            "run `betr model fetch --stt --model {}` to replace it",
            spec.name
        );
        Ok(ExitCode::from(1))
    }
}
