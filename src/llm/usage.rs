//! Accounting: every call's tokens, latency and estimated price, kept for the command's
//! summary and appended to a JSONL log (default `$XDG_STATE_HOME/betr/usage.jsonl`, else
//! `~/.local/state/betr/usage.jsonl`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use serde::{Deserialize, Serialize};

use super::{ChatReply, ChatRequest, LanguageModel, LlmError, ReplySource};

/// US dollars per million tokens.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Price {
    pub prompt_per_mtok: f64,
    pub completion_per_mtok: f64,
}

/// Prices by model name; a name also prices the models it is a prefix of
/// (`gpt-4o` prices `gpt-4o-2024-08-06`), the longest match winning.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct PriceTable(pub BTreeMap<String, Price>);

impl PriceTable {
    pub fn price(&self, model: &str) -> Option<Price> {
        self.0
            .iter()
            .filter(|(name, _)| model.starts_with(name.as_str()))
            .max_by_key(|(name, _)| name.len())
            .map(|(_, p)| *p)
    }
}

/// One accounted call (a line of the usage log).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UsageRecord {
    pub unix_time: u64,
    /// The command or session step that made the call (`interpret`, `resolve`).
    pub purpose: String,
    pub model: String,
    /// `model`, `recorded` or `hand-written`: only `model` calls cost money.
    pub source: String,
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
    pub latency_ms: u64,
    /// Estimated price in USD; `None` when the table has no price for the model.
    pub price_usd: Option<f64>,
}

/// Totals over several calls.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct UsageTotals {
    pub calls: usize,
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
    pub latency_ms: u64,
    pub price_usd: f64,
    /// Calls whose price is unknown.
    pub unpriced: usize,
}

impl std::fmt::Display for UsageTotals {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} call(s), {} prompt + {} completion tokens, {:.2} s, ${:.4}",
            self.calls,
            self.prompt_tokens,
            self.completion_tokens,
            self.latency_ms as f64 / 1000.0,
            self.price_usd
        )?;
        if self.unpriced > 0 {
            write!(
                f,
                " (+{} call(s) with no price in the table)",
                self.unpriced
            )?;
        }
        Ok(())
    }
}

/// Seconds since the Unix epoch.
pub fn unix_now() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

