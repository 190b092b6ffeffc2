//! What the world's refusals say about a parameter value, so that a value is never tried
//! twice and never against what the world already said.
//!
//! Each refusal is read for its side: a value too high ("more force than an egg can take",
//! "limit exceeded", "at most") or too low ("too little force", "too slow", "at least").
//! A refused value on a known side bounds every later value; when the refusal states the
//! limit itself ("6 N at most"), the bound is that limit. Values outside the bounds are
//! turned away before they are tried, the bounds are told to the model in words, and when
//! both sides are known a value midway between them can be tried. What the skill declares
//! the robot can do (its hardware range) bounds values from the start.

use crate::domain::{Value, ValueParam};

/// Which way a refused value missed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    TooHigh,
    TooLow,
}

/// Phrases that say a value was too high, and that it was too low.
const TOO_HIGH: [&str; 13] = [
    "at most",
    "too much",
    "too high",
    "too fast",
    "too strong",
    "too hard",
    "too large",
    "more than",
    "faster than",
    "higher than",
    "exceed",
    "maximum",
    "over the limit",
];
const TOO_LOW: [&str; 13] = [
    "at least",
    "too little",
    "too low",
    "too slow",
    "too weak",
    "too soft",
    "too small",
    "less than",
    "slower than",
    "lower than",
    "not enough",
    "insufficient",
    "minimum",
];

/// The side a refusal's words give, when they give one side only.
pub fn side(error: &str) -> Option<Side> {
    let text = error.to_lowercase();
    let high = TOO_HIGH.iter().any(|p| text.contains(p));
    let low = TOO_LOW.iter().any(|p| text.contains(p));
    match (high, low) {
        (true, false) => Some(Side::TooHigh),
        (false, true) => Some(Side::TooLow),
        _ => None,
    }
}

/// The limit a refusal states in `unit` on `side`: "(6 N at most)", "at least 1 m/s".
pub fn stated_limit(error: &str, unit: &str, side: Side) -> Option<f64> {
    let words: Vec<String> = error
        .split_whitespace()
        .map(|w| {
            w.trim_matches(|c: char| matches!(c, '(' | ')' | '[' | ']' | ',' | ';' | ':'))
                .trim_end_matches('.')
                .to_lowercase()
        })
        .collect();
    let bound = match side {
        Side::TooHigh => "most",
        Side::TooLow => "least",
    };
    let unit = unit.to_lowercase();
    // The number of a quantity that ends at word `end` (exclusive): "6 N" or "6N".
    let quantity_before = |end: usize| -> Option<f64> {
        let last = words.get(end.checked_sub(1)?)?;
        if let Some(number) = last.strip_suffix(unit.as_str())
            && let Ok(n) = number.parse()
        {
            return Some(n);
        }
        (*last == unit).then(|| words.get(end.checked_sub(2)?)?.parse().ok())?
    };
    let quantity_after = |start: usize| -> Option<f64> {
        let first = words.get(start)?;
        if let Some(number) = first.strip_suffix(unit.as_str())
            && let Ok(n) = number.parse()
        {
            return Some(n);
        }
        (words.get(start + 1)? == &unit)
            .then(|| first.parse().ok())
            .flatten()
    };
    (0..words.len().saturating_sub(1))
        .filter(|&i| words[i] == "at" && words[i + 1] == bound)
        .find_map(|i| quantity_before(i).or_else(|| quantity_after(i + 2)))
}

/// One side's bound: the refused value, the limit the refusal stated, or what the skill
/// declares the robot can do.
#[derive(Debug, Clone, PartialEq)]
struct Limit {
    value: f64,
    /// The limit itself is allowed (a stated "at most"), not only what lies beyond it.
    allowed: bool,
    /// Where the bound comes from, in words: the refused value and what the world said
    /// of it, or the skill's declaration.
    source: String,
}

impl Limit {
    /// Whether `v` lies beyond this limit on `side`.
    fn excludes(&self, v: f64, side: Side) -> bool {
        match side {
            Side::TooHigh => v > self.value || (v == self.value && !self.allowed),
            Side::TooLow => v < self.value || (v == self.value && !self.allowed),
        }
    }

    fn words(&self, side: Side, unit: &str) -> String {
        let v = Value::Number {
            value: self.value,
            unit: unit.to_string(),
        };
        match (side, self.allowed) {
            (Side::TooHigh, true) => format!("at most {v}"),
            (Side::TooHigh, false) => format!("below {v}"),
            (Side::TooLow, true) => format!("at least {v}"),
            (Side::TooLow, false) => format!("above {v}"),
        }
    }
}

/// Why a value is turned away before it is tried, in words the person and the model can
/// be told.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotAdmitted {
    /// The world refused this very value, saying `error`.
    #[error("{value} was refused before ({error})")]
    RefusedBefore { value: Value, error: String },
    /// The value lies beyond a bound: `bound` says which side in words, `origin` where
    /// the bound comes from.
    #[error("{value} is not {bound}: {origin}")]
    Beyond {
        value: Value,
        bound: String,
        origin: String,
    },
}

