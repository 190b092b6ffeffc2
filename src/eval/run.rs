//! What every experiment shares: a per-case view of the model (seed, accounting), the
//! journal of finished cases that makes runs resumable, a guard against resuming with
//! other settings, a progress callback and the concurrency limit.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use futures_util::StreamExt;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::llm::usage::PriceTable;
use crate::llm::{ChatReply, ChatRequest, LanguageModel, LlmError};

use super::EvalError;

/// Told how a long run advances; the CLI draws a progress bar with it.
pub trait Progress {
    /// `total` cases, of which `done` were already recorded by an earlier run.
    fn begin(&self, total: usize, done: usize);
    /// One more case finished (`label` names it).
    fn finished(&self, label: &str);
    fn end(&self);
}

/// No progress reporting.
pub struct Silent;

impl Progress for Silent {
    fn begin(&self, _: usize, _: usize) {}
    fn finished(&self, _: &str) {}
    fn end(&self) {}
}

/// How a run proceeds (shared by the three experiments).
pub struct RunConfig<'a> {
    /// Repetitions; run k (1-based) sends seed k.
    pub runs: usize,
    /// Cases in flight at once.
    pub concurrency: usize,
    /// Stop after this many newly finished cases (to test interruption and resumption).
    pub limit: Option<usize>,
    pub prices: PriceTable,
    pub progress: &'a dyn Progress,
    /// Starts the executor each cell scenario's session performs its actions in (none:
    /// betr's world performs them).
    pub executor: Option<&'a ExecutorFactory>,
}

/// Starts an executor for one session.
pub type ExecutorFactory =
    dyn Fn() -> Result<Box<dyn crate::executor::Executor>, crate::executor::ExecutorError> + Sync;

/// One call a case made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CallRecord {
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
    pub latency_ms: f64,
    /// Estimated price in USD (0 for replayed or hand-written replies; `None`: no price).
    pub price_usd: Option<f64>,
    /// `model`, `recorded` or `hand-written`.
    pub source: String,
}

/// The model as one case sees it: every request carries the run's seed, and every reply
/// is accounted to the case (so concurrent cases never mix their numbers).
pub struct Tap {
    inner: Arc<dyn LanguageModel>,
    seed: Option<u64>,
    prices: PriceTable,
    calls: Mutex<Vec<CallRecord>>,
}

impl Tap {
    /// Owns its model (an `Arc`), because the session engine it is handed to runs model
    /// calls as spawned tasks.
    pub fn new(inner: Arc<dyn LanguageModel>, seed: Option<u64>, prices: &PriceTable) -> Self {
        Tap {
            inner,
            seed,
            prices: prices.clone(),
            calls: Mutex::new(Vec::new()),
        }
    }

    pub fn calls(&self) -> Vec<CallRecord> {
        self.calls.lock().map(|c| c.clone()).unwrap_or_default()
    }

    fn record(&self, reply: &ChatReply) -> CallRecord {
        let (source, price_usd) =
            crate::llm::usage::billing(&self.prices, reply, self.inner.model());
        CallRecord {
            prompt_tokens: reply.usage.prompt_tokens,
            completion_tokens: reply.usage.completion_tokens,
            latency_ms: reply.latency.as_secs_f64() * 1000.0,
            price_usd,
            source: source.into(),
        }
    }

    async fn call(&self, request: &ChatRequest) -> Result<ChatReply, LlmError> {
        let mut request = request.clone();
        // Run k's seed, combined with a draw's own seed so that the sampled candidates of
        // one question still differ from each other.
        if let Some(run) = self.seed {
            request.seed = Some(match request.seed {
                Some(draw) => run.wrapping_mul(1000).wrapping_add(draw),
                None => run,
            });
        }
        let reply = self.inner.chat(&request).await?;
        let record = self.record(&reply);
        if let Ok(mut c) = self.calls.lock() {
            c.push(record);
        }
        Ok(reply)
    }
}

crate::llm::forwarding_model!(impl for Tap);

