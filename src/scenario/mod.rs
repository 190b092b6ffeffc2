//! Scenario files (TOML). A scenario holds what the planner is told (objects, vocabulary,
//! skills, example instructions, the instruction and its expected goal) and, in its
//! `[world]` table, what the world really does; the `world` module reads that table (and
//! the `verify` module its `[verify]` table).
//!
//! A scenario may `extends = "other.toml"`: objects and predicates are added to the base's,
//! a skill name defined in the child replaces every base skill of that name, and the world
//! table is merged by the world module. Every error names the file, line and column.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

mod file;

use crate::domain::skill::{Domain, Param, Skill, ValueParam, parse_template};
use crate::domain::vocabulary::{Object, Predicate, Vocabulary};
use crate::goal::Formula;
use file::{RawFile, RawPool, RawSkill, value_range};

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
}

/// What a request means in a domain beyond its vocabulary ("what is brought to the
/// person goes on the tray"), written by whoever sets the domain up.
#[derive(Debug, Clone, PartialEq)]
pub struct Convention {
    pub text: String,
    /// The objects it speaks of: it applies to a scene that has all of them.
    pub objects: Vec<String>,
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

impl SourceFile {
    pub fn read(path: &Path) -> Result<SourceFile, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
            file: path.to_path_buf(),
            line: 0,
            column: 0,
            message: format!("cannot read scenario file: {e}"),
        })?;
        Ok(SourceFile {
            path: path.to_path_buf(),
            text,
        })
    }

    /// An error at byte `offset` of this file.
    pub fn error_at(&self, offset: usize, message: impl Into<String>) -> ScenarioError {
        let offset = offset.min(self.text.len());
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = self.text[line_start..offset].chars().count() + 1;
        ScenarioError {
            file: self.path.clone(),
            line,
            column,
            message: message.into(),
        }
    }

    /// An error inside a quoted TOML string whose span is `span`, `inner` bytes into its
    /// contents (the opening quote is skipped).
    pub fn error_in_string(
        &self,
        span: &std::ops::Range<usize>,
        inner: usize,
        message: impl Into<String>,
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

/// Where a skill came from, so its errors can point into the right file.
struct SkillSource<'a> {
    raw: &'a RawSkill,
    file: &'a SourceFile,
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
                let pooled: RawPool = SourceFile::read(&pool_path)?.parse()?;
                raw.examples.extend(pooled.examples);
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

    fn build(files: Vec<SourceFile>, raws: Vec<RawFile>) -> Result<Scenario, ScenarioError> {
        let child = files.len() - 1;
        let Some(meta) = raws[child].scenario.as_ref() else {
            return Err(files[child].error_at(0, "missing [scenario] table with at least `name`"));
        };

        let mut vocabulary = Vocabulary::default();
        // Where each object stands in the vocabulary, so a large scene loads in linear time.
        let mut index: HashMap<String, usize> = HashMap::new();
        for (raw, file) in raws.iter().zip(&files) {
            for (ty, names) in &raw.objects {
                for name in names {
                    let n = name.get_ref().trim();
                    if n.is_empty() || n.contains('"') {
                        return Err(file.error_in_string(
                            &name.span(),
                            0,
                            "an object name must be non-empty and contain no quote",
                        ));
                    }
                    match index.get(n).and_then(|&i| vocabulary.objects.get_mut(i)) {
                        Some(o) if !o.types.contains(ty) => o.types.push(ty.clone()),
                        Some(_) => {}
                        None => {
                            index.insert(n.to_string(), vocabulary.objects.len());
                            vocabulary.objects.push(Object {
                                name: n.to_string(),
                                types: vec![ty.clone()],
                            });
                        }
                    }
                }
            }
        }
        for (raw, file) in raws.iter().zip(&files) {
            for p in &raw.predicates {
                let mut arg_types = Vec::new();
                for a in &p.args {
                    let types = split_types(a.get_ref());
                    for t in &types {
                        if !vocabulary.is_type(t) && vocabulary.object(t).is_none() {
                            return Err(file.error_in_string(
                                &a.span(),
                                0,
                                format!("unknown type {t:?} (no object has it)"),
                            ));
                        }
                    }
                    arg_types.push(types);
                }
                let predicate = Predicate {
                    name: p.name.get_ref().clone(),
                    arg_types,
                    description: p.description.clone(),
                };
                match vocabulary
                    .predicates
                    .iter_mut()
                    .find(|q| q.name == predicate.name)
                {
                    Some(q) => *q = predicate,
                    None => vocabulary.predicates.push(predicate),
                }
            }
        }

        // A skill name defined in a later file replaces that name from earlier files.
        let mut sources: Vec<SkillSource> = Vec::new();
        for (raw, file) in raws.iter().zip(&files) {
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
            .map(|s| build_skill(s, &vocabulary))
            .collect::<Result<Vec<_>, _>>()?;

        let file = &files[child];
        let goal = match &meta.goal {
            Some(g) => Some(parse_goal(file, g, &vocabulary)?),
            None => None,
        };
        for fix in &meta.expected_fix {
            parse_goal(file, fix, &vocabulary)?;
        }
        let examples = raws
            .iter()
            .rev()
            .find(|r| !r.examples.is_empty())
            .map(|r| {
                r.examples
                    .iter()
                    .map(|e| Example {
                        instruction: e.instruction.clone(),
                        goal: e.goal.clone(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        let world_kind = raws
            .iter()
            .rev()
            .find_map(|r| r.world.as_ref()?.get("kind")?.as_str().map(str::to_string))
            .unwrap_or_else(|| "symbolic".to_string());
        Ok(Scenario {
            name: meta.name.clone(),
            description: meta.description.clone(),
            instruction: meta.instruction.clone(),
            goal,
            expected_fix: meta
                .expected_fix
                .iter()
                .map(|f| f.get_ref().clone())
                .collect(),
            examples,
            conventions: raws
                .iter()
                .flat_map(|r| &r.conventions)
                .map(|c| Convention {
                    text: c.text.trim().to_string(),
                    objects: c.objects.clone(),
                })
                .collect(),
            domain: Domain { vocabulary, skills },
            world_kind,
            files,
        })
    }

    /// Parse a goal written by a person against this scenario's vocabulary.
    pub fn parse_goal(&self, text: &str) -> Result<Formula, String> {
        let f = Formula::parse(text).map_err(|e| e.to_string())?;
        for atom in f.atoms() {
            self.domain
                .vocabulary
                .check_atom(&atom)
                .map_err(|e| e.to_string())?;
        }
        Ok(f)
    }
}

fn parse_goal(
    file: &SourceFile,
    text: &Spanned<String>,
    vocabulary: &Vocabulary,
) -> Result<Formula, ScenarioError> {
    let f = Formula::parse(text.get_ref())
        .map_err(|e| file.error_in_string(&text.span(), e.at, e.to_string()))?;
    for atom in f.atoms() {
        vocabulary
            .check_atom(&atom)
            .map_err(|e| file.error_in_string(&text.span(), 0, e.to_string()))?;
    }
    Ok(f)
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
    literal: impl Fn(&Spanned<String>) -> Result<crate::domain::skill::LiteralTemplate, ScenarioError>,
) -> Result<
    (
        Vec<crate::domain::skill::AtomTemplate>,
        Vec<crate::domain::skill::AtomTemplate>,
    ),
    ScenarioError,
> {
    let mut added = Vec::new();
    for s in add {
        let t = literal(s)?;
        if t.negated || t.atom.args.contains(&crate::domain::skill::Term::Every) {
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
    let mut params = Vec::new();
    for p in &raw.params {
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
    let literal = |s: &Spanned<String>| {
        let t = parse_template(s.get_ref(), &params)
            .map_err(|m| file.error_in_string(&s.span(), 0, m))?;
        check_template(&t.atom, &params, vocabulary)
            .map_err(|m| file.error_in_string(&s.span(), 0, m))?;
        Ok::<_, ScenarioError>(t)
    };
    let pre = raw.pre.iter().map(literal).collect::<Result<Vec<_>, _>>()?;
    let (add, del) = effect_templates(file, &raw.add, &raw.del, literal)?;
    if !raw.cost.is_finite() || raw.cost < 0.0 {
        return Err(file.error_in_string(&raw.name.span(), 0, "cost must be a finite number >= 0"));
    }
    for v in &raw.values {
        value_range(v).map_err(|m| {
            file.error_in_string(&raw.name.span(), 0, format!("value {:?}: {m}", v.name))
        })?;
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

/// A template's predicate must exist with the right arity, and its constants must fit.
fn check_template(
    t: &crate::domain::skill::AtomTemplate,
    params: &[Param],
    vocabulary: &Vocabulary,
) -> Result<(), String> {
    use crate::domain::skill::Term;
    let Some(pred) = vocabulary.predicate(&t.predicate) else {
        return Err(format!("unknown predicate {:?}", t.predicate));
    };
    if pred.arg_types.len() != t.args.len() {
        return Err(format!(
            "{:?} takes {} argument(s), found {}",
            t.predicate,
            pred.arg_types.len(),
            t.args.len()
        ));
    }
    for (term, types) in t.args.iter().zip(&pred.arg_types) {
        match term {
            Term::Const(c)
                if c != crate::domain::condition::ANY_OBJECT && !vocabulary.fits(c, types) =>
            {
                return Err(format!(
                    "{c:?} is not a known object of type {}",
                    types.join(" or ")
                ));
            }
            Term::Param(i) => {
                let p = &params[*i];
                if !p.candidates(vocabulary).any(|o| vocabulary.fits(o, types)) {
                    return Err(format!(
                        "parameter {:?} ({}) can never fit {:?}'s argument of type {}",
                        p.name,
                        p.types.join("|"),
                        t.predicate,
                        types.join(" or ")
                    ));
                }
            }
            Term::Const(_) | Term::Every => {}
        }
    }
    Ok(())
}
