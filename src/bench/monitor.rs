//! `betr monitor` against a real BehaviorTree.CPP tree of ~500 nodes ticked at 100 Hz under
//! Groot2's publisher (scripts/btcpp_publisher.py --nodes, in behaviortreepy): how soon the
//! tree is on the screen after connecting, how long a status change takes from the
//! publisher's tick to a drawn screen, whether the monitor keeps up, and whether its
//! memory grows. The screen is the monitor's own, drawn into a test terminal after every
//! batch of changes as the terminal loop draws it.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime};

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use tokio::sync::mpsc;

use super::{BenchError, Better, Row, Target};
use crate::monitor::{Address, WatchEvent, WatchTiming, watch_only};
use crate::tui::monitor::{MonitorScreen, draw, gather};

/// What one run measured.
#[derive(Debug, Clone)]
pub struct MonitorRun {
    pub nodes: usize,
    /// From starting to watch to the first drawn screen with the tree.
    pub first_show: Duration,
    /// Every status change's time from the publisher's clock at the change to the screen
    /// drawn with it.
    pub latencies: Latencies,
    pub changes: u64,
    pub seconds: f64,
    /// The most changes read at once; the publisher keeps at most 1000 between two reads.
    pub largest_batch: usize,
    /// Resident memory after the first second of ticking and at the end, in KiB.
    pub rss_kib: (u64, u64),
    pub publisher_ticks: u64,
    pub publisher_late: u64,
}

/// BT.CPP's bindings in the venv the tests use (scripts/btcpp-venv.sh).
pub fn btcpp_python() -> Result<PathBuf, BenchError> {
    let out = super::run_anchor(
        "scripts/btcpp-venv.sh",
        Command::new("bash").arg("scripts/btcpp-venv.sh"),
    )?;
    Ok(PathBuf::from(out.trim()))
}