/// The default log path.
pub fn default_log_path() -> Option<PathBuf> {
    let state = std::env::var_os("XDG_STATE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".local/state")))?;
    Some(state.join("betr").join("usage.jsonl"))
}

/// The calls of one program run, shared by every metered model.
#[derive(Debug, Clone, Default)]
pub struct Ledger {
    records: Arc<Mutex<Vec<UsageRecord>>>,
    log: Option<PathBuf>,
    /// The first error appending to the log gave, if one did.
    log_error: Arc<Mutex<Option<String>>>,
}

impl Ledger {
    /// A ledger that also appends to `log` (none: memory only).
    pub fn new(log: Option<PathBuf>) -> Self {
        Ledger {
            records: Arc::default(),
            log,
            log_error: Arc::default(),
        }
    }

    pub fn log_path(&self) -> Option<&Path> {
        self.log.as_deref()
    }

    /// Why a record could not be appended to the log (the first time one could not).
    pub fn log_error(&self) -> Option<String> {
        self.log_error.lock().ok().and_then(|e| e.clone())
    }

    pub fn records(&self) -> Vec<UsageRecord> {
        self.records.lock().map(|r| r.clone()).unwrap_or_default()
    }

    pub fn totals(&self) -> UsageTotals {
        totals(&self.records())
    }

    /// Keep a record and append it to the log. A log that cannot be written is reported
    /// (tracing) but does not fail the call that was already paid for.
    pub fn add(&self, record: UsageRecord) {
        if let Some(path) = &self.log
            && let Err(e) = append_line(path, &record)
        {
            tracing::warn!(path = %path.display(), error = %e, "cannot append to the usage log");
            if let Ok(mut first) = self.log_error.lock() {
                first.get_or_insert_with(|| e.to_string());
            }
            crate::store::note_unwritten(path, &e);
        }
        if let Ok(mut r) = self.records.lock() {
            r.push(record);
        }
    }
}

pub fn totals(records: &[UsageRecord]) -> UsageTotals {
    let mut t = UsageTotals::default();
    for r in records {
        t.calls += 1;
        t.prompt_tokens += r.prompt_tokens;
        t.completion_tokens += r.completion_tokens;
        t.latency_ms += r.latency_ms;
        match r.price_usd {
            Some(p) => t.price_usd += p,
            None => t.unpriced += 1,
        }
    }
    t
}

/// One record as one whole line (`store::append_line`).
fn append_line(path: &Path, record: &UsageRecord) -> std::io::Result<()> {
    let line = serde_json::to_string(record).map_err(std::io::Error::other)?;
    crate::store::append_line(path, &line)
}

/// Wraps a model and accounts each call in a ledger.
pub struct Metered<M> {
    inner: M,
    ledger: Ledger,
    prices: PriceTable,
    purpose: Mutex<String>,
}

impl<M: LanguageModel> Metered<M> {
    pub fn new(inner: M, ledger: Ledger, prices: PriceTable) -> Self {
        Metered {
            inner,
            ledger,
            prices,
            purpose: Mutex::new("chat".into()),
        }
    }

    /// Label the following calls (shown in the log).
    pub fn set_purpose(&self, purpose: &str) {
        if let Ok(mut p) = self.purpose.lock() {
            *p = purpose.to_string();
        }
    }

    pub fn ledger(&self) -> &Ledger {
        &self.ledger
    }

    /// The record a reply makes.
    pub fn record_for(&self, reply: &ChatReply) -> UsageRecord {
        let (source, price_usd) = billing(&self.prices, reply, self.inner.model());
        UsageRecord {
            unix_time: unix_now(),
            purpose: self.purpose.lock().map(|p| p.clone()).unwrap_or_default(),
            model: reply.model.clone(),
            source: source.into(),
            prompt_tokens: reply.usage.prompt_tokens,
            completion_tokens: reply.usage.completion_tokens,
            latency_ms: u64::try_from(reply.latency.as_millis()).unwrap_or(u64::MAX),
            price_usd,
        }
    }

    async fn call(&self, request: &ChatRequest) -> Result<ChatReply, LlmError> {
        let reply = self.inner.chat(request).await?;
        self.ledger.add(self.record_for(&reply));
        Ok(reply)
    }
}

super::forwarding_model!(impl<M> for Metered<M>);

/// Where a reply came from (`model`, `recorded`, `hand-written`) and what it cost: only a
/// model's live answer is billed, at the price of the model it names (else the model the
/// request was for); `None` when the price table does not know it.
pub fn billing(
    prices: &PriceTable,
    reply: &ChatReply,
    requested: &str,
) -> (&'static str, Option<f64>) {
    let (source, billed) = match reply.source {
        ReplySource::Model => ("model", true),
        ReplySource::Recorded => ("recorded", false),
        ReplySource::HandWritten { .. } => ("hand-written", false),
    };
    let price = if billed {
        prices
            .price(&reply.model)
            .or_else(|| prices.price(requested))
            .map(|p| {
                (reply.usage.prompt_tokens as f64 * p.prompt_per_mtok
                    + reply.usage.completion_tokens as f64 * p.completion_per_mtok)
                    / 1e6
            })
    } else {
        Some(0.0)
    };
    (source, price)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llm::{ChatFuture, TokenUsage};
    use std::time::Duration;

    #[test]
    fn longest_prefix_prices_and_totals_add_up() {
        let mut t = PriceTable::default();
        let p = |a, b| Price {
            prompt_per_mtok: a,
            completion_per_mtok: b,
        };
        t.0.insert("gpt-4o".into(), p(2.5, 10.0));
        t.0.insert("gpt-4o-mini".into(), p(0.15, 0.6));
        assert_eq!(t.price("gpt-4o-mini-2024").unwrap().prompt_per_mtok, 0.15);
        assert_eq!(t.price("gpt-4o-2024").unwrap().prompt_per_mtok, 2.5);
        assert!(t.price("llama3").is_none());

        struct Nop;
        impl LanguageModel for Nop {
            fn model(&self) -> &str {
                "gpt-4o"
            }
            fn chat<'a>(&'a self, _: &'a ChatRequest) -> ChatFuture<'a> {
                Box::pin(std::future::ready(Err(LlmError::Local("no model".into()))))
            }
        }
        let dir = std::env::temp_dir().join(format!("betr-usage-{}", std::process::id()));
        let log = dir.join("u.jsonl");
        let m = Metered::new(Nop, Ledger::new(Some(log.clone())), t);
        let reply = ChatReply {
            ranked: Vec::new(),
            text: String::new(),
            model: "gpt-4o".into(),
            usage: TokenUsage {
                prompt_tokens: 1_000_000,
                completion_tokens: 100_000,
            },
            latency: Duration::from_millis(1500),
            source: ReplySource::Model,
        };
        let r = m.record_for(&reply);
        assert!((r.price_usd.unwrap() - 3.5).abs() < 1e-9);
        m.ledger().add(r);
        let replayed = ChatReply {
            source: ReplySource::Recorded,
            ..reply
        };
        m.ledger().add(m.record_for(&replayed));
        let totals = m.ledger().totals();
        assert_eq!(totals.calls, 2);
        assert!((totals.price_usd - 3.5).abs() < 1e-9);
        assert_eq!(std::fs::read_to_string(&log).unwrap().lines().count(), 2);
        assert_eq!(m.ledger().log_error(), None);

        // A log that cannot be written (its directory is a file) is said, not claimed.
        let blocked = Ledger::new(Some(log.join("u.jsonl")));
        blocked.add(m.record_for(&replayed));
        assert!(blocked.log_error().is_some());
        assert_eq!(blocked.totals().calls, 1, "the call is still counted");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
