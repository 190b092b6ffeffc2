//! The `[verify]` table of a scenario: disturbances the tree must survive, properties it
//! must satisfy, and whether actions may fail.
//!
//! ```toml
//! [verify]
//! properties = ["never Holding_Coffee & Holding_Milk"]   # see `temporal.rs`
//! action_failures = false   # true: any action may also fail, leaving the state unchanged
//!
//! # Something outside the robot's control that may happen between any two ticks, as
//! # often as it likes. `params` range over the objects their types admit (same syntax as
//! # a skill's: `name: type`, `name: type1|type2`, `name: type except other`); `pre` are
//! # conditions that must hold for it to happen; `add` / `del` are the atoms it makes true /
//! # false, as `{param}` templates like a skill's effects (`{*}` in `del`: every object).
//! [[verify.disturbances]]
//! description = "a human may put any cube on any other cube"
//! params = ["a: cube", "b: cube"]
//! pre = ['~"any object" on "{a}"', '~"any object" on "{b}"']
//! add = ['"{a}" on "{b}"']
//! del = ['"{a}" on "{*}"']
//! ```
//!
//! Tables of a scenario and the files it extends accumulate (base first); a later
//! `action_failures` overrides an earlier one. Every error names file, line and column.

use serde::Deserialize;
use toml::Spanned;

use super::temporal::Property;
use crate::domain::skill::{AtomTemplate, LiteralTemplate};
use crate::domain::template::parse_template;
use crate::domain::{Param, Vocabulary};
use crate::scenario::{Scenario, ScenarioError, SourceFile};

/// A declared disturbance, not yet grounded over objects.
#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    pub description: String,
    pub params: Vec<Param>,
    pub pre: Vec<LiteralTemplate>,
    pub add: Vec<AtomTemplate>,
    pub del: Vec<AtomTemplate>,
}

/// A user property with the text it was written as.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedProperty {
    pub text: String,
    pub property: Property,
}

/// Everything a scenario says about verification.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VerifyConfig {
    pub disturbances: Vec<Disturbance>,
    pub properties: Vec<NamedProperty>,
    pub action_failures: bool,
}