/// Watches a tree of `nodes` nodes ticked every 10 ms for `seconds`.
pub fn run(python: &Path, nodes: usize, seconds: f64) -> Result<MonitorRun, BenchError> {
    let port = free_port_pair()?;
    let mut publisher = Command::new(python)
        .arg("scripts/btcpp_publisher.py")
        .args([
            port.to_string(),
            "0".into(),
            "--nodes".into(),
            nodes.to_string(),
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()?;
    let setup = |what: &str| BenchError::Setup(format!("the publisher: {what}"));
    let mut input = publisher.stdin.take().ok_or_else(|| setup("no input"))?;
    let mut output = BufReader::new(publisher.stdout.take().ok_or_else(|| setup("no output"))?);
    let mut line = String::new();
    output.read_line(&mut line)?;
    if line.trim() != format!("ready {port}") {
        let _ = publisher.kill();
        return Err(setup(&format!("it said {line:?} instead of ready")));
    }
    // As the screen runs: the watch on a worker of its own.
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    let watched = runtime.block_on(follow(port, seconds, &mut input));
    drop(input);
    line.clear();
    output.read_line(&mut line)?;
    let _ = publisher.wait();
    let mut run = watched?;
    let said: serde_json::Value = serde_json::from_str(line.trim())
        .map_err(|e| setup(&format!("{e} in its last line {line:?}")))?;
    run.publisher_ticks = said["ticks"].as_u64().unwrap_or(0);
    run.publisher_late = said["late"].as_u64().unwrap_or(0);
    Ok(run)
}

/// The watch and the screen, in this process: connect, draw, start the ticks, follow.
async fn follow(port: u16, seconds: f64, go: &mut impl Write) -> Result<MonitorRun, BenchError> {
    let address = Address::parse(&format!("127.0.0.1:{port}"))
        .map_err(|e| BenchError::Setup(e.to_string()))?;
    let (events, mut received) = mpsc::channel(256);
    let began = Instant::now();
    let watcher = tokio::spawn(watch_only(address.clone(), WatchTiming::default(), events));
    let mut screen = MonitorScreen::new(address, false);
    // A test terminal cannot fail (its error type is `Infallible`).
    let Ok(mut terminal) = Terminal::new(TestBackend::new(160, 50));
    let mut run = MonitorRun {
        nodes: 0,
        first_show: Duration::ZERO,
        latencies: Latencies::new(),
        changes: 0,
        seconds,
        largest_batch: 0,
        rss_kib: (0, 0),
        publisher_ticks: 0,
        publisher_late: 0,
    };
    let mut frame = FrameTally::default();
    let mut ticking_since = None;
    let mut last_draw = tokio::time::Instant::now();
    let deadline = tokio::time::Instant::now() + Duration::from_secs_f64(seconds + 30.0);
    loop {
        let Ok(Some(first)) = tokio::time::timeout_at(deadline, received.recv()).await else {
            watcher.abort();
            return Err(BenchError::Setup(
                "the watch ended before the run did".into(),
            ));
        };
        // The screen's own frame: the events of one frame gathered, then one drawing.
        gather(&mut screen, first, &mut received, last_draw, |event| {
            frame.observe(&mut run, event);
        })
        .await;
        if let Some(reason) = frame.failed.take().or_else(|| {
            frame
                .started
                .is_none()
                .then(|| "the publisher did not say its clock".to_string())
        }) {
            watcher.abort();
            return Err(BenchError::Setup(reason));
        }
        let Ok(_) = terminal.draw(|f| draw(f, &mut screen));
        last_draw = tokio::time::Instant::now();
        let drawn = SystemTime::now();
        for t in frame.times.drain(..) {
            run.latencies
                .add(drawn.duration_since(t).unwrap_or(Duration::ZERO));
        }
        match ticking_since {
            None => {
                run.first_show = began.elapsed();
                go.write_all(b"go\n")?;
                go.flush()?;
                ticking_since = Some(Instant::now());
            }
            Some(since) => {
                let elapsed = since.elapsed().as_secs_f64();
                if run.rss_kib.0 == 0 && elapsed >= 1.0 {
                    run.rss_kib.0 = resident_kib();
                }
                if elapsed >= seconds {
                    break;
                }
            }
        }
    }
    run.rss_kib.1 = resident_kib();
    watcher.abort();
    Ok(run)
}

/// What the benchmark takes from the watch's events, frame by frame.
#[derive(Default)]
struct FrameTally {
    /// The publisher's clock when it began keeping changes.
    started: Option<SystemTime>,
    /// The nodes the tree has.
    uids: std::collections::HashSet<u16>,
    /// When each change of this frame was made, by the publisher's clock.
    times: Vec<SystemTime>,
    failed: Option<String>,
}

impl FrameTally {
    fn observe(&mut self, run: &mut MonitorRun, event: &WatchEvent) {
        match event {
            WatchEvent::Connected {
                tree, started: at, ..
            } => {
                run.nodes = tree.nodes.len();
                self.uids = tree.nodes.iter().map(|n| n.uid).collect();
                if self.started.is_some() {
                    self.failed
                        .get_or_insert("the publisher was connected twice".to_string());
                }
                self.started = *at;
            }
            WatchEvent::Changes(changes) => {
                run.largest_batch = run.largest_batch.max(changes.len());
                run.changes += changes.len() as u64;
                if let Some(at) = self.started {
                    // Only the changes of nodes the tree has reach the screen (BT.CPP 4.8's
                    // publisher can send an all-zero entry when a change races its read).
                    self.times.extend(
                        changes
                            .iter()
                            .filter(|c| self.uids.contains(&c.uid))
                            .map(|c| at + Duration::from_micros(c.micros)),
                    );
                }
            }
            WatchEvent::Lost(reason) | WatchEvent::Waiting(reason) => {
                self.failed.get_or_insert(reason.clone());
            }
            WatchEvent::Restarted
            | WatchEvent::Stopped(_)
            | WatchEvent::Refused(_)
            | WatchEvent::Blackboards(_) => {}
        }
    }
}

/// This process's resident memory in KiB (0 where /proc cannot tell).
fn resident_kib() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |pages| pages * 4)
}

/// A port free on every interface whose next port is free too (Groot2's publisher binds
/// both).
pub fn free_port_pair() -> Result<u16, BenchError> {
    for _ in 0..50 {
        let first = std::net::TcpListener::bind("0.0.0.0:0")?;
        let port = first.local_addr()?.port();
        if port < u16::MAX && std::net::TcpListener::bind(("0.0.0.0", port + 1)).is_ok() {
            return Ok(port);
        }
    }
    Err(BenchError::Setup("no two free ports in a row".into()))
}

