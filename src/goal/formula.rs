//! The goal formula tree, its constructors, evaluation and printing.

use std::collections::BTreeSet;
use std::fmt;

use super::GoalError;
use crate::domain::{Atom, Condition};

/// A propositional formula over condition atoms.
///
/// `And(vec![])` is true and `Or(vec![])` is false; neither has a surface syntax (they print
/// as `true` / `false`, which the parser does not accept).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Formula {
    Atom(Atom),
    Not(Box<Formula>),
    And(Vec<Formula>),
    Or(Vec<Formula>),
}

impl Formula {
    /// Parse a goal: atoms combined with `~`, `&`, `|` and parentheses (`~` binds tightest,
    /// `|` weakest). Nested `&` / `|` groups are flattened.
    pub fn parse(text: &str) -> Result<Formula, GoalError> {
        super::parse::parse(text)
    }

    /// A literal as a formula: the atom, or `Not` of it.
    pub fn literal(condition: &Condition) -> Formula {
        let atom = Formula::Atom(condition.atom.clone());
        if condition.negated {
            Formula::Not(Box::new(atom))
        } else {
            atom
        }
    }

    /// The conjunction of the literals: a single literal stays itself, none gives the
    /// always-true `And(vec![])`.
    pub fn from_literals<'a>(literals: impl IntoIterator<Item = &'a Condition>) -> Formula {
        Formula::and(literals.into_iter().map(Formula::literal).collect())
    }

    /// The items of a conjunction, or the formula itself as the one item of any other.
    pub fn conjuncts(&self) -> Vec<Formula> {
        match self {
            Formula::And(items) => items.clone(),
            other => vec![other.clone()],
        }
    }

    /// A flattened conjunction: nested `And`s are merged, an item said twice is kept once
    /// (`A & A` is `A`), and a single item is returned as is.
    pub fn and(items: Vec<Formula>) -> Formula {
        let mut out = Vec::with_capacity(items.len());
        for item in items {
            match item {
                Formula::And(inner) => out.extend(inner),
                other => out.push(other),
            }
        }
        single_or(once_each(out), Formula::And)
    }

    /// A flattened disjunction: nested `Or`s are merged, an item said twice is kept once,
    /// and a single item is returned as is.
    pub fn or(items: Vec<Formula>) -> Formula {
        let mut out = Vec::with_capacity(items.len());
        for item in items {
            match item {
                Formula::Or(inner) => out.extend(inner),
                other => out.push(other),
            }
        }
        single_or(once_each(out), Formula::Or)
    }

    /// The same formula with every nested `And` / `Or` merged into its parent and every
    /// one-item `And` / `Or` replaced by its item. Parsing always gives a flattened formula.
    pub fn flatten(&self) -> Formula {
        match self {
            Formula::Atom(a) => Formula::Atom(a.clone()),
            Formula::Not(x) => Formula::Not(Box::new(x.flatten())),
            Formula::And(v) => Formula::and(v.iter().map(Formula::flatten).collect()),
            Formula::Or(v) => Formula::or(v.iter().map(Formula::flatten).collect()),
        }
    }

    /// Every atom the formula mentions.
    pub fn atoms(&self) -> BTreeSet<Atom> {
        self.atoms_in_order().into_iter().collect()
    }

    /// Every atom the formula mentions, once each, in order of first appearance.
    pub fn atoms_in_order(&self) -> Vec<Atom> {
        let mut seen = BTreeSet::new();
        let mut out = Vec::new();
        self.visit_atoms(&mut |a| {
            if seen.insert(a) {
                out.push(a.clone());
            }
        });
        out
    }

    fn visit_atoms<'a>(&'a self, f: &mut impl FnMut(&'a Atom)) {
        match self {
            Formula::Atom(a) => f(a),
            Formula::Not(x) => x.visit_atoms(f),
            Formula::And(v) | Formula::Or(v) => v.iter().for_each(|x| x.visit_atoms(f)),
        }
    }

    /// The formula's value when each atom has the value `truth` gives it.
    pub fn eval(&self, truth: &dyn Fn(&Atom) -> bool) -> bool {
        match self {
            Formula::Atom(a) => truth(a),
            Formula::Not(x) => !x.eval(truth),
            Formula::And(v) => v.iter().all(|x| x.eval(truth)),
            Formula::Or(v) => v.iter().any(|x| x.eval(truth)),
        }
    }

    /// Binding strength when printed: 2 for atoms, negations and constants, 1 for `&`,
    /// 0 for `|`. One-item groups print as their item.
    fn prec(&self) -> u8 {
        match self {
            Formula::And(v) | Formula::Or(v) if v.len() == 1 => v[0].prec(),
            Formula::And(v) if v.len() > 1 => 1,
            Formula::Or(v) if v.len() > 1 => 0,
            _ => 2,
        }
    }

    fn fmt_in(&self, f: &mut fmt::Formatter<'_>, min: u8) -> fmt::Result {
        if let Formula::And(v) | Formula::Or(v) = self
            && let [only] = v.as_slice()
        {
            return only.fmt_in(f, min);
        }
        let paren = self.prec() < min;
        if paren {
            f.write_str("(")?;
        }
        match self {
            Formula::Atom(a) => write!(f, "{a}")?,
            Formula::Not(x) => {
                f.write_str("~")?;
                x.fmt_in(f, 2)?;
            }
            Formula::And(v) if v.is_empty() => f.write_str("true")?,
            Formula::Or(v) if v.is_empty() => f.write_str("false")?,
            Formula::And(v) => join(f, v, " & ", 1)?,
            Formula::Or(v) => join(f, v, " | ", 0)?,
        }
        if paren {
            f.write_str(")")?;
        }
        Ok(())
    }
}

