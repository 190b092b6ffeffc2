//! Minimal disjunctive normal form.

use std::collections::BTreeSet;
use std::convert::Infallible;
use std::fmt;

use super::Formula;
use super::qm;
use super::truth::{Ix, index_of};
use crate::domain::{Atom, Condition};

/// Up to this many distinct atoms, [`Formula::to_dnf`] minimises exactly; beyond it, it
/// only drops contradictory conjunctions, duplicate literals and absorbed conjunctions.
pub const EXACT_ATOM_LIMIT: usize = 12;

/// The most alternatives (conjunctions of the DNF) a goal from outside may have: its `|`
/// choices multiply out (`(A | B) & (C | D)` has four), so a line of sixteen either/or
/// choices has 65,536, each a branch of the tree. A goal with more is refused when it is
/// read ([`Formula::parse`]).
pub const MAX_ALTERNATIVES: usize = 1024;

/// A goal whose DNF has more than [`MAX_ALTERNATIVES`] conjunctions.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "more than {limit} alternatives when its '|' choices are multiplied out (betr plans at most {limit})"
)]
pub struct TooManyAlternatives {
    pub limit: usize,
}

/// How many conjunctions distributing may hold: after each step is absorbed, and (so that
/// absorbing, which compares each conjunction with those kept, stays cheap) before.
trait Budget {
    type Error;
    fn absorbed(&self, conjunctions: usize) -> Result<(), Self::Error>;
    fn raw(&self, conjunctions: usize) -> Result<(), Self::Error>;
}

/// No bound: for formulas already checked.
struct Unbounded;

impl Budget for Unbounded {
    type Error = Infallible;
    fn absorbed(&self, _: usize) -> Result<(), Infallible> {
        Ok(())
    }
    fn raw(&self, _: usize) -> Result<(), Infallible> {
        Ok(())
    }
}

/// At most this many conjunctions after each absorbed step, and four times as many before.
struct Alternatives(usize);

impl Alternatives {
    fn within(&self, conjunctions: usize, limit: usize) -> Result<(), TooManyAlternatives> {
        if conjunctions > limit {
            Err(TooManyAlternatives { limit: self.0 })
        } else {
            Ok(())
        }
    }
}

impl Budget for Alternatives {
    type Error = TooManyAlternatives;
    fn absorbed(&self, conjunctions: usize) -> Result<(), TooManyAlternatives> {
        self.within(conjunctions, self.0)
    }
    fn raw(&self, conjunctions: usize) -> Result<(), TooManyAlternatives> {
        self.within(conjunctions, self.0.saturating_mul(4))
    }
}

/// A disjunction of conjunctions of literals. `Dnf(vec![])` is false; a DNF with an empty
/// conjunction, such as `Dnf(vec![vec![]])`, is true.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Dnf(pub Vec<Vec<Condition>>);

/// A literal by atom index (first appearance in the goal) and sign (`true` = negated).
type Lit = (usize, bool);

impl Formula {
    /// The minimal DNF of the formula.
    ///
    /// Negations are pushed to the atoms (De Morgan), `&` is distributed over `|`, and
    /// conjunctions containing `A & ~A` are dropped. With at most [`EXACT_ATOM_LIMIT`]
    /// distinct atoms the result is then minimised exactly (prime implicants, then a cover
    /// with the fewest conjunctions and, among those, the fewest literals; ties broken by
    /// the atoms' canonical order so that equivalent goals give the same DNF). With more
    /// atoms, only duplicate literals and absorbed conjunctions (`A | A & B` → `A`) are
    /// removed, which need not give a minimal DNF.
    ///
    /// Order: the literals of each conjunction follow the order in which their atoms first
    /// appear in the formula, and the conjunctions are sorted by their literals in the same
    /// order (a positive literal before the negative one of the same atom). So
    /// `On_Chips_Table3 | On_Dessert_Table3` gives the Chips conjunction first.
    ///
    /// A tautology gives `Dnf(vec![vec![]])`, a contradiction `Dnf(vec![])`.
    pub fn to_dnf(&self) -> Dnf {
        let atoms = self.atoms_in_order();
        let index = index_of(&atoms);
        let ix = Ix::compile(self, &index);
        let conjunctions = if atoms.len() <= EXACT_ATOM_LIMIT {
            exact(&ix, &atoms)
        } else {
            match distribute(&ix, false, &Unbounded) {
                Ok(c) => c,
                Err(never) => match never {},
            }
        };
        named(conjunctions, &atoms)
    }

