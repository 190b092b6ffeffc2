//! Preconditions learned from approved fixes, kept as rules of a skill so that the next
//! task plans them from the start.
//!
//! A fix says "`grasp "blue cube"` needs `~"any object" on "blue cube"` first". Lifted, the
//! action's objects become its parameters: `grasp {x}` needs `~"any object" on "{x}"`, for
//! every object. Objects of the condition that are not the action's stay as they are (the
//! vocabulary has no way to say "the counter the item lies on"), which is why a rule can
//! also be kept only for the objects of the fix.
//!
//! A rule is written with positional placeholders (`{1}` is the action's first object), so
//! it applies to every scenario whose skill of that name takes as many objects, whatever
//! the scenario calls its parameters.

use super::action::ActionCall;
use super::condition::Condition;
use super::skill::{Domain, LiteralTemplate, Skill, Term};
use super::template::{TemplateError, parse_template};

/// A precondition of a skill kept from an approved fix.
#[derive(Debug, Clone, PartialEq)]
pub struct LearnedRule {
    /// The rule's name in the knowledge file (`r3`).
    pub id: String,
    pub skill: String,
    /// The condition, its arguments positional: `~"any object" on "{1}"`.
    pub requires: String,
    /// When set, the rule holds only for an action on exactly these objects.
    pub only: Option<Vec<String>>,
}

/// A learned rule as the planner applies it to a skill.
#[derive(Debug, Clone, PartialEq)]
pub struct LearnedPrecondition {
    pub rule: String,
    pub condition: LiteralTemplate,
    pub only: Option<Vec<String>>,
    /// Per skill parameter the condition names, the objects its predicate can take there:
    /// a rule learned for a cup says nothing of a centrifuge that is not an item.
    pub fitting: Fitting,
}

