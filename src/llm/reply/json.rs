//! Structured (JSON) replies, as a schema-constrained backend returns them.

use serde_json::Value as Json;

use crate::domain::Condition;

use super::{ReplyError, extract};

pub(super) fn json_object(text: &str) -> Option<serde_json::Map<String, Json>> {
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

pub(super) fn json_reasoning(obj: &serde_json::Map<String, Json>) -> Option<String> {
    obj.get("reasoning")
        .and_then(Json::as_str)
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(str::to_string)
}

/// A literal in JSON: `"~Exists_Coffee"` or `{"negated": true, "predicate": "on", "args": [...]}`.
pub(super) fn json_literal(item: &Json) -> Result<Condition, ReplyError> {
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