    /// [`Formula::to_dnf`], unless the DNF has more than `limit` conjunctions, found without
    /// writing them all out (distributing gives up as soon as it holds too many).
    pub fn to_dnf_within(&self, limit: usize) -> Result<Dnf, TooManyAlternatives> {
        self.check_alternatives(limit)?;
        let dnf = self.to_dnf();
        Alternatives(limit).absorbed(dnf.0.len())?;
        Ok(dnf)
    }

    /// Whether the formula's conjunctions, distributed and absorbed, number at most
    /// `limit` (the minimal DNF has at most as many).
    pub fn check_alternatives(&self, limit: usize) -> Result<(), TooManyAlternatives> {
        let atoms = self.atoms_in_order();
        let ix = Ix::compile(self, &index_of(&atoms));
        distribute(&ix, false, &Alternatives(limit)).map(drop)
    }
}

/// Conjunctions of literals by index as conditions on `atoms`, in the canonical order.
fn named(mut conjunctions: Vec<Vec<Lit>>, atoms: &[Atom]) -> Dnf {
    for c in &mut conjunctions {
        c.sort_unstable();
    }
    conjunctions.sort();
    Dnf(conjunctions
        .into_iter()
        .map(|c| {
            c.into_iter()
                .map(|(i, negated)| Condition {
                    atom: atoms[i].clone(),
                    negated,
                })
                .collect()
        })
        .collect())
}

fn exact(ix: &Ix, atoms: &[Atom]) -> Vec<Vec<Lit>> {
    let n = atoms.len();
    let minterms: Vec<u32> = (0..1u32 << n).filter(|&m| ix.eval(u64::from(m))).collect();
    let mut by_name: Vec<usize> = (0..n).collect();
    by_name.sort_by(|&a, &b| atoms[a].cmp(&atoms[b]));
    let mut rank = vec![0; n];
    for (r, &i) in by_name.iter().enumerate() {
        rank[i] = r;
    }
    qm::minimise(n, &minterms, &rank)
        .into_iter()
        .map(|cube| {
            (0..n)
                .filter(|&i| cube.mask >> i & 1 == 1)
                .map(|i| (i, cube.bits >> i & 1 == 0))
                .collect()
        })
        .collect()
}

/// DNF of `ix` (of its negation when `negated`), with each step absorbed; `budget` is
/// asked at every step whether the conjunctions held so far may grow on.
fn distribute<B: Budget>(ix: &Ix, negated: bool, budget: &B) -> Result<Vec<Vec<Lit>>, B::Error> {
    match ix {
        Ix::Var(i) => Ok(vec![vec![(*i, negated)]]),
        Ix::Not(x) => distribute(x, !negated, budget),
        Ix::And(v) | Ix::Or(v) if matches!(ix, Ix::And(_)) != negated => {
            // A conjunction (or a negated disjunction): the product of the parts.
            let mut acc: Vec<Vec<Lit>> = vec![Vec::new()];
            for part in v {
                let part = distribute(part, negated, budget)?;
                budget.raw(acc.len().saturating_mul(part.len()))?;
                let mut next = Vec::with_capacity(acc.len() * part.len());
                for a in &acc {
                    for b in &part {
                        if let Some(c) = conjoin(a, b) {
                            next.push(c);
                        }
                    }
                }
                acc = absorb(next);
                budget.absorbed(acc.len())?;
            }
            Ok(acc)
        }
        Ix::And(v) | Ix::Or(v) => {
            let mut all = Vec::new();
            for x in v {
                all.extend(distribute(x, negated, budget)?);
                budget.raw(all.len())?;
            }
            let all = absorb(all);
            budget.absorbed(all.len())?;
            Ok(all)
        }
    }
}

/// `a & b` as a sorted, deduplicated conjunction, or `None` when it contains `A & ~A`.
fn conjoin(a: &[Lit], b: &[Lit]) -> Option<Vec<Lit>> {
    let mut c: Vec<Lit> = a.iter().chain(b).copied().collect();
    c.sort_unstable();
    c.dedup();
    if c.windows(2).any(|w| w[0].0 == w[1].0) {
        return None;
    }
    Some(c)
}

