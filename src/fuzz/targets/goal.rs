//! Goal formulas: `Formula::parse`, `Scenario::parse_goal` over the scenarios' vocabularies
//! and `Condition::parse`.
//!
//! Properties: a parsed formula prints and reads back to the same formula (and, when it
//! has few atoms, an equivalent one with the same minimal DNF, whose formula is equivalent
//! too, of at most `MAX_ALTERNATIVES` conjunctions); an error's byte offset lies in the text on a character boundary and its column
//! counts the characters before it; `parse_goal` agrees with `Formula::parse` and accepts
//! only atoms of the vocabulary; a parsed condition prints and reads back the same.

use crate::fuzz::Material;
use std::sync::Arc;

use super::{
    Rng, Target, Violation, atoms_of, check_offset, ensure, pairs, random_formula, strings, text_of,
};
use crate::domain::{Atom, Condition};
use crate::fuzz::Corpus;
use crate::goal::{Formula, MAX_ALTERNATIVES, equivalent, same_dnf};
use crate::scenario::{GoalTextError, Scenario};

/// Formulas with more atoms are not compared by truth table (it doubles per atom).
const TRUTH_TABLE_ATOMS: usize = 8;

pub struct GoalTarget {
    material: Material,
    /// One scenario per domain (the cafe, the cell).
    scenarios: Vec<Arc<Scenario>>,
    atoms: Vec<Atom>,
}

impl GoalTarget {
    pub fn new(corpus: &Corpus) -> GoalTarget {
        let mut scenarios: Vec<Arc<Scenario>> = Vec::new();
        for s in &corpus.scenarios {
            if !scenarios
                .iter()
                .any(|k| k.domain.vocabulary.predicates == s.scenario.domain.vocabulary.predicates)
            {
                scenarios.push(s.scenario.clone());
            }
        }
        let atoms: Vec<Atom> = scenarios
            .iter()
            .flat_map(|s| atoms_of(&s.domain, 60))
            .collect();
        let mut tokens = strings(&["&", "|", "~", "(", ")", " ", "_", "\"any object\"", " on "]);
        tokens.extend(atoms.iter().take(40).map(ToString::to_string));
        GoalTarget {
            material: Material {
                seeds: corpus.goals.iter().map(|g| g.as_bytes().to_vec()).collect(),
                tokens,
                brackets: pairs(&[("(", ")"), ("~", ""), ("~(", ")"), ("( ", " )")]),
            },
            scenarios,
            atoms,
        }
    }

    fn formula(&self, text: &str) -> Result<(), Violation> {
        match Formula::parse(text) {
            Ok(f) => {
                let printed = f.to_string();
                let back = Formula::parse(&printed);
                ensure(
                    back.as_ref() == Ok(&f),
                    "a printed goal reads back the same",
                    || format!("{text:?} printed as {printed:?} reads back as {back:?}"),
                )?;
                if f.atoms().len() <= TRUTH_TABLE_ATOMS {
                    let dnf = f.to_dnf();
                    ensure(
                        equivalent(&f, &dnf.to_formula()) == Ok(true),
                        "a goal's minimal DNF is equivalent to it",
                        || format!("{printed} has the DNF {dnf}"),
                    )?;
                    ensure(
                        same_dnf(&f, &dnf.to_formula()),
                        "a goal's minimal DNF is its own minimal DNF",
                        || format!("{printed} has the DNF {dnf}"),
                    )?;
                    ensure(
                        dnf.0.len() <= MAX_ALTERNATIVES,
                        "a goal read has at most MAX_ALTERNATIVES alternatives",
                        || format!("{printed} has {} alternatives", dnf.0.len()),
                    )?;
                }
                Ok(())
            }
            Err(e) => {
                check_offset(text, e.at, "a goal error's offset is inside the goal")?;
                let column = text.get(..e.at).map(|s| s.chars().count() + 1);
                ensure(
                    column == Some(e.column),
                    "a goal error's column counts the characters before it",
                    || format!("{e} at byte {} of {text:?}", e.at),
                )?;
                ensure(
                    !e.to_string().is_empty(),
                    "a goal error says something",
                    || text.to_string(),
                )
            }
        }
    }

    fn in_scenarios(&self, text: &str) -> Result<(), Violation> {
        let plain = Formula::parse(text);
        for s in &self.scenarios {
            match s.parse_goal(text) {
                Ok(goal) => {
                    ensure(
                        plain.as_ref() == Ok(&goal),
                        "parse_goal reads what parse reads",
                        || format!("{text:?}: {goal} against {plain:?}"),
                    )?;
                    for atom in goal.atoms() {
                        ensure(
                            s.domain.vocabulary.check_atom(&atom).is_ok(),
                            "parse_goal accepts only atoms of the vocabulary",
                            || format!("{atom} in {text:?} ({})", s.name),
                        )?;
                    }
                }
                Err(GoalTextError::Syntax(e)) => {
                    ensure(
                        plain.as_ref().err() == Some(&e),
                        "parse_goal's syntax error is parse's",
                        || format!("{text:?}: {e} against {plain:?}"),
                    )?;
                }
                Err(e @ GoalTextError::Vocabulary { at, .. }) => {
                    ensure(
                        plain.is_ok(),
                        "a vocabulary error is about a goal that parses",
                        || format!("{text:?}: {e}"),
                    )?;
                    ensure(
                        text.is_char_boundary(at) && at <= text.len(),
                        "a vocabulary error points inside the goal, on a character",
                        || format!("{text:?}: {e} at byte {at}"),
                    )?;
                }
            }
        }
        Ok(())
    }

    fn condition(&self, text: &str) -> Result<(), Violation> {
        match Condition::parse(text) {
            Ok(c) => {
                let printed = c.to_string();
                let back = Condition::parse(&printed);
                ensure(
                    back.as_ref() == Ok(&c),
                    "a printed condition reads back the same",
                    || format!("{text:?} printed as {printed:?} reads back as {back:?}"),
                )
            }
            Err(e) => check_offset(text, e.at, "a condition error's offset is inside the text"),
        }
    }
}

impl Target for GoalTarget {
    fn name(&self) -> &'static str {
        "goal"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        if rng.chance(10) {
            // Nesting around the parser's depth limit, balanced or not.
            let depth = rng.between(200, 320);
            let (open, close) = if rng.chance(50) {
                ("(", ")")
            } else {
                ("~", "")
            };
            let inner = random_formula(rng, &self.atoms, 2).to_string();
            return format!("{}{inner}{}", open.repeat(depth), close.repeat(depth)).into_bytes();
        }
        if !self.atoms.is_empty() && rng.chance(4) {
            // Either/or choices joined by '&', around the limit of alternatives (2^10):
            // their DNF doubles with each one.
            let choices: Vec<String> = (0..rng.between(8, 16))
                .map(|_| {
                    let mut pick = || self.atoms[rng.below(self.atoms.len())].to_string();
                    format!("({} | {})", pick(), pick())
                })
                .collect();
            return choices.join(" & ").into_bytes();
        }
        let depth = rng.small(6);
        let f = random_formula(rng, &self.atoms, depth);
        let mut text = f.to_string();
        if rng.chance(30) {
            // Whitespace and redundant parentheses a person might write.
            text = text.replace(" & ", "&").replace(" | ", "\t|\n");
            text = format!("( {text} )");
        }
        text.into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        self.formula(&text)?;
        self.in_scenarios(&text)?;
        self.condition(&text)
    }
}
