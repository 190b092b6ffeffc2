//! Learned knowledge: the preconditions people kept from approved fixes, as rules of the
//! domain's skills, in one file beside the policies (`knowledge.toml`), with where each
//! came from. Every planning command adds the rules of its scenario's domain to the
//! skills, so a new task plans them from the start (no failure, no model call).
//!
//! A rule is checked before it is kept (`check.rs`): it must fit the skill, must not
//! contradict what the skill declares, and every goal of the domain must still plan.
//!
//! The file is written atomically (`store::write_atomic`): a crash never leaves half of it.
//! A change is made under a lock (`knowledge.toml.lock` beside it) to the file as it is
//! then, read again: sessions sharing a policy directory keep each other's rules.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::domain::{ActionCall, Condition, LearnError, LearnedRule};
use crate::scenario::Scenario;

mod check;
pub mod examples;

pub use check::{Refusal, Unplannable, check_rule, domain_scenarios, offered_rule, rule_for_fix};

/// Each condition of the approved changes `kept` in a tree, with the action it was
/// inserted before and who proposed it: the fixes that may become rules.
pub fn kept_conditions(
    kept: &[(crate::session::Proposal, String)],
) -> impl Iterator<Item = (&ActionCall, &Condition, &str)> {
    kept.iter().flat_map(|(proposal, author)| match proposal {
        crate::session::Proposal::Conditions {
            action, conditions, ..
        } => conditions
            .iter()
            .map(|c| (action, c, author.as_str()))
            .collect::<Vec<_>>(),
        crate::session::Proposal::Value { .. } => Vec::new(),
    })
}

/// The file's name inside the policy directory.
pub const FILE_NAME: &str = "knowledge.toml";

const VERSION: u32 = 1;

/// A kept rule with its provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KeptRule {
    pub id: String,
    /// The domain's base file stem (`cell`, `cafe`): rules apply only there.
    pub domain: String,
    pub skill: String,
    /// The condition, the action's objects positional (`~"any object" on "{1}"`).
    pub requires: String,
    /// Kept only for an action on these objects.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub only: Option<Vec<String>>,
    pub kept_at: String,
    /// The scenario file the fix was made in.
    pub scenario: String,
    /// The failing action and the condition as approved.
    pub action: String,
    pub condition: String,
    /// Who proposed the fix (a model's name, a person) and how it was kept.
    pub proposed_by: String,
    pub kept_by: String,
}

/// Where a kept rule came from: the fix, in which scenario, who proposed and who kept it.
#[derive(Debug, Clone)]
pub struct Provenance<'a> {
    pub scenario_file: String,
    pub action: &'a ActionCall,
    pub condition: &'a Condition,
    pub proposed_by: String,
    pub kept_by: String,
}

impl KeptRule {
    /// `rule` of `scenario`'s domain with its provenance, kept now (the id is given when
    /// it is kept).
    pub fn new(rule: &LearnedRule, scenario: &Scenario, from: Provenance) -> KeptRule {
        KeptRule {
            id: String::new(),
            domain: domain_of(scenario),
            skill: rule.skill.clone(),
            requires: rule.requires.clone(),
            only: rule.only.clone(),
            kept_at: crate::session::policy::now_rfc3339(),
            scenario: from.scenario_file,
            action: from.action.to_string(),
            condition: from.condition.to_string(),
            proposed_by: from.proposed_by,
            kept_by: from.kept_by,
        }
    }

    pub fn rule(&self) -> LearnedRule {
        LearnedRule {
            id: self.id.clone(),
            skill: self.skill.clone(),
            requires: self.requires.clone(),
            only: self.only.clone(),
        }
    }
}

#[derive(Debug, Default, Serialize, Deserialize)]
struct KnowledgeFile {
    version: u32,
    #[serde(default)]
    rules: Vec<KeptRule>,
}

