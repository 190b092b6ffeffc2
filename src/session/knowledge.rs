//! Learned knowledge: the preconditions people kept from approved fixes, as rules of the
//! domain's skills, in one file beside the policies (`knowledge.toml`), with where each
//! came from. Every planning command adds the rules of its scenario's domain to the
//! skills, so a new task plans them from the start (no failure, no model call).
//!
//! A rule is checked before it is kept: it must fit the skill, must not contradict what
//! the skill declares (the negation of a declared precondition, or the skill's own
//! effect), and every scenario of the domain (the files beside the domain's base file)
//! must still plan its goal in the planner's model with it.
//!
//! The file is written atomically (`store::write_atomic`): a crash never leaves half of it.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::domain::{ActionCall, Condition, LearnError, LearnedRule, Scenario};
use crate::planner::Outcome;
use crate::verify::plan_in_model;

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
    #[error(transparent)]
    Learn(#[from] LearnError),
}

/// Why a rule was not kept.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Refusal {
    #[error("{0}")]
    DoesNotFit(LearnError),
    #[error(
        "it contradicts {skill}'s declared precondition {declared}: the action could never run"
    )]
    ContradictsPrecondition { skill: String, declared: String },
    #[error(
        "it asks for {skill}'s own effect {effect} before the action, which is there to make it true"
    )]
    ContradictsEffect { skill: String, effect: String },
    #[error("with it, {scenario}'s goal {goal} can no longer be planned ({why})")]
    GoalUnplannable {
        scenario: String,
        goal: String,
        why: String,
    },
    #[error("it is kept already as {0}")]
    Known(String),
}

/// The rules kept so far, and where they live.
#[derive(Debug, Clone)]
pub struct Knowledge {
    pub path: PathBuf,
    pub rules: Vec<KeptRule>,
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

