//! Reading a parameter value: a number in the parameter's unit (SI prefixes m, c, k are
//! converted), or one of its categories (the one named first, else the most similar).

use crate::domain::{Value, ValueParam, action::parse_value};

use super::{ReplyError, Substitution, extract, similarity};

pub(super) fn read_value(
    text: &str,
    param: &ValueParam,
    min_similarity: f64,
    substitutions: &mut Vec<Substitution>,
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
            let best = param
                .categories
                .iter()
                .map(|c| (c, similarity(word, c)))
                .max_by(|a, b| a.1.total_cmp(&b.1));
            match best {
                Some((c, s)) if s >= min_similarity => {
                    substitutions.push(Substitution {
                        written: word.to_string(),
                        used: c.clone(),
                        similarity: s,
                        in_text: text.to_string(),
                    });
                    Ok(Value::Category(c.clone()))
                }
                _ => Err(bad(format!(
                    "expected one of: {}",
                    param.categories.join(", ")
                ))),
            }
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
