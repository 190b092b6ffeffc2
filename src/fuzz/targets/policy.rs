//! Saved policies (`session::policy::parse`) over the domain of the scenario the header
//! names, and the header readers (`scenario_of`, `parse_node_path`).
//!
//! Properties: a policy that reads is rendered (`render`) to text that reads again and
//! renders the same, with the same tree, fixes and time; a tree error names a line of the
//! input and a column inside that line.

use super::{Rng, Target, Violation, check_line_column, ensure, random_tree, strings, text_of};
use crate::bt;
use crate::domain::{Atom, Domain};
use crate::fuzz::Corpus;
use crate::fuzz::Material;
use crate::fuzz::mutate::random_char;
use crate::session::policy::{
    self, Approval, Fix, Policy, PolicyTreeError, parse_node_path, render, scenario_of,
};

pub struct PolicyTarget {
    material: Material,
    /// Scenario path (relative), domain, atoms, planned tree.
    scenes: Vec<(String, Domain, Vec<Atom>, Option<bt::Tree>)>,
}

impl PolicyTarget {
    pub fn new(corpus: &Corpus) -> PolicyTarget {
        let scenes: Vec<_> = corpus
            .scenarios
            .iter()
            .map(|s| {
                let d = s.scenario.domain.clone();
                let atoms = super::atoms_of(&d, 30);
                (s.rel.clone(), d, atoms, s.planned.clone())
            })
            .collect();
        let seeds = corpus
            .scenarios
            .iter()
            .filter_map(|s| {
                let tree = s.planned.clone()?;
                let policy = Policy {
                    scenario: format!("{} ({})", s.rel, s.scenario.name),
                    instruction: s.scenario.instruction.clone(),
                    goal: s.scenario.goal.as_ref().map(ToString::to_string).unwrap_or_default(),
                    saved_at: policy::rfc3339(1_700_000_000),
                    fixes: vec![Fix {
                        change: "insert ~\"any object\" on \"blue cube\" as the first precondition(s) of grasp \"blue cube\"!".into(),
                        nodes: vec!["0.1.0".into(), "0.1.0.1".into()],
                        model: "fake-model".into(),
                        approval: Approval::Person,
                        at: policy::rfc3339(1_700_000_100),
                    }],
                    tree,
                };
                Some(render(&policy).into_bytes())
            })
            .collect();
        PolicyTarget {
            material: Material {
                seeds,
                tokens: strings(&[
                    "# betr policy\n",
                    "# scenario: ",
                    "# instruction: ",
                    "# goal: ",
                    "# saved at: ",
                    "# fix 1: ",
                    "#   nodes: ",
                    "#   model: ",
                    "; approved by a person; at ",
                    "; auto-approved; at ",
                    "; written by a person; at ",
                    ", ",
                    "root",
                    "0.1.2",
                    "18446744073709551616.1",
                    " (",
                    ")",
                    "sequence\n",
                    "fallback\n",
                    "  ",
                    "?\n",
                    "!\n",
                ]),
                brackets: super::pairs(&[("  ", ""), ("# ", "\n"), ("(", ")")]),
            },
            scenes,
        }
    }

    fn domain_for(&self, text: &str) -> Option<&Domain> {
        let named = scenario_of(text).map(|p| p.to_string_lossy().into_owned());
        let name = named.unwrap_or_default();
        self.scenes
            .iter()
            .find(|(rel, ..)| {
                !name.is_empty() && (rel.ends_with(&name) || name.ends_with(rel.as_str()))
            })
            .or_else(|| self.scenes.first())
            .map(|(_, d, ..)| d)
    }
}

/// Random header text: words, separators the header uses, awkward characters.
fn header_text(rng: &mut Rng) -> String {
    let mut s = String::new();
    for _ in 0..rng.small(24) {
        match rng.below(6) {
            0 => s.push_str(
                rng.pick(&["; ", ": ", ", ", " (", ")", "at "])
                    .copied()
                    .unwrap_or(" "),
            ),
            1 => s.push(random_char(rng)),
            2 => s.push_str(rng.pick(&["\r", "\n", "\t", "  "]).copied().unwrap_or(" ")),
            _ => s.push_str(
                rng.pick(&["red", "cube", "0.1", "x", "approved by a person"])
                    .copied()
                    .unwrap_or("x"),
            ),
        }
    }
    s
}

impl Target for PolicyTarget {
    fn name(&self) -> &'static str {
        "policy"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        let Some((rel, domain, atoms, planned)) = rng.pick(&self.scenes) else {
            return Vec::new();
        };
        let tree = match planned {
            Some(t) if rng.chance(60) => t.clone(),
            _ => {
                let size = rng.small(30);
                random_tree(rng, atoms, domain, size)
            }
        };
        let fixes = (0..rng.small(4))
            .map(|_| Fix {
                change: header_text(rng),
                nodes: (0..rng.small(4)).map(|_| header_text(rng)).collect(),
                model: header_text(rng),
                approval: *rng
                    .pick(&[Approval::Person, Approval::Auto, Approval::Edited])
                    .unwrap_or(&Approval::Person),
                at: header_text(rng),
            })
            .collect();
        let policy = Policy {
            scenario: format!("{rel} ({})", header_text(rng)),
            instruction: rng.chance(70).then(|| header_text(rng)),
            goal: header_text(rng),
            saved_at: header_text(rng),
            fixes,
            tree,
        };
        render(&policy).into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        let Some(domain) = self.domain_for(&text) else {
            return Ok(());
        };
        let policy = match policy::parse(&text, domain) {
            Ok(p) => p,
            Err(PolicyTreeError::Text(e)) => {
                return check_line_column(
                    &text,
                    e.line,
                    e.column,
                    "a policy error names a place in the input",
                );
            }
            Err(PolicyTreeError::Check(_)) => return Ok(()),
        };
        for fix in &policy.fixes {
            for node in &fix.nodes {
                let _ = parse_node_path(node);
            }
        }
        let rendered = render(&policy);
        let back = policy::parse(&rendered, domain);
        let Ok(back) = back else {
            return ensure(false, "a rendered policy reads again", || {
                format!("{rendered:?}: {back:?}")
            });
        };
        let again = render(&back);
        ensure(
            again == rendered,
            "a rendered policy renders the same when read again",
            || format!("{rendered:?} then {again:?}"),
        )?;
        ensure(
            bt::to_text(&back.tree) == bt::to_text(&policy.tree)
                && back.saved_at == policy.saved_at
                && back.fixes.len() == policy.fixes.len()
                && back
                    .fixes
                    .iter()
                    .zip(&policy.fixes)
                    .all(|(a, b)| a.nodes == b.nodes && a.approval == b.approval && a.at == b.at),
            "a rendered policy reads back its tree, time and fixes",
            || format!("{rendered:?}"),
        )
    }
}