    /// Read the file; a missing file is no knowledge yet.
    pub fn open(path: &Path) -> Result<Knowledge, KnowledgeError> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(Knowledge {
                    path: path.to_path_buf(),
                    rules: Vec::new(),
                });
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
        Ok(Knowledge {
            path: path.to_path_buf(),
            rules: file.rules,
        })
    }

    /// The rules of `domain`.
    pub fn rules_of<'a>(&'a self, domain: &'a str) -> impl Iterator<Item = &'a KeptRule> + 'a {
        self.rules.iter().filter(move |r| r.domain == domain)
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
        let known: Vec<&str> = self.rules.iter().map(|r| r.id.as_str()).collect();
        KnowledgeError::NoSuchRule {
            id: id.to_string(),
            path: self.path.clone(),
            known: if known.is_empty() {
                "none".into()
            } else {
                known.join(", ")
            },
        }
    }

    /// Keep `rule` (its id is assigned here) and write the file.
    pub fn keep(&mut self, mut rule: KeptRule) -> Result<KeptRule, KnowledgeError> {
        let next = self
            .rules
            .iter()
            .filter_map(|r| r.id.strip_prefix('r')?.parse::<u32>().ok())
            .max()
            .unwrap_or(0)
            + 1;
        rule.id = format!("r{next}");
        self.rules.push(rule.clone());
        if let Err(e) = self.write() {
            self.rules.pop();
            return Err(e);
        }
        Ok(rule)
    }

    /// Take a rule out and write the file.
    pub fn revoke(&mut self, id: &str) -> Result<KeptRule, KnowledgeError> {
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

/// The rule a fix teaches, as it would be kept: lifted to the action's parameters where
/// the condition names the action's objects, else (nothing to generalise) only for them.
pub fn offered_rule(action: &ActionCall, condition: &Condition, only: bool) -> LearnedRule {
    let lifted = LearnedRule::from_fix(action, condition, false);
    if only || !lifted.generalises() {
        LearnedRule::from_fix(action, condition, true)
    } else {
        lifted
    }
}

/// Whether `rule` may be kept for `scenario`'s domain, given the rules kept already:
/// it fits, contradicts no declaration, and every scenario of the domain still plans.
pub fn check_rule(
    rule: &LearnedRule,
    scenario: &Scenario,
    knowledge: &Knowledge,
) -> Result<(), Refusal> {
    let domain = domain_of(scenario);
    if let Some(same) = knowledge
        .rules_of(&domain)
        .find(|k| k.skill == rule.skill && k.requires == rule.requires && k.only == rule.only)
    {
        return Err(Refusal::Known(same.id.clone()));
    }
    let mut probe = scenario.domain.clone();
    probe.learn(rule).map_err(Refusal::DoesNotFit)?;
    for skill in scenario
        .domain
        .skills
        .iter()
        .filter(|s| s.name == rule.skill)
    {
        let t = rule.template(skill).map_err(Refusal::DoesNotFit)?;
        if let Some(declared) = skill
            .pre
            .iter()
            .find(|p| p.atom == t.atom && p.negated != t.negated)
        {
            return Err(Refusal::ContradictsPrecondition {
                skill: skill.name.clone(),
                declared: template_text(skill, declared),
            });
        }
        if !t.negated && skill.add.contains(&t.atom) {
            return Err(Refusal::ContradictsEffect {
                skill: skill.name.clone(),
                effect: template_text(
                    skill,
                    &crate::domain::skill::LiteralTemplate {
                        atom: t.atom.clone(),
                        negated: false,
                    },
                ),
            });
        }
    }
    // Judged against the rules kept so far, so that only this rule's effect counts.
    let known = |s: &Scenario| {
        let mut s = s.clone();
        knowledge.apply(&mut s);
        s
    };
    let with_rule = |s: &Scenario| {
        let mut s = known(s);
        s.domain.learn(rule).ok().map(|()| s)
    };
    // The domain's worked examples are goals a person may ask for: in this scenario and
    // in the domain's base file (a scenario may declare its skills differently).
    let base = scenario
        .files
        .first()
        .and_then(|f| Scenario::load(&f.path).ok());
    for scene in std::iter::once(scenario).chain(base.as_ref()) {
        let (Some(after), Ok(facts)) = (with_rule(scene), facts_of(scene)) else {
            continue;
        };
        let before = known(scene);
        for example in &scenario.examples {
            let Ok(goal) = scene.parse_goal(&example.goal) else {
                continue;
            };
            if plans(&before, &facts, &goal).is_err() {
                continue;
            }
            if let Err(why) = plans(&after, &facts, &goal) {
                return Err(Refusal::GoalUnplannable {
                    scenario: format!("the worked example {:?}", example.instruction),
                    goal: goal.to_string(),
                    why,
                });
            }
        }
    }
    for path in domain_scenarios(scenario) {
        let Ok(other) = Scenario::load(&path) else {
            continue;
        };
        let Some(goal) = other.goal.clone() else {
            continue;
        };
        let Ok(facts) = facts_of(&other) else {
            continue;
        };
        // Unplannable without the rule too: not the rule's doing.
        if plans(&known(&other), &facts, &goal).is_err() {
            continue;
        }
        let Some(after) = with_rule(&other) else {
            continue;
        };
        if let Err(why) = plans(&after, &facts, &goal) {
            return Err(Refusal::GoalUnplannable {
                scenario: path.display().to_string(),
                goal: goal.to_string(),
                why,
            });
        }
    }
    Ok(())
}

/// The facts true in the scenario's world at the start.
fn facts_of(scenario: &Scenario) -> Result<Vec<Condition>, String> {
    Ok(crate::world::load(scenario)
        .map_err(|e| e.to_string())?
        .facts())
}

/// Whether `goal` plans to success in the model from `facts`.
fn plans(
    scenario: &Scenario,
    facts: &[Condition],
    goal: &crate::goal::Formula,
) -> Result<(), String> {
    let planned = plan_in_model(&scenario.domain, facts, &goal.to_dnf(), &[], &[])
        .map_err(|e| e.to_string())?;
    match planned.plan.outcome {
        Outcome::Success => Ok(()),
        Outcome::Unreachable { condition, .. } => Err(format!("{condition} cannot be achieved")),
        Outcome::ActionFailed { action, error, .. } => Err(format!("{action}! fails: {error}")),
        Outcome::Exhausted { reason } => Err(reason),
    }
}

/// The scenario files of the same domain: every `.toml` under the directory of the
/// domain's base file whose chain starts at the same base file.
pub fn domain_scenarios(scenario: &Scenario) -> Vec<PathBuf> {
    let Some(base) = scenario.files.first().map(|f| f.path.clone()) else {
        return Vec::new();
    };
    let base_canon = std::fs::canonicalize(&base).unwrap_or_else(|_| base.clone());
    let Some(dir) = base.parent() else {
        return Vec::new();
    };
    let mut files = Vec::new();
    collect_toml(dir, &mut files, 3);
    files.sort();
    files
        .into_iter()
        .filter(|p| {
            Scenario::load(p).is_ok_and(|s| {
                s.files.first().is_some_and(|f| {
                    std::fs::canonicalize(&f.path).unwrap_or_else(|_| f.path.clone()) == base_canon
                })
            })
        })
        .collect()
}

fn collect_toml(dir: &Path, out: &mut Vec<PathBuf>, depth: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let path = entry.path();
        if path.is_dir() && depth > 0 {
            collect_toml(&path, out, depth - 1);
        } else if path.extension().is_some_and(|e| e == "toml") {
            out.push(path);
        }
    }
}

fn template_text(
    skill: &crate::domain::Skill,
    t: &crate::domain::skill::LiteralTemplate,
) -> String {
    use crate::domain::skill::Term;
    let atom = crate::domain::Atom {
        predicate: t.atom.predicate.clone(),
        args: t
            .atom
            .args
            .iter()
            .map(|a| match a {
                Term::Param(i) => skill
                    .params
                    .get(*i)
                    .map_or_else(|| "?".into(), |p| format!("{{{}}}", p.name)),
                Term::Const(c) => c.clone(),
                Term::Every => "{*}".into(),
            })
            .collect(),
    };
    Condition {
        atom,
        negated: t.negated,
    }
    .to_string()
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

/// The rule to keep for a fix when nobody is asked (`--yes --learn`): the lifted rule, or,
/// when that is refused, the rule for the fix's objects alone; with every refusal on the
/// way (a narrower rule kept after the lifted one was refused says why).
pub fn rule_for_fix(
    action: &ActionCall,
    condition: &Condition,
    scenario: &Scenario,
    knowledge: &Knowledge,
) -> (Option<LearnedRule>, Vec<(LearnedRule, Refusal)>) {
    let lifted = offered_rule(action, condition, false);
    let only = offered_rule(action, condition, true);
    let mut refused: Vec<(LearnedRule, Refusal)> = Vec::new();
    for rule in [lifted, only] {
        if refused.iter().any(|(r, _)| *r == rule) {
            continue;
        }
        match check_rule(&rule, scenario, knowledge) {
            Ok(()) => return (Some(rule), refused),
            Err(e) => refused.push((rule, e)),
        }
    }
    (None, refused)
}
