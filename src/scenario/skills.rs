//! A scenario's skills from the files of its `extends` chain: each checked (its name, its
//! parameters' types, its conditions and effects against the vocabulary, its cost and
//! values), a later file's skill replacing an earlier one of that name, and two skills of
//! one name that could take the same objects refused. Every error points into the file and
//! string it is about.

use toml::Spanned;

use super::file::{RawFile, RawSkill, value_range};
use super::{ScenarioError, SourceFile, effect_templates, split_types};
use crate::domain::skill::{Param, Skill, ValueParam};
use crate::domain::template::parse_template;
use crate::domain::vocabulary::Vocabulary;

/// Where a skill came from, so its errors can point into the right file.
struct SkillSource<'a> {
    raw: &'a RawSkill,
    file: &'a SourceFile,
}

/// The skills of the chain: a skill name defined in a later file replaces that name from
/// earlier files.
pub(super) fn skills(
    files: &[SourceFile],
    raws: &[RawFile],
    vocabulary: &Vocabulary,
) -> Result<Vec<Skill>, ScenarioError> {
    let mut sources: Vec<SkillSource> = Vec::new();
    for (raw, file) in raws.iter().zip(files) {
        let names: Vec<&str> = raw
            .skills
            .iter()
            .map(|s| s.name.get_ref().as_str())
            .collect();
        sources.retain(|s| !names.contains(&s.raw.name.get_ref().as_str()));
        sources.extend(raw.skills.iter().map(|raw| SkillSource { raw, file }));
    }
    let skills = sources
        .iter()
        .map(|s| build_skill(s, vocabulary))
        .collect::<Result<Vec<Skill>, _>>()?;
    // Skills may share a name when they take different objects ("open" a door, "open" a
    // cabinet): an action names its skill by name and objects, so two that could take the
    // same objects leave an action meaning either, and the world would run the first.
    for (later, skill) in skills.iter().enumerate() {
        if let Some(earlier) = skills[..later]
            .iter()
            .position(|e| e.name == skill.name && take_the_same_objects(e, skill, vocabulary))
        {
            let (at, first) = (&sources[later], &sources[earlier]);
            let line = first.file.error_at(first.raw.name.span().start, "").line;
            return Err(at.file.error_in_string(
                &at.raw.name.span(),
                0,
                format!(
                    "the skill {:?} can take the same objects as the {:?} at line {line} of {}, so an action naming it could mean either: give one another name, or parameters of types the other does not take",
                    skill.name,
                    skill.name,
                    first.file.path.display()
                ),
            ));
        }
    }
    Ok(skills)
}

/// Whether some objects fit every parameter of both `a` and `b`.
fn take_the_same_objects(a: &Skill, b: &Skill, vocabulary: &Vocabulary) -> bool {
    a.params.len() == b.params.len()
        && a.params.iter().zip(&b.params).all(|(p, q)| {
            vocabulary
                .objects
                .iter()
                .any(|o| p.admits(vocabulary, &o.name) && q.admits(vocabulary, &o.name))
        })
}

fn build_skill(source: &SkillSource, vocabulary: &Vocabulary) -> Result<Skill, ScenarioError> {
    let raw = source.raw;
    let file = source.file;
    let name = raw.name.get_ref().trim();
    if name.is_empty()
        || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        || !name.starts_with(|c: char| c.is_ascii_alphabetic())
    {
        return Err(file.error_in_string(
            &raw.name.span(),
            0,
            "a skill name is letters, digits and _ (starting with a letter)",
        ));
    }
    let params = skill_params(source, vocabulary)?;
    let literal = |s: &Spanned<String>| {
        let t = parse_template(s.get_ref(), &params)
            .map_err(|e| file.error_in_string(&s.span(), e.at(), e))?;
        t.atom
            .check(vocabulary, Some(&params))
            .map_err(|e| file.error_in_string(&s.span(), 0, e))?;
        Ok::<_, ScenarioError>(t)
    };
    let pre = raw.pre.iter().map(literal).collect::<Result<Vec<_>, _>>()?;
    let (add, del) = effect_templates(file, &raw.add, &raw.del, literal)?;
    if !raw.cost.is_finite() || raw.cost < 0.0 {
        return Err(file.error_in_string(&raw.name.span(), 0, "cost must be a finite number >= 0"));
    }
    for v in &raw.values {
        value_range(v).map_err(|e| file.error_in_string(&raw.name.span(), 0, e))?;
    }
    Ok(Skill {
        name: name.to_string(),
        description: raw.description.clone(),
        params,
        pre,
        add,
        del,
        cost: raw.cost,
        ticks: raw.ticks.max(1),
        values: raw
            .values
            .iter()
            .map(|v| ValueParam {
                name: v.name.clone(),
                unit: v.unit.clone(),
                categories: v.categories.clone(),
                description: v.description.clone(),
                min: v.min,
                max: v.max,
            })
            .collect(),
        learned: Vec::new(),
    })
}

/// A skill's `params`: `name: type`, `name: a|b` or `name: type except other`, each type
/// a type or an object of the vocabulary.
fn skill_params(
    source: &SkillSource,
    vocabulary: &Vocabulary,
) -> Result<Vec<Param>, ScenarioError> {
    let file = source.file;
    let mut params = Vec::new();
    for p in &source.raw.params {
        let Some((pname, spec)) = p.get_ref().split_once(':') else {
            return Err(file.error_in_string(&p.span(), 0, "expected `name: type` (e.g. `item: item`, `target: place|item`, `x: item except makable`)"));
        };
        let (types, except) = match spec.split_once(" except ") {
            Some((t, e)) => (split_types(t), split_types(e)),
            None => (split_types(spec), Vec::new()),
        };
        for t in types.iter().chain(&except) {
            if !vocabulary.is_type(t) && vocabulary.object(t).is_none() {
                return Err(file.error_in_string(
                    &p.span(),
                    0,
                    format!("unknown type or object {t:?}"),
                ));
            }
        }
        params.push(Param {
            name: pname.trim().to_string(),
            types,
            except,
        });
    }
    Ok(params)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::scenario::Scenario;

    const BASE: &str = "[scenario]\nname = \"t\"\n\n[objects]\nitem = [\"Chips\", \"Cup\"]\n\n[[predicates]]\nname = \"Holding\"\nargs = [\"item\"]\ndescription = \"held\"\n\n";

    #[test]
    fn two_skills_of_one_name_that_take_the_same_objects_are_refused_with_both_places() {
        let skill = |name: &str, param: &str| {
            format!(
                "[[skills]]\nname = \"{name}\"\nparams = [\"{param}\"]\nadd = [\"Holding_{{i}}\"]\n\n"
            )
        };
        let text = format!(
            "{BASE}{}{}",
            skill("Raise", "i: item"),
            skill("Raise", "i: item")
        );
        let err = Scenario::from_text(Path::new("twice.toml"), text)
            .expect_err("two Raise on an item")
            .to_string();
        assert!(
            err.contains("twice.toml:18:") && err.contains("line 13"),
            "{err}"
        );
        assert!(err.contains("could mean either"), "{err}");
        // One name over objects no object fits both of is fine.
        let text = format!(
            "{}{}{}",
            BASE.replace(
                "item = [\"Chips\", \"Cup\"]",
                "item = [\"Chips\", \"Cup\"]\nbox = [\"Crate\"]"
            )
            .replace("args = [\"item\"]", "args = [\"item|box\"]"),
            skill("Raise", "i: item"),
            skill("Raise", "i: box")
        );
        Scenario::from_text(Path::new("apart.toml"), text).expect("different objects");
    }
}