/// Drop duplicate conjunctions and those that contain another one (`A | A & B` → `A`).
fn absorb(mut conjunctions: Vec<Vec<Lit>>) -> Vec<Vec<Lit>> {
    conjunctions.sort_by(|a, b| a.len().cmp(&b.len()).then_with(|| a.cmp(b)));
    conjunctions.dedup();
    let mut kept: Vec<Vec<Lit>> = Vec::new();
    for c in conjunctions {
        if !kept
            .iter()
            .any(|k| k.iter().all(|l| c.binary_search(l).is_ok()))
        {
            kept.push(c);
        }
    }
    kept
}

impl Dnf {
    /// The DNF as a formula: `|` of `&` of literals (flattened, so a single conjunction or
    /// literal is itself). False is `Or(vec![])`, true `And(vec![])`.
    pub fn to_formula(&self) -> Formula {
        Formula::or(self.0.iter().map(Formula::from_literals).collect())
    }

    /// True when some conjunction is empty (always so for a tautology's minimal DNF).
    pub fn is_true(&self) -> bool {
        self.0.iter().any(Vec::is_empty)
    }

    /// True when every conjunction contains `A & ~A` (in particular when there is none).
    pub fn is_false(&self) -> bool {
        self.0.iter().all(|c| {
            c.iter()
                .any(|l| c.iter().any(|m| m.atom == l.atom && m.negated != l.negated))
        })
    }

    /// The value when each atom has the value `truth` gives it.
    pub fn eval(&self, truth: &dyn Fn(&Atom) -> bool) -> bool {
        self.0
            .iter()
            .any(|c| c.iter().all(|l| truth(&l.atom) != l.negated))
    }

    /// The DNF as a set of sets of literals, ignoring order (the published scoring rule
    /// compares these).
    pub fn to_sets(&self) -> BTreeSet<BTreeSet<Condition>> {
        self.0.iter().map(|c| c.iter().cloned().collect()).collect()
    }
}

