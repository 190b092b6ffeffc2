//! Exact two-level minimisation: Quine–McCluskey prime implicants, then a minimum cover.
//!
//! The cover is minimum in the number of conjunctions, then in the number of literals.
//! Among covers equal in both, the one whose conjunctions come first under a canonical
//! order of the atoms (their `Ord`, not their position in the goal) is chosen, so that two
//! equivalent goals written differently get the same minimal DNF.
//!
//! The cover search is a branch and bound after taking the essential prime implicants. It
//! visits at most [`SEARCH_BUDGET`] nodes; functions that need more (only contrived ones
//! with large cyclic cores) get the best cover found by then, which is a correct DNF but
//! may not be minimum.

use std::collections::HashSet;

/// Most search nodes the cover search visits.
pub(super) const SEARCH_BUDGET: usize = 200_000;

/// A conjunction of literals over variables `0..n`: variable `i` appears when bit `i` of
/// `mask` is set, positively when bit `i` of `bits` is also set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) struct Cube {
    pub bits: u32,
    pub mask: u32,
}

impl Cube {
    fn covers(self, minterm: u32) -> bool {
        minterm & self.mask == self.bits
    }

    fn literals(self) -> u32 {
        self.mask.count_ones()
    }

    /// `(canonical rank, negated)` of each literal, sorted.
    fn canonical_key(self, rank: &[usize]) -> Vec<(usize, bool)> {
        let mut key: Vec<(usize, bool)> = (0..rank.len())
            .filter(|&i| self.mask >> i & 1 == 1)
            .map(|i| (rank[i], self.bits >> i & 1 == 0))
            .collect();
        key.sort_unstable();
        key
    }
}

/// A minimum set of prime implicants covering exactly `minterms` (the assignments, over `n`
/// variables, where the function is true). `rank[i]` is variable `i`'s canonical rank, used
/// only to break ties. No minterms gives no cubes; all `2^n` give the one empty cube.
pub(super) fn minimise(n: usize, minterms: &[u32], rank: &[usize]) -> Vec<Cube> {
    if minterms.is_empty() {
        return Vec::new();
    }
    let mut primes = prime_implicants(n, minterms);
    primes.sort_by_cached_key(|c| (c.literals(), c.canonical_key(rank)));
    let keys: Vec<Vec<(usize, bool)>> = primes.iter().map(|c| c.canonical_key(rank)).collect();
    let covering: Vec<Vec<usize>> = minterms
        .iter()
        .map(|&m| (0..primes.len()).filter(|&p| primes[p].covers(m)).collect())
        .collect();
    let members: Vec<Vec<usize>> = (0..primes.len())
        .map(|p| {
            (0..minterms.len())
                .filter(|&m| primes[p].covers(minterms[m]))
                .collect()
        })
        .collect();
    let mut search = Search {
        covering: &covering,
        members: &members,
        primes: &primes,
        keys: &keys,
        count: vec![0; minterms.len()],
        uncovered: minterms.len(),
        chosen: Vec::new(),
        best: None,
        nodes: 0,
    };
    // Essential primes belong to every cover.
    for list in &covering {
        if let [only] = list.as_slice()
            && !search.chosen.contains(only)
        {
            search.select(*only);
        }
    }
    search.run();
    let chosen = search
        .best
        .map_or_else(|| (0..primes.len()).collect(), |b| b.0);
    chosen.into_iter().map(|p| primes[p]).collect()
}

fn prime_implicants(n: usize, minterms: &[u32]) -> Vec<Cube> {
    let full = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
    let mut level: HashSet<Cube> = minterms
        .iter()
        .map(|&m| Cube {
            bits: m,
            mask: full,
        })
        .collect();
    let mut primes = Vec::new();
    while !level.is_empty() {
        let mut next = HashSet::new();
        let mut merged = HashSet::new();
        for &c in &level {
            for v in 0..n {
                let b = 1u32 << v;
                if c.mask & b != 0 && c.bits & b == 0 {
                    let partner = Cube {
                        bits: c.bits | b,
                        mask: c.mask,
                    };
                    if level.contains(&partner) {
                        next.insert(Cube {
                            bits: c.bits,
                            mask: c.mask & !b,
                        });
                        merged.insert(c);
                        merged.insert(partner);
                    }
                }
            }
        }
        primes.extend(level.iter().filter(|c| !merged.contains(c)).copied());
        level = next;
    }
    primes.sort_unstable();
    primes
}

type Score = (usize, u32, Vec<Vec<(usize, bool)>>);

struct Search<'a> {
    covering: &'a [Vec<usize>],
    members: &'a [Vec<usize>],
    primes: &'a [Cube],
    keys: &'a [Vec<(usize, bool)>],
    count: Vec<u32>,
    uncovered: usize,
    chosen: Vec<usize>,
    best: Option<(Vec<usize>, Score)>,
    nodes: usize,
}