#[derive(Debug, thiserror::Error)]
pub enum KnowledgeError {
    #[error("cannot read {}: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {message}", path.display())]
    Parse { path: PathBuf, message: String },
    #[error("cannot write {}: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("no rule {id:?} in {} (rules: {known})", path.display())]
    NoSuchRule {
        id: String,
        path: PathBuf,
        known: String,
    },
    #[error("no kept example {id:?} in {} (examples: {known})", path.display())]
    NoSuchExample {
        id: String,
        path: PathBuf,
        known: String,
    },
    #[error(transparent)]
    Learn(#[from] LearnError),
    #[error("the correction is not kept: {0}")]
    NotKept(#[from] examples::NotKept),
}

/// The rules and the corrected readings kept so far, and where they live.
#[derive(Debug, Clone)]
pub struct Knowledge {
    pub path: PathBuf,
    pub rules: Vec<KeptRule>,
    /// Corrections of readings kept as worked examples, in the same directory.
    pub examples: examples::KeptExamples,
}

/// The domain a scenario belongs to: the stem of the base file of its `extends` chain.
pub fn domain_of(scenario: &Scenario) -> String {
    scenario
        .files
        .first()
        .and_then(|f| f.path.file_stem())
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
}

impl Knowledge {
    /// The knowledge file of a policy directory.
    pub fn path_in(policy_dir: &Path) -> PathBuf {
        policy_dir.join(FILE_NAME)
    }

    /// Read the file and the kept examples beside it; a missing file is no knowledge yet.
    pub fn open(path: &Path) -> Result<Knowledge, KnowledgeError> {
        let examples = examples::KeptExamples::open(&path.with_file_name(examples::FILE_NAME))?;
        Ok(Knowledge {
            path: path.to_path_buf(),
            rules: Knowledge::open_rules(path)?,
            examples,
        })
    }

    /// The rules of the knowledge file.
    fn open_rules(path: &Path) -> Result<Vec<KeptRule>, KnowledgeError> {
        let text = match crate::store::read_text(path, crate::store::SMALL_FILE_BYTES) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(Vec::new());
            }
            Err(source) => {
                return Err(KnowledgeError::Read {
                    path: path.to_path_buf(),
                    source,
                });
            }
        };
        let file: KnowledgeFile = toml::from_str(&text).map_err(|e| KnowledgeError::Parse {
            path: path.to_path_buf(),
            message: located(&text, &e),
        })?;
        if file.version != VERSION {
            return Err(KnowledgeError::Parse {
                path: path.to_path_buf(),
                message: format!(
                    "version {} is not one this betr reads (it reads {VERSION})",
                    file.version
                ),
            });
        }
        Ok(file.rules)
    }

    /// The rules of `domain`.
    pub fn rules_of<'a>(&'a self, domain: &'a str) -> impl Iterator<Item = &'a KeptRule> + 'a {
        self.rules.iter().filter(move |r| r.domain == domain)
    }

    /// Add the kept examples of the scenario's domain that fit the scene to its example
    /// pool. An example naming what the scene lacks is left out and said in the returned
    /// notes, with each line of the examples' file that did not read; the ids added come
    /// first.
    pub fn apply_examples(&self, scenario: &mut Scenario) -> (Vec<String>, Vec<String>) {
        let mut notes = self.examples.problems.clone();
        let (kept, left_out) = self.examples.for_scenario(scenario);
        notes.extend(left_out);
        let mut added = Vec::new();
        for example in kept {
            if let crate::scenario::ExampleSource::Kept(id) = &example.source {
                added.push(id.clone());
            }
            scenario.examples.push(example);
        }
        (added, notes)
    }

    /// Add the rules of the scenario's domain to its skills. A rule that does not fit this
    /// scenario's skills (another scenario may declare them differently) is left out and
    /// said in the returned notes; the ids applied come first.
    pub fn apply(&self, scenario: &mut Scenario) -> (Vec<String>, Vec<String>) {
        let domain = domain_of(scenario);
        let mut applied = Vec::new();
        let mut notes = Vec::new();
        for kept in self.rules_of(&domain) {
            match scenario.domain.learn(&kept.rule()) {
                Ok(()) => applied.push(kept.id.clone()),
                Err(LearnError::UnknownSkill { .. }) => {}
                Err(e) => notes.push(format!("{e}; left out")),
            }
        }
        (applied, notes)
    }

    /// The rule with this id.
    pub fn get(&self, id: &str) -> Result<&KeptRule, KnowledgeError> {
        self.rules
            .iter()
            .find(|r| r.id == id)
            .ok_or_else(|| self.no_such_rule(id))
    }

    fn no_such_rule(&self, id: &str) -> KnowledgeError {
        KnowledgeError::NoSuchRule {
            id: id.to_string(),
            path: self.path.clone(),
            known: known_ids(self.rules.iter().map(|r| r.id.as_str())),
        }
    }

    /// Keep `rule` (its id is assigned here) and write the file; with whether it is
    /// new. The rules kept meanwhile by another session are read again first and kept
    /// too; a rule the file holds already, or holds for every object where this one is
    /// for some, is not kept again (the one kept is returned, not new).
    pub fn keep(&mut self, mut rule: KeptRule) -> Result<(KeptRule, bool), KnowledgeError> {
        let _lock = self.lock()?;
        self.reread()?;
        if let Some(same) = self.rules.iter().find(|r| {
            (&r.domain, &r.skill, &r.requires) == (&rule.domain, &rule.skill, &rule.requires)
                && (r.only.is_none() || r.only == rule.only)
        }) {
            return Ok((same.clone(), false));
        }
        rule.id = next_id('r', self.rules.iter().map(|r| r.id.as_str()));
        self.rules.push(rule.clone());
        if let Err(e) = self.write() {
            self.rules.pop();
            return Err(e);
        }
        Ok((rule, true))
    }

    /// Take a rule out and write the file (as it is now, read again).
    pub fn revoke(&mut self, id: &str) -> Result<KeptRule, KnowledgeError> {
        let _lock = self.lock()?;
        self.reread()?;
        let Some(at) = self.rules.iter().position(|r| r.id == id) else {
            return Err(self.no_such_rule(id));
        };
        let removed = self.rules.remove(at);
        if let Err(e) = self.write() {
            self.rules.insert(at, removed);
            return Err(e);
        }
        Ok(removed)
    }

    /// An exclusive lock of the knowledge file, held until the returned file is dropped.
    /// The lock is on `knowledge.toml.lock` beside it, since the file itself is replaced
    /// by each write.
    fn lock(&self) -> Result<std::fs::File, KnowledgeError> {
        lock_beside(&self.path)
    }

    /// The rules as the file holds them now.
    fn reread(&mut self) -> Result<(), KnowledgeError> {
        self.rules = Knowledge::open_rules(&self.path)?;
        Ok(())
    }

    fn write(&self) -> Result<(), KnowledgeError> {
        let file = KnowledgeFile {
            version: VERSION,
            rules: self.rules.clone(),
        };
        let body = toml::to_string_pretty(&file).map_err(|e| KnowledgeError::Parse {
            path: self.path.clone(),
            message: e.to_string(),
        })?;
        let text = format!(
            "# betr learned knowledge: preconditions kept from approved fixes.\n\
             # `betr knowledge list|show|revoke` reads and changes this file.\n{body}"
        );
        crate::store::write_atomic(&self.path, text.as_bytes()).map_err(|source| {
            KnowledgeError::Write {
                path: self.path.clone(),
                source,
            }
        })
    }
}