/// Latencies counted in 0.1 ms steps up to 10 s, so measuring a million changes takes
/// no memory of its own while the monitor's is measured.
#[derive(Debug, Clone)]
pub struct Latencies {
    counts: Vec<u64>,
    total: u64,
    largest: Duration,
}

const STEP_MICROS: u128 = 100;
const STEPS: usize = 100_000;

impl Latencies {
    fn new() -> Latencies {
        Latencies {
            counts: vec![0; STEPS],
            total: 0,
            largest: Duration::ZERO,
        }
    }

    fn add(&mut self, latency: Duration) {
        let step = usize::try_from(latency.as_micros() / STEP_MICROS).unwrap_or(STEPS);
        self.counts[step.min(STEPS - 1)] += 1;
        self.total += 1;
        self.largest = self.largest.max(latency);
    }

    /// The latency below which a share `p` of the changes came, in milliseconds (the
    /// upper edge of its 0.1 ms step).
    pub fn percentile_ms(&self, p: f64) -> f64 {
        if self.total == 0 {
            return f64::NAN;
        }
        let wanted = ((self.total as f64) * p).ceil().max(1.0) as u64;
        let mut seen = 0;
        for (step, count) in self.counts.iter().enumerate() {
            seen += count;
            if seen >= wanted {
                return (step + 1) as f64 * STEP_MICROS as f64 / 1000.0;
            }
        }
        self.largest.as_secs_f64() * 1000.0
    }
}

/// The table's rows.
pub fn rows(run: &MonitorRun) -> Vec<Row> {
    let row = |measure: &str, unit: &str, betr: f64, target: Option<Target>, note: String| Row {
        part: "monitor".into(),
        measure: measure.into(),
        unit: unit.into(),
        better: Better::Lower,
        betr,
        anchor: None,
        target,
        note,
    };
    let setting = format!(
        "a {}-node BT.CPP tree (behaviortreepy) ticked every 10 ms for {} s: {} ticks, {} late",
        run.nodes, run.seconds, run.publisher_ticks, run.publisher_late
    );
    vec![
        row(
            "connect to the tree on the screen",
            "ms",
            run.first_show.as_secs_f64() * 1000.0,
            Some(Target::AtMost(1000.0)),
            format!("{setting}; reading the tree, starting the recording, one drawing"),
        ),
        row(
            "status change to the screen, 99th percentile",
            "ms",
            run.latencies.percentile_ms(0.99),
            Some(Target::AtMost(50.0)),
            format!(
                "{} changes ({:.0}/s); median {:.1} ms, largest {:.1} ms; from the publisher's clock at the change to the drawn screen",
                run.changes,
                run.changes as f64 / run.seconds,
                run.latencies.percentile_ms(0.5),
                run.latencies.largest.as_secs_f64() * 1000.0
            ),
        ),
        row(
            "most changes read at once",
            "changes",
            run.largest_batch as f64,
            Some(Target::AtMost(999.0)),
            "the publisher keeps at most 1000 between two reads: below that, none was lost".into(),
        ),
        row(
            "memory growth while watching",
            "KiB",
            run.rss_kib.1.saturating_sub(run.rss_kib.0) as f64,
            Some(Target::AtMost(4096.0)),
            format!(
                "resident memory after the first second {} KiB, at the end {} KiB",
                run.rss_kib.0, run.rss_kib.1
            ),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latencies_give_percentiles_to_a_tenth_of_a_millisecond() {
        let mut l = Latencies::new();
        for ms in 1..=100u64 {
            l.add(Duration::from_micros(ms * 1000 - 50));
        }
        l.add(Duration::from_secs(60));
        assert_eq!(l.percentile_ms(0.5), 51.0);
        assert_eq!(l.percentile_ms(0.99), 100.0);
        assert_eq!(l.percentile_ms(1.0), 10_000.0);
        assert_eq!(l.largest, Duration::from_secs(60));
    }
}
