//! Running a target: make each input from the run's seed and its index, check it under
//! `catch_unwind`, count inputs and time, keep the failures and save their inputs.

use std::cell::{Cell, RefCell};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Once;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::mutate::Grammar;
use super::rng::Rng;
use super::{FuzzError, Target, Violation};

/// Failing inputs saved per distinct failure (panic place or broken rule), and in all.
const SAVED_PER_KIND: usize = 3;
const SAVED_AT_MOST: usize = 30;

/// How a run goes.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    pub seed: u64,
    /// The index of the first input.
    pub start: u64,
    pub inputs: u64,
    /// Failing inputs are saved under `DIR/TARGET/`.
    pub save_dir: Option<PathBuf>,
    /// Each input is written here before it is checked, so an input that takes the
    /// process down (stack overflow, out of memory) is left behind.
    pub pending: Option<PathBuf>,
}

/// One failing input.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    pub index: u64,
    pub key: String,
    pub message: String,
    pub input_len: usize,
    /// Where the input was saved, if it was.
    pub saved: Option<PathBuf>,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    pub target: String,
    pub seed: u64,
    pub start: u64,
    pub inputs: u64,
    pub seconds: f64,
    /// The slowest input (index, seconds).
    pub slowest: (u64, f64),
    /// Failing inputs (every one is counted; the first few of each kind are listed).
    pub failed: u64,
    pub failures: Vec<Failure>,
}

thread_local! {
    static CAPTURING: Cell<bool> = const { Cell::new(false) };
    static LAST_PANIC: RefCell<Option<(String, String)>> = const { RefCell::new(None) };
}

/// A panic hook that, on a thread checking an input, keeps the panic's place and message
/// instead of printing them; other threads get the hook that was there before.
fn install_hook() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CAPTURING.with(Cell::get) {
                previous(info);
                return;
            }
            let mut location = info
                .location()
                .map(|l| format!("{}:{}:{}", l.file(), l.line(), l.column()))
                .unwrap_or_else(|| "unknown place".into());
            // A panic inside the standard library (a slice index, `clamp` with NaN) is
            // told by the betr function that called it.
            if location.starts_with("/rustc/") {
                let trace = std::backtrace::Backtrace::force_capture().to_string();
                let caller = trace
                    .lines()
                    .map(str::trim)
                    .filter_map(|l| l.split_once(": ").map(|(_, f)| f))
                    .find(|f| f.starts_with("betr::") && !f.starts_with("betr::fuzz"));
                if let Some(caller) = caller {
                    location = format!("{location} in {caller}");
                }
            }
            let message = panic_message(info.payload());
            LAST_PANIC.with(|p| *p.borrow_mut() = Some((location, message)));
        }));
    });
}

/// Check `input` with `target`, a panic turned into a [`Violation::Panic`].
pub fn check_caught(target: &dyn Target, input: &[u8]) -> Result<(), Violation> {
    install_hook();
    CAPTURING.with(|c| c.set(true));
    let result = catch_unwind(AssertUnwindSafe(|| target.check(input)));
    CAPTURING.with(|c| c.set(false));
    match result {
        Ok(checked) => checked,
        Err(_) => {
            let (location, message) = LAST_PANIC
                .with(|p| p.borrow_mut().take())
                .unwrap_or_else(|| ("unknown place".into(), "no message".into()));
            Err(Violation::Panic { location, message })
        }
    }
}

/// Input `index` of the run seeded with `seed`: a seed or a generated input, then a few
/// mutations (sometimes none, so seeds are checked as they are).
pub fn make_input(target: &dyn Target, seed: u64, index: u64) -> Vec<u8> {
    let mut rng = Rng::for_input(seed, index);
    let material = target.material();
    let seeds = &material.seeds;
    let mut data = if seeds.is_empty() || rng.chance(20) {
        target.generate(&mut rng)
    } else {
        rng.pick(seeds).cloned().unwrap_or_default()
    };
    if rng.chance(5) {
        return data;
    }
    let grammar = Grammar {
        tokens: &material.tokens,
        brackets: &material.brackets,
        seeds,
        text: target.is_text(),
    };
    // Mostly one or two mutations, so that many inputs still read and what they read is
    // checked; sometimes many.
    let count = match rng.below(4) {
        0 | 1 => 1,
        2 => 2,
        _ => 1 + rng.small(12),
    };
    for _ in 0..count {
        grammar.mutate(&mut data, &mut rng);
    }
    data
}

