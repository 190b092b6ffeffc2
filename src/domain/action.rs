//! A grounded skill invocation as it appears in a tree: `grasp "blue cube"`,
//! `PutDown "Coffee" "Table1"`, `grasp "egg" {force = 5.3 N}`.
//!
//! The skill name is an identifier, the arguments are quoted object names, and value
//! parameters (grasp force, speed, tool), when set, follow in braces.

use std::fmt;

/// A value parameter's value: a number with its unit, or a category such as a tool name.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Number { value: f64, unit: String },
    Category(String),
}

/// One action as the tree names it.
#[derive(Debug, Clone, PartialEq)]
pub struct ActionCall {
    pub skill: String,
    pub args: Vec<String>,
    /// Value parameters in the order they were set.
    pub values: Vec<(String, Value)>,
}

/// Why an action could not be read; `at` is a byte offset into the parsed text.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("at byte {at}: expected {expected}, found {found}")]
pub struct ActionError {
    pub at: usize,
    pub expected: &'static str,
    pub found: String,
}

impl ActionCall {
    pub fn new(
        skill: impl Into<String>,
        args: impl IntoIterator<Item = impl Into<String>>,
    ) -> Self {
        ActionCall {
            skill: skill.into(),
            args: args.into_iter().map(Into::into).collect(),
            values: Vec::new(),
        }
    }

    /// The value set for parameter `name`, if any.
    pub fn value(&self, name: &str) -> Option<&Value> {
        self.values.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    /// Set (or replace) a value parameter.
    pub fn set_value(&mut self, name: &str, value: Value) {
        match self.values.iter_mut().find(|(n, _)| n == name) {
            Some(slot) => slot.1 = value,
            None => self.values.push((name.to_string(), value)),
        }
    }

    /// The same skill on the same objects, whatever the values (used to find every node
    /// that a parameter value must reach).
    pub fn same_invocation(&self, other: &ActionCall) -> bool {
        self.skill == other.skill && self.args == other.args
    }

    /// Parse a whole string as one action (without the trailing `!`).
    pub fn parse(text: &str) -> Result<ActionCall, ActionError> {
        let (call, used) = parse_action_prefix(text, 0)?;
        let rest = text[used..].trim_start();
        if let Some(c) = rest.chars().next() {
            return Err(ActionError {
                at: text.len() - rest.len(),
                expected: "end of action",
                found: format!("{c:?}"),
            });
        }
        Ok(call)
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Number { value, unit } if unit.is_empty() => write!(f, "{value}"),
            Value::Number { value, unit } => write!(f, "{value} {unit}"),
            Value::Category(c) => write!(f, "\"{c}\""),
        }
    }
}

impl fmt::Display for ActionCall {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.skill)?;
        for a in &self.args {
            write!(f, " \"{a}\"")?;
        }
        if !self.values.is_empty() {
            f.write_str(" {")?;
            for (i, (name, value)) in self.values.iter().enumerate() {
                if i > 0 {
                    f.write_str(", ")?;
                }
                write!(f, "{name} = {value}")?;
            }
            f.write_str("}")?;
        }
        Ok(())
    }
}

