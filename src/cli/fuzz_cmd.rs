//! Hidden `betr fuzz TARGET N [--seed S]`: fuzz one reader (or `all`) with N inputs.
//!
//! Each target runs in a child process (this binary with `--worker`), so an input that
//! takes the process down (a stack overflow, an allocation the system refuses) is found
//! too: the child reports its progress, and when it dies the range since its last report
//! is run again with every input written to a file before it is checked; the input left
//! in that file is saved as the failure, and fuzzing goes on after it.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

use anyhow::{Context, Result, bail};

use betr::fuzz::{self, Corpus, Failure, Progress, Report, RunOptions, TARGETS};

/// Inputs run again, one by one, to find the one that took a child down.
const RERUN: u64 = 1025;
/// The address space a child may reserve, in KiB (4 GiB).
const CHILD_MEMORY_KB: u64 = 4 << 20;

#[derive(clap::Args)]
pub struct FuzzArgs {
    /// A target (goal, reply, tree, btcpp, scenario, policy, cassette, journal, wav,
    /// recording) or `all`.
    pub target: String,
    /// Inputs per target.
    #[arg(default_value_t = 10_000)]
    pub inputs: u64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The index of the first input (input i of a seed is the same on every run).
    #[arg(long, default_value_t = 0)]
    pub start: u64,
    /// Failing inputs are saved under DIR/TARGET/.
    #[arg(long, default_value = "target/fuzz", value_name = "DIR")]
    pub out: PathBuf,
    /// Check these files with the target instead of fuzzing (exit 1 if one fails).
    #[arg(long, num_args = 1.., value_name = "FILE")]
    pub replay: Vec<PathBuf>,
    /// Run in this process, without a child to survive crashes.
    #[arg(long)]
    pub in_process: bool,
    #[arg(long, hide = true)]
    pub worker: bool,
    #[arg(long, hide = true)]
    pub pending: Option<PathBuf>,
}