impl Search<'_> {
    fn select(&mut self, p: usize) {
        for &m in &self.members[p] {
            if self.count[m] == 0 {
                self.uncovered -= 1;
            }
            self.count[m] += 1;
        }
        self.chosen.push(p);
    }

    fn unselect(&mut self, p: usize) {
        for &m in &self.members[p] {
            self.count[m] -= 1;
            if self.count[m] == 0 {
                self.uncovered += 1;
            }
        }
        self.chosen.pop();
    }

    fn literals(&self) -> u32 {
        self.chosen.iter().map(|&p| self.primes[p].literals()).sum()
    }

    fn run(&mut self) {
        self.nodes += 1;
        if self.nodes > SEARCH_BUDGET && self.best.is_some() {
            return;
        }
        if self.uncovered == 0 {
            let mut keys: Vec<Vec<(usize, bool)>> =
                self.chosen.iter().map(|&p| self.keys[p].clone()).collect();
            keys.sort_unstable();
            let score = (self.chosen.len(), self.literals(), keys);
            if self.best.as_ref().is_none_or(|(_, best)| score < *best) {
                self.best = Some((self.chosen.clone(), score));
            }
            return;
        }
        if let Some((_, (count, lits, _))) = &self.best
            && (self.chosen.len() + 1, self.literals() + 1) > (*count, *lits)
        {
            return;
        }
        // Branch on the uncovered minterm with the fewest ways to cover it.
        let Some(m) = (0..self.count.len())
            .filter(|&m| self.count[m] == 0)
            .min_by_key(|&m| self.covering[m].len())
        else {
            return;
        };
        let covering = self.covering;
        for &p in &covering[m] {
            self.select(p);
            self.run();
            self.unselect(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(n: usize, f: impl Fn(u32) -> bool) -> Vec<u32> {
        (0..1u32 << n).filter(|&m| f(m)).collect()
    }

    #[test]
    fn merges_adjacent_minterms() {
        // a & b | a & ~b = a  (bit 0 = a, bit 1 = b)
        let cubes = minimise(2, &table(2, |m| m & 1 == 1), &[0, 1]);
        assert_eq!(cubes, vec![Cube { bits: 1, mask: 1 }]);
        let all = minimise(2, &table(2, |_| true), &[0, 1]);
        assert_eq!(all, vec![Cube { bits: 0, mask: 0 }]);
        assert!(minimise(2, &[], &[0, 1]).is_empty());
    }

    #[test]
    fn cyclic_core_gets_a_minimum_cover() {
        // The classic cyclic function of three variables: 6 primes, minimum cover of 3.
        let f = |m: u32| ![0b000, 0b111].contains(&m);
        let cubes = minimise(3, &table(3, f), &[0, 1, 2]);
        assert_eq!(cubes.len(), 3);
        for m in 0..8 {
            assert_eq!(cubes.iter().any(|c| c.covers(m)), f(m));
        }
    }

    #[test]
    fn twelve_variables_stay_fast() {
        // Parity of 12 variables: 2048 essential primes, no merging.
        let f = |m: u32| m.count_ones() % 2 == 1;
        let rank: Vec<usize> = (0..12).collect();
        assert_eq!(minimise(12, &table(12, f), &rank).len(), 2048);
        // Threshold of 12 variables: many primes and a real search.
        let g = |m: u32| m.count_ones() >= 6;
        let cubes = minimise(12, &table(12, g), &rank);
        for m in 0..1u32 << 12 {
            assert_eq!(cubes.iter().any(|c| c.covers(m)), g(m));
        }
    }

    #[test]
    fn minimum_for_every_function_of_three_variables() {
        for f in 0..256u32 {
            let minterms = table(3, |m| f >> m & 1 == 1);
            let cubes = minimise(3, &minterms, &[0, 1, 2]);
            for m in 0..8 {
                assert_eq!(
                    cubes.iter().any(|c| c.covers(m)),
                    f >> m & 1 == 1,
                    "{f:08b}"
                );
            }
            // Brute force over every set of prime implicants.
            let primes = prime_implicants(3, &minterms);
            let mut best = (usize::MAX, u32::MAX);
            for set in 0..1u32 << primes.len() {
                let chosen: Vec<Cube> = (0..primes.len())
                    .filter(|&i| set >> i & 1 == 1)
                    .map(|i| primes[i])
                    .collect();
                if minterms.iter().all(|&m| chosen.iter().any(|c| c.covers(m))) {
                    let lits = chosen.iter().map(|c| c.literals()).sum();
                    best = best.min((chosen.len(), lits));
                }
            }
            if minterms.is_empty() {
                best = (0, 0);
            }
            let lits = cubes.iter().map(|c| c.literals()).sum();
            assert_eq!((cubes.len(), lits), best, "{f:08b}");
        }
    }
}
