//! Scenario files (TOML). A scenario holds what the planner is told (objects, vocabulary,
//! skills, example instructions, the instruction and its expected goal) and, in its
//! `[world]` table, what the world really does; the `world` module reads that table (and
//! the `verify` module its `[verify]` table).
//!
//! A scenario may `extends = "other.toml"`: objects and predicates are added to the base's,
//! a skill name defined in the child replaces every base skill of that name, and the world
//! table is merged by the world module. Every error names the file, line and column.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

mod build;
pub mod catalog;
mod file;
mod shipped;
mod skills;

use crate::domain::Atom;
use crate::domain::names::{MIN_SIMILARITY, did_you_mean, nearest};
use crate::domain::skill::{AtomTemplate, Domain, LiteralTemplate, Term};
use crate::domain::vocabulary::{Vocabulary, VocabularyError};
use crate::goal::{Formula, GoalError};
use file::{RawFile, RawPool};

/// One file of a scenario, kept so later readers (the world) can locate their errors.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceFile {
    pub path: PathBuf,
    pub text: String,
}

/// An instruction with its goal, used as an example in prompts.
#[derive(Debug, Clone, PartialEq)]
pub struct Example {
    pub instruction: String,
    pub goal: String,
    pub source: ExampleSource,
}

/// Where an example of a domain's pool comes from.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum ExampleSource {
    /// Written in the scenario file.
    #[default]
    Written,
    /// Made by betr from the domain itself, for a domain whose file has none.
    Made,
    /// A person's correction of a reading, kept (its id in the knowledge directory).
    Kept(String),
}

impl Example {
    /// An example as a scenario file writes it.
    pub fn written(instruction: impl Into<String>, goal: impl Into<String>) -> Example {
        Example {
            instruction: instruction.into(),
            goal: goal.into(),
            source: ExampleSource::Written,
        }
    }
}

/// What a request means in a domain beyond its vocabulary ("what is brought to the
/// person goes on the tray"), written by whoever sets the domain up.
#[derive(Debug, Clone, PartialEq)]
pub struct Convention {
    pub text: String,
    /// The objects it speaks of: it applies to a scene that has all of them.
    pub objects: Vec<String>,
    /// The same, in a form a goal can be checked against, when the convention gives one.
    pub puts: Option<ConventionPuts>,
}

/// What a convention's words ask for each item they name: "bring me the cup" asks for
/// `relation(cup, place)`.
#[derive(Debug, Clone, PartialEq)]
pub struct ConventionPuts {
    /// The request's words that invoke it ("bring me", "for me").
    pub words: Vec<String>,
    /// A predicate of two arguments: the item, then the place.
    pub relation: String,
    /// One of the convention's objects.
    pub place: String,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    pub name: String,
    pub description: String,
    /// The instruction a person gives in this scenario.
    pub instruction: Option<String>,
    /// The goal that instruction means (what interpretation should produce).
    pub goal: Option<Formula>,
    /// Conditions that fix the scenario's failure (for evaluation, never used to resolve).
    pub expected_fix: Vec<String>,
    pub examples: Vec<Example>,
    /// The domain's conventions, base file first.
    pub conventions: Vec<Convention>,
    pub domain: Domain,
    /// Which simulator runs this scenario (`symbolic`, `cell`).
    pub world_kind: String,
    /// The files read, base first.
    pub files: Vec<SourceFile>,
}

/// An error in a scenario file, located to the character.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}:{column}: {message}", file.display())]
pub struct ScenarioError {
    pub file: PathBuf,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

/// Why a goal written against a scenario's vocabulary was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GoalTextError {
    /// The text is not a goal formula.
    #[error(transparent)]
    Syntax(#[from] GoalError),
    /// An atom of the formula does not fit the vocabulary: where it stands (`at`, a byte
    /// offset, and its column) and the atoms of the vocabulary most like it.
    #[error("column {column}: {error}{}", did_you_mean(nearest))]
    Vocabulary {
        error: VocabularyError,
        at: usize,
        column: usize,
        nearest: Vec<String>,
    },
}

impl GoalTextError {
    /// The byte offset into the goal text the error is about (0: the whole goal).
    pub fn at(&self) -> usize {
        match self {
            GoalTextError::Syntax(e) => e.at,
            GoalTextError::Vocabulary { at, .. } => *at,
        }
    }
}

impl SourceFile {
    pub fn read(path: &Path) -> Result<SourceFile, ScenarioError> {
        let text = crate::store::read_text(path, crate::store::SMALL_FILE_BYTES).map_err(|e| {
            ScenarioError {
                file: path.to_path_buf(),
                line: 0,
                column: 0,
                message: format!("cannot read scenario file: {e}"),
            }
        })?;
        Ok(SourceFile {
            path: path.to_path_buf(),
            text,
        })
    }

