//! Values from outside — flags, `betr.toml`, the environment — checked before anything
//! uses them: numbers against the range betr can work with, so a typo such as `1e20`
//! seconds or `4294967296` examples is a clear error rather than a panic, an abort or
//! hours of work (every range here is inclusive), and on/off switches read one way.

use std::fmt::Display;
use std::time::Duration;

/// The longest wait betr accepts for anything: an hour.
pub const MAX_SECONDS: f64 = 3600.0;

/// A number outside its range: which setting, what it was, what it may be.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{what} = {value} is out of range: expected {expected}")]
pub struct OutOfRange {
    pub what: String,
    pub value: String,
    pub expected: String,
}

/// Seconds to wait (a timeout): more than 0 and at most [`MAX_SECONDS`].
pub fn seconds(what: &str, value: f64) -> Result<Duration, OutOfRange> {
    if value.is_finite() && value > 0.0 && value <= MAX_SECONDS {
        Ok(Duration::from_secs_f64(value))
    } else {
        Err(OutOfRange {
            what: what.to_string(),
            value: value.to_string(),
            expected: format!("more than 0 and at most {MAX_SECONDS} seconds"),
        })
    }
}

/// `value` when `min <= value <= max` (a NaN is never in range).
pub fn within<T: PartialOrd + Display>(
    what: &str,
    value: T,
    min: T,
    max: T,
) -> Result<T, OutOfRange> {
    if min <= value && value <= max {
        Ok(value)
    } else {
        Err(OutOfRange {
            what: what.to_string(),
            value: value.to_string(),
            expected: format!("{min} to {max}"),
        })
    }
}

/// An on/off setting as an environment variable gives it: `1`, `true`, `yes` (any case)
/// are on, `0`, `false`, `no` off, anything else `None`.
pub fn switch_value(value: &str) -> Option<bool> {
    match value.trim().to_ascii_lowercase().as_str() {
        "1" | "true" | "yes" => Some(true),
        "0" | "false" | "no" => Some(false),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timeouts_are_positive_finite_and_at_most_an_hour() {
        assert_eq!(seconds("t", 1.5), Ok(Duration::from_millis(1500)));
        assert!(seconds("t", 3600.0).is_ok());
        for bad in [0.0, -1.0, 3600.5, 1e20, f64::INFINITY, f64::NAN] {
            let e = seconds("timeout_secs", bad).unwrap_err().to_string();
            assert!(e.starts_with("timeout_secs = "), "{e}");
            assert!(e.contains("at most 3600 seconds"), "{e}");
        }
    }

    #[test]
    fn counts_and_fractions_stay_in_their_range() {
        assert_eq!(within("k", 6usize, 0, 100), Ok(6));
        assert!(within("k", 4_294_967_296usize, 0, 100).is_err());
        assert!(within("t", f32::NAN, 0.0, 2.0).is_err());
        assert_eq!(
            within("n", 0u32, 1, 8).unwrap_err().to_string(),
            "n = 0 is out of range: expected 1 to 8"
        );
    }

    #[test]
    fn switches_read_on_off_or_neither() {
        for on in ["1", "true", " YES "] {
            assert_eq!(switch_value(on), Some(true), "{on}");
        }
        for off in ["0", "False", "no"] {
            assert_eq!(switch_value(off), Some(false), "{off}");
        }
        assert_eq!(switch_value("maybe"), None);
        assert_eq!(switch_value(""), None);
    }
}
