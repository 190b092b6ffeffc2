//! Judging value parameters (grasp force, speed, tool) the way the world would: an egg
//! squeezed too hard breaks, a hammer held too softly slips, a tool that cannot scoop
//! does not move sand. The limits and the texts are scenario data (`[[world.values]]`),
//! so the simulator carries no knowledge of eggs.
//!
//! A skill that declares a value parameter cannot run without it: the failure names the
//! parameter in the words of its declaration ("Grasping force not defined. Please define
//! grasping force in N"), which is what a person or an LLM needs to propose one.

use crate::domain::{ActionCall, Value, ValueParam};

/// One limit on one value of one skill (optionally only for one object).
#[derive(Debug, Clone, PartialEq)]
pub struct Judge {
    pub skill: String,
    /// `None`: every object the skill acts on.
    pub object: Option<String>,
    pub value: String,
    pub min: Option<(f64, String)>,
    pub max: Option<(f64, String)>,
    /// Allowed categories, and the text when another one is given.
    pub allowed: Option<(Vec<String>, String)>,
}

/// The text a skill reports when a declared value is not set.
pub fn missing_text(param: &ValueParam) -> String {
    let noun = if param.description.trim().is_empty() {
        param.name.as_str()
    } else {
        param.description.trim()
    };
    let mut capital = noun.to_string();
    if let Some(first) = capital.get_mut(0..1) {
        first.make_ascii_uppercase();
    }
    match (&param.unit, param.categories.as_slice()) {
        (Some(unit), _) => format!("{capital} not defined. Please define {noun} in {unit}"),
        (None, []) => format!("{capital} not defined. Please define {noun}"),
        (None, cats) => format!(
            "{capital} not defined. Please define {noun} (one of: {})",
            cats.join(", ")
        ),
    }
}

/// Fill `{value}`, `{unit}`, `{min}`, `{max}`, `{object}` in a judge's text.
fn fill(text: &str, value: &Value, judge: &Judge, object: &str) -> String {
    let (v, unit) = match value {
        Value::Number { value, unit } => (format!("{value}"), unit.clone()),
        Value::Category(c) => (c.clone(), String::new()),
    };
    let bound =
        |b: &Option<(f64, String)>| b.as_ref().map(|(x, _)| format!("{x}")).unwrap_or_default();
    text.replace("{value}", &v)
        .replace("{unit}", &unit)
        .replace("{min}", &bound(&judge.min))
        .replace("{max}", &bound(&judge.max))
        .replace("{object}", object)
}

/// The first problem with the values of `action`, given the skill's declared value
/// parameters and the world's judges: a missing value, a wrong unit, or a value the
/// world rejects.
pub fn judge(action: &ActionCall, declared: &[ValueParam], judges: &[Judge]) -> Option<String> {
    let object = action.args.first().map(String::as_str).unwrap_or_default();
    for param in declared {
        let Some(value) = action.value(&param.name) else {
            return Some(missing_text(param));
        };
        match (value, &param.unit) {
            (Value::Number { unit, .. }, Some(want)) if unit != want && !unit.is_empty() => {
                return Some(format!(
                    "{} must be given in {want}, found {value}",
                    missing_text(param)
                        .split(" not defined")
                        .next()
                        .unwrap_or(&param.name)
                ));
            }
            (Value::Category(_), Some(want)) => {
                return Some(format!(
                    "{} must be a number in {want}, found {value}",
                    param.name
                ));
            }
            (Value::Number { .. }, None) => {
                return Some(format!(
                    "{} must be one of {}, found {value}",
                    param.name,
                    param.categories.join(", ")
                ));
            }
            _ => {}
        }
    }
    for j in judges
        .iter()
        .filter(|j| j.skill == action.skill && j.object.as_deref().is_none_or(|o| o == object))
    {
        let Some(value) = action.value(&j.value) else {
            continue;
        };
        match value {
            Value::Number { value: x, .. } => {
                if let Some((min, text)) = &j.min
                    && x < min
                {
                    return Some(fill(text, value, j, object));
                }
                if let Some((max, text)) = &j.max
                    && x > max
                {
                    return Some(fill(text, value, j, object));
                }
            }
            Value::Category(c) => {
                if let Some((allowed, text)) = &j.allowed
                    && !allowed.contains(c)
                {
                    return Some(fill(text, value, j, object));
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn force() -> ValueParam {
        ValueParam {
            name: "force".into(),
            unit: Some("N".into()),
            categories: vec![],
            description: "grasping force".into(),
            min: None,
            max: None,
        }
    }

    fn egg_judge() -> Judge {
        Judge {
            skill: "grasp".into(),
            object: Some("egg".into()),
            value: "force".into(),
            min: None,
            max: Some((
                6.0,
                "The egg broke: {value} {unit} is more than it can bear ({max} {unit} at most)"
                    .into(),
            )),
            allowed: None,
        }
    }

    #[test]
    fn missing_value_names_the_parameter() {
        let a = ActionCall::new("grasp", ["egg"]);
        assert_eq!(
            judge(&a, &[force()], &[egg_judge()]).unwrap(),
            "Grasping force not defined. Please define grasping force in N"
        );
    }

    #[test]
    fn values_are_judged_per_object() {
        let mut a = ActionCall::new("grasp", ["egg"]);
        a.set_value(
            "force",
            Value::Number {
                value: 50.0,
                unit: "N".into(),
            },
        );
        assert_eq!(
            judge(&a, &[force()], &[egg_judge()]).unwrap(),
            "The egg broke: 50 N is more than it can bear (6 N at most)"
        );
        a.set_value(
            "force",
            Value::Number {
                value: 5.0,
                unit: "N".into(),
            },
        );
        assert_eq!(judge(&a, &[force()], &[egg_judge()]), None);
        let mut b = ActionCall::new("grasp", ["hammer"]);
        b.set_value(
            "force",
            Value::Number {
                value: 50.0,
                unit: "N".into(),
            },
        );
        assert_eq!(judge(&b, &[force()], &[egg_judge()]), None);
        b.set_value(
            "force",
            Value::Number {
                value: 50.0,
                unit: "lbf".into(),
            },
        );
        assert!(
            judge(&b, &[force()], &[])
                .unwrap()
                .contains("must be given in N")
        );
    }

    #[test]
    fn categories_are_checked() {
        let tool = ValueParam {
            name: "tool".into(),
            unit: None,
            categories: vec!["shovel".into(), "hammer".into()],
            description: "tool".into(),
            min: None,
            max: None,
        };
        let j = Judge {
            skill: "scoop".into(),
            object: None,
            value: "tool".into(),
            min: None,
            max: None,
            allowed: Some((
                vec!["shovel".into()],
                "A {value} cannot scoop {object}".into(),
            )),
        };
        let mut a = ActionCall::new("scoop", ["sand", "bucket"]);
        assert_eq!(
            judge(&a, std::slice::from_ref(&tool), std::slice::from_ref(&j)).unwrap(),
            "Tool not defined. Please define tool (one of: shovel, hammer)"
        );
        a.set_value("tool", Value::Category("hammer".into()));
        assert_eq!(
            judge(&a, std::slice::from_ref(&tool), std::slice::from_ref(&j)).unwrap(),
            "A hammer cannot scoop sand"
        );
    }
}
