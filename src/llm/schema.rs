//! JSON schemas for structured output: a reply constrained to the scenario's vocabulary.
//! A literal is an enumerated string (`"~Exists_Coffee"`) when the vocabulary's ground
//! literals are few, else an object whose predicate and arguments are enumerated.

use serde_json::{Value as Json, json};

use super::OutputConstraint;
use crate::domain::{ANY_OBJECT, Atom, Condition, ValueParam, Vocabulary};

/// Above this many ground literals, literals are objects of enumerated parts.
pub const MAX_ENUMERATED: usize = 1000;

/// Every ground literal, with `"any object"` in the argument places of quoted-form
/// predicates; `None` when there are more than `limit`.
pub fn ground_literals(vocabulary: &Vocabulary, limit: usize) -> Option<Vec<String>> {
    let mut out = Vec::new();
    for p in &vocabulary.predicates {
        let wildcard = crate::domain::condition::is_word_predicate(&p.name);
        let mut partial: Vec<Vec<String>> = vec![Vec::new()];
        for types in &p.arg_types {
            let mut choices: Vec<String> = vocabulary
                .objects_fitting(types)
                .map(str::to_string)
                .collect();
            if wildcard {
                choices.push(ANY_OBJECT.to_string());
            }
            partial = partial
                .iter()
                .flat_map(|prefix| {
                    choices.iter().map(move |c| {
                        let mut next = prefix.clone();
                        next.push(c.clone());
                        next
                    })
                })
                .collect();
            if partial.len() * 2 > limit {
                return None;
            }
        }
        for args in partial {
            let atom = Atom::new(p.name.clone(), args);
            out.push(Condition::pos(atom.clone()).to_string());
            out.push(Condition::neg(atom).to_string());
            if out.len() > limit {
                return None;
            }
        }
    }
    Some(out)
}

fn literal_schema(vocabulary: &Vocabulary) -> Json {
    match ground_literals(vocabulary, MAX_ENUMERATED) {
        Some(all) => json!({ "type": "string", "enum": all }),
        None => {
            let predicates: Vec<&str> = vocabulary
                .predicates
                .iter()
                .map(|p| p.name.as_str())
                .collect();
            let mut objects: Vec<&str> =
                vocabulary.objects.iter().map(|o| o.name.as_str()).collect();
            objects.push(ANY_OBJECT);
            json!({
                "type": "object",
                "properties": {
                    "negated": { "type": "boolean" },
                    "predicate": { "type": "string", "enum": predicates },
                    "args": { "type": "array", "items": { "type": "string", "enum": objects } },
                },
                "required": ["negated", "predicate", "args"],
                "additionalProperties": false,
            })
        }
    }
}

fn object(properties: Json, required: &[&str]) -> Json {
    json!({
        "type": "object",
        "properties": properties,
        "required": required,
        "additionalProperties": false,
    })
}

/// A goal as a disjunction of conjunctions of literals.
pub fn goal(vocabulary: &Vocabulary) -> OutputConstraint {
    let lit = literal_schema(vocabulary);
    OutputConstraint::JsonSchema {
        name: "goal".into(),
        schema: object(
            json!({
                "reasoning": { "type": "string" },
                "goal": { "type": "array", "items": { "type": "array", "items": lit } },
            }),
            &["reasoning", "goal"],
        ),
    }
}

/// Missing preconditions.
pub fn conditions(vocabulary: &Vocabulary) -> OutputConstraint {
    OutputConstraint::JsonSchema {
        name: "conditions".into(),
        schema: object(
            json!({
                "reasoning": { "type": "string" },
                "conditions": { "type": "array", "items": literal_schema(vocabulary) },
            }),
            &["reasoning", "conditions"],
        ),
    }
}

/// A parameter value: a number in the unit, or one of the categories.
pub fn value(param: &ValueParam) -> OutputConstraint {
    let properties = match &param.unit {
        Some(unit) => json!({
            "reasoning": { "type": "string" },
            "value": { "type": "number" },
            "unit": { "type": "string", "enum": [unit] },
        }),
        None => json!({
            "reasoning": { "type": "string" },
            "value": { "type": "string", "enum": param.categories },
        }),
    };
    let required: &[&str] = if param.unit.is_some() {
        &["reasoning", "value", "unit"]
    } else {
        &["reasoning", "value"]
    };
    OutputConstraint::JsonSchema {
        name: "parameter_value".into(),
        schema: object(properties, required),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    #[test]
    fn large_vocabularies_fall_back_to_parts() {
        let path =
            std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml");
        let v = Scenario::load(&path).unwrap().domain.vocabulary;
        assert!(ground_literals(&v, MAX_ENUMERATED).is_none());
        let OutputConstraint::JsonSchema { schema, .. } = conditions(&v) else {
            panic!("conditions() builds a JSON schema");
        };
        assert_eq!(
            schema["properties"]["conditions"]["items"]["type"],
            "object"
        );
        let small = ground_literals(&v, 1_000_000).unwrap();
        assert!(small.contains(&"~Exists_Coffee".to_string()));
    }
}
