//! `betr bench`: betr measured against the tools people use today, each pair back to back
//! in one run on one machine, with the ratio and the target, as a table and as JSON.
//!
//! The parts: the tick loop against py_trees on the same tree (`ticks`); planning and
//! repair at scale, scenario 1 end to end and towers of up to 10,000 cubes (`scale`); the
//! embedded model's prompt and generation speed against llama.cpp's own `llama-bench`
//! built from the same source with the same settings (`model`); the first answer of a
//! one-shot command against a warm one (`cold`); and seeking in a long recording through
//! the replay workbench's own seek (`replay`); the YuMi's forward kinematics against
//! Pinocchio and its collision-free paths against OMPL with PyBullet (`motion`, not in the
//! default set: it needs the robot's description in the cache); `betr monitor` following a
//! real BehaviorTree.CPP tree at 100 Hz (`monitor`, not in the default set). Nothing here is timed inside tests.

pub mod cell_motion;
pub mod cold;
pub mod model;
pub mod monitor;
pub mod motion;
pub mod mujoco;
pub mod pybullet;
pub mod replay;
pub mod scale;
pub mod ticks;
pub mod towers;

use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use serde::Serialize;

/// Why a benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("{what}: {detail}")]
    Anchor { what: String, detail: String },
    #[error("{0}")]
    Setup(String),
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error("cannot write the scenario text: {0}")]
    Format(#[from] std::fmt::Error),
    #[error(transparent)]
    Scenario(#[from] crate::scenario::ScenarioError),
    #[error(transparent)]
    Motion(#[from] crate::motion::MotionError),
    #[error(transparent)]
    Shape(#[from] pybullet::UnconvertedShape),
    #[error(transparent)]
    Prompt(#[from] crate::llm::prompt::PromptError),
    #[error(transparent)]
    Model(#[from] crate::llm::local::EngineError),
}

/// Run an anchor's command: its standard output, or an error naming `what` with the end
/// of its standard error (when that was captured).
pub fn run_anchor(what: &str, command: &mut Command) -> Result<String, BenchError> {
    let anchor = |detail: String| BenchError::Anchor {
        what: what.to_string(),
        detail,
    };
    let program = command.get_program().to_string_lossy().into_owned();
    let out = command
        .output()
        .map_err(|e| anchor(format!("cannot run {program}: {e}")))?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = err.lines().rev().take(5).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(anchor(format!(
            "{program} failed ({}){}",
            out.status,
            if tail.is_empty() {
                String::new()
            } else {
                format!(": {}", tail.join(" / "))
            }
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// A Python in the virtual environment `venv` (made the first time, with `packages`
/// installed by pip with `pip_flags`) on which the script `check` runs cleanly. The venv's
/// lock (`<venv>.lock`) is held while it is looked at and made: two benchmarks or two
/// tests of one run would otherwise create and install into the same venv at once and
/// find it half-made; the operating system releases the lock of a killed process.
pub fn anchor_venv(
    venv: &Path,
    packages: &[&str],
    pip_flags: &[&str],
    check: &str,
) -> Result<std::path::PathBuf, BenchError> {
    let python = venv.join("bin").join("python");
    let has = |python: &Path| {
        Command::new(python)
            .args(["-c", check])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    let what = format!("installing {} into {}", packages.join(" "), venv.display());
    if let Some(parent) = venv.parent() {
        std::fs::create_dir_all(parent)?;
    }
    let lock_path = venv.with_extension("lock");
    let lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(|e| BenchError::Anchor {
            what: what.clone(),
            detail: format!("cannot open the lock {}: {e}", lock_path.display()),
        })?;
    lock.lock().map_err(|e| BenchError::Anchor {
        what: what.clone(),
        detail: format!("cannot take the lock {}: {e}", lock_path.display()),
    })?;
    if python.is_file() && has(&python) {
        return Ok(python);
    }
    eprintln!("bench: {what} (once)");
    run_anchor(
        &what,
        Command::new("python3").arg("-m").arg("venv").arg(venv),
    )?;
    run_anchor(
        &what,
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet"])
            .args(pip_flags)
            .args(packages),
    )?;
    if !has(&python) {
        return Err(BenchError::Anchor {
            what,
            detail: format!("`{check}` fails after installing"),
        });
    }
    Ok(python)
}

/// Which way a measure is better.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Better {
    Higher,
    Lower,
}

/// What a row must reach.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "value")]
pub enum Target {
    /// betr's value over the anchor's (for a higher-is-better measure), at least this.
    RatioAtLeast(f64),
    /// betr's value, at most this (in the row's unit).
    AtMost(f64),
    /// betr's value, at least this (in the row's unit).
    AtLeast(f64),
}

/// One line of the table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    pub part: String,
    pub measure: String,
    pub unit: String,
    pub better: Better,
    pub betr: f64,
    /// The tool compared against, and its value, measured in the same run.
    pub anchor: Option<(String, f64)>,
    pub target: Option<Target>,
    /// How the values were obtained (sizes, threads, repeats).
    pub note: String,
}

impl Row {
    /// How many times better betr is than the anchor (above 1: betr is better).
    pub fn ratio(&self) -> Option<f64> {
        let (_, anchor) = self.anchor.as_ref()?;
        let r = match self.better {
            Better::Higher => self.betr / anchor,
            Better::Lower => anchor / self.betr,
        };
        r.is_finite().then_some(r)
    }

    /// Whether the row meets its target (`None`: it has none).
    pub fn met(&self) -> Option<bool> {
        Some(match self.target? {
            Target::RatioAtLeast(min) => self.ratio().is_some_and(|r| r >= min),
            Target::AtMost(max) => self.betr <= max,
            Target::AtLeast(min) => self.betr >= min,
        })
    }
}

/// The machine a report was measured on.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Machine {
    pub cores: usize,
    /// The 1-, 5- and 15-minute load averages when the run started and ended.
    pub load_before: [f64; 3],
    pub load_after: [f64; 3],
    pub cpu: String,
}

impl Machine {
    pub fn read() -> Machine {
        let load = load_average();
        Machine {
            cores: cores() as usize,
            // The end's load is read again when the run ends.
            load_before: load,
            load_after: load,
            cpu: std::fs::read_to_string("/proc/cpuinfo")
                .ok()
                .and_then(|t| {
                    t.lines()
                        .find(|l| l.starts_with("model name"))
                        .and_then(|l| l.split_once(':'))
                        .map(|(_, v)| v.trim().to_string())
                })
                .unwrap_or_default(),
        }
    }
}

/// The cores this process may use.
pub fn cores() -> u32 {
    std::thread::available_parallelism()
        .ok()
        .and_then(|n| u32::try_from(n.get()).ok())
        .unwrap_or(1)
}

/// The load averages (zero where the system does not say).
pub fn load_average() -> [f64; 3] {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut out = [0.0; 3];
    for (slot, field) in out.iter_mut().zip(text.split_whitespace()) {
        *slot = field.parse().unwrap_or(0.0);
    }
    out
}

/// Every row of one run, with the machine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    pub betr_version: String,
    pub machine: Machine,
    pub rows: Vec<Row>,
}

impl Report {
    pub fn new() -> Report {
        Report {
            betr_version: env!("CARGO_PKG_VERSION").to_string(),
            machine: Machine::read(),
            rows: Vec::new(),
        }
    }

    /// The table as Markdown, with the machine's load beside it.
    pub fn markdown(&self) -> String {
        let mut t = String::new();
        let m = &self.machine;
        let _ = writeln!(
            t,
            "{} cores ({}), load average {:.2} {:.2} {:.2} at the start, {:.2} {:.2} {:.2} at the end\n",
            m.cores,
            if m.cpu.is_empty() {
                "cpu unknown"
            } else {
                &m.cpu
            },
            m.load_before[0],
            m.load_before[1],
            m.load_before[2],
            m.load_after[0],
            m.load_after[1],
            m.load_after[2],
        );
        t.push_str(
            "| part | measure | betr | anchor | anchor value | ratio | target | met | how |\n",
        );
        t.push_str("|---|---|---:|---|---:|---:|---|:-:|---|\n");
        for r in &self.rows {
            let (anchor, value) = match &r.anchor {
                Some((name, v)) => (name.clone(), number(*v)),
                None => ("—".to_string(), "—".to_string()),
            };
            let ratio = r
                .ratio()
                .map_or("—".to_string(), |x| format!("{}×", number(x)));
            let target = match r.target {
                Some(Target::RatioAtLeast(x)) => format!("≥ {}×", number(x)),
                Some(Target::AtMost(x)) => format!("≤ {} {}", number(x), r.unit),
                Some(Target::AtLeast(x)) => format!("≥ {} {}", number(x), r.unit),
                None => "—".to_string(),
            };
            let met = match r.met() {
                Some(true) => "yes",
                Some(false) => "**no**",
                None => "—",
            };
            let _ = writeln!(
                t,
                "| {} | {} ({}) | {} | {anchor} | {value} | {ratio} | {target} | {met} | {} |",
                r.part,
                r.measure,
                r.unit,
                number(r.betr),
                r.note
            );
        }
        t
    }

    /// Write the report as JSON, whole or not at all.
    pub fn write_json(&self, path: &Path) -> Result<(), BenchError> {
        let json = serde_json::to_vec_pretty(self)
            .map_err(|e| BenchError::Setup(format!("cannot encode the report: {e}")))?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        crate::store::write_atomic(path, &json)?;
        Ok(())
    }
}

impl Default for Report {
    fn default() -> Self {
        Report::new()
    }
}

/// A number with three significant digits, in scientific form when large.
pub fn number(x: f64) -> String {
    let a = x.abs();
    if a >= 1e6 {
        format!("{x:.2e}")
    } else if a >= 100.0 {
        format!("{x:.0}")
    } else if a >= 10.0 {
        format!("{x:.1}")
    } else if a >= 0.1 {
        format!("{x:.2}")
    } else {
        format!("{x:.3}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(better: Better, betr: f64, anchor: f64, target: Target) -> Row {
        Row {
            part: "p".into(),
            measure: "m".into(),
            unit: "u".into(),
            better,
            betr,
            anchor: Some(("a".into(), anchor)),
            target: Some(target),
            note: String::new(),
        }
    }

    #[test]
    fn ratios_say_how_many_times_better_betr_is() {
        let fast = row(Better::Higher, 100.0, 2.0, Target::RatioAtLeast(50.0));
        assert_eq!(fast.ratio(), Some(50.0));
        assert_eq!(fast.met(), Some(true));
        let slow = row(Better::Higher, 0.85, 1.0, Target::RatioAtLeast(0.9));
        assert_eq!(slow.met(), Some(false));
        let quick = row(Better::Lower, 2.0, 8.0, Target::AtMost(2.0));
        assert_eq!(quick.ratio(), Some(4.0));
        assert_eq!(quick.met(), Some(true));
        let zero = row(Better::Higher, 1.0, 0.0, Target::RatioAtLeast(1.0));
        assert_eq!(zero.ratio(), None);
        assert_eq!(zero.met(), Some(false));
    }

    #[test]
    fn the_table_has_a_line_per_row_and_the_load() {
        let mut report = Report::new();
        report
            .rows
            .push(row(Better::Lower, 0.08, 2.3, Target::AtMost(0.25)));
        let md = report.markdown();
        assert!(md.contains("load average"), "{md}");
        assert!(
            md.contains("| p | m (u) | 0.080 | a | 2.30 | 28.7× | ≤ 0.25 u | yes |"),
            "{md}"
        );
    }
}
