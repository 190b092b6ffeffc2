//! `--set "force of egg = 5 N"`: a value parameter for every action that uses a skill
//! declaring that parameter with that object.
//!
//! The parameter may be named as the skill declares it (`force`), with its skill
//! (`grasp force`) or by its description (`grasping force`). The value is checked against
//! the declaration: a number takes the declared unit (a bare number gets it), a category
//! must be one of the declared categories.

use crate::bt::Tree;
use crate::domain::action::{ActionError, parse_value};
use crate::domain::{Value, ValueParam};
use crate::planner;
use crate::scenario::Scenario;

/// One parsed `--set`: the value, the object, and every (skill, parameter) it applies to.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    pub text: String,
    pub object: String,
    pub value: Value,
    pub targets: Vec<(String, String)>,
}

/// Why a setting could not be read; each names the text as typed (shortened when long).
/// Front ends say where it came from (`--set` on the command line, the workbench's input).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SettingError {
    #[error("{text}: expected `<parameter> of <object> = <value>`, e.g. \"force of egg = 5 N\"")]
    Form { text: String },
    #[error("{text}: no object {object:?} in this scenario")]
    UnknownObject { text: String, object: String },
    #[error("{text}: no skill declares a value {param:?} (declared: {declared})")]
    UnknownValue {
        text: String,
        param: String,
        declared: String,
    },
    #[error("{text}: {reason}")]
    Unreadable { text: String, reason: ActionError },
    #[error("{text}: {reason}")]
    Unfit { text: String, reason: ConformError },
}

/// Why a value does not fit its parameter's declaration; each names the parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConformError {
    #[error("{value} {unit} is more than the robot can do ({param} at most {max} {unit})")]
    AboveMax {
        param: String,
        value: f64,
        unit: String,
        max: f64,
    },
    #[error("{value} {unit} is less than the robot can do ({param} at least {min} {unit})")]
    BelowMin {
        param: String,
        value: f64,
        unit: String,
        min: f64,
    },
    #[error("{param} is given in {unit}, not {given}")]
    WrongUnit {
        param: String,
        unit: String,
        given: String,
    },
    #[error("{category:?} is not one of {}", .categories.join(", "))]
    UnknownCategory {
        param: String,
        category: String,
        categories: Vec<String>,
    },
    #[error("{param} is a number in {unit}, found {value}")]
    NotANumber {
        param: String,
        unit: String,
        value: Value,
    },
    #[error("{param} is one of {}, found {value}", .categories.join(", "))]
    NotACategory {
        param: String,
        categories: Vec<String>,
        value: Value,
    },
}

pub fn parse_setting(scenario: &Scenario, text: &str) -> Result<Setting, SettingError> {
    let shown = crate::excerpt::excerpt(text, None);
    let form = || SettingError::Form {
        text: shown.clone(),
    };
    let (left, value_text) = text.split_once('=').ok_or_else(form)?;
    let (param, object) = left.split_once(" of ").ok_or_else(form)?;
    let param = param.trim();
    let object = object.trim().trim_matches('"').to_string();
    if scenario.domain.vocabulary.object(&object).is_none() {
        return Err(SettingError::UnknownObject {
            text: shown,
            object,
        });
    }
    let mut targets = Vec::new();
    let mut declared = None;
    for skill in &scenario.domain.skills {
        for v in &skill.values {
            let names = [
                v.name.clone(),
                format!("{} {}", skill.name, v.name),
                v.description.clone(),
            ];
            if names.iter().any(|n| n == param)
                && !targets.contains(&(skill.name.clone(), v.name.clone()))
            {
                targets.push((skill.name.clone(), v.name.clone()));
                declared = Some(v.clone());
            }
        }
    }
    let Some(declared) = declared else {
        let known: Vec<String> = scenario
            .domain
            .skills
            .iter()
            .flat_map(|s| {
                s.values
                    .iter()
                    .map(move |v| format!("{} {} ({})", s.name, v.name, v.description))
            })
            .collect();
        return Err(SettingError::UnknownValue {
            text: shown,
            param: param.to_string(),
            declared: if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            },
        });
    };
    let value = parse_value(value_text).map_err(|reason| SettingError::Unreadable {
        text: shown.clone(),
        reason,
    })?;
    let value = conform(&declared, value).map_err(|reason| SettingError::Unfit {
        text: shown.clone(),
        reason,
    })?;
    Ok(Setting {
        text: text.to_string(),
        object,
        value,
        targets,
    })
}

