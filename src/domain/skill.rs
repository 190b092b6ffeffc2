//! Skills as the planner knows them: typed parameters, preconditions, effects (atoms that
//! become true, patterns of atoms that become false), a cost and a duration in ticks.
//!
//! In scenario files, conditions inside a skill use `{param}` for a parameter and `{*}` for
//! "every object" (only in deletions): `On_{item}_{*}` is removed by picking the item up.

use super::action::ActionCall;
use super::condition::{ANY_OBJECT, Atom, Condition};
use super::learned::LearnedPrecondition;
use super::vocabulary::Vocabulary;

/// One argument of a condition template.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Term {
    /// The skill's parameter with this index.
    Param(usize),
    /// A fixed object.
    Const(String),
    /// Every object (deletions only): `On_{item}_{*}`.
    Every,
}

#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AtomTemplate {
    pub predicate: String,
    pub args: Vec<Term>,
}

#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct LiteralTemplate {
    pub atom: AtomTemplate,
    pub negated: bool,
}

/// A typed parameter: `item: item`, `target: place|item`, a fixed object `m: Coffee`, or
/// with exclusions `x: item except makable`.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    pub name: String,
    pub types: Vec<String>,
    pub except: Vec<String>,
}

impl Param {
    /// Whether `object` may stand for this parameter.
    pub fn admits(&self, vocabulary: &Vocabulary, object: &str) -> bool {
        vocabulary.fits(object, &self.types) && !vocabulary.fits(object, &self.except)
    }

    /// The objects that may stand for this parameter, in declaration order.
    pub fn candidates<'a>(
        &'a self,
        vocabulary: &'a Vocabulary,
    ) -> impl Iterator<Item = &'a str> + 'a {
        vocabulary.objects_fitting_except(&self.types, &self.except)
    }
}

/// A value the skill needs that the planner cannot derive (grasp force, speed, tool).
#[derive(Debug, Clone, PartialEq)]
pub struct ValueParam {
    pub name: String,
    /// Unit of a numeric value (`N`, `m/s`); `None` for a categorical value.
    pub unit: Option<String>,
    /// The allowed categories of a categorical value (e.g. tool names).
    pub categories: Vec<String>,
    pub description: String,
    /// What the robot can do at all (its hardware range, such as the gripper's largest
    /// force), for a numeric value; what an object needs is for the model to judge.
    pub min: Option<f64>,
    pub max: Option<f64>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Skill {
    pub name: String,
    pub description: String,
    pub params: Vec<Param>,
    pub pre: Vec<LiteralTemplate>,
    pub add: Vec<AtomTemplate>,
    pub del: Vec<AtomTemplate>,
    pub cost: f64,
    /// How many ticks the action runs before it completes (at least 1).
    pub ticks: u32,
    pub values: Vec<ValueParam>,
    /// Preconditions kept from approved fixes (`betr knowledge`), checked before the
    /// declared ones.
    pub learned: Vec<LearnedPrecondition>,
}

/// An atom with some positions open (`None` = any object): what a deletion removes.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AtomPattern {
    pub predicate: String,
    pub args: Vec<Option<String>>,
}

/// A skill applied to concrete objects.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundSkill {
    pub call: ActionCall,
    pub cost: f64,
    pub ticks: u32,
    pub pre: Vec<Condition>,
    pub add: Vec<Atom>,
    pub del: Vec<AtomPattern>,
}

/// The planner's view of a domain: what exists and what the robot can do.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Domain {
    pub vocabulary: Vocabulary,
    pub skills: Vec<Skill>,
}

impl AtomPattern {
    pub fn matches(&self, atom: &Atom) -> bool {
        self.predicate == atom.predicate
            && self.args.len() == atom.args.len()
            && self
                .args
                .iter()
                .zip(&atom.args)
                .all(|(p, a)| p.as_ref().is_none_or(|p| p == a))
    }

    /// Whether the pattern can match some atom that also matches `atom`, where
    /// `"any object"` in `atom` stands for any object.
    pub fn overlaps(&self, atom: &Atom) -> bool {
        self.predicate == atom.predicate
            && self.args.len() == atom.args.len()
            && self
                .args
                .iter()
                .zip(&atom.args)
                .all(|(p, a)| a == ANY_OBJECT || p.as_ref().is_none_or(|p| p == a))
    }
}