    /// An error at byte `offset` of this file.
    pub fn error_at(&self, offset: usize, message: impl std::fmt::Display) -> ScenarioError {
        // An offset into a string's contents lands inside a character when the string
        // holds escapes before a multi-byte character: point at that character.
        let offset = self.text.floor_char_boundary(offset.min(self.text.len()));
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = self.text[line_start..offset].chars().count() + 1;
        ScenarioError {
            file: self.path.clone(),
            line,
            column,
            message: message.to_string(),
        }
    }

    /// An error inside a quoted TOML string whose span is `span`, `inner` bytes into its
    /// contents (the opening quote is skipped).
    pub fn error_in_string(
        &self,
        span: &std::ops::Range<usize>,
        inner: usize,
        message: impl std::fmt::Display,
    ) -> ScenarioError {
        let quote = match self.text.get(span.start..span.start + 3) {
            Some("'''") | Some("\"\"\"") => 3,
            _ => 1,
        };
        self.error_at(span.start + quote + inner, message)
    }

    /// Parse the whole file as `T`, turning TOML errors into located ones.
    pub fn parse<T: for<'de> Deserialize<'de>>(&self) -> Result<T, ScenarioError> {
        toml::from_str(&self.text).map_err(|e| {
            let at = e.span().map_or(0, |s| s.start);
            self.error_at(at, e.message().trim().to_string())
        })
    }
}

impl Scenario {
    /// Read a scenario file (and the files it extends).
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        Self::load_chain(SourceFile::read(path)?)
    }

    /// A scenario from text, as if read from `path` (which names it in errors and anchors
    /// `extends`).
    pub fn from_text(path: &Path, text: impl Into<String>) -> Result<Scenario, ScenarioError> {
        Self::load_chain(SourceFile {
            path: path.to_path_buf(),
            text: text.into(),
        })
    }

    fn load_chain(first: SourceFile) -> Result<Scenario, ScenarioError> {
        let mut files = Vec::new();
        let mut raws = Vec::new();
        let mut pending = Some(first);
        while let Some(file) = pending.take() {
            let p = file.path.clone();
            if files.iter().any(|f: &SourceFile| f.path == p) || files.len() > 8 {
                return Err(ScenarioError {
                    file: p,
                    line: 0,
                    column: 0,
                    message: "`extends` forms a cycle or a chain longer than 8 files".into(),
                });
            }
            let mut raw: RawFile = file.parse()?;
            if let Some(pool) = &raw.example_pool {
                let pool_path = p.parent().unwrap_or(Path::new(".")).join(pool.get_ref());
                if !pool_path.exists() {
                    return Err(file.error_in_string(
                        &pool.span(),
                        0,
                        format!("the example pool {} does not exist", pool_path.display()),
                    ));
                }
                let pool_file = SourceFile::read(&pool_path)?;
                let pooled: RawPool = pool_file.parse()?;
                raw.pooled = Some((pool_file, pooled.examples));
            }
            if let Some(base) = &raw.extends {
                let base_path = p.parent().unwrap_or(Path::new(".")).join(base.get_ref());
                if !base_path.exists() {
                    return Err(file.error_in_string(
                        &base.span(),
                        0,
                        format!("the extended file {} does not exist", base_path.display()),
                    ));
                }
                pending = Some(SourceFile::read(&base_path)?);
            }
            files.push(file);
            raws.push(raw);
        }
        files.reverse();
        raws.reverse();
        Self::build(files, raws)
    }

    /// Parse a goal written by a person against this scenario's vocabulary.
    pub fn parse_goal(&self, text: &str) -> Result<Formula, GoalTextError> {
        goal_in(text, &self.domain.vocabulary)
    }
}

/// A goal formula whose every atom fits `vocabulary`; the first that does not is refused
/// with where it stands and the atoms of the vocabulary most like it.
fn goal_in(text: &str, vocabulary: &Vocabulary) -> Result<Formula, GoalTextError> {
    goal_with_objects(text, vocabulary, true)
}

