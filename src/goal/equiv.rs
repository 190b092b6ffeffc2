//! Comparing goals: logical equivalence by truth table, and the published scoring rule.

use super::Formula;
use super::truth::{Ix, index_of};

/// [`equivalent`] refuses formulas with more distinct atoms than this (2^20 assignments).
pub const EQUIV_ATOM_LIMIT: usize = 20;

/// The two formulas mention too many distinct atoms to compare by truth table.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot compare goals over {count} distinct atoms by truth table (at most {limit})")]
pub struct TooManyAtoms {
    pub count: usize,
    pub limit: usize,
}

/// True when `a` and `b` have the same value under every assignment of the atoms of both.
pub fn equivalent(a: &Formula, b: &Formula) -> Result<bool, TooManyAtoms> {
    let mut atoms = a.atoms_in_order();
    for atom in b.atoms_in_order() {
        if !atoms.contains(&atom) {
            atoms.push(atom);
        }
    }
    if atoms.len() > EQUIV_ATOM_LIMIT {
        return Err(TooManyAtoms {
            count: atoms.len(),
            limit: EQUIV_ATOM_LIMIT,
        });
    }
    let index = index_of(&atoms);
    let (ia, ib) = (Ix::compile(a, &index), Ix::compile(b, &index));
    Ok((0..1u64 << atoms.len()).all(|bits| ia.eval(bits) == ib.eval(bits)))
}

/// The published scoring rule: the minimal DNFs of `a` and `b` are equal as sets of sets of
/// literals. Agrees with [`equivalent`] whenever both goals have at most
/// [`super::EXACT_ATOM_LIMIT`] distinct atoms (minimal DNFs are chosen canonically); beyond
/// that the DNFs are only absorbed, so equivalent goals may compare unequal.
pub fn same_dnf(a: &Formula, b: &Formula) -> bool {
    a.to_dnf().to_sets() == b.to_dnf().to_sets()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::goal::parse::tests::formula;
    use proptest::prelude::*;

    fn p(text: &str) -> Formula {
        Formula::parse(text).unwrap()
    }

    #[test]
    fn equivalence_by_truth_table() {
        assert_eq!(equivalent(&p("~(A | B)"), &p("~A & ~B")), Ok(true));
        assert_eq!(
            equivalent(&p("A | B & C"), &p("(A | B) & (A | C)")),
            Ok(true)
        );
        assert_eq!(equivalent(&p("A | B & C"), &p("(A | B) & C")), Ok(false));
        // Atoms only one side mentions count too.
        assert_eq!(equivalent(&p("A"), &p("A & (B | ~B)")), Ok(true));
        assert_eq!(equivalent(&p("A"), &p("A & B")), Ok(false));
    }

    #[test]
    fn same_dnf_is_the_scoring_rule() {
        assert!(same_dnf(&p("A & B | C"), &p("C | B & A")));
        assert!(same_dnf(&p("(A & B) | (A & ~B)"), &p("A")));
        assert!(!same_dnf(&p("A & B | C"), &p("A & B")));
        assert!(!same_dnf(&p("A"), &p("~A")));
    }

    #[test]
    fn too_many_atoms_is_an_error() {
        let big: Vec<String> = (0..21).map(|i| format!("P_{i}")).collect();
        let f = p(&big.join(" & "));
        let e = equivalent(&f, &p("A")).unwrap_err();
        assert_eq!((e.count, e.limit), (22, EQUIV_ATOM_LIMIT));
        assert!(e.to_string().contains("22 distinct atoms"));
    }

    /// Every `&` / `|` list reversed and the whole goal doubly negated.
    fn rewritten(f: &Formula) -> Formula {
        fn rev(f: &Formula) -> Formula {
            match f {
                Formula::Atom(_) => f.clone(),
                Formula::Not(x) => Formula::Not(Box::new(rev(x))),
                Formula::And(v) => Formula::And(v.iter().rev().map(rev).collect()),
                Formula::Or(v) => Formula::Or(v.iter().rev().map(rev).collect()),
            }
        }
        Formula::Not(Box::new(Formula::Not(Box::new(rev(f)))))
    }

    proptest! {
        #[test]
        fn dnf_is_equivalent_and_both_rules_agree(a in formula(), b in formula()) {
            let dnf = a.to_dnf();
            prop_assert_eq!(equivalent(&a, &dnf.to_formula()), Ok(true), "{} vs {}", a, dnf);
            prop_assert!(same_dnf(&a, &rewritten(&a)), "{}", a);
            prop_assert_eq!(equivalent(&a, &b), Ok(same_dnf(&a, &b)), "{} vs {}", a, b);
            let or = Formula::Or(vec![a.clone(), b.clone()]);
            let or_swapped = Formula::Or(vec![b.clone(), a.clone()]);
            prop_assert!(same_dnf(&or, &or_swapped), "{}", or);
        }
    }
}