impl GroundSkill {
    /// Whether completing this action makes `c` true (given the declared effects).
    pub fn achieves(&self, c: &Condition) -> bool {
        if c.negated {
            if c.atom.has_wildcard() {
                // `~"any object" on X` needs every matching atom gone: only a deletion that
                // covers the whole pattern guarantees that.
                return self.del.iter().any(|d| covers(d, &c.atom)) && !self.adds_matching(&c.atom);
            }
            self.del.iter().any(|d| d.matches(&c.atom)) && !self.add.contains(&c.atom)
        } else if c.atom.has_wildcard() {
            self.adds_matching(&c.atom)
        } else {
            self.add.contains(&c.atom)
        }
    }

    /// Whether completing this action makes `c` false.
    pub fn undoes(&self, c: &Condition) -> bool {
        self.achieves(&c.negate())
    }

    fn adds_matching(&self, atom: &Atom) -> bool {
        self.add.iter().any(|a| {
            a.predicate == atom.predicate
                && a.args.len() == atom.args.len()
                && a.args
                    .iter()
                    .zip(&atom.args)
                    .all(|(x, y)| y == ANY_OBJECT || x == y)
        })
    }

    /// The declared effects as conditions that must hold after completion (deletions that
    /// the action also re-adds are not expected to be false).
    pub fn postconditions(&self) -> Vec<Condition> {
        let mut out: Vec<Condition> = self.add.iter().cloned().map(Condition::pos).collect();
        for d in &self.del {
            if d.args.iter().all(Option::is_some) {
                let atom = Atom {
                    predicate: d.predicate.clone(),
                    args: d.args.iter().flatten().cloned().collect(),
                };
                if !self.add.contains(&atom) {
                    out.push(Condition::neg(atom));
                }
            }
        }
        out
    }
}

/// Whether deleting `pattern` removes every atom matching `atom` (whose `"any object"`
/// positions are open).
fn covers(pattern: &AtomPattern, atom: &Atom) -> bool {
    pattern.predicate == atom.predicate
        && pattern.args.len() == atom.args.len()
        && pattern.args.iter().zip(&atom.args).all(|(p, a)| match p {
            None => true,
            Some(p) => a != ANY_OBJECT && p == a,
        })
}

impl Skill {
    /// Whether these objects fit the parameters.
    pub fn accepts(&self, vocabulary: &Vocabulary, args: &[String]) -> bool {
        args.len() == self.params.len()
            && self
                .params
                .iter()
                .zip(args)
                .all(|(p, a)| p.admits(vocabulary, a))
    }

    /// Apply the skill to objects. The caller checks `accepts` first.
    pub fn ground(&self, args: &[String]) -> GroundSkill {
        let (mut pre, add, del) = ground_templates(&self.pre, &self.add, &self.del, args);
        let learned: Vec<LiteralTemplate> = self
            .learned
            .iter()
            .filter(|l| l.applies(args))
            .map(|l| l.condition.clone())
            .collect();
        if !learned.is_empty() {
            let (mut first, _, _) = ground_templates(&learned, &[], &[], args);
            first.retain(|c| !pre.contains(c));
            first.dedup();
            first.append(&mut pre);
            pre = first;
        }
        GroundSkill {
            call: ActionCall::new(self.name.clone(), args.iter().cloned()),
            cost: self.cost,
            ticks: self.ticks.max(1),
            pre,
            add,
            del,
        }
    }

    /// Partial parameter bindings under which one of the skill's effects could make `c`
    /// true: each entry fixes some parameters (`None` = still free).
    pub fn bindings_for(&self, c: &Condition) -> Vec<Vec<Option<String>>> {
        let effects = if c.negated { &self.del } else { &self.add };
        let mut out = Vec::new();
        for t in effects {
            if t.predicate != c.atom.predicate || t.args.len() != c.atom.args.len() {
                continue;
            }
            let mut binding: Vec<Option<String>> = vec![None; self.params.len()];
            let mut ok = true;
            for (term, arg) in t.args.iter().zip(&c.atom.args) {
                if arg == ANY_OBJECT {
                    continue;
                }
                match term {
                    Term::Every => {}
                    Term::Const(k) => ok &= k == arg,
                    Term::Param(i) => match &binding[*i] {
                        Some(b) => ok &= b == arg,
                        None => binding[*i] = Some(arg.clone()),
                    },
                }
            }
            if ok && !out.contains(&binding) {
                out.push(binding);
            }
        }
        out
    }
}