/// Parse a value as written after `=`: `5.3 N`, `0.6 m/s`, `"shovel"`, `shovel`.
pub fn parse_value(text: &str) -> Result<Value, ActionError> {
    let t = text.trim();
    let offset = text.len() - text.trim_start().len();
    if let Some(inner) = t.strip_prefix('"') {
        return match inner.strip_suffix('"') {
            Some(c) if !c.is_empty() && !c.contains('"') => Ok(Value::Category(c.to_string())),
            _ => Err(ActionError {
                at: offset,
                expected: "a quoted category such as \"shovel\"",
                found: format!("{t:?}"),
            }),
        };
    }
    let number_end = t
        .char_indices()
        .find(|(_, c)| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E')))
        .map_or(t.len(), |(i, _)| i);
    // A bare word (no leading digit) is a category: `tool = shovel`.
    if number_end == 0 || t[..number_end].parse::<f64>().is_err() {
        if !t.is_empty()
            && t.chars()
                .all(|c| c.is_alphanumeric() || c == ' ' || c == '_' || c == '-')
        {
            return Ok(Value::Category(t.to_string()));
        }
        return Err(ActionError {
            at: offset,
            expected: "a number with a unit (5 N, 0.6 m/s) or a category (\"shovel\")",
            found: format!("{t:?}"),
        });
    }
    let value: f64 = t[..number_end].parse().map_err(|_| ActionError {
        at: offset,
        expected: "a number",
        found: format!("{:?}", &t[..number_end]),
    })?;
    if !value.is_finite() {
        return Err(ActionError {
            at: offset,
            expected: "a finite number",
            found: format!("{:?}", &t[..number_end]),
        });
    }
    let unit = t[number_end..].trim().to_string();
    Ok(Value::Number { value, unit })
}

/// Parse one action starting at byte `start` (leading spaces allowed); returns the action
/// and the byte offset just after it.
pub fn parse_action_prefix(text: &str, start: usize) -> Result<(ActionCall, usize), ActionError> {
    let bytes = text.as_bytes();
    let mut i = skip_spaces(bytes, start);
    let begin = i;
    if !bytes.get(i).is_some_and(u8::is_ascii_alphabetic) {
        return Err(ActionError {
            at: i,
            expected: "a skill name such as grasp or PutDown",
            found: found_at(text, i),
        });
    }
    while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
        i += 1;
    }
    let skill = text[begin..i].to_string();
    let mut args = Vec::new();
    loop {
        let j = skip_spaces(bytes, i);
        if bytes.get(j) != Some(&b'"') {
            break;
        }
        let rest = &text[j + 1..];
        match rest.find(['"', '\n']) {
            Some(end) if rest.as_bytes()[end] == b'"' && end > 0 => {
                args.push(rest[..end].to_string());
                i = j + 1 + end + 1;
            }
            _ => {
                return Err(ActionError {
                    at: j,
                    expected: "a quoted object name with a closing quote",
                    found: found_at(text, j),
                });
            }
        }
    }
    let mut values = Vec::new();
    let j = skip_spaces(bytes, i);
    if bytes.get(j) == Some(&b'{') {
        let Some(close) = text[j..].find('}') else {
            return Err(ActionError {
                at: j,
                expected: "a closing '}' after the value parameters",
                found: "end of line".into(),
            });
        };
        let body = &text[j + 1..j + close];
        let mut at = j + 1;
        for item in body.split(',') {
            let Some((written, value)) = item.split_once('=') else {
                return Err(ActionError {
                    at,
                    expected: "name = value",
                    found: format!("{:?}", item.trim()),
                });
            };
            let name = written.trim();
            if name.is_empty()
                || !name
                    .chars()
                    .all(|c| c.is_alphanumeric() || c == ' ' || c == '_')
            {
                return Err(ActionError {
                    at,
                    expected: "a parameter name",
                    found: format!("{name:?}"),
                });
            }
            // The value starts after the name as written (blanks around it included).
            let value_at = at + written.len() + 1;
            let value = parse_value(value).map_err(|e| ActionError {
                at: e.at + value_at,
                ..e
            })?;
            values.push((name.to_string(), value));
            at += item.len() + 1;
        }
        i = j + close + 1;
    }
    Ok((
        ActionCall {
            skill,
            args,
            values,
        },
        i,
    ))
}

fn skip_spaces(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() && (bytes[i] == b' ' || bytes[i] == b'\t') {
        i += 1;
    }
    i
}

fn found_at(text: &str, i: usize) -> String {
    match text[i..].chars().next() {
        Some(c) => format!("{c:?}"),
        None => "end of text".into(),
    }
}

crate::domain::as_text::serde_as_text!(Value, parse_value);
crate::domain::as_text::serde_as_text!(ActionCall, ActionCall::parse);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn actions_round_trip() {
        for text in [
            "grasp \"blue cube\"",
            "PutDown \"Coffee\" \"Table1\"",
            "grasp \"egg\" {force = 5.3 N}",
            "move \"pillow\" {speed = 0.6 m/s, tool = \"shovel\"}",
            "Sweep",
        ] {
            let a = ActionCall::parse(text).unwrap();
            assert_eq!(a.to_string(), text);
        }
    }

    #[test]
    fn values_parse() {
        assert_eq!(
            parse_value(" 5 N").unwrap(),
            Value::Number {
                value: 5.0,
                unit: "N".into()
            }
        );
        assert_eq!(
            parse_value("shovel").unwrap(),
            Value::Category("shovel".into())
        );
        assert_eq!(
            parse_value("\"sponge\"").unwrap(),
            Value::Category("sponge".into())
        );
        assert!(parse_value("").is_err());
        assert!(parse_value("1e999 N").is_err());
    }

    #[test]
    fn set_value_replaces() {
        let mut a = ActionCall::new("grasp", ["egg"]);
        a.set_value(
            "force",
            Value::Number {
                value: 50.0,
                unit: "N".into(),
            },
        );
        a.set_value(
            "force",
            Value::Number {
                value: 5.0,
                unit: "N".into(),
            },
        );
        assert_eq!(a.to_string(), "grasp \"egg\" {force = 5 N}");
        assert!(a.same_invocation(&ActionCall::new("grasp", ["egg"])));
    }

    #[test]
    fn a_value_error_points_into_the_value_after_a_blank_name_end() {
        // U+2028 is a blank of three bytes, trimmed off the name.
        let text = "wipe \"table\" {tool\u{2028} = \"sr\" on ponge\"}";
        let e = ActionCall::parse(text).unwrap_err();
        assert_eq!(e.at, text.find("\"sr").unwrap(), "{e}");
        assert!(text.is_char_boundary(e.at));
        let e = ActionCall::parse("grasp \"egg\" {force  = 5 N, speed =  \"fast}").unwrap_err();
        assert_eq!(e.at, "grasp \"egg\" {force  = 5 N, speed =  ".len(), "{e}");
    }

    #[test]
    fn errors_name_the_problem() {
        assert!(ActionCall::parse("\"x\"").is_err());
        assert_eq!(ActionCall::parse("grasp \"egg").unwrap_err().at, 6);
        assert!(ActionCall::parse("grasp \"egg\" {force 5}").is_err());
        assert!(ActionCall::parse("grasp \"egg\" {force = 5").is_err());
    }
}