pub fn run(args: &FuzzArgs) -> Result<ExitCode> {
    let targets: Vec<&str> = if args.target == "all" {
        TARGETS.to_vec()
    } else if TARGETS.contains(&args.target.as_str()) {
        vec![args.target.as_str()]
    } else {
        bail!(
            "unknown fuzz target {:?} (known: {}, all)",
            args.target,
            TARGETS.join(", ")
        );
    };
    if !args.replay.is_empty() {
        return replay(&targets, &args.replay);
    }
    if args.worker {
        return worker(targets[0], args);
    }
    let mut failed = false;
    for target in targets {
        let started = Instant::now();
        let report = if args.in_process {
            in_process(target, args)?
        } else {
            supervise(target, args)?
        };
        failed |= report.failed > 0;
        print_report(&report, started.elapsed().as_secs_f64());
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

fn corpus() -> Result<Corpus> {
    let root = std::env::current_dir().context("the current directory")?;
    Corpus::load(&root).context("reading the seed corpus (run from the repository's root)")
}

fn options(args: &FuzzArgs, start: u64, inputs: u64, pending: Option<PathBuf>) -> RunOptions {
    RunOptions {
        seed: args.seed,
        start,
        inputs,
        save_dir: Some(args.out.clone()),
        pending,
    }
}

fn in_process(target: &str, args: &FuzzArgs) -> Result<Report> {
    let corpus = corpus()?;
    let t = fuzz::target(target, &corpus)?;
    let options = options(args, args.start, args.inputs, None);
    Ok(fuzz::run(t.as_ref(), &options, &mut |_| {})?)
}

/// The child's side: progress lines (`at I`, or `input I` before each input when every
/// input is written to `--pending`), each failure as it is found (`failure JSON`), then
/// the report (`report JSON`).
fn worker(target: &str, args: &FuzzArgs) -> Result<ExitCode> {
    let corpus = corpus()?;
    let t = fuzz::target(target, &corpus)?;
    let mut out = std::io::stdout().lock();
    let mut tell = |p: Progress| {
        let line = match p {
            Progress::At(i) => format!("at {i}"),
            Progress::Failed(f) => {
                format!("failure {}", serde_json::to_string(f).unwrap_or_default())
            }
        };
        let _ = writeln!(out, "{line}").and_then(|()| out.flush());
    };
    let options = options(args, args.start, args.inputs, args.pending.clone());
    let report = if args.pending.is_some() {
        let mut report: Option<Report> = None;
        for index in args.start..args.start + args.inputs {
            tell(Progress::At(index));
            let one = RunOptions {
                start: index,
                inputs: 1,
                ..options.clone()
            };
            let r = fuzz::run(t.as_ref(), &one, &mut tell)?;
            report = Some(add(report, r));
        }
        report.context("no inputs")?
    } else {
        fuzz::run(t.as_ref(), &options, &mut tell)?
    };
    outln!("report {}", serde_json::to_string(&report)?);
    Ok(ExitCode::SUCCESS)
}

/// What a child said before it ended.
struct ChildEnd {
    /// The last index it said it reached.
    last: Option<u64>,
    failures: Vec<Failure>,
    report: Option<Report>,
    status: String,
}

fn child(
    target: &str,
    args: &FuzzArgs,
    start: u64,
    inputs: u64,
    pending: Option<&Path>,
) -> Result<ChildEnd> {
    let exe = std::env::current_exe().context("finding the betr binary")?;
    // The child's address space is limited, so an input that makes it reserve memory
    // without bound fails at once instead of pushing the machine into swap.
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg(format!(
            "ulimit -v {CHILD_MEMORY_KB} 2>/dev/null; exec \"$0\" \"$@\""
        ))
        .arg(exe)
        .args(["fuzz", target, &inputs.to_string(), "--worker"])
        .args([
            "--seed",
            &args.seed.to_string(),
            "--start",
            &start.to_string(),
        ])
        .arg("--out")
        .arg(&args.out)
        .stdout(Stdio::piped());
    if let Some(p) = pending {
        cmd.arg("--pending").arg(p);
    }
    let mut process = cmd.spawn().context("starting a fuzzing child")?;
    let stdout = process.stdout.take().context("the child's output")?;
    let mut end = ChildEnd {
        last: None,
        failures: Vec::new(),
        report: None,
        status: String::new(),
    };
    let mut told = Instant::now();
    for line in BufReader::new(stdout).lines() {
        let line = line?;
        if let Some(i) = line.strip_prefix("at ") {
            end.last = i.parse().ok();
            if told.elapsed().as_secs() >= 60 {
                errln!("{target}: input {i} of {}", args.start + args.inputs);
                told = Instant::now();
            }
        } else if let Some(json) = line.strip_prefix("failure ") {
            end.failures.push(serde_json::from_str(json)?);
        } else if let Some(json) = line.strip_prefix("report ") {
            end.report = Some(serde_json::from_str(json)?);
        }
    }
    end.status = process.wait()?.to_string();
    Ok(end)
}

fn supervise(target: &str, args: &FuzzArgs) -> Result<Report> {
    let end_at = args.start + args.inputs;
    let mut start = args.start;
    let mut total: Option<Report> = None;
    let pending = args.out.join(target).join("pending.input");
    while start < end_at {
        let begun = Instant::now();
        let ended = child(target, args, start, end_at - start, None)?;
        if let Some(r) = ended.report {
            total = Some(add(total, r));
            break;
        }
        // The child died: what it did up to its last progress report counts, and the
        // input that took it down is found by running the rest again one by one.
        let from = ended.last.unwrap_or(start).max(start);
        let done = partial(target, args, start, from - start, begun, ended.failures);
        total = Some(add(total, done));
        let count = RERUN.min(end_at - from);
        let begun = Instant::now();
        let again = child(target, args, from, count, Some(&pending))?;
        if let Some(r) = again.report {
            errln!(
                "{target}: a child died ({}) after input {from}, but not again",
                ended.status
            );
            total = Some(add(total, r));
            start = from + count;
            continue;
        }
        let index = again.last.unwrap_or(from);
        let saved = args
            .out
            .join(target)
            .join(format!("{}-{index}-died.input", args.seed));
        std::fs::rename(&pending, &saved)
            .with_context(|| format!("keeping {}", pending.display()))?;
        let mut failures = again.failures;
        failures.push(Failure {
            index,
            key: "the process died".into(),
            message: format!("the process died: {}", again.status),
            input_len: std::fs::metadata(&saved).map_or(0, |m| m.len() as usize),
            saved: Some(saved),
        });
        let died = partial(target, args, from, index - from + 1, begun, failures);
        total = Some(add(total, died));
        start = index + 1;
    }
    total.context("no inputs were run")
}

/// The report of a child that died: `inputs` from `start`, timed by the clock.
fn partial(
    target: &str,
    args: &FuzzArgs,
    start: u64,
    inputs: u64,
    begun: Instant,
    failures: Vec<Failure>,
) -> Report {
    Report {
        target: target.into(),
        seed: args.seed,
        start,
        inputs,
        seconds: begun.elapsed().as_secs_f64(),
        slowest: (start, 0.0),
        failed: failures.len() as u64,
        failures,
    }
}

fn add(total: Option<Report>, r: Report) -> Report {
    match total {
        None => r,
        Some(t) => merge(t, r),
    }
}

fn merge(mut a: Report, b: Report) -> Report {
    a.inputs += b.inputs;
    a.seconds += b.seconds;
    if b.slowest.1 > a.slowest.1 {
        a.slowest = b.slowest;
    }
    a.failed += b.failed;
    a.failures.extend(b.failures);
    a
}

fn print_report(r: &Report, wall: f64) {
    let rate = r.inputs as f64 / r.seconds.max(1e-9);
    outln!(
        "{}: {} inputs (seed {}, from {}) in {:.1} s ({:.0}/s; {:.1} s with setup), slowest {:.4} s (input {}), {} failing",
        r.target,
        r.inputs,
        r.seed,
        r.start,
        r.seconds,
        rate,
        wall,
        r.slowest.1,
        r.slowest.0,
        r.failed
    );
    for f in &r.failures {
        let saved = f
            .saved
            .as_ref()
            .map_or_else(String::new, |p| format!(" saved as {}", p.display()));
        outln!(
            "  input {} ({} bytes){saved}: {}",
            f.index,
            f.input_len,
            f.message
        );
    }
}

/// Check saved inputs with each target; print what fails.
fn replay(targets: &[&str], files: &[PathBuf]) -> Result<ExitCode> {
    let corpus = corpus()?;
    let mut failed = false;
    for name in targets {
        let t = fuzz::target(name, &corpus)?;
        for file in files {
            let input =
                std::fs::read(file).with_context(|| format!("reading {}", file.display()))?;
            match fuzz::check_caught(t.as_ref(), &input) {
                Ok(()) => outln!("{name}: {}: ok", file.display()),
                Err(v) => {
                    failed = true;
                    outln!("{name}: {}: {v}", file.display());
                }
            }
        }
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}
