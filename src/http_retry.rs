//! When to try an HTTP request again: the chat and the transcription clients retry a
//! 429 or a 5xx the same way (exponential backoff, a server's `Retry-After` winning, both
//! capped), and describe a failed connection by its innermost cause.

use std::time::Duration;

/// How often and how long to wait before trying a request again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RetryPolicy {
    /// Retries after the first attempt.
    pub max_retries: u32,
    pub initial_backoff: Duration,
    /// Longest wait between attempts, also for a server's `Retry-After`.
    pub max_backoff: Duration,
}

impl Default for RetryPolicy {
    fn default() -> Self {
        RetryPolicy {
            max_retries: 3,
            initial_backoff: Duration::from_millis(500),
            max_backoff: Duration::from_secs(20),
        }
    }
}

impl RetryPolicy {
    /// The wait before trying again after `attempt` (1-based) answered `status`, or `None`
    /// when the answer is final (not a 429 or 5xx, or no retries left). `retry_after` is
    /// the server's own wish, which wins over the backoff.
    pub fn delay(
        &self,
        status: u16,
        attempt: u32,
        retry_after: Option<Duration>,
    ) -> Option<Duration> {
        let retryable = status == 429 || (500..=599).contains(&status);
        if !retryable || attempt > self.max_retries {
            return None;
        }
        let backoff = self
            .initial_backoff
            .saturating_mul(2u32.saturating_pow(attempt.saturating_sub(1)));
        Some(retry_after.unwrap_or(backoff).min(self.max_backoff))
    }
}

impl RetryPolicy {
    /// Sleep before the next attempt when [`RetryPolicy::delay`] allows one (saying so in
    /// the log); false when the answer is final.
    pub async fn wait_before_retry(
        &self,
        status: u16,
        attempt: u32,
        retry_after: Option<Duration>,
    ) -> bool {
        let Some(delay) = self.delay(status, attempt, retry_after) else {
            return false;
        };
        tracing::warn!(
            status,
            attempt,
            delay_ms = delay.as_millis() as u64,
            "retrying"
        );
        tokio::time::sleep(delay).await;
        true
    }
}

/// `Retry-After: 2` / `Retry-After: 1.5`, or OpenAI's `retry-after-ms: 1500`.
pub fn retry_after(headers: &reqwest::header::HeaderMap) -> Option<Duration> {
    let get = |name: &str| headers.get(name)?.to_str().ok()?.trim().parse::<f64>().ok();
    let seconds = get("retry-after-ms")
        .map(|ms| ms / 1000.0)
        .or_else(|| get("retry-after"))?;
    (seconds.is_finite() && seconds >= 0.0).then(|| Duration::from_secs_f64(seconds.min(3600.0)))
}

/// The innermost cause of `error` ("Connection refused" rather than "error sending
/// request"): what a person can act on.
pub fn innermost_cause(error: &dyn std::error::Error) -> String {
    let mut detail = error.to_string();
    let mut source = error.source();
    while let Some(s) = source {
        detail = s.to_string();
        source = s.source();
    }
    detail
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backoff_doubles_retry_after_wins_and_both_are_capped() {
        let p = RetryPolicy {
            max_retries: 3,
            initial_backoff: Duration::from_millis(100),
            max_backoff: Duration::from_millis(300),
        };
        assert_eq!(p.delay(503, 1, None), Some(Duration::from_millis(100)));
        assert_eq!(p.delay(429, 2, None), Some(Duration::from_millis(200)));
        assert_eq!(p.delay(500, 3, None), Some(Duration::from_millis(300)));
        assert_eq!(p.delay(500, 4, None), None, "retries used up");
        assert_eq!(p.delay(404, 1, None), None, "not retryable");
        let wish = Some(Duration::from_millis(50));
        assert_eq!(p.delay(429, 1, wish), wish);
        assert_eq!(
            p.delay(429, 1, Some(Duration::from_secs(9))),
            Some(Duration::from_millis(300))
        );
    }

    #[test]
    fn retry_after_reads_seconds_and_milliseconds() {
        let mut h = reqwest::header::HeaderMap::new();
        assert_eq!(retry_after(&h), None);
        h.insert("retry-after", "1.5".parse().unwrap());
        assert_eq!(retry_after(&h), Some(Duration::from_millis(1500)));
        h.insert("retry-after-ms", "250".parse().unwrap());
        assert_eq!(retry_after(&h), Some(Duration::from_millis(250)));
        h.insert("retry-after-ms", "-1".parse().unwrap());
        h.remove("retry-after");
        assert_eq!(retry_after(&h), None);
    }
}