/// Check `value` against the declaration: a number takes the declared unit (a bare
/// number gets it), a category must be one of the declared categories.
pub fn conform(declared: &ValueParam, value: Value) -> Result<Value, ConformError> {
    let param = || declared.name.clone();
    match (value, &declared.unit) {
        (Value::Number { value, unit }, Some(want)) if unit.is_empty() || unit == *want => {
            if let Some(max) = declared.max.filter(|m| value > *m) {
                return Err(ConformError::AboveMax {
                    param: param(),
                    value,
                    unit: want.clone(),
                    max,
                });
            }
            if let Some(min) = declared.min.filter(|m| value < *m) {
                return Err(ConformError::BelowMin {
                    param: param(),
                    value,
                    unit: want.clone(),
                    min,
                });
            }
            Ok(Value::Number {
                value,
                unit: want.clone(),
            })
        }
        (Value::Number { unit, .. }, Some(want)) => Err(ConformError::WrongUnit {
            param: param(),
            unit: want.clone(),
            given: unit,
        }),
        (Value::Category(c), None)
            if declared.categories.is_empty() || declared.categories.contains(&c) =>
        {
            Ok(Value::Category(c))
        }
        (Value::Category(category), None) => Err(ConformError::UnknownCategory {
            param: param(),
            category,
            categories: declared.categories.clone(),
        }),
        (value, Some(want)) => Err(ConformError::NotANumber {
            param: param(),
            unit: want.clone(),
            value,
        }),
        (value, None) => Err(ConformError::NotACategory {
            param: param(),
            categories: declared.categories.clone(),
            value,
        }),
    }
}

/// Apply a setting to every matching action of `tree`; how many actions changed.
pub fn apply(tree: &mut Tree, setting: &Setting) -> usize {
    setting
        .targets
        .iter()
        .map(|(skill, name)| planner::set_value(tree, skill, &setting.object, name, &setting.value))
        .sum()
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    fn egg() -> Scenario {
        Scenario::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/params/egg.toml"),
        )
        .unwrap()
    }

    #[test]
    fn settings_name_the_parameter_in_three_ways() {
        let s = egg();
        for text in [
            "force of egg = 5 N",
            "grasp force of egg = 5",
            "grasping force of \"egg\" = 5 N",
        ] {
            let set = parse_setting(&s, text).unwrap();
            assert_eq!(set.object, "egg");
            assert_eq!(
                set.targets,
                vec![("grasp".to_string(), "force".to_string())]
            );
            assert_eq!(
                set.value,
                Value::Number {
                    value: 5.0,
                    unit: "N".into()
                }
            );
        }
    }

    #[test]
    fn a_value_beyond_what_the_robot_can_do_is_refused() {
        let s = Scenario::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/params/hammer.toml"),
        )
        .unwrap();
        assert!(parse_setting(&s, "force of hammer = 80 N").is_ok());
        let e = parse_setting(&s, "force of hammer = 120 N").unwrap_err();
        assert!(e.to_string().contains("more than the robot can do"), "{e}");
    }

    #[test]
    fn bad_settings_say_why() {
        let s = egg();
        assert!(
            parse_setting(&s, "force of dragon = 5 N")
                .unwrap_err()
                .to_string()
                .contains("no object")
        );
        assert!(
            parse_setting(&s, "speed of egg = 5 N")
                .unwrap_err()
                .to_string()
                .contains("no skill declares")
        );
        assert!(
            parse_setting(&s, "force of egg = 5 lbf")
                .unwrap_err()
                .to_string()
                .contains("not lbf")
        );
        assert!(
            parse_setting(&s, "force egg 5")
                .unwrap_err()
                .to_string()
                .contains("expected")
        );
    }
}