/// `items` in their order with each repeated item left out after its first time.
fn once_each(items: Vec<Formula>) -> Vec<Formula> {
    let mut out: Vec<Formula> = Vec::with_capacity(items.len());
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

fn single_or(mut items: Vec<Formula>, wrap: fn(Vec<Formula>) -> Formula) -> Formula {
    if items.len() == 1
        && let Some(only) = items.pop()
    {
        return only;
    }
    wrap(items)
}

fn join(f: &mut fmt::Formatter<'_>, items: &[Formula], sep: &str, min: u8) -> fmt::Result {
    for (i, item) in items.iter().enumerate() {
        if i > 0 {
            f.write_str(sep)?;
        }
        item.fmt_in(f, min)?;
    }
    Ok(())
}

/// Prints with the fewest parentheses that parse back to the same (flattened) formula.
impl fmt::Display for Formula {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.fmt_in(f, 0)
    }
}

crate::domain::as_text::serde_as_text!(Formula, Formula::parse);

#[cfg(test)]
mod tests {
    use super::*;

    fn p(text: &str) -> Formula {
        Formula::parse(text).unwrap()
    }

    #[test]
    fn prints_minimal_parentheses() {
        for text in [
            "~Closed_Curtain | Active_AC & ~Low_ACTemperature",
            "(A | B) & C",
            "~(A | B) & ~(C & D)",
            "~~A",
            "A & B & C | D",
            "~\"any object\" on \"blue cube\" & \"blue cube\" on \"green cube\"",
        ] {
            assert_eq!(p(text).to_string(), text);
        }
        assert_eq!(p("((A)) & ((B & C))").to_string(), "A & B & C");
        assert_eq!(p("(A | (B | C)) | D").to_string(), "A | B | C | D");
        // An item said twice is one.
        assert_eq!(p("A & B & A").to_string(), "A & B");
        assert_eq!(p("(A | B) & (A | B)").to_string(), "A | B");
    }

    #[test]
    fn unflattened_trees_print_as_their_flattening() {
        let a = || Formula::Atom(Atom::new("A", Vec::<String>::new()));
        let f = Formula::And(vec![
            Formula::And(vec![a(), a()]),
            Formula::Or(vec![Formula::Or(vec![a()])]),
        ]);
        assert_eq!(f.to_string(), "A & A & A");
        assert_eq!(p(&f.to_string()), f.flatten());
        assert_eq!(Formula::And(vec![]).to_string(), "true");
        assert_eq!(Formula::Or(vec![]).to_string(), "false");
    }

    #[test]
    fn atoms_and_eval() {
        let f = p("On_Chips_Table3 | ~On_Dessert_Table3 & On_Chips_Table3");
        let order: Vec<String> = f.atoms_in_order().iter().map(|a| a.to_string()).collect();
        assert_eq!(order, ["On_Chips_Table3", "On_Dessert_Table3"]);
        assert_eq!(f.atoms().len(), 2);
        assert!(f.eval(&|a: &Atom| a.args[0] == "Chips"));
        assert!(!f.eval(&|_: &Atom| false));
    }

    #[test]
    fn from_literals_builds_conjunctions() {
        let c = |t: &str| Condition::parse(t).unwrap();
        let lits = [c("A_x"), c("~B_y")];
        assert_eq!(Formula::from_literals(&lits).to_string(), "A_x & ~B_y");
        assert_eq!(Formula::from_literals(&lits[..1]).to_string(), "A_x");
        assert_eq!(Formula::from_literals(&[]), Formula::And(vec![]));
    }
}
