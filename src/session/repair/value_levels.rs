//! A first value for a numeric parameter asked as a level of what the robot can do.
//!
//! A small model judges well that an egg is fragile, a pillow soft and a wound urgent, but
//! it has little sense of physical scale: asked for a number, it answers near the middle
//! or the top of the range the robot can do, whatever the object (an egg grasped with
//! 50 N of the gripper's 80). So the first question about a value asks for a level —
//! from "very low" to "very high" of the robot's declared range — and betr turns the
//! level into a number at a fixed place in that range, the same places for every
//! parameter. What the world then says of a value is learned in numbers
//! ([`super::value_bounds`]), and later questions ask for numbers.

use crate::domain::{Value, ValueParam};

/// The levels offered, each with its place in the robot's range (0: the least it can do,
/// 1: the most). Evenly spread, with the two extremes near, not at, the ends: the least
/// the robot can do rarely holds anything and the most is rarely safe.
pub const LEVELS: [(&str, f64); 5] = [
    ("very low", 0.05),
    ("low", 0.25),
    ("medium", 0.5),
    ("high", 0.75),
    ("very high", 0.95),
];

/// `param` asked as a level: a categorical parameter whose categories are the levels and
/// whose description gives the number each stands for. `None` for a parameter that is
/// not a number or has no largest value declared (there is no range to place levels in).
pub fn as_levels(param: &ValueParam) -> Option<ValueParam> {
    let unit = param.unit.as_deref()?;
    let max = param.max?;
    let min = param.min.unwrap_or(0.0);
    if !(max.is_finite() && min.is_finite() && max > min) {
        return None;
    }
    let places: Vec<String> = LEVELS
        .iter()
        .map(|(name, at)| format!("{name} = {} {unit}", number_at(min, max, *at)))
        .collect();
    let mut description = if param.description.is_empty() {
        String::new()
    } else {
        format!("{}; ", param.description)
    };
    description.push_str(&format!(
        "as a level of what the robot can do ({min} to {max} {unit}): {}. Judge the object and the task: what it takes to do it, and what breaks, slips or hurts someone",
        places.join(", ")
    ));
    Some(ValueParam {
        name: param.name.clone(),
        unit: None,
        categories: LEVELS.iter().map(|(name, _)| (*name).to_string()).collect(),
        description,
        min: None,
        max: None,
    })
}

/// The number a level read for `param` stands for; `None` for a value that is not one of
/// the levels or a parameter [`as_levels`] does not ask as levels.
pub fn level_value(param: &ValueParam, level: &Value) -> Option<Value> {
    let Value::Category(name) = level else {
        return None;
    };
    let (_, at) = LEVELS.iter().find(|(n, _)| n == name)?;
    let unit = param.unit.clone()?;
    let max = param.max?;
    let min = param.min.unwrap_or(0.0);
    Some(Value::Number {
        value: number_at(min, max, *at),
        unit,
    })
}

/// The number at `at` of the way from `min` to `max`, to three significant digits (a
/// level is a rough place, and "3.8 N" reads better than "3.8000000000000003 N").
fn number_at(min: f64, max: f64, at: f64) -> f64 {
    let x = min + at * (max - min);
    if x == 0.0 {
        return 0.0;
    }
    let digits = 3 - 1 - x.abs().log10().floor() as i32;
    let scale = 10f64.powi(digits);
    (x * scale).round() / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn force() -> ValueParam {
        ValueParam {
            name: "force".into(),
            unit: Some("N".into()),
            categories: Vec::new(),
            description: "grasping force".into(),
            min: None,
            max: Some(80.0),
        }
    }

    #[test]
    fn levels_are_places_in_the_declared_range() {
        let levels = as_levels(&force()).expect("a number with a largest value");
        assert_eq!(levels.categories.len(), LEVELS.len());
        assert!(levels.unit.is_none());
        assert!(
            levels.description.contains(
                "very low = 4 N, low = 20 N, medium = 40 N, high = 60 N, very high = 76 N"
            ),
            "{}",
            levels.description
        );
        let number = |name: &str| level_value(&force(), &Value::Category(name.into()));
        assert_eq!(
            number("very low"),
            Some(Value::Number {
                value: 4.0,
                unit: "N".into()
            })
        );
        assert_eq!(number("loud"), None);
        let speed = ValueParam {
            unit: Some("m/s".into()),
            min: Some(0.1),
            max: Some(1.5),
            ..force()
        };
        assert_eq!(
            level_value(&speed, &Value::Category("very low".into())),
            Some(Value::Number {
                value: 0.17,
                unit: "m/s".into()
            })
        );
    }

    #[test]
    fn no_levels_without_a_range() {
        let tool = ValueParam {
            unit: None,
            categories: vec!["shovel".into(), "spoon".into()],
            max: None,
            ..force()
        };
        assert!(as_levels(&tool).is_none());
        assert!(
            as_levels(&ValueParam {
                max: None,
                ..force()
            })
            .is_none()
        );
        let upside_down = ValueParam {
            min: Some(90.0),
            ..force()
        };
        assert!(as_levels(&upside_down).is_none());
        assert_eq!(number_at(0.0, 1.5, 0.05), 0.075);
        assert_eq!(number_at(0.0, 0.0, 0.5), 0.0);
    }
}