/// Totals over calls, with latency percentiles.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct UsageSummary {
    pub calls: usize,
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
    pub price_usd: f64,
    /// Calls with no price in the table.
    pub unpriced: usize,
    pub latency_median_ms: f64,
    pub latency_p95_ms: f64,
    /// Calls by where the reply came from (`model`, `recorded`, `hand-written`).
    pub sources: BTreeMap<String, usize>,
}

/// The lines under a per-scenario table: usage, what the columns mean (`definition`, one
/// line ending in a newline), a partial-run warning, and the usage notes.
pub fn table_footer(
    u: &UsageSummary,
    definition: &str,
    finished: usize,
    expected: usize,
) -> String {
    let mut out = format!(
        "\n- {} LLM call(s), {} prompt + {} completion tokens, ${:.4}; latency median {:.2} s, p95 {:.2} s.\n",
        u.calls,
        u.prompt_tokens,
        u.completion_tokens,
        u.price_usd,
        u.latency_median_ms / 1000.0,
        u.latency_p95_ms / 1000.0
    );
    out.push_str(definition);
    if finished < expected {
        out.push_str(&format!(
            "- Partial: {finished} of {expected} runs finished; run the same command again to finish.\n"
        ));
    }
    for n in u.notes() {
        out.push_str(&format!("- {n}\n"));
    }
    out
}

impl UsageSummary {
    pub fn of<'a>(calls: impl IntoIterator<Item = &'a CallRecord>) -> Self {
        let mut s = UsageSummary::default();
        let mut latencies = Vec::new();
        for c in calls {
            s.calls += 1;
            s.prompt_tokens += c.prompt_tokens;
            s.completion_tokens += c.completion_tokens;
            match c.price_usd {
                Some(p) => s.price_usd += p,
                None => s.unpriced += 1,
            }
            *s.sources.entry(c.source.clone()).or_default() += 1;
            latencies.push(c.latency_ms);
        }
        s.latency_median_ms = percentile(&latencies, 50.0);
        s.latency_p95_ms = percentile(&latencies, 95.0);
        s
    }

    /// Notes for a table's footer: who answered, prices unknown.
    pub fn notes(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(n) = self.sources.get("hand-written") {
            out.push(format!(
                "{n} of {} replies were hand-written fixtures, not a model's answers; their numbers test the plumbing only.",
                self.calls
            ));
        }
        if let Some(n) = self.sources.get("recorded") {
            out.push(format!(
                "{n} of {} replies were replayed from a cassette (cost 0 here).",
                self.calls
            ));
        }
        if self.unpriced > 0 {
            out.push(format!(
                "{} call(s) have no price in the price table; the cost leaves them out.",
                self.unpriced
            ));
        }
        out
    }
}

/// The `p`-th percentile (nearest rank) of `values`; 0 for none.
pub fn percentile(values: &[f64], p: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let rank = ((p / 100.0) * v.len() as f64).ceil() as usize;
    v[rank.clamp(1, v.len()) - 1]
}