/// What the refusals of one failure's values say so far.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Bounds {
    high: Option<Limit>,
    low: Option<Limit>,
    /// Every refused value with what the world said.
    refused: Vec<(Value, String)>,
}

impl Bounds {
    /// The bounds before anything was refused: the range the skill declares the robot
    /// can do, if it declares one.
    pub fn declared(param: &ValueParam) -> Bounds {
        let limit = |value: f64| Limit {
            value,
            allowed: true,
            source: format!(
                "the robot's range for {} is declared by its skill",
                param.name
            ),
        };
        Bounds {
            high: param.max.map(limit),
            low: param.min.map(limit),
            refused: Vec::new(),
        }
    }

    /// Take in that the world refused `value` with `error`.
    pub fn learn(&mut self, value: &Value, error: &str) {
        self.refused.push((value.clone(), error.to_string()));
        let Value::Number { value: v, unit } = value else {
            return;
        };
        let Some(side) = side(error) else {
            return;
        };
        let stated = stated_limit(error, unit, side).filter(|l| match side {
            Side::TooHigh => l < v,
            Side::TooLow => l > v,
        });
        let limit = Limit {
            value: stated.unwrap_or(*v),
            allowed: stated.is_some(),
            source: format!("the world refused {value} ({error})"),
        };
        let slot = match side {
            Side::TooHigh => &mut self.high,
            Side::TooLow => &mut self.low,
        };
        let tighter = slot.as_ref().is_none_or(|old| {
            let inside = match side {
                Side::TooHigh => limit.value < old.value,
                Side::TooLow => limit.value > old.value,
            };
            inside || (limit.value == old.value && old.allowed && !limit.allowed)
        });
        if tighter {
            *slot = Some(limit);
        }
    }

    /// Ok when `value` is neither refused already nor beyond a bound; else why not, in
    /// words the person and the model can be told.
    pub fn admits(&self, value: &Value) -> Result<(), NotAdmitted> {
        if let Some((_, why)) = self.refused.iter().find(|(r, _)| same_value(r, value)) {
            return Err(NotAdmitted::RefusedBefore {
                value: value.clone(),
                error: why.clone(),
            });
        }
        let Value::Number { value: v, unit } = value else {
            return Ok(());
        };
        for (limit, side) in [(&self.high, Side::TooHigh), (&self.low, Side::TooLow)] {
            if let Some(l) = limit
                && l.excludes(*v, side)
            {
                return Err(NotAdmitted::Beyond {
                    value: value.clone(),
                    bound: l.words(side, unit),
                    origin: l.source.clone(),
                });
            }
        }
        Ok(())
    }

    /// A value midway between the two bounds, when both are known and leave room.
    pub fn midway(&self) -> Option<f64> {
        let (low, high) = (self.low.as_ref()?, self.high.as_ref()?);
        if low.value >= high.value {
            return None;
        }
        let exact = f64::midpoint(low.value, high.value);
        let rounded = round_to_two_digits(exact);
        let inside = |v: f64| !low.excludes(v, Side::TooLow) && !high.excludes(v, Side::TooHigh);
        [rounded, exact].into_iter().find(|&v| inside(v))
    }

    /// The bounds in words ("at most 6 N and above 0.5 N"), if there are any.
    pub fn describe(&self, unit: &str) -> Option<String> {
        let parts: Vec<String> = [(&self.high, Side::TooHigh), (&self.low, Side::TooLow)]
            .into_iter()
            .filter_map(|(l, side)| l.as_ref().map(|l| l.words(side, unit)))
            .collect();
        (!parts.is_empty()).then(|| parts.join(" and "))
    }

    /// The bounds in one sentence for the model, if there are any.
    pub fn summary(&self, unit: &str) -> Option<String> {
        self.describe(unit).map(|range| {
            format!(
                "What the world said so far leaves only values {range}: choose a value in that range, different from every value already tried."
            )
        })
    }
}

/// The same value: equal numbers in the same unit, or the same category in any case.
fn same_value(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number { value: x, unit: u }, Value::Number { value: y, unit: w }) => {
            x == y && u == w
        }
        (Value::Category(x), Value::Category(y)) => x.eq_ignore_ascii_case(y),
        _ => false,
    }
}