/// Templates with their parameters replaced by `args`: the conditions (`{*}` becomes
/// `"any object"`), the atoms that become true, and the patterns that become false (`{*}`
/// open). Shared by skills and by anything else written as templates (disturbances).
pub fn ground_templates(
    pre: &[LiteralTemplate],
    add: &[AtomTemplate],
    del: &[AtomTemplate],
    args: &[String],
) -> (Vec<Condition>, Vec<Atom>, Vec<AtomPattern>) {
    let term = |t: &Term| match t {
        Term::Param(i) => args.get(*i).cloned(),
        Term::Const(c) => Some(c.clone()),
        Term::Every => None,
    };
    let atom = |t: &AtomTemplate| Atom {
        predicate: t.predicate.clone(),
        args: t
            .args
            .iter()
            .map(|a| term(a).unwrap_or_else(|| ANY_OBJECT.to_string()))
            .collect(),
    };
    (
        pre.iter()
            .map(|l| Condition {
                atom: atom(&l.atom),
                negated: l.negated,
            })
            .collect(),
        add.iter().map(atom).collect(),
        del.iter()
            .map(|t| AtomPattern {
                predicate: t.predicate.clone(),
                args: t.args.iter().map(term).collect(),
            })
            .collect(),
    )
}

impl Domain {
    /// The ground skill an action names, if some skill of that name accepts its objects.
    pub fn resolve(&self, call: &ActionCall) -> Option<GroundSkill> {
        self.skills
            .iter()
            .find(|s| s.name == call.skill && s.accepts(&self.vocabulary, &call.args))
            .map(|s| {
                let mut g = s.ground(&call.args);
                g.call.values = call.values.clone();
                g
            })
    }

    /// The skill definition an action names.
    pub fn skill_for(&self, call: &ActionCall) -> Option<&Skill> {
        self.skills
            .iter()
            .find(|s| s.name == call.skill && s.accepts(&self.vocabulary, &call.args))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::template::parse_template;
    use crate::domain::template::tests::params;

    fn pick_up() -> Skill {
        let ps = params(&["item"]);
        let t = |s: &str| parse_template(s, &ps).unwrap();
        Skill {
            name: "PickUp".into(),
            description: String::new(),
            pre: vec![t("RobotNear_{item}"), t("Holding_Nothing")],
            add: vec![t("Holding_{item}").atom],
            del: vec![t("Holding_Nothing").atom, t("On_{item}_{*}").atom],
            params: ps,
            cost: 2.0,
            ticks: 1,
            values: vec![],
            learned: vec![],
        }
    }

    #[test]
    fn ground_effects_achieve_and_undo() {
        let g = pick_up().ground(&["Chips".to_string()]);
        assert_eq!(g.call.to_string(), "PickUp \"Chips\"");
        assert!(g.achieves(&Condition::parse("Holding_Chips").unwrap()));
        assert!(g.achieves(&Condition::parse("~On_Chips_Bar").unwrap()));
        assert!(g.undoes(&Condition::parse("Holding_Nothing").unwrap()));
        assert!(!g.achieves(&Condition::parse("~On_Coffee_Bar").unwrap()));
        let post: Vec<String> = g.postconditions().iter().map(ToString::to_string).collect();
        assert_eq!(post, vec!["Holding_Chips", "~Holding_Nothing"]);
    }

    #[test]
    fn bindings_come_from_effects() {
        let s = pick_up();
        let b = s.bindings_for(&Condition::parse("Holding_Chips").unwrap());
        assert_eq!(b, vec![vec![Some("Chips".to_string())]]);
        let b = s.bindings_for(&Condition::parse("~On_Chips_Bar").unwrap());
        assert_eq!(b, vec![vec![Some("Chips".to_string())]]);
        assert!(
            s.bindings_for(&Condition::parse("Active_AC").unwrap())
                .is_empty()
        );
    }
}
