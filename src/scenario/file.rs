//! The scenario file as TOML gives it, before it is checked: what `Scenario::load` reads
//! from each file of an `extends` chain and from an example pool.

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFile {
    pub(super) extends: Option<Spanned<String>>,
    pub(super) scenario: Option<RawMeta>,
    #[serde(default)]
    pub(super) objects: IndexMap<String, Vec<Spanned<String>>>,
    /// What people call objects whose names do not say it: object name → words.
    #[serde(default)]
    pub(super) called: IndexMap<Spanned<String>, Vec<Spanned<String>>>,
    #[serde(default)]
    pub(super) predicates: Vec<RawPredicate>,
    #[serde(default)]
    pub(super) skills: Vec<RawSkill>,
    #[serde(default)]
    pub(super) examples: Vec<RawExample>,
    /// The examples read from `example_pool`, with the file they are located in.
    #[serde(skip)]
    pub(super) pooled: Option<(super::SourceFile, Vec<RawExample>)>,
    /// A file of `[[examples]]` beside this one: the domain's pool of worked examples,
    /// from which prompts choose the ones most like each request.
    pub(super) example_pool: Option<Spanned<String>>,
    /// What requests mean here beyond the vocabulary, told to the model with each goal
    /// question in a scene that has the objects a convention names.
    #[serde(default)]
    pub(super) conventions: Vec<RawConvention>,
    /// Read by the world module.
    #[allow(dead_code)]
    pub(super) world: Option<toml::Value>,
    /// Read by the verify module (`verify::VerifyConfig::from_scenario`).
    #[allow(dead_code)]
    pub(super) verify: Option<toml::Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMeta {
    pub(super) name: String,
    #[serde(default)]
    pub(super) description: String,
    pub(super) instruction: Option<String>,
    pub(super) goal: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) expected_fix: Vec<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPredicate {
    pub(super) name: Spanned<String>,
    #[serde(default)]
    pub(super) args: Vec<Spanned<String>>,
    pub(super) description: String,
    /// Words that say the condition holds, and words that say its opposite.
    #[serde(default)]
    pub(super) says: Vec<Spanned<String>>,
    #[serde(default)]
    pub(super) opposite: Vec<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSkill {
    pub(super) name: Spanned<String>,
    #[serde(default)]
    pub(super) description: String,
    #[serde(default)]
    pub(super) params: Vec<Spanned<String>>,
    #[serde(default)]
    pub(super) pre: Vec<Spanned<String>>,
    #[serde(default)]
    pub(super) add: Vec<Spanned<String>>,
    #[serde(default)]
    pub(super) del: Vec<Spanned<String>>,
    #[serde(default = "default_cost")]
    pub(super) cost: f64,
    #[serde(default = "default_ticks")]
    pub(super) ticks: u32,
    #[serde(default)]
    pub(super) values: Vec<RawValueParam>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawValueParam {
    pub(super) name: String,
    pub(super) unit: Option<String>,
    #[serde(default)]
    pub(super) categories: Vec<String>,
    #[serde(default)]
    pub(super) description: String,
    pub(super) min: Option<f64>,
    pub(super) max: Option<f64>,
}

/// An example pool file: nothing but `[[examples]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPool {
    #[serde(default)]
    pub(super) examples: Vec<RawExample>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawConvention {
    pub(super) text: String,
    #[serde(default)]
    pub(super) objects: Vec<String>,
    /// The request's words that invoke it ("bring me").
    #[serde(default)]
    pub(super) words: Vec<Spanned<String>>,
    /// The condition those words ask for each item they name: a predicate of two
    /// arguments and the place (`{ relation = "on", place = "tray" }`).
    pub(super) puts: Option<Spanned<RawPuts>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPuts {
    pub(super) relation: String,
    pub(super) place: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawExample {
    pub(super) instruction: String,
    pub(super) goal: Spanned<String>,
}

pub(super) fn default_cost() -> f64 {
    1.0
}

pub(super) fn default_ticks() -> u32 {
    1
}

/// Why a value's declared range was refused; each names the value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum ValueRangeError {
    #[error("value {value:?}: min and max are for a number with a unit")]
    NoUnit { value: String },
    #[error("value {value:?}: min and max must be finite numbers")]
    NotFinite { value: String },
    #[error("value {value:?}: min {min} is above max {max}")]
    Empty { value: String, min: f64, max: f64 },
}

/// A declared range is for a number with a unit, finite, and not empty.
pub(super) fn value_range(v: &RawValueParam) -> Result<(), ValueRangeError> {
    let value = || v.name.clone();
    if (v.min.is_some() || v.max.is_some()) && v.unit.is_none() {
        return Err(ValueRangeError::NoUnit { value: value() });
    }
    if v.min.into_iter().chain(v.max).any(|x| !x.is_finite()) {
        return Err(ValueRangeError::NotFinite { value: value() });
    }
    if let (Some(min), Some(max)) = (v.min, v.max)
        && min > max
    {
        return Err(ValueRangeError::Empty {
            value: value(),
            min,
            max,
        });
    }
    Ok(())
}