/// What a run tells as it goes.
#[derive(Debug)]
pub enum Progress<'a> {
    /// Inputs up to this index are done (told every 1024 inputs).
    At(u64),
    /// An input failed (told for each one the report lists).
    Failed(&'a Failure),
}

/// Run `options.inputs` inputs of `target`, telling `progress` how it goes.
pub fn run(
    target: &dyn Target,
    options: &RunOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Report, FuzzError> {
    let started = Instant::now();
    let mut report = Report {
        target: target.name().into(),
        seed: options.seed,
        start: options.start,
        inputs: 0,
        seconds: 0.0,
        slowest: (options.start, 0.0),
        failed: 0,
        failures: Vec::new(),
    };
    let mut saved = 0;
    for index in options.start..options.start.saturating_add(options.inputs) {
        let input = make_input(target, options.seed, index);
        if let Some(pending) = &options.pending {
            write(pending, &input)?;
        }
        let checking = Instant::now();
        let result = check_caught(target, &input);
        let took = checking.elapsed();
        if took > Duration::from_secs_f64(report.slowest.1) {
            report.slowest = (index, took.as_secs_f64());
        }
        report.inputs += 1;
        if let Err(violation) = result {
            report.failed += 1;
            let key = violation.key().to_string();
            let of_kind = report.failures.iter().filter(|f| f.key == key).count();
            if of_kind < SAVED_PER_KIND {
                let path = match &options.save_dir {
                    Some(dir) if saved < SAVED_AT_MOST => {
                        let path = dir
                            .join(target.name())
                            .join(format!("{}-{index}.input", options.seed));
                        write(&path, &input)?;
                        saved += 1;
                        Some(path)
                    }
                    _ => None,
                };
                let failure = Failure {
                    index,
                    key,
                    message: violation.to_string(),
                    input_len: input.len(),
                    saved: path,
                };
                progress(Progress::Failed(&failure));
                report.failures.push(failure);
            }
        }
        if index % 1024 == 0 {
            progress(Progress::At(index));
        }
    }
    report.seconds = started.elapsed().as_secs_f64();
    Ok(report)
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), FuzzError> {
    let io = |source| FuzzError::Io {
        path: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    std::fs::write(path, bytes).map_err(io)
}

/// What a panic said: its message, or that it had none.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fuzz::Material;

    struct Picky;

    impl Target for Picky {
        fn name(&self) -> &'static str {
            "picky"
        }
        fn material(&self) -> &Material {
            static NONE: Material = Material {
                seeds: Vec::new(),
                tokens: Vec::new(),
                brackets: Vec::new(),
            };
            &NONE
        }
        fn generate(&self, rng: &mut Rng) -> Vec<u8> {
            vec![(rng.next_u64() % 4) as u8]
        }
        fn check(&self, input: &[u8]) -> Result<(), Violation> {
            match input.first() {
                Some(0) => panic!("zero"),
                Some(1) => Err(super::super::broken("no ones", "a one")),
                _ => Ok(()),
            }
        }
    }

    #[test]
    fn panics_and_broken_rules_are_failures_and_runs_repeat() {
        let options = RunOptions {
            seed: 3,
            inputs: 200,
            ..RunOptions::default()
        };
        let a = run(&Picky, &options, &mut |_| {}).unwrap();
        let b = run(&Picky, &options, &mut |_| {}).unwrap();
        assert_eq!(a.inputs, 200);
        assert!(a.failed > 0);
        assert_eq!(a.failed, b.failed);
        assert_eq!(a.failures, b.failures);
        assert!(a.failures.iter().any(|f| f.message.contains("panic at")
            && f.message.contains("zero")
            && f.key.contains("runner.rs")));
        assert!(a.failures.iter().any(|f| f.key == "no ones"));
        assert!(a.failures.len() <= 2 * SAVED_PER_KIND);
        assert_eq!(make_input(&Picky, 3, 17), make_input(&Picky, 3, 17));
    }
}