#[derive(Deserialize)]
struct Table {
    verify: Option<RawVerify>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVerify {
    #[serde(default)]
    properties: Vec<Spanned<String>>,
    action_failures: Option<bool>,
    #[serde(default)]
    disturbances: Vec<RawDisturbance>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDisturbance {
    description: Spanned<String>,
    #[serde(default)]
    params: Vec<Spanned<String>>,
    #[serde(default)]
    pre: Vec<Spanned<String>>,
    #[serde(default)]
    add: Vec<Spanned<String>>,
    #[serde(default)]
    del: Vec<Spanned<String>>,
}

impl VerifyConfig {
    /// Read the `[verify]` tables of a scenario's files.
    pub fn from_scenario(scenario: &Scenario) -> Result<VerifyConfig, ScenarioError> {
        let vocabulary = &scenario.domain.vocabulary;
        let mut config = VerifyConfig::default();
        for file in &scenario.files {
            let table: Table = file.parse()?;
            let Some(raw) = table.verify else { continue };
            if let Some(f) = raw.action_failures {
                config.action_failures = f;
            }
            for p in &raw.properties {
                let property = Property::parse_checked(p.get_ref(), vocabulary)
                    .map_err(|e| file.error_in_string(&p.span(), e.at, e.message))?;
                config.properties.push(NamedProperty {
                    text: p.get_ref().trim().to_string(),
                    property,
                });
            }
            for d in &raw.disturbances {
                config
                    .disturbances
                    .push(read_disturbance(file, d, vocabulary)?);
            }
        }
        Ok(config)
    }
}

fn read_disturbance(
    file: &SourceFile,
    raw: &RawDisturbance,
    vocabulary: &Vocabulary,
) -> Result<Disturbance, ScenarioError> {
    if raw.description.get_ref().trim().is_empty() {
        return Err(file.error_in_string(
            &raw.description.span(),
            0,
            "a disturbance needs a description saying what happens",
        ));
    }
    let mut params = Vec::new();
    for p in &raw.params {
        let param = parse_param(p.get_ref(), vocabulary)
            .map_err(|e| file.error_in_string(&p.span(), 0, e))?;
        params.push(param);
    }
    let literal = |s: &Spanned<String>| {
        let t = parse_template(s.get_ref(), &params)
            .map_err(|e| file.error_in_string(&s.span(), e.at(), e))?;
        // Disturbance parameters range over whatever their types admit, so only the
        // predicate and the constants are checked.
        t.atom
            .check(vocabulary, None)
            .map_err(|e| file.error_in_string(&s.span(), 0, e))?;
        Ok::<_, ScenarioError>(t)
    };
    let pre = raw.pre.iter().map(literal).collect::<Result<Vec<_>, _>>()?;
    let (add, del) = crate::scenario::effect_templates(file, &raw.add, &raw.del, literal)?;
    if add.is_empty() && del.is_empty() {
        return Err(file.error_in_string(
            &raw.description.span(),
            0,
            "a disturbance must change something: give `add` or `del`",
        ));
    }
    Ok(Disturbance {
        description: raw.description.get_ref().trim().to_string(),
        params,
        pre,
        add,
        del,
    })
}

/// Why a disturbance parameter could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
enum ParamError {
    #[error("expected `name: type` (e.g. `a: cube`, `x: item except makable`)")]
    Form,
    #[error("parameter {name:?} has no type")]
    NoType { name: String },
    #[error("unknown type or object {name:?}")]
    UnknownType { name: String },
}

/// `name: type`, `name: a|b`, `name: type except other` (the skill parameter syntax).
fn parse_param(text: &str, vocabulary: &Vocabulary) -> Result<Param, ParamError> {
    let Some((name, spec)) = text.split_once(':') else {
        return Err(ParamError::Form);
    };
    let split = |s: &str| -> Vec<String> {
        s.split('|')
            .map(|t| t.trim().to_string())
            .filter(|t| !t.is_empty())
            .collect()
    };
    let (types, except) = match spec.split_once(" except ") {
        Some((t, e)) => (split(t), split(e)),
        None => (split(spec), Vec::new()),
    };
    if types.is_empty() {
        return Err(ParamError::NoType {
            name: name.trim().to_string(),
        });
    }
    if let Some(t) = types
        .iter()
        .chain(&except)
        .find(|t| !vocabulary.is_type(t) && vocabulary.object(t).is_none())
    {
        return Err(ParamError::UnknownType { name: t.clone() });
    }
    Ok(Param {
        name: name.trim().to_string(),
        types,
        except,
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::domain::skill::Term;

    const HEAD: &str = r#"
[scenario]
name = "t"
[objects]
cube = ["red", "blue"]
[[predicates]]
name = "on"
args = ["cube", "cube"]
description = "a lies on b"
"#;

    fn config(tail: &str) -> Result<VerifyConfig, ScenarioError> {
        let s = Scenario::from_text(Path::new("t.toml"), format!("{HEAD}{tail}")).unwrap();
        VerifyConfig::from_scenario(&s)
    }

    #[test]
    fn reads_disturbances_and_properties() {
        let c = config(
            r#"
[verify]
properties = ['never "red" on "blue" & "blue" on "red"']
action_failures = true
[[verify.disturbances]]
description = "a human may put any cube on any cube"
params = ["a: cube", "b: cube"]
add = ['"{a}" on "{b}"']
del = ['"{a}" on "{*}"']
"#,
        )
        .unwrap();
        assert!(c.action_failures);
        assert_eq!(c.properties.len(), 1);
        assert_eq!(c.disturbances[0].params.len(), 2);
        assert_eq!(c.disturbances[0].del[0].args[1], Term::Every);
    }

    #[test]
    fn errors_are_located() {
        let tail = "\n[verify]\nproperties = [\"always on_x\"]\n";
        let e = config(tail).unwrap_err();
        assert_eq!(e.line, HEAD.lines().count() + 3, "{e}");
        let tail = "\n[[verify.disturbances]]\ndescription = \"x\"\nparams = [\"a: sphere\"]\nadd = ['\"{a}\" on \"red\"']\n";
        let e = config(tail).unwrap_err();
        assert!(e.message.contains("sphere"), "{e}");
        let tail = "\n[[verify.disturbances]]\ndescription = \"x\"\nadd = ['\"{b}\" on \"red\"']\n";
        let e = config(tail).unwrap_err();
        assert!(e.message.contains("not a parameter"), "{e}");
        let tail = "\n[verify]\nbogus = 1\n";
        assert!(config(tail).unwrap_err().message.contains("bogus"));
    }
}