/// An exclusive lock for changing `path`, on the file of its name with `.lock` added
/// beside it (the file itself is replaced by writes), held until the returned file is
/// dropped.
pub(super) fn lock_beside(path: &Path) -> Result<std::fs::File, KnowledgeError> {
    let mut name = path.as_os_str().to_os_string();
    name.push(".lock");
    let lock = PathBuf::from(name);
    let failed = |source| KnowledgeError::Write {
        path: lock.clone(),
        source,
    };
    if let Some(dir) = lock.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(failed)?;
    }
    let file = std::fs::File::options()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock)
        .map_err(failed)?;
    file.lock().map_err(failed)?;
    Ok(file)
}

/// `ids` in a list for an error, `none` when there are none.
pub(super) fn known_ids<'a>(ids: impl Iterator<Item = &'a str>) -> String {
    let known: Vec<&str> = ids.collect();
    if known.is_empty() {
        "none".into()
    } else {
        known.join(", ")
    }
}

/// The id after the largest of `ids` that are `prefix` and a number (`r3` → `r4`).
pub(super) fn next_id<'a>(prefix: char, ids: impl Iterator<Item = &'a str>) -> String {
    let last = ids
        .filter_map(|id| id.strip_prefix(prefix)?.parse::<u32>().ok())
        .max()
        .unwrap_or(0);
    format!("{prefix}{}", last + 1)
}

/// The text of `path`, empty when it does not exist yet.
pub(super) fn read_or_empty(path: &Path) -> Result<String, KnowledgeError> {
    match crate::store::read_text(path, crate::store::SMALL_FILE_BYTES) {
        Ok(t) => Ok(t),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(String::new()),
        Err(source) => Err(KnowledgeError::Read {
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// A TOML error with its line and column.
fn located(text: &str, e: &toml::de::Error) -> String {
    let message = e.message().to_string();
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("line {line}, column {column}: {message}")
        }
        None => message,
    }
}

/// A condition of a tree that a learned rule put there.
#[derive(Debug, Clone, PartialEq)]
pub struct LearnedNode {
    pub node: crate::bt::NodeId,
    pub condition: Condition,
    pub action: ActionCall,
    pub rules: Vec<String>,
}

/// The conditions of `tree` guarding an action because a learned rule of `domain` asks
/// for them: the condition before the action in its sequence, bare or as the first child
/// of a fallback (the shape backchaining gives a precondition).
pub fn learned_in_tree(domain: &crate::domain::Domain, tree: &crate::bt::Tree) -> Vec<LearnedNode> {
    use crate::bt::NodeKind;
    let mut out = Vec::new();
    for (id, action) in tree.actions() {
        let Ok(Some(parent)) = tree.parent(id) else {
            continue;
        };
        let Ok(siblings) = tree.children(parent) else {
            continue;
        };
        for &sibling in siblings.iter().take_while(|&&s| s != id) {
            let guard = match tree.kind(sibling) {
                Ok(NodeKind::Condition(_)) => Some(sibling),
                Ok(NodeKind::Fallback) => {
                    tree.children(sibling).ok().and_then(|c| c.first().copied())
                }
                _ => None,
            };
            let Some(guard) = guard else { continue };
            let Ok(NodeKind::Condition(c)) = tree.kind(guard) else {
                continue;
            };
            let rules = domain.rules_requiring(action, c);
            if !rules.is_empty() {
                out.push(LearnedNode {
                    node: guard,
                    condition: c.clone(),
                    action: action.clone(),
                    rules,
                });
            }
        }
    }
    out
}
