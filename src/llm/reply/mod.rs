//! Reading replies: the goal of a goal-interpretation reply, the conditions of a
//! failure-resolution reply, the value of a parameter-value reply, and the reasoning of
//! each. Text and JSON (structured output) replies are both accepted. Every atom is
//! validated against the scenario's vocabulary, so nothing invalid leaves this module.
//! No input makes these functions panic.

pub mod extract;
mod json;
pub mod validate;
mod value;

use json::{json_literal, json_object, json_reasoning};
use value::read_value;

use serde_json::Value as Json;

use crate::domain::Value;
use crate::domain::{Condition, ValueParam, Vocabulary};
use crate::goal::Formula;

pub use crate::domain::names::{MIN_SIMILARITY, did_you_mean, similarity};

/// Why a reply is not used. Every text of the reply a message echoes is cut to
/// [`ECHOED`] characters, so an error (and a prompt that tells the model about it) never
/// grows with the reply's size.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReplyError {
    #[error("the reply has no `{label}:` answer: {excerpt:?}")]
    MissingAnswer {
        label: &'static str,
        excerpt: String,
    },
    #[error("cannot read {:?}: {}", echoed(text), echoed(reason))]
    Unreadable { text: String, reason: String },
    #[error("{:?} does not fit the scene: {}", echoed(text), echoed(reason))]
    Invalid { text: String, reason: String },
    #[error(
        "{:?} in {} is not in the scene{}",
        echoed(object),
        echoed(text),
        did_you_mean(nearest)
    )]
    UnknownObject {
        text: String,
        object: String,
        /// The listed names most like it, most alike first.
        nearest: Vec<String>,
    },
    #[error("the reply proposes no condition")]
    NoConditions,
    #[error("parameter value {:?}: {}", echoed(text), echoed(reason))]
    BadValue { text: String, reason: String },
}

/// How many characters of a reply's text an error echoes.
pub const ECHOED: usize = 200;

fn echoed(text: &str) -> String {
    crate::excerpt::shortened(text, ECHOED)
}

#[derive(Debug, Clone, PartialEq)]
pub struct GoalAnswer {
    pub goal: Formula,
    pub reasoning: Option<String>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ConditionsAnswer {
    pub conditions: Vec<Condition>,
    pub reasoning: Option<String>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ValueAnswer {
    pub value: Value,
    pub reasoning: Option<String>,
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
        let goal = validate::formula(vocabulary, formula, min_similarity)?;
        return Ok(GoalAnswer { goal, reasoning });
    }
    let lines = extract::lines(text);
    let candidates = answers(&lines, GOAL);
    let mut first_error = None;
    for (i, answer) in candidates.iter().rev() {
        match read_formula(answer) {
            Ok(f) => {
                let goal = validate::formula(vocabulary, f, min_similarity)?;
                return Ok(GoalAnswer {
                    goal,
                    reasoning: reasoning(&lines, *i),
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
        let goal = validate::formula(vocabulary, f, min_similarity)?;
        return Ok(GoalAnswer {
            goal,
            reasoning: None,
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
        let c = validate::condition(vocabulary, c, min_similarity)?;
        if !conditions.contains(&c) {
            conditions.push(c);
        }
    }
    Ok(ConditionsAnswer {
        conditions,
        reasoning,
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
    let value = read_value(extract::strip_ticks(&raw), param, min_similarity)?;
    Ok(ValueAnswer { value, reasoning })
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
    // A model that writes its answer's label at the end of its reasoning, then the label
    // again on the next line as the format asks, would show the label twice.
    let mut text = text.trim();
    while let Some(label) = all.iter().find(|l| {
        let l = format!("{l}:");
        text.len() >= l.len()
            && text.is_char_boundary(text.len() - l.len())
            && text[text.len() - l.len()..].eq_ignore_ascii_case(&l)
    }) {
        text = text[..text.len() - label.len() - 1].trim_end();
    }
    (!text.is_empty()).then(|| text.to_string())
}

#[cfg(test)]
mod tests;