/// Prints like the equivalent formula: `A & ~B | C`; `true` / `false` for the constants.
impl fmt::Display for Dnf {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.to_formula())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::goal::{equivalent, same_dnf};

    fn dnf(text: &str) -> String {
        Formula::parse(text).unwrap().to_dnf().to_string()
    }

    #[test]
    fn minimal_examples() {
        assert_eq!(dnf("(A & B) | (A & ~B)"), "A");
        assert_eq!(dnf("A | (A & B)"), "A");
        assert_eq!(dnf("A | ~A & B"), "A | B");
        assert_eq!(dnf("(A | B) & (A | C)"), "A | B & C");
        assert_eq!(dnf("A & A & (B | B)"), "A & B");
        assert_eq!(dnf("(A | B) & ~A"), "~A & B");
        assert_eq!(dnf("A & B | ~A & B | A & ~B"), "A | B");
    }

    #[test]
    fn de_morgan() {
        assert_eq!(dnf("~(A | B)"), "~A & ~B");
        assert_eq!(dnf("~(A & B)"), "~A | ~B");
        assert_eq!(dnf("~(A & ~(B | ~C))"), "~A | B | ~C");
        assert_eq!(dnf("~~A"), "A");
    }

    #[test]
    fn tautology_and_contradiction() {
        let t = Formula::parse("A | ~A").unwrap().to_dnf();
        assert_eq!(t, Dnf(vec![vec![]]));
        assert!(t.is_true() && !t.is_false());
        assert_eq!(t.to_string(), "true");
        let f = Formula::parse("A & ~A | B & ~B").unwrap().to_dnf();
        assert_eq!(f, Dnf(vec![]));
        assert!(f.is_false() && !f.is_true());
        assert_eq!(f.to_string(), "false");
        assert_eq!(dnf("(A | ~A) & B"), "B");
        assert_eq!(dnf("A & ~A | B"), "B");
    }

    #[test]
    fn order_follows_first_appearance() {
        assert_eq!(
            dnf("On_Chips_Table3 | On_Dessert_Table3"),
            "On_Chips_Table3 | On_Dessert_Table3"
        );
        assert_eq!(
            dnf("On_Dessert_Table3 | On_Chips_Table3"),
            "On_Dessert_Table3 | On_Chips_Table3"
        );
        assert_eq!(
            dnf("~Closed_Curtain | Active_AC & ~Low_ACTemperature"),
            "~Closed_Curtain | Active_AC & ~Low_ACTemperature"
        );
        assert_eq!(
            dnf("On_Yogurt_Table1 & (RobotNear_WaterStation | RobotNear_CoffeeStation)"),
            "On_Yogurt_Table1 & RobotNear_WaterStation | On_Yogurt_Table1 & RobotNear_CoffeeStation"
        );
        assert_eq!(
            dnf("~\"any object\" on \"blue cube\" & \"blue cube\" on \"green cube\""),
            "~\"any object\" on \"blue cube\" & \"blue cube\" on \"green cube\""
        );
    }

    #[test]
    fn equivalent_goals_get_the_same_minimal_dnf() {
        // A cyclic function: several minimum covers exist; the choice must not depend on
        // how the goal was written.
        let a = Formula::parse("A & ~B | B & ~C | C & ~A").unwrap();
        let b = Formula::parse("~A & C | ~C & B | ~B & A").unwrap();
        assert_eq!(equivalent(&a, &b), Ok(true));
        assert!(same_dnf(&a, &b));
        let c = Formula::parse("B & ~A | C & ~B | A & ~C").unwrap();
        assert_eq!(equivalent(&a, &c), Ok(true));
        assert!(same_dnf(&a, &c));
        assert_eq!(a.to_dnf().0.len(), 3);
    }

    #[test]
    fn beyond_the_exact_limit_absorption_only() {
        let atoms: Vec<String> = (0..14).map(|i| format!("P_{i}")).collect();
        let text = format!(
            "{} | {} & X | {} & ~{}",
            atoms.join(" & "),
            atoms[0],
            atoms[1],
            atoms[1]
        );
        let f = Formula::parse(&text).unwrap();
        let d = f.to_dnf();
        assert_eq!(d.to_string(), format!("{} | P_0 & X", atoms.join(" & ")));
        assert_eq!(equivalent(&f, &d.to_formula()), Ok(true));
        let t = Formula::parse(&format!("{} | ~P_0", atoms.join(" & "))).unwrap();
        // Minimal would be `P_1 & ... & P_13 | ~P_0`; absorption keeps P_0 in the first.
        let d = t.to_dnf();
        assert_eq!((d.0.len(), d.0[0].len()), (2, 14));
    }

    #[test]
    fn dnf_eval_and_to_formula_agree() {
        let f = Formula::parse("(A | ~B) & ~(C & A)").unwrap();
        let d = f.to_dnf();
        assert_eq!(equivalent(&f, &d.to_formula()), Ok(true));
        for bits in 0..8u32 {
            let t = |a: &Atom| match a.predicate.as_str() {
                "A" => bits & 1 == 1,
                "B" => bits & 2 == 2,
                _ => bits & 4 == 4,
            };
            assert_eq!(d.eval(&t), f.eval(&t));
        }
    }

    /// `n` either/or choices joined by `&`: 2^n alternatives.
    fn choices(n: usize) -> String {
        (0..n)
            .map(|i| format!("(A{i} | B{i})"))
            .collect::<Vec<_>>()
            .join(" & ")
    }

    #[test]
    fn goals_with_too_many_alternatives_are_refused_when_read() {
        // 2^10 = 1024: the most there may be.
        let ten = Formula::parse(&choices(10)).unwrap();
        assert_eq!(ten.to_dnf().0.len(), MAX_ALTERNATIVES);
        // 2^16: refused (distributing gives up at 2^11, before writing them all out).
        let e = Formula::parse(&choices(16)).unwrap_err();
        assert!(e.expected.contains("at most 1024 alternatives"), "{e}");
        // Repeated choices absorb: not refused however many.
        let same = vec!["(A | B)"; 40].join(" & ");
        assert_eq!(dnf(&same), "A | B");
        // A negation that multiplies out is bounded too.
        let ors = (0..16)
            .map(|i| format!("A{i} & B{i}"))
            .collect::<Vec<_>>()
            .join(" | ");
        let f = Formula::parse(&ors).unwrap();
        assert_eq!(
            Formula::Not(Box::new(f)).to_dnf_within(MAX_ALTERNATIVES),
            Err(TooManyAlternatives {
                limit: MAX_ALTERNATIVES
            })
        );
    }
}
