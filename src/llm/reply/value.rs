//! Reading a parameter value: a number in the parameter's unit (SI prefixes m, c, k are
//! converted), or one of its categories (the one named first; a word that names none is
//! an error offering the most similar, never replaced by it).

use crate::domain::{Value, ValueParam, action::parse_value};

use super::{ReplyError, did_you_mean, extract};
use crate::domain::names::nearest;

pub(super) fn read_value(
    text: &str,
    param: &ValueParam,
    min_similarity: f64,
) -> Result<Value, ReplyError> {
    let bad = |reason: String| ReplyError::BadValue {
        text: text.to_string(),
        reason,
    };
    match &param.unit {
        Some(unit) => {
            let start = text
                .find(|c: char| c.is_ascii_digit() || c == '.' || c == '-')
                .ok_or_else(|| bad(format!("expected a number in {unit}")))?;
            let number = &text[start..];
            let end = number
                .char_indices()
                .find(|(i, c)| !(c.is_ascii_digit() || *c == '.' || (*i == 0 && *c == '-')))
                .map_or(number.len(), |(i, _)| i);
            let after = number[end..].trim_start();
            let written_unit = after
                .split_whitespace()
                .next()
                .unwrap_or("")
                .trim_end_matches(['.', ',', ')']);
            let parsed = parse_value(&number[..end]).map_err(|e| bad(e.to_string()))?;
            let Value::Number { value, .. } = parsed else {
                return Err(bad(format!("expected a number in {unit}")));
            };
            let scale = unit_scale(written_unit, unit)
                .ok_or_else(|| bad(format!("the unit {written_unit:?} is not {unit}")))?;
            let value = value * scale;
            if !value.is_finite() || value < 0.0 {
                return Err(bad("expected a finite, non-negative number".into()));
            }
            Ok(Value::Number {
                value,
                unit: unit.clone(),
            })
        }
        None => {
            let lower = text.to_ascii_lowercase();
            // The category named first in the text.
            let named = param
                .categories
                .iter()
                .filter_map(|c| lower.find(&c.to_ascii_lowercase()).map(|at| (at, c)))
                .min_by_key(|(at, _)| *at);
            if let Some((_, c)) = named {
                return Ok(Value::Category(c.clone()));
            }
            let word = extract::strip_ticks(text.trim_matches('"'));
            let near = nearest(
                word,
                param.categories.iter().map(String::as_str),
                min_similarity,
            );
            Err(bad(format!(
                "{word:?} is none of: {}{}",
                param.categories.join(", "),
                did_you_mean(&near)
            )))
        }
    }
}

/// The factor from a written unit to `unit` (`""` means `unit`; `mm/s` → `m/s` is 0.001).
fn unit_scale(written: &str, unit: &str) -> Option<f64> {
    if written.is_empty() || written.eq_ignore_ascii_case(unit) {
        return Some(1.0);
    }
    let prefix = written.strip_suffix(unit)?;
    match prefix {
        "m" => Some(1e-3),
        "c" => Some(1e-2),
        "k" => Some(1e3),
        _ => None,
    }
}