/// As [`goal_in`]; without `objects_checked`, atoms over objects this scene lacks (a
/// worked example from another situation of the domain) pass when their predicate and
/// its number of arguments fit.
pub(super) fn goal_with_objects(
    text: &str,
    vocabulary: &Vocabulary,
    objects_checked: bool,
) -> Result<Formula, GoalTextError> {
    let f = Formula::parse(text)?;
    for atom in f.atoms() {
        if let Err(error) = vocabulary.check_atom(&atom) {
            let about_objects = matches!(
                error,
                VocabularyError::UnknownObject { .. } | VocabularyError::WrongType(_)
            );
            if about_objects && !objects_checked {
                continue;
            }
            let at = where_in(text, &atom, &error);
            return Err(GoalTextError::Vocabulary {
                nearest: atoms_like(vocabulary, &atom, &error),
                at,
                column: crate::goal::column_of(text, at),
                error,
            });
        }
    }
    Ok(f)
}

/// The byte offset of `atom` in the goal text it was read from: as it prints, else the
/// name the error is about, else the start.
fn where_in(text: &str, atom: &Atom, error: &VocabularyError) -> usize {
    let name = match error {
        VocabularyError::UnknownObject { object, .. } => object.as_str(),
        _ => atom.predicate.as_str(),
    };
    text.find(&atom.to_string())
        .or_else(|| text.find(&format!("\"{name}\"")))
        .or_else(|| text.find(name))
        .unwrap_or(0)
}

/// The atoms of the vocabulary most like `atom` where it names a predicate or an object
/// the vocabulary lacks: the same atom with the most similar name in that place (not one
/// the atom names already).
fn atoms_like(vocabulary: &Vocabulary, atom: &Atom, error: &VocabularyError) -> Vec<String> {
    let min = MIN_SIMILARITY;
    match error {
        VocabularyError::UnknownPredicate { predicate, .. } => {
            let same_arity = vocabulary
                .predicates
                .iter()
                .filter(|p| p.arg_types.len() == atom.args.len())
                .map(|p| p.name.as_str());
            nearest(predicate, same_arity, min)
                .into_iter()
                .map(|predicate| {
                    Atom {
                        predicate,
                        args: atom.args.clone(),
                    }
                    .to_string()
                })
                .collect()
        }
        VocabularyError::UnknownObject { object, .. } => {
            let Some(position) = atom.args.iter().position(|a| a == object) else {
                return Vec::new();
            };
            let types = vocabulary
                .predicate(&atom.predicate)
                .and_then(|p| p.arg_types.get(position))
                .cloned()
                .unwrap_or_default();
            // An object already named elsewhere in the atom is no offer: a thing is not on
            // itself.
            let others = vocabulary
                .objects_fitting(&types)
                .filter(|name| !atom.args.iter().any(|a| a == *name));
            nearest(object, others, min)
                .into_iter()
                .map(|name| {
                    let mut like = atom.clone();
                    like.args[position] = name;
                    like.to_string()
                })
                .collect()
        }
        _ => Vec::new(),
    }
}

/// `place|item` → [place, item]; `item except makable` keeps the exclusion for `Param`.
fn split_types(spec: &str) -> Vec<String> {
    spec.split('|')
        .map(|t| t.trim().to_string())
        .filter(|t| !t.is_empty())
        .collect()
}

/// The `add` and `del` lists of a skill or a disturbance, read with `literal`: atoms only
/// (no `~`), and no `{*}` among the atoms that become true.
pub(crate) fn effect_templates(
    file: &SourceFile,
    add: &[Spanned<String>],
    del: &[Spanned<String>],
    literal: impl Fn(&Spanned<String>) -> Result<LiteralTemplate, ScenarioError>,
) -> Result<(Vec<AtomTemplate>, Vec<AtomTemplate>), ScenarioError> {
    let mut added = Vec::new();
    for s in add {
        let t = literal(s)?;
        if t.negated || t.atom.args.contains(&Term::Every) {
            return Err(file.error_in_string(
                &s.span(),
                0,
                "`add` lists atoms that become true: no `~` and no {*} (put removals in `del`)",
            ));
        }
        added.push(t.atom);
    }
    let mut deleted = Vec::new();
    for s in del {
        let t = literal(s)?;
        if t.negated {
            return Err(file.error_in_string(
                &s.span(),
                0,
                "`del` lists atoms that become false: write them without `~`",
            ));
        }
        deleted.push(t.atom);
    }
    Ok((added, deleted))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_offset_inside_a_character_points_at_that_character() {
        let file = SourceFile {
            path: PathBuf::from("t.toml"),
            text: "a = \"\\\"é{x}\"\n".into(),
        };
        let e = file.error_at(8, "here");
        assert_eq!((e.line, e.column), (1, 8), "{e}");
    }
}