impl LearnedPrecondition {
    /// Whether the rule holds for an action on `args`.
    pub fn applies(&self, args: &[String]) -> bool {
        self.only.as_ref().is_none_or(|only| only == args)
            && self
                .fitting
                .iter()
                .all(|(i, objects)| args.get(*i).is_some_and(|a| objects.contains(a)))
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LearnError {
    #[error("{rule}: no skill named {skill:?} in this domain")]
    UnknownSkill { rule: String, skill: String },
    #[error("{rule}: {skill} takes {arity} object(s), the rule names object {{{position}}}")]
    NoSuchObject {
        rule: String,
        skill: String,
        arity: usize,
        position: usize,
    },
    #[error("{rule}: {skill} takes {arity} object(s), the rule is kept only for {only}")]
    OnlyArity {
        rule: String,
        skill: String,
        arity: usize,
        only: usize,
    },
    #[error("{rule}: {requires:?} is not a condition of this domain: {reason}")]
    Condition {
        rule: String,
        requires: String,
        reason: Box<Misfit>,
    },
}

/// Why a rule's condition does not fit the skill it names.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Misfit {
    #[error(transparent)]
    Template(#[from] TemplateError),
    #[error("{{*}} stands only in a deletion")]
    EveryObject,
    #[error("no object {skill} takes as {{{param}}} fits {predicate}")]
    NoObjectFits {
        skill: String,
        param: String,
        predicate: String,
    },
    #[error("{skill} does not take {}", .objects.join(", "))]
    NotTaken { skill: String, objects: Vec<String> },
}

impl LearnedRule {
    /// The rule a fix teaches: `condition` before `action`, with the action's objects
    /// lifted to its parameters (`only` empty), or kept for these objects alone.
    pub fn from_fix(action: &ActionCall, condition: &Condition, for_these_only: bool) -> Self {
        let mut lifted = condition.clone();
        for arg in &mut lifted.atom.args {
            if let Some(i) = action.args.iter().position(|a| a == arg) {
                *arg = format!("{{{}}}", i + 1);
            }
        }
        LearnedRule {
            id: String::new(),
            skill: action.skill.clone(),
            requires: lifted.to_string(),
            only: for_these_only.then(|| action.args.clone()),
        }
    }

    /// How errors name the rule: by its id once kept.
    fn label(&self) -> String {
        if self.id.is_empty() {
            "the rule".into()
        } else {
            format!("rule {}", self.id)
        }
    }

    /// Whether lifting made the rule hold for other objects than the fix's: the condition
    /// names at least one of the action's objects.
    pub fn generalises(&self) -> bool {
        self.only.is_none() && (1..=9).any(|i| self.requires.contains(&format!("{{{i}}}")))
    }

    /// The objects of the condition that stay fixed when the rule is lifted (not the
    /// action's, and not "any object").
    pub fn fixed_objects(&self) -> Vec<String> {
        let Ok(c) = Condition::parse(&self.requires.replace(['{', '}'], "")) else {
            return Vec::new();
        };
        c.atom
            .args
            .into_iter()
            .filter(|a| a != super::condition::ANY_OBJECT && a.parse::<usize>().is_err())
            .collect()
    }

    /// The rule's condition as a template of `skill`.
    pub fn template(&self, skill: &Skill) -> Result<LiteralTemplate, LearnError> {
        let arity = skill.params.len();
        let mut text = self.requires.clone();
        for (i, p) in skill.params.iter().enumerate().rev() {
            text = text.replace(&format!("{{{}}}", i + 1), &format!("{{{}}}", p.name));
        }
        if let Some(position) = (arity + 1..=arity + 9).find(|i| text.contains(&format!("{{{i}}}")))
        {
            return Err(LearnError::NoSuchObject {
                rule: self.label(),
                skill: skill.name.clone(),
                arity,
                position,
            });
        }
        if let Some(only) = &self.only
            && only.len() != arity
        {
            return Err(LearnError::OnlyArity {
                rule: self.label(),
                skill: skill.name.clone(),
                arity,
                only: only.len(),
            });
        }
        let template =
            parse_template(&text, &skill.params).map_err(|reason| LearnError::Condition {
                rule: self.label(),
                requires: self.requires.clone(),
                reason: Box::new(reason.into()),
            })?;
        if template.atom.args.contains(&Term::Every) {
            return Err(LearnError::Condition {
                rule: self.label(),
                requires: self.requires.clone(),
                reason: Box::new(Misfit::EveryObject),
            });
        }
        Ok(template)
    }

    /// The rule in words: `grasp {x} needs ~"any object" on "{x}"` (the skill's own
    /// parameter names), or with the objects it is kept for.
    pub fn describe(&self, domain: &Domain) -> String {
        let names: Vec<String> = match &self.only {
            Some(only) => only.iter().map(|o| format!("\"{o}\"")).collect(),
            None => domain
                .skills
                .iter()
                .find(|s| s.name == self.skill)
                .map(|s| s.params.iter().map(|p| format!("{{{}}}", p.name)).collect())
                .unwrap_or_default(),
        };
        let mut requires = self.requires.clone();
        for (i, name) in names.iter().enumerate().rev() {
            let bare = name.trim_matches('"');
            requires = requires.replace(&format!("{{{}}}", i + 1), bare);
        }
        let scope = if self.only.is_some() {
            " (only for these objects)"
        } else {
            ""
        };
        format!("{} {} needs {requires}{scope}", self.skill, names.join(" "))
    }
}

/// For each parameter of `skill` that `condition` names, the objects the parameter admits
/// that the predicate takes at that position.
fn fitting(vocabulary: &super::Vocabulary, skill: &Skill, condition: &LiteralTemplate) -> Fitting {
    let Some(predicate) = vocabulary.predicate(&condition.atom.predicate) else {
        return Vec::new();
    };
    let mut out: Vec<(usize, Vec<String>)> = Vec::new();
    for (term, types) in condition.atom.args.iter().zip(&predicate.arg_types) {
        let Term::Param(i) = term else { continue };
        let Some(param) = skill.params.get(*i) else {
            continue;
        };
        let objects: Vec<String> = param
            .candidates(vocabulary)
            .filter(|o| vocabulary.fits(o, types))
            .map(str::to_string)
            .filter(|o| out.iter().all(|(j, os)| j != i || os.contains(o)))
            .collect();
        out.retain(|(j, _)| j != i);
        out.push((*i, objects));
    }
    out
}

/// Per skill parameter a condition names, the objects it may be there.
type Fitting = Vec<(usize, Vec<String>)>;

/// The rule's condition as a template of `skill`, with the objects each parameter it names
/// may be, when the rule fits the skill (its objects, when kept only for them, too).
fn fit(
    vocabulary: &super::Vocabulary,
    skill: &Skill,
    rule: &LearnedRule,
) -> Result<(LiteralTemplate, Fitting), LearnError> {
    let condition = rule.template(skill)?;
    let fitting = fitting(vocabulary, skill, &condition);
    if let Some((i, _)) = fitting.iter().find(|(_, objects)| objects.is_empty()) {
        return Err(LearnError::Condition {
            rule: rule.label(),
            requires: rule.requires.clone(),
            reason: Box::new(Misfit::NoObjectFits {
                skill: skill.name.clone(),
                param: skill
                    .params
                    .get(*i)
                    .map_or_else(|| "?".to_string(), |p| p.name.clone()),
                predicate: condition.atom.predicate.clone(),
            }),
        });
    }
    if let Some(only) = &rule.only
        && !skill.accepts(vocabulary, only)
    {
        return Err(LearnError::Condition {
            rule: rule.label(),
            requires: rule.requires.clone(),
            reason: Box::new(Misfit::NotTaken {
                skill: skill.name.clone(),
                objects: only.clone(),
            }),
        });
    }
    Ok((condition, fitting))
}

impl Domain {
    /// Add `rule` to every skill it names, as a first precondition (before the declared
    /// ones); a rule the skill already declares changes nothing.
    pub fn learn(&mut self, rule: &LearnedRule) -> Result<(), LearnError> {
        // A skill name may have several declarations (MoveTo a place, MoveTo a made
        // item): the rule goes to those it fits; it is an error only when it fits none.
        let mut first_error = None;
        let mut fitted = false;
        let vocabulary = self.vocabulary.clone();
        for skill in self.skills.iter_mut().filter(|s| s.name == rule.skill) {
            let condition = match fit(&vocabulary, skill, rule) {
                Ok(c) => c,
                Err(e) => {
                    first_error.get_or_insert(e);
                    continue;
                }
            };
            fitted = true;
            let (condition, fitting) = condition;
            if skill.pre.contains(&condition)
                || skill
                    .learned
                    .iter()
                    .any(|l| l.condition == condition && l.only == rule.only)
            {
                continue;
            }
            skill.learned.push(LearnedPrecondition {
                rule: rule.id.clone(),
                condition,
                only: rule.only.clone(),
                fitting,
            });
        }
        match (fitted, first_error) {
            (true, _) => Ok(()),
            (false, Some(e)) => Err(e),
            (false, None) => Err(LearnError::UnknownSkill {
                rule: rule.label(),
                skill: rule.skill.clone(),
            }),
        }
    }

    /// The learned rules that put `condition` before `action` (their ids).
    pub fn rules_requiring(&self, action: &ActionCall, condition: &Condition) -> Vec<String> {
        self.skills
            .iter()
            .filter(|s| s.name == action.skill && s.params.len() == action.args.len())
            .flat_map(|s| &s.learned)
            .filter(|l| l.applies(&action.args))
            .filter(|l| {
                let (pre, _, _) = super::skill::ground_templates(
                    std::slice::from_ref(&l.condition),
                    &[],
                    &[],
                    &action.args,
                );
                pre.first() == Some(condition)
            })
            .map(|l| l.rule.clone())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Param, Vocabulary};

    fn grasp() -> Skill {
        let params = vec![Param {
            name: "x".into(),
            types: vec!["item".into()],
            except: vec![],
        }];
        let t = |s: &str| parse_template(s, &params).unwrap();
        Skill {
            name: "grasp".into(),
            description: String::new(),
            pre: vec![t("~\"any object\" grasped")],
            add: vec![t("\"{x}\" grasped").atom],
            del: vec![t("\"{x}\" on \"{*}\"").atom],
            params,
            cost: 1.0,
            ticks: 1,
            values: vec![],
            learned: vec![],
        }
    }

    fn domain() -> Domain {
        let objects = ["blue cube", "red cube", "green cube"]
            .into_iter()
            .map(|name| crate::domain::Object {
                name: name.into(),
                types: vec!["item".into()],
                called: Vec::new(),
            })
            .collect();
        Domain {
            vocabulary: Vocabulary {
                objects,
                ..Vocabulary::default()
            },
            skills: vec![grasp()],
        }
    }

    fn call(text: &str) -> ActionCall {
        ActionCall::parse(text).unwrap()
    }

    #[test]
    fn a_fix_lifts_to_the_actions_parameters() {
        let fix = Condition::parse("~\"any object\" on \"blue cube\"").unwrap();
        let rule = LearnedRule::from_fix(&call("grasp \"blue cube\""), &fix, false);
        assert_eq!(rule.requires, "~\"any object\" on \"{1}\"");
        assert!(rule.generalises());
        assert!(rule.fixed_objects().is_empty());
        assert_eq!(
            rule.describe(&domain()),
            "grasp {x} needs ~\"any object\" on \"{x}\""
        );
        let only = LearnedRule::from_fix(&call("grasp \"blue cube\""), &fix, true);
        assert_eq!(only.only, Some(vec!["blue cube".to_string()]));
        assert!(!only.generalises());
        assert_eq!(
            only.describe(&domain()),
            "grasp \"blue cube\" needs ~\"any object\" on \"blue cube\" (only for these objects)"
        );
    }

    #[test]
    fn objects_not_the_actions_stay_fixed() {
        let fix = Condition::parse("RobotNear_Bar").unwrap();
        let rule = LearnedRule::from_fix(&call("PickUp \"Chips\""), &fix, false);
        assert_eq!(rule.requires, "RobotNear_Bar");
        assert!(!rule.generalises());
        assert_eq!(rule.fixed_objects(), vec!["Bar".to_string()]);
    }

    #[test]
    fn learned_preconditions_come_first_and_only_where_they_apply() {
        let mut d = domain();
        let fix = Condition::parse("~\"any object\" on \"blue cube\"").unwrap();
        let mut rule = LearnedRule::from_fix(&call("grasp \"blue cube\""), &fix, false);
        rule.id = "r1".into();
        d.learn(&rule).unwrap();
        let g = d.skills[0].ground(&["red cube".to_string()]);
        assert_eq!(g.pre[0].to_string(), "~\"any object\" on \"red cube\"");
        assert_eq!(g.pre.len(), 2);
        // Learning twice adds nothing.
        d.learn(&rule).unwrap();
        assert_eq!(d.skills[0].learned.len(), 1);

        let mut only = LearnedRule::from_fix(&call("grasp \"blue cube\""), &fix, true);
        only.id = "r2".into();
        let mut d = domain();
        d.learn(&only).unwrap();
        assert_eq!(d.skills[0].ground(&["red cube".to_string()]).pre.len(), 1);
        assert_eq!(d.skills[0].ground(&["blue cube".to_string()]).pre.len(), 2);
    }

    #[test]
    fn rules_that_do_not_fit_are_refused_with_their_name() {
        let mut d = domain();
        let bad = LearnedRule {
            id: "r7".into(),
            skill: "grasp".into(),
            requires: "\"{2}\" on \"{1}\"".into(),
            only: None,
        };
        let e = d.learn(&bad).unwrap_err();
        assert!(e.to_string().contains("rule r7"), "{e}");
        assert!(e.to_string().contains("{2}"), "{e}");
        let unknown = LearnedRule {
            skill: "fly".into(),
            ..bad.clone()
        };
        assert!(matches!(
            d.learn(&unknown),
            Err(LearnError::UnknownSkill { .. })
        ));
        let every = LearnedRule {
            requires: "\"{1}\" on \"{*}\"".into(),
            ..bad
        };
        assert!(d.learn(&every).is_err());
    }

    #[test]
    fn the_rules_behind_a_precondition_are_found() {
        let mut d = domain();
        let fix = Condition::parse("~\"any object\" on \"blue cube\"").unwrap();
        let mut rule = LearnedRule::from_fix(&call("grasp \"blue cube\""), &fix, false);
        rule.id = "r1".into();
        d.learn(&rule).unwrap();
        let c = Condition::parse("~\"any object\" on \"green cube\"").unwrap();
        assert_eq!(
            d.rules_requiring(&call("grasp \"green cube\""), &c),
            vec!["r1"]
        );
        assert!(
            d.rules_requiring(&call("grasp \"blue cube\""), &c)
                .is_empty()
        );
    }
}
