//! Reading replies: the goal of a goal-interpretation reply, the conditions of a
//! failure-resolution reply, the value of a parameter-value reply, and the reasoning of
//! each. Text and JSON (structured output) replies are both accepted. Every atom is
//! validated against the scenario's vocabulary, so nothing invalid leaves this module.
//! No input makes these functions panic.

pub mod extract;
pub mod validate;

use serde_json::Value as Json;

use crate::domain::{Condition, ValueParam, Vocabulary};
use crate::domain::{Value, action::parse_value};
use crate::goal::Formula;

pub use validate::similarity;

/// The default lower bound on the similarity of a replaced object name.
pub const MIN_SIMILARITY: f64 = 0.6;

/// An object name the reply used that is not in the scene, and the listed one used instead.
#[derive(Debug, Clone, PartialEq)]
pub struct Substitution {
    pub written: String,
    pub used: String,
    pub similarity: f64,
    /// The condition (or value) it appeared in, as written.
    pub in_text: String,
}

impl std::fmt::Display for Substitution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:?} is not in the scene; used {:?} instead (similarity {:.2}, in {})",
            self.written, self.used, self.similarity, self.in_text
        )
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReplyError {
    #[error("the reply has no `{label}:` answer: {excerpt:?}")]
    MissingAnswer {
        label: &'static str,
        excerpt: String,
    },
    #[error("cannot read {text:?}: {reason}")]
    Unreadable { text: String, reason: String },
    #[error("{text:?} does not fit the scene: {reason}")]
    Invalid { text: String, reason: String },
    #[error("unknown object {object:?} in {text}{}", closest_text(closest))]
    UnknownObject {
        text: String,
        object: String,
        closest: Option<(String, f64)>,
    },
    #[error("the reply proposes no condition")]
    NoConditions,
    #[error("parameter value {text:?}: {reason}")]
    BadValue { text: String, reason: String },
}

