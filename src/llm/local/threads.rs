//! How many threads the embedded model gets when none is configured: the cores idle when
//! it loads. llama.cpp's threads wait for each other at every step, so a thread on a core
//! another process keeps busy slows all of them; measured on a 2-core machine, two
//! threads answer in about half the time of one when the machine is idle, and stall when
//! another process is busy, where one thread keeps its speed.

use std::time::Duration;

/// How long the CPU is watched to count idle cores.
const SAMPLE: Duration = Duration::from_millis(200);

/// Threads for the cores idle now (at least 1, at most the cores there are); 1 when the
/// load cannot be read (no `/proc/stat`).
pub fn idle_threads() -> u32 {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let Some(first) = cpu_times() else {
        return 1;
    };
    std::thread::sleep(SAMPLE);
    let Some(second) = cpu_times() else {
        return 1;
    };
    let threads = threads_for(cores, first, second);
    tracing::info!(
        threads,
        cores,
        "threads for the embedded model from the idle cores"
    );
    threads
}

/// Total and idle jiffies of all CPUs since boot, from the first line of `/proc/stat`.
fn cpu_times() -> Option<(u64, u64)> {
    let stat = std::fs::read_to_string("/proc/stat").ok()?;
    parse_cpu_line(stat.lines().next()?)
}

/// `cpu  user nice system idle iowait irq softirq …` → (total, idle + iowait).
fn parse_cpu_line(line: &str) -> Option<(u64, u64)> {
    let mut fields = line.split_whitespace();
    if fields.next()? != "cpu" {
        return None;
    }
    let values: Vec<u64> = fields.map(|f| f.parse().ok()).collect::<Option<_>>()?;
    if values.len() < 4 {
        return None;
    }
    let idle = values[3] + values.get(4).copied().unwrap_or(0);
    Some((values.iter().sum(), idle))
}

/// The idle share of the interval between two samples, in cores, rounded down with a
/// little slack (a core 80% idle counts), clamped to 1..=cores.
fn threads_for(cores: usize, first: (u64, u64), second: (u64, u64)) -> u32 {
    let total = second.0.saturating_sub(first.0);
    let idle = second.1.saturating_sub(first.1);
    if total == 0 {
        return 1;
    }
    let idle_cores = idle as f64 / total as f64 * cores as f64;
    let threads = (idle_cores + 0.2).floor() as usize;
    u32::try_from(threads.clamp(1, cores.max(1))).unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cpu_line_gives_total_and_idle() {
        let line = "cpu  100 5 50 800 20 0 5 0 0 0";
        assert_eq!(parse_cpu_line(line), Some((980, 820)));
        assert_eq!(parse_cpu_line("cpu0 1 2 3 4"), None);
        assert_eq!(parse_cpu_line("cpu  1 2"), None);
        assert_eq!(parse_cpu_line("cpu  1 x 3 4"), None);
    }

    #[test]
    fn idle_cores_become_threads() {
        // Both cores idle: 2 threads; one busy: 1; both busy: still 1; 85% idle counts.
        assert_eq!(threads_for(2, (0, 0), (200, 200)), 2);
        assert_eq!(threads_for(2, (0, 0), (200, 100)), 1);
        assert_eq!(threads_for(2, (0, 0), (200, 0)), 1);
        assert_eq!(threads_for(2, (0, 0), (200, 185)), 2);
        assert_eq!(threads_for(2, (5, 5), (5, 5)), 1);
        assert_eq!(threads_for(8, (0, 0), (800, 790)), 8);
    }
}
