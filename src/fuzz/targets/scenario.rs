//! Scenario TOML (`Scenario::from_text`, the loader `Scenario::load` uses), then the world
//! and the verification settings the scenario describes (`world::load`,
//! `VerifyConfig::from_scenario`). The input is read as a file beside the repository's
//! scenarios, so its `extends` and `example_pool` reach the real base files.
//!
//! Properties: a loaded scenario's goal prints back to text that `parse_goal` reads as the
//! same goal, and its expected fixes read too; the facts of the world it builds print and
//! read back the same; an error in the input names a line of it and a column inside that
//! line (or no place at all, line 0 and column 0).

use crate::fuzz::Material;
use std::path::{Path, PathBuf};

use super::{Rng, Target, Violation, check_line_column, ensure, random_formula, strings, text_of};
use crate::domain::{Atom, Condition};
use crate::fuzz::Corpus;
use crate::scenario::{Scenario, ScenarioError};
use crate::verify::VerifyConfig;

pub struct ScenarioTarget {
    material: Material,
    root: PathBuf,
    /// Every file read as a base or pool, by path, to check errors located in them.
    files: Vec<(PathBuf, String)>,
    /// Loaded scenarios' texts and atoms, for generated goals.
    scenes: Vec<(String, Vec<Atom>)>,
}

impl ScenarioTarget {
    pub fn new(corpus: &Corpus) -> ScenarioTarget {
        let scenes = corpus
            .scenarios
            .iter()
            .filter_map(|s| {
                let text = corpus
                    .toml_files
                    .iter()
                    .find(|(p, _)| *p == s.path)?
                    .1
                    .clone();
                Some((text, super::atoms_of(&s.scenario.domain, 30)))
            })
            .collect();
        ScenarioTarget {
            material: Material {
                seeds: corpus
                    .toml_files
                    .iter()
                    .map(|(_, t)| t.as_bytes().to_vec())
                    .collect(),
                tokens: strings(&[
                    "[scenario]\n",
                    "[[skills]]\n",
                    "[[predicates]]\n",
                    "[objects]\n",
                    "[world]\n",
                    "[verify]\n",
                    "[[examples]]\n",
                    "[[conventions]]\n",
                    "[world.solids.\"x\"]\n",
                    "name = ",
                    "goal = ",
                    "extends = ",
                    "example_pool = ",
                    "instruction = ",
                    "expected_fix = [",
                    "params = [",
                    "pre = [",
                    "add = [",
                    "del = [",
                    "args = [",
                    "cost = ",
                    "ticks = ",
                    "values = [{ name = \"force\", unit = \"N\", min = 1, max = 0 }]\n",
                    "kind = \"cell\"\n",
                    "kind = \"symbolic\"\n",
                    "properties = ['never \"red cube\" grasped']\n",
                    "\"\"\"",
                    "'''",
                    "\\u0000",
                    "\\U0010FFFF",
                    "\\uD800",
                    "\\",
                    "= [",
                    "{ ",
                    " }",
                    "1979-05-27T07:32:00Z",
                    "+inf",
                    "0b101",
                    "0o7",
                    "1_000",
                    "{*}",
                    "\"{x}\"",
                    "x: item",
                    " except ",
                    "|",
                    "\"any object\"",
                ]),
                brackets: super::pairs(&[("[", "]"), ("{a = ", "}"), ("[[", "]]"), ("\"", "\"")]),
            },
            root: corpus.root.clone(),
            files: corpus.toml_files.clone(),
            scenes,
        }
    }

    /// Where the input is read as if it were a file: beside the files its `extends` names.
    fn path_for(&self, text: &str) -> PathBuf {
        let dir = if text.contains("../../../") {
            "tests/fixtures/scenarios"
        } else if text.contains("\"../") {
            "scenarios/cell/params"
        } else if text.contains("cafe") {
            "scenarios/cafe"
        } else {
            "scenarios/cell"
        };
        self.root.join(dir).join("fuzz-input.toml")
    }

    fn located(&self, e: &ScenarioError, path: &Path, text: &str) -> Result<(), Violation> {
        if e.line == 0 {
            return ensure(
                e.column == 0,
                "a scenario error without a line has no column",
                || e.to_string(),
            );
        }
        let file_text = if e.file == path {
            Some(text)
        } else {
            self.files
                .iter()
                .find(|(p, _)| *p == e.file)
                .map(|(_, t)| t.as_str())
        };
        match file_text {
            Some(t) => check_line_column(
                t,
                e.line,
                e.column,
                "a scenario error names a place in its file",
            ),
            None => Ok(()),
        }
    }
}

impl Target for ScenarioTarget {
    fn name(&self) -> &'static str {
        "scenario"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        if rng.chance(10) {
            let depth = rng
                .pick(&[100usize, 127, 128, 129, 1000, 5000])
                .copied()
                .unwrap_or(100);
            let (open, close) = if rng.chance(50) {
                ("[", "]")
            } else {
                ("{a = ", "}")
            };
            return format!("x = {}1{}\n", open.repeat(depth), close.repeat(depth)).into_bytes();
        }
        if rng.chance(2) {
            // A base without end, or one that is not text: read only up to the limit.
            let base = rng
                .pick(&["/dev/zero", "/dev/urandom"])
                .copied()
                .unwrap_or("/dev/zero");
            return format!("extends = {base:?}\n[scenario]\nname = \"x\"\n").into_bytes();
        }
        let Some((text, atoms)) = rng.pick(&self.scenes) else {
            return Vec::new();
        };
        // The scenario with another goal over its own atoms.
        let depth = rng.small(4);
        let goal = random_formula(rng, atoms, depth).to_string();
        let mut out = String::new();
        for line in text.lines() {
            if line.starts_with("goal = ") {
                out.push_str(&format!("goal = {:?}\n", goal));
            } else {
                out.push_str(line);
                out.push('\n');
            }
        }
        out.into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        let path = self.path_for(&text);
        let scenario = match Scenario::from_text(&path, text.as_ref()) {
            Ok(s) => s,
            Err(e) => return self.located(&e, &path, &text),
        };
        if let Some(goal) = &scenario.goal {
            let printed = goal.to_string();
            let back = scenario.parse_goal(&printed);
            ensure(
                back.as_ref() == Ok(&goal.flatten()),
                "a scenario's goal prints back the same",
                || format!("{printed:?} read back as {back:?}"),
            )?;
        }
        for fix in &scenario.expected_fix {
            ensure(
                scenario.parse_goal(fix).is_ok(),
                "a scenario's expected fix reads",
                || fix.clone(),
            )?;
        }
        if let Err(e) = VerifyConfig::from_scenario(&scenario) {
            self.located(&e, &path, &text)?;
        }
        match crate::world::load(&scenario) {
            Ok(world) => {
                for fact in world.facts() {
                    let back = Condition::parse(&fact.to_string());
                    ensure(
                        back.as_ref() == Ok(&fact),
                        "a world's facts print back the same",
                        || format!("{fact} read back as {back:?}"),
                    )?;
                }
                Ok(())
            }
            Err(e) => self.located(&e, &path, &text),
        }
    }
}