fn closest_text(closest: &Option<(String, f64)>) -> String {
    match closest {
        Some((name, s)) => {
            format!(" (the closest listed object, {name:?}, is too different: similarity {s:.2})")
        }
        None => " (no listed object fits that place)".into(),
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct GoalAnswer {
    pub goal: Formula,
    pub reasoning: Option<String>,
    pub substitutions: Vec<Substitution>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ConditionsAnswer {
    pub conditions: Vec<Condition>,
    pub reasoning: Option<String>,
    pub substitutions: Vec<Substitution>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ValueAnswer {
    pub value: Value,
    pub reasoning: Option<String>,
    pub substitutions: Vec<Substitution>,
}

const GOAL: &[&str] = &["goal", "final goal"];
const CONDITIONS: &[&str] = &["conditions", "condition", "preconditions", "precondition"];
const VALUE: &[&str] = &["parameter value", "value"];
const REASONING: &[&str] = &["reasoning"];

/// Read and validate a goal-interpretation reply.
pub fn goal(
    text: &str,
    vocabulary: &Vocabulary,
    min_similarity: f64,
) -> Result<GoalAnswer, ReplyError> {
    let mut substitutions = Vec::new();
    if let Some(obj) = json_object(text) {
        let reasoning = json_reasoning(&obj);
        let formula = match obj.get("goal") {
            Some(Json::String(s)) => read_formula(s)?,
            Some(Json::Array(disjuncts)) => {
                let mut ors = Vec::new();
                for d in disjuncts {
                    let lits = d.as_array().map(Vec::as_slice).unwrap_or_default();
                    let conj = lits
                        .iter()
                        .map(json_literal)
                        .collect::<Result<Vec<_>, _>>()?;
                    ors.push(Formula::from_literals(&conj));
                }
                Formula::or(ors)
            }
            _ => return Err(missing("goal", text)),
        };
        let goal = validate::formula(vocabulary, formula, min_similarity, &mut substitutions)?;
        return Ok(GoalAnswer {
            goal,
            reasoning,
            substitutions,
        });
    }
    let lines = extract::lines(text);
    let candidates = answers(&lines, GOAL);
    let mut first_error = None;
    for (i, answer) in candidates.iter().rev() {
        match read_formula(answer) {
            Ok(f) => {
                let goal = validate::formula(vocabulary, f, min_similarity, &mut substitutions)?;
                return Ok(GoalAnswer {
                    goal,
                    reasoning: reasoning(&lines, *i),
                    substitutions,
                });
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    // A bare formula with no label.
    if candidates.is_empty()
        && let [only] = lines
            .iter()
            .filter(|l| !l.trim().is_empty())
            .collect::<Vec<_>>()
            .as_slice()
        && let Ok(f) = Formula::parse(extract::strip_item(only))
    {
        let goal = validate::formula(vocabulary, f, min_similarity, &mut substitutions)?;
        return Ok(GoalAnswer {
            goal,
            reasoning: None,
            substitutions,
        });
    }
    Err(first_error.unwrap_or_else(|| missing("Goal", text)))
}

/// Read and validate a failure-resolution reply.
pub fn conditions(
    text: &str,
    vocabulary: &Vocabulary,
    min_similarity: f64,
) -> Result<ConditionsAnswer, ReplyError> {
    let mut substitutions = Vec::new();
    let (raw, reasoning) = match json_object(text) {
        Some(obj) => {
            let items = match obj.get("conditions") {
                Some(Json::Array(items)) => items
                    .iter()
                    .map(json_literal)
                    .collect::<Result<Vec<_>, _>>()?,
                Some(Json::String(s)) => read_condition_items(std::slice::from_ref(s))?,
                _ => return Err(missing("conditions", text)),
            };
            (items, json_reasoning(&obj))
        }
        None => {
            let lines = extract::lines(text);
            let labelled = extract::labelled(&lines, CONDITIONS);
            match labelled.last() {
                Some((i, rest)) => {
                    let mut block = vec![rest.clone()];
                    block.extend(
                        lines[i + 1..]
                            .iter()
                            .take_while(|l| extract::label_end(l, REASONING).is_none())
                            .cloned(),
                    );
                    (read_condition_items(&block)?, reasoning(&lines, *i))
                }
                None => {
                    // No label: the lines that read wholly as conditions.
                    let found: Vec<String> = lines
                        .iter()
                        .filter(|l| {
                            let parts = extract::split_conditions(extract::strip_item(l));
                            !parts.is_empty() && parts.iter().all(|p| Condition::parse(p).is_ok())
                        })
                        .cloned()
                        .collect();
                    if found.is_empty() {
                        return Err(missing("Conditions", text));
                    }
                    (read_condition_items(&found)?, None)
                }
            }
        }
    };
    if raw.is_empty() {
        return Err(ReplyError::NoConditions);
    }
    let mut conditions: Vec<Condition> = Vec::new();
    for c in raw {
        let c = validate::condition(vocabulary, c, min_similarity, &mut substitutions)?;
        if !conditions.contains(&c) {
            conditions.push(c);
        }
    }
    Ok(ConditionsAnswer {
        conditions,
        reasoning,
        substitutions,
    })
}

/// Read and validate a parameter-value reply for `param`.
pub fn value(
    text: &str,
    param: &ValueParam,
    min_similarity: f64,
) -> Result<ValueAnswer, ReplyError> {
    let (raw, reasoning) = match json_object(text) {
        Some(obj) => {
            let raw = match (obj.get("value"), obj.get("unit").and_then(Json::as_str)) {
                (Some(Json::Number(n)), unit) => format!("{n} {}", unit.unwrap_or_default()),
                (Some(Json::String(s)), _) => s.clone(),
                _ => return Err(missing("value", text)),
            };
            (raw, json_reasoning(&obj))
        }
        None => {
            let lines = extract::lines(text);
            let Some((i, rest)) = answers(&lines, VALUE).pop() else {
                return Err(missing("Parameter value", text));
            };
            (rest, reasoning(&lines, i))
        }
    };
    let mut substitutions = Vec::new();
    let value = read_value(
        extract::strip_ticks(&raw),
        param,
        min_similarity,
        &mut substitutions,
    )?;
    Ok(ValueAnswer {
        value,
        reasoning,
        substitutions,
    })
}

fn missing(label: &'static str, text: &str) -> ReplyError {
    let excerpt: String = text.trim().chars().take(160).collect();
    ReplyError::MissingAnswer { label, excerpt }
}

/// Labelled answers; a label alone on its line takes the next non-empty line.
fn answers(lines: &[String], labels: &[&str]) -> Vec<(usize, String)> {
    extract::labelled(lines, labels)
        .into_iter()
        .filter_map(|(i, rest)| {
            if rest.is_empty() {
                lines[i + 1..]
                    .iter()
                    .find(|l| !l.trim().is_empty())
                    .map(|l| (i, extract::strip_item(l).to_string()))
            } else {
                Some((i, rest))
            }
        })
        .collect()
}

/// A formula, tolerating prose after it (`On_A (because ...)` reads as `On_A`).
fn read_formula(text: &str) -> Result<Formula, ReplyError> {
    let t = extract::strip_ticks(text);
    match Formula::parse(t) {
        Ok(f) => Ok(f),
        Err(e) => t
            .get(..e.at)
            .map(extract::strip_ticks)
            .filter(|p| !p.is_empty())
            .and_then(|p| Formula::parse(p).ok())
            .ok_or_else(|| ReplyError::Unreadable {
                text: t.to_string(),
                reason: e.to_string(),
            }),
    }
}

/// Conditions from lines after a `Conditions:` label: prose before the first condition is
/// skipped, prose after the last ends the list, and text meant as a condition that cannot
/// be read is an error.
fn read_condition_items(lines: &[String]) -> Result<Vec<Condition>, ReplyError> {
    let mut out = Vec::new();
    for line in lines {
        let item = extract::strip_item(line);
        if item.is_empty() {
            if out.is_empty() {
                continue;
            }
            break;
        }
        if ["none", "nothing", "n/a"].contains(&item.to_ascii_lowercase().as_str()) {
            break;
        }
        let mut line_items = Vec::new();
        let mut prose = false;
        for piece in extract::split_conditions(item) {
            match Condition::parse(piece) {
                Ok(c) => line_items.push(c),
                Err(e) if extract::looks_like_condition(piece) => {
                    return Err(ReplyError::Unreadable {
                        text: piece.to_string(),
                        reason: e.to_string(),
                    });
                }
                Err(_) => prose = true,
            }
        }
        if prose && line_items.is_empty() {
            if out.is_empty() {
                continue;
            }
            break;
        }
        out.extend(line_items);
    }
    Ok(out)
}

/// The reasoning: after a `Reasoning:` label up to the next answer label, else the prose
/// before the answer on line `answer`.
fn reasoning(lines: &[String], answer: usize) -> Option<String> {
    let all: Vec<&str> = GOAL
        .iter()
        .chain(CONDITIONS)
        .chain(VALUE)
        .copied()
        .collect();
    let text = match extract::labelled(lines, REASONING).first() {
        Some((i, rest)) => {
            let mut parts = vec![rest.clone()];
            parts.extend(
                lines[i + 1..]
                    .iter()
                    .take_while(|l| extract::label_end(l, &all).is_none())
                    .cloned(),
            );
            parts.join("\n")
        }
        None => lines[..answer.min(lines.len())].join("\n"),
    };
    let text = text.trim();
    (!text.is_empty()).then(|| text.to_string())
}

fn read_value(
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

fn json_object(text: &str) -> Option<serde_json::Map<String, Json>> {
    let body: String = extract::lines(text).join("\n");
    let t = body.trim();
    if !t.starts_with('{') {
        return None;
    }
    match serde_json::from_str::<Json>(t) {
        Ok(Json::Object(map)) => Some(map),
        _ => None,
    }
}

fn json_reasoning(obj: &serde_json::Map<String, Json>) -> Option<String> {
    obj.get("reasoning")
        .and_then(Json::as_str)
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(str::to_string)
}

/// A literal in JSON: `"~Exists_Coffee"` or `{"negated": true, "predicate": "on", "args": [...]}`.
fn json_literal(item: &Json) -> Result<Condition, ReplyError> {
    let unreadable = |reason: &str| ReplyError::Unreadable {
        text: item.to_string(),
        reason: reason.into(),
    };
    match item {
        Json::String(s) => Condition::parse(s).map_err(|e| ReplyError::Unreadable {
            text: s.clone(),
            reason: e.to_string(),
        }),
        Json::Object(o) => {
            let predicate = o
                .get("predicate")
                .and_then(Json::as_str)
                .ok_or_else(|| unreadable("no predicate"))?;
            let args = o
                .get("args")
                .and_then(Json::as_array)
                .ok_or_else(|| unreadable("no args"))?
                .iter()
                .map(|a| {
                    a.as_str()
                        .map(str::to_string)
                        .ok_or_else(|| unreadable("an argument is not a string"))
                })
                .collect::<Result<Vec<_>, _>>()?;
            let atom = crate::domain::Atom::new(predicate, args);
            if !atom.is_well_formed() {
                return Err(unreadable("not a well-formed condition"));
            }
            let negated = o.get("negated").and_then(Json::as_bool).unwrap_or(false);
            Ok(Condition { atom, negated })
        }
        _ => Err(unreadable("expected a condition")),
    }
}

#[cfg(test)]
mod tests;