/// Mean and sample standard deviation; `None` for no values.
pub fn mean_sd(values: &[f64]) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let sd = if values.len() > 1 {
        (values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((mean, sd))
}

/// `DIR/cases.jsonl`: one JSON line per finished case, appended and synced as each
/// finishes, so an interrupted run loses at most the cases in flight.
pub struct Journal {
    path: PathBuf,
    lock: Mutex<()>,
}

impl Journal {
    pub fn new(dir: &Path) -> Self {
        Journal {
            path: dir.join("cases.jsonl"),
            lock: Mutex::new(()),
        }
    }

    /// Every record written so far. A line that does not read (the tail of a write cut
    /// short) is skipped: that case runs again, on a line of its own.
    pub fn read<T: DeserializeOwned>(&self) -> Result<Vec<T>, EvalError> {
        let text = match std::fs::read_to_string(&self.path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => return Err(EvalError::io(&self.path, e)),
        };
        if !text.is_empty() && !text.ends_with('\n') {
            self.write_line("")?;
        }
        Ok(records(&text))
    }

    /// Append one record as a single write, then sync it to disk.
    pub fn append<T: Serialize>(&self, record: &T) -> Result<(), EvalError> {
        let line = serde_json::to_string(record)
            .map_err(|e| EvalError::io(&self.path, std::io::Error::other(e)))?;
        self.write_line(&line)
    }

    fn write_line(&self, line: &str) -> Result<(), EvalError> {
        let line = format!("{line}\n");
        let _guard = self.lock.lock();
        let write = || -> std::io::Result<()> {
            let mut f = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(&self.path)?;
            f.write_all(line.as_bytes())?;
            f.sync_data()
        };
        write().map_err(|e| EvalError::io(&self.path, e))
    }
}

/// The records of a journal's text: every line that reads as a `T`; the others (the tail
/// of a write cut short, blank lines) are left out.
pub fn records<T: DeserializeOwned>(text: &str) -> Vec<T> {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect()
}

/// `DIR/run.json`: the settings the recorded cases were made with. Resuming with other
/// settings would mix two experiments, so it is refused.
pub fn check_settings(
    dir: &Path,
    experiment: &str,
    settings: &BTreeMap<String, String>,
) -> Result<(), EvalError> {
    #[derive(Serialize, Deserialize, PartialEq)]
    struct Meta {
        experiment: String,
        settings: BTreeMap<String, String>,
    }
    let path = dir.join("run.json");
    let meta = Meta {
        experiment: experiment.into(),
        settings: settings.clone(),
    };
    if let Ok(text) = std::fs::read_to_string(&path) {
        let old: Meta = serde_json::from_str(&text)
            .map_err(|e| EvalError::io(&path, std::io::Error::other(e)))?;
        if old.experiment != experiment {
            return Err(EvalError::Mismatch {
                dir: dir.display().to_string(),
                what: "experiment".into(),
                old: old.experiment,
                new: experiment.into(),
            });
        }
        for (k, v) in settings {
            let was = old.settings.get(k).cloned().unwrap_or_default();
            if &was != v {
                return Err(EvalError::Mismatch {
                    dir: dir.display().to_string(),
                    what: k.clone(),
                    old: was,
                    new: v.clone(),
                });
            }
        }
        return Ok(());
    }
    let json = serde_json::to_string_pretty(&meta)
        .map_err(|e| EvalError::io(&path, std::io::Error::other(e)))?;
    crate::store::write_atomic(&path, json.as_bytes()).map_err(|e| EvalError::io(&path, e))
}

/// Run `jobs` with at most `cfg.concurrency` in flight, appending each finished record to
/// the journal and reporting progress. Stops at the first error (cases in flight are
/// dropped, not recorded) or after `cfg.limit` finished cases.
pub async fn drive<J, T, F, Fut>(
    jobs: Vec<J>,
    done: usize,
    cfg: &RunConfig<'_>,
    journal: &Journal,
    label: impl Fn(&T) -> String,
    work: F,
) -> Result<Vec<T>, EvalError>
where
    F: Fn(J) -> Fut,
    Fut: std::future::Future<Output = Result<T, EvalError>>,
    T: Serialize,
{
    let wanted = cfg.limit.map_or(jobs.len(), |l| l.min(jobs.len()));
    cfg.progress.begin(done + jobs.len(), done);
    let mut out = Vec::new();
    let mut stream = futures_util::stream::iter(jobs.into_iter().take(wanted))
        .map(work)
        .buffer_unordered(cfg.concurrency.max(1));
    while let Some(result) = stream.next().await {
        let record = match result {
            Ok(r) => r,
            Err(e) => {
                cfg.progress.end();
                return Err(e);
            }
        };
        journal.append(&record)?;
        cfg.progress.finished(&label(&record));
        out.push(record);
    }
    cfg.progress.end();
    Ok(out)
}

/// Milliseconds since `start`.
pub fn elapsed_ms(start: std::time::Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1000.0
}
