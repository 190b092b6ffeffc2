//! A formula with its atoms replaced by indices, for fast evaluation over truth tables.

use std::collections::HashMap;

use super::Formula;
use crate::domain::Atom;

pub(super) enum Ix {
    Var(usize),
    Not(Box<Ix>),
    And(Vec<Ix>),
    Or(Vec<Ix>),
}

impl Ix {
    /// Compile `f` against `index` (which must contain every atom of `f`; an unknown atom
    /// would be a bug, and is treated as variable 0 rather than panicking).
    pub(super) fn compile(f: &Formula, index: &HashMap<&Atom, usize>) -> Ix {
        match f {
            Formula::Atom(a) => Ix::Var(index.get(a).copied().unwrap_or(0)),
            Formula::Not(x) => Ix::Not(Box::new(Ix::compile(x, index))),
            Formula::And(v) => Ix::And(v.iter().map(|x| Ix::compile(x, index)).collect()),
            Formula::Or(v) => Ix::Or(v.iter().map(|x| Ix::compile(x, index)).collect()),
        }
    }

    /// The value when variable `i` has the value of bit `i` of `bits`.
    pub(super) fn eval(&self, bits: u64) -> bool {
        match self {
            Ix::Var(i) => bits >> i & 1 == 1,
            Ix::Not(x) => !x.eval(bits),
            Ix::And(v) => v.iter().all(|x| x.eval(bits)),
            Ix::Or(v) => v.iter().any(|x| x.eval(bits)),
        }
    }
}

/// Atom → index for the atoms in `atoms`.
pub(super) fn index_of(atoms: &[Atom]) -> HashMap<&Atom, usize> {
    atoms.iter().enumerate().map(|(i, a)| (a, i)).collect()
}
