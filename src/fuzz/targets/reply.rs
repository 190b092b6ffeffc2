//! Language-model replies (`llm::reply`): the goal reply and the conditions reply against
//! each domain's vocabulary, the value reply against every value parameter of the
//! scenarios' skills.
//!
//! Properties: an accepted goal uses only atoms of the vocabulary and prints back to text
//! that reads as the same goal; accepted conditions are at least one, distinct, of the
//! vocabulary, and each prints and reads back the same; an accepted number is finite,
//! not negative and in the parameter's unit, an accepted category one of the parameter's;
//! an unknown object is refused, the names it offers instead all objects of the scene;
//! every error says something.

use super::{Rng, Target, Violation, atoms_of, ensure, random_formula, strings, text_of};
use crate::domain::{Atom, Condition, Value, ValueParam, Vocabulary};
use crate::fuzz::Corpus;
use crate::fuzz::Material;
use crate::goal::Formula;
use crate::llm::reply::{self, MIN_SIMILARITY, ReplyError};

pub struct ReplyTarget {
    material: Material,
    vocabularies: Vec<Vocabulary>,
    params: Vec<ValueParam>,
    atoms: Vec<Atom>,
}

impl ReplyTarget {
    pub fn new(corpus: &Corpus) -> ReplyTarget {
        let mut vocabularies: Vec<Vocabulary> = Vec::new();
        let mut params: Vec<ValueParam> = Vec::new();
        let mut atoms = Vec::new();
        for s in &corpus.scenarios {
            let domain = &s.scenario.domain;
            if !vocabularies
                .iter()
                .any(|v| v.predicates == domain.vocabulary.predicates)
            {
                vocabularies.push(domain.vocabulary.clone());
                atoms.extend(atoms_of(domain, 40));
            }
            for p in domain.skills.iter().flat_map(|k| &k.values) {
                if !params
                    .iter()
                    .any(|q| q.unit == p.unit && q.categories == p.categories)
                {
                    params.push(p.clone());
                }
            }
        }
        let mut tokens = strings(&[
            "Goal:",
            "Final goal:",
            "Conditions:",
            "Precondition:",
            "Reasoning:",
            "Parameter value:",
            "value:",
            "```",
            "```json\n",
            "**",
            "- ",
            "* ",
            "• ",
            "1. ",
            "(2) ",
            "`",
            ".",
            "{\"goal\": ",
            "{\"conditions\": ",
            "{\"value\": ",
            "\"unit\": \"N\"",
            "\"predicate\": ",
            "\"args\": [",
            "\"negated\": true",
            "\"reasoning\": \"",
            "none",
            "n/a",
            " mN",
            " kN",
            " N",
            " m/s",
            " mm/s",
            " cm/s",
        ]);
        tokens.extend(atoms.iter().take(30).map(ToString::to_string));
        for v in &vocabularies {
            tokens.extend(v.objects.iter().take(10).map(|o| o.name.clone()));
        }
        tokens.extend(params.iter().flat_map(|p| p.categories.clone()));
        ReplyTarget {
            material: Material {
                seeds: corpus
                    .replies
                    .iter()
                    .map(|r| r.text.as_bytes().to_vec())
                    .collect(),
                tokens,
                brackets: super::pairs(&[("(", ")"), ("[", "]"), ("{\"a\": ", "}"), ("**", "**")]),
            },
            vocabularies,
            params,
            atoms,
        }
    }

    fn goal(&self, text: &str, v: &Vocabulary) -> Result<(), Violation> {
        let answer = match reply::goal(text, v, MIN_SIMILARITY) {
            Ok(a) => a,
            Err(e) => return refusal(&e, v, text),
        };
        for atom in answer.goal.atoms() {
            ensure(
                v.check_atom(&atom).is_ok(),
                "a goal reply's atoms are of the vocabulary",
                || format!("{atom} from {text:?}"),
            )?;
        }
        let printed = answer.goal.to_string();
        let back = Formula::parse(&printed);
        ensure(
            back.as_ref() == Ok(&answer.goal.flatten()),
            "a goal read from a reply prints back to the same goal",
            || format!("{text:?} gave {printed:?}, read back as {back:?}"),
        )
    }