/// `v` to two significant digits (3.5, 0.45, 50), for a value a person can read.
fn round_to_two_digits(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn n(value: f64, unit: &str) -> Value {
        Value::Number {
            value,
            unit: unit.into(),
        }
    }

    const BROKE: &str = "grasp \"egg\" {force = 10 N}! failed: The egg broke: 10 N is more force than an egg can take (6 N at most)";
    const SLIPPED: &str = "The hammer slipped from the gripper: 5 N is too little force to hold it";

    #[test]
    fn a_refusal_is_read_for_its_side() {
        assert_eq!(side(BROKE), Some(Side::TooHigh));
        assert_eq!(side(SLIPPED), Some(Side::TooLow));
        assert_eq!(
            side("Speed limit exceeded: 3 m/s is more than the arm can move"),
            Some(Side::TooHigh)
        );
        assert_eq!(side("Too slow for an emergency"), Some(Side::TooLow));
        // Words of both sides, or of neither, say nothing.
        assert_eq!(side("No collision free path found"), None);
        assert_eq!(side("at least 1 N and at most 6 N"), None);
    }

    #[test]
    fn a_stated_limit_is_read_before_or_after_its_phrase() {
        assert_eq!(stated_limit(BROKE, "N", Side::TooHigh), Some(6.0));
        assert_eq!(stated_limit(BROKE, "N", Side::TooLow), None);
        assert_eq!(
            stated_limit("moved too slowly: at least 1.5 m/s.", "m/s", Side::TooLow),
            Some(1.5)
        );
        assert_eq!(
            stated_limit("(0.2m/s at most near a baby)", "m/s", Side::TooHigh),
            Some(0.2)
        );
        // A number in another unit is not the limit.
        assert_eq!(stated_limit("(6 kg at most)", "N", Side::TooHigh), None);
    }

    #[test]
    fn refusals_bound_later_values() {
        let mut b = Bounds::default();
        b.learn(&n(10.0, "N"), BROKE);
        // The stated limit, not the refused value, is the bound; it is itself allowed.
        assert!(b.admits(&n(6.0, "N")).is_ok());
        let why = b.admits(&n(15.0, "N")).unwrap_err().to_string();
        assert!(why.contains("not at most 6 N"), "{why}");
        assert!(why.contains("10 N"), "{why}");
        assert!(
            b.admits(&n(10.0, "N"))
                .unwrap_err()
                .to_string()
                .contains("refused before")
        );
        assert_eq!(b.midway(), None);

        b.learn(&n(1.0, "N"), "1 N is too little force to hold it");
        assert!(b.admits(&n(1.0, "N")).is_err());
        assert!(
            b.admits(&n(0.4, "N"))
                .unwrap_err()
                .to_string()
                .contains("above 1 N")
        );
        assert_eq!(b.describe("N").unwrap(), "at most 6 N and above 1 N");
        assert_eq!(b.midway(), Some(3.5));
        let summary = b.summary("N").unwrap();
        assert!(summary.contains("at most 6 N and above 1 N"), "{summary}");
    }

    #[test]
    fn the_declared_range_bounds_values_from_the_start() {
        let speed = ValueParam {
            name: "speed".into(),
            unit: Some("m/s".into()),
            categories: vec![],
            description: "movement speed".into(),
            min: None,
            max: Some(1.5),
        };
        let mut b = Bounds::declared(&speed);
        assert!(b.admits(&n(1.5, "m/s")).is_ok());
        let why = b.admits(&n(10.0, "m/s")).unwrap_err().to_string();
        assert!(why.contains("not at most 1.5 m/s"), "{why}");
        assert!(why.contains("declared by its skill"), "{why}");
        // A refusal below the declared limit tightens it; one above it does not widen it.
        b.learn(&n(1.0, "m/s"), "1 m/s is faster than is safe near a person");
        assert_eq!(b.describe("m/s").unwrap(), "below 1 m/s");
        b.learn(&n(0.1, "m/s"), "Too slow: 0.1 m/s keeps the person waiting");
        assert_eq!(b.midway(), Some(0.55));
    }

    #[test]
    fn a_looser_refusal_does_not_widen_a_bound() {
        let mut b = Bounds::default();
        b.learn(&n(5.0, "m/s"), "5 m/s is faster than is safe");
        b.learn(&n(50.0, "m/s"), "50 m/s is faster than is safe");
        assert!(b.admits(&n(6.0, "m/s")).is_err());
        assert_eq!(b.describe("m/s").unwrap(), "below 5 m/s");
    }

    #[test]
    fn a_refusal_without_a_side_only_rules_out_its_own_value() {
        let mut b = Bounds::default();
        b.learn(&n(3.0, "N"), "No collision free path found");
        assert!(b.admits(&n(3.0, "N")).is_err());
        assert!(b.admits(&n(30.0, "N")).is_ok());
        assert_eq!(b.summary("N"), None);
        b.learn(&Value::Category("spoon".into()), "the sand spilled");
        assert!(b.admits(&Value::Category("Spoon".into())).is_err());
        assert!(b.admits(&Value::Category("shovel".into())).is_ok());
    }

    #[test]
    fn midway_is_rounded_only_when_that_stays_inside() {
        assert_eq!(round_to_two_digits(1.1375), 1.1);
        assert_eq!(round_to_two_digits(45.0), 45.0);
        assert_eq!(round_to_two_digits(0.126), 0.13);
        let mut b = Bounds::default();
        b.learn(&n(1.0, "N"), "1 N is too little");
        b.learn(&n(1.02, "N"), "1.02 N is too much");
        let m = b.midway().unwrap();
        assert!(m > 1.0 && m < 1.02, "{m}");
    }
}