    fn conditions(&self, text: &str, v: &Vocabulary) -> Result<(), Violation> {
        let answer = match reply::conditions(text, v, MIN_SIMILARITY) {
            Ok(a) => a,
            Err(e) => return refusal(&e, v, text),
        };
        let cs = &answer.conditions;
        ensure(
            !cs.is_empty(),
            "a conditions reply proposes at least one",
            || text.to_string(),
        )?;
        for (i, c) in cs.iter().enumerate() {
            ensure(
                !cs[..i].contains(c),
                "proposed conditions are distinct",
                || format!("{c} twice from {text:?}"),
            )?;
            ensure(
                v.check_condition(c).is_ok(),
                "proposed conditions are of the vocabulary",
                || format!("{c} from {text:?}"),
            )?;
            let back = Condition::parse(&c.to_string());
            ensure(
                back.as_ref() == Ok(c),
                "a proposed condition prints back the same",
                || format!("{c} read back as {back:?}"),
            )?;
        }
        Ok(())
    }

    fn value(&self, text: &str, param: &ValueParam) -> Result<(), Violation> {
        let answer = match reply::value(text, param, MIN_SIMILARITY) {
            Ok(a) => a,
            Err(e) => {
                return ensure(
                    !e.to_string().is_empty(),
                    "a reply error says something",
                    || text.to_string(),
                );
            }
        };
        match &answer.value {
            Value::Number { value, unit } => ensure(
                value.is_finite() && *value >= 0.0 && Some(unit) == param.unit.as_ref(),
                "a value reply's number is finite, not negative, in the parameter's unit",
                || format!("{value} {unit} for {:?} from {text:?}", param.unit),
            ),
            Value::Category(c) => ensure(
                param.unit.is_none() && param.categories.contains(c),
                "a value reply's category is one of the parameter's",
                || format!("{c:?} for {:?} from {text:?}", param.categories),
            ),
        }
    }
}

/// A refused reply says something, and an unknown object is offered only names the scene
/// has.
fn refusal(e: &ReplyError, v: &Vocabulary, text: &str) -> Result<(), Violation> {
    ensure(
        !e.to_string().is_empty(),
        "a reply error says something",
        || text.to_string(),
    )?;
    if let ReplyError::UnknownObject {
        object, nearest, ..
    } = e
    {
        ensure(
            v.object(object).is_none() && nearest.iter().all(|n| v.object(n).is_some()),
            "an unknown object is one the scene lacks, and the names offered are the scene's",
            || format!("{e} in {text:?}"),
        )?;
    }
    Ok(())
}

impl Target for ReplyTarget {
    fn name(&self) -> &'static str {
        "reply"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        let depth = rng.small(4);
        let f = random_formula(rng, &self.atoms, depth);
        let literal = |rng: &mut Rng| {
            let atom = rng
                .pick(&self.atoms)
                .cloned()
                .unwrap_or_else(|| Atom::new("Active", ["AC"]));
            if rng.chance(40) {
                Condition::neg(atom).to_string()
            } else {
                atom.to_string()
            }
        };
        let lits: Vec<String> = (0..1 + rng.small(4)).map(|_| literal(rng)).collect();
        let number = format!("{}.{}", rng.below(1000), rng.below(100));
        let text = match rng.below(8) {
            0 => format!("Reasoning: because.\nGoal: {f}\n"),
            1 => format!("**Final goal:**\n```\n{f}\n```"),
            2 => format!("Conditions:\n- {}\n", lits.join("\n- ")),
            3 => format!("Reasoning: x\nConditions: {}", lits.join(", ")),
            4 => format!(
                "Parameter value: {number} {}",
                rng.pick(&["N", "mN", "m/s", ""]).copied().unwrap_or("")
            ),
            5 => serde_json::json!({"reasoning": "r", "goal": f.to_string()}).to_string(),
            6 => serde_json::json!({"goal": [lits.clone()], "conditions": lits}).to_string(),
            _ => serde_json::json!({"value": number, "unit": "N", "reasoning": "r"}).to_string(),
        };
        text.into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        for v in &self.vocabularies {
            self.goal(&text, v)?;
            self.conditions(&text, v)?;
        }
        for p in &self.params {
            self.value(&text, p)?;
        }
        Ok(())
    }
}
