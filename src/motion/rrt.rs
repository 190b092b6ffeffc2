//! Collision-free paths in one arm's joint space: the straight segment when it is free,
//! else RRT-Connect (two trees, from the start and from the goal, each extended towards
//! random samples and greedily towards the other, a step reaching up to a fifth of the
//! arm's joint space across as OMPL's RRTConnect does; a step stopped by a collision
//! keeps its free part when that is a quarter step or more) within a budget of samples, then
//! shortcutting (random pairs of points on the path joined straight when the segment is
//! free). Segments are checked at a fixed joint resolution. The random sequence comes
//! from the seed, so a query gives the same path every time.

use std::collections::BTreeMap;

use crate::robot::SplitMix;

use super::MotionError;
use super::check::ArmCheck;

/// How a path is searched for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanOptions {
    pub seed: u64,
    /// Random samples drawn at most before giving up.
    pub samples: usize,
    /// Longest step a tree grows at once, as a fraction of the diagonal of the arm's
    /// joint limits (its joint space across). Short steps explore slowly: a goal far from
    /// the start behind a narrow way then needs many more samples than the budget.
    pub range: f64,
    /// Largest joint-space distance between two configurations checked along a segment.
    pub resolution: f64,
    /// Attempts at shortening the path found.
    pub shortcuts: usize,
    /// Whether a step stopped by a collision keeps its free part.
    pub keep_partial: bool,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            seed: 39,
            samples: 4000,
            range: 0.2,
            resolution: 0.03,
            shortcuts: 60,
            keep_partial: true,
        }
    }
}

/// A collision-free path and what finding it took.
#[derive(Debug, Clone, PartialEq)]
pub struct JointPath {
    /// From the start to the goal; consecutive points are joined straight in joint space.
    pub waypoints: Vec<Vec<f64>>,
    /// Random samples drawn (0 when the straight segment was free).
    pub samples: usize,
    /// Configurations checked for collision.
    pub checks: usize,
}

impl JointPath {
    /// The path's length in joint space (radians).
    pub fn length(&self) -> f64 {
        self.waypoints
            .windows(2)
            .map(|w| distance(&w[0], &w[1]))
            .sum()
    }
}

/// A tree of configurations, each but the root with its parent.
struct Tree {
    dof: usize,
    points: Vec<f64>,
    parents: Vec<usize>,
}

impl Tree {
    fn new(root: &[f64]) -> Tree {
        Tree {
            dof: root.len(),
            points: root.to_vec(),
            parents: vec![0],
        }
    }

    fn point(&self, i: usize) -> &[f64] {
        &self.points[i * self.dof..(i + 1) * self.dof]
    }

    fn nearest(&self, q: &[f64]) -> usize {
        (0..self.parents.len())
            .map(|i| (i, distance_squared(self.point(i), q)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |(i, _)| i)
    }

    fn add(&mut self, q: &[f64], parent: usize) -> usize {
        self.points.extend_from_slice(q);
        self.parents.push(parent);
        self.parents.len() - 1
    }

    /// The configurations from node `i` up to the root.
    fn to_root(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut out = vec![self.point(i).to_vec()];
        while i != 0 {
            i = self.parents[i];
            out.push(self.point(i).to_vec());
        }
        out
    }
}

enum Grown {
    Reached(usize),
    Advanced(usize),
    Trapped,
}

/// The planner's state for one query.
struct Search<'c, 'a> {
    check: &'c ArmCheck<'a>,
    options: PlanOptions,
    /// Longest step (radians, joint-space distance) a tree grows at once.
    step: f64,
    checks: usize,
    /// How often each blocker stopped a step.
    blocked: BTreeMap<String, usize>,
}

impl Search<'_, '_> {
    /// Whether the straight segment from `a` to `b` is free (`a` is known to be free).
    fn segment_free(&mut self, a: &[f64], b: &[f64]) -> bool {
        self.free_part(a, b) == 1.0
    }

    /// How far (0–1) along the straight segment from `a` to `b` every configuration
    /// checked is free (`a` is known to be free): 1 when the whole segment is.
    fn free_part(&mut self, a: &[f64], b: &[f64]) -> f64 {
        let steps = (distance(a, b) / self.options.resolution).ceil().max(1.0) as usize;
        let mut q = vec![0.0; a.len()];
        for s in 1..=steps {
            let t = s as f64 / steps as f64;
            for (k, v) in q.iter_mut().enumerate() {
                *v = a[k] + (b[k] - a[k]) * t;
            }
            self.checks += 1;
            if let Some(blocker) = self.check.blocker(&q) {
                *self.blocked.entry(blocker).or_insert(0) += 1;
                return (s - 1) as f64 / steps as f64;
            }
        }
        1.0
    }

    /// Grow `tree` one step from its nearest node towards `target`.
    fn extend(&mut self, tree: &mut Tree, target: &[f64]) -> Grown {
        let near = tree.nearest(target);
        let from = tree.point(near).to_vec();
        let d = distance(&from, target);
        let (to, reached) = if d <= self.step {
            (target.to_vec(), true)
        } else {
            let t = self.step / d;
            (
                from.iter()
                    .zip(target)
                    .map(|(a, b)| a + (b - a) * t)
                    .collect(),
                false,
            )
        };
        let free = self.free_part(&from, &to);
        if free == 1.0 {
            let i = tree.add(&to, near);
            return if reached {
                Grown::Reached(i)
            } else {
                Grown::Advanced(i)
            };
        }
        // The free part of a blocked step is kept when it is a step of its own: the tree
        // grows up to what is in the way rather than not at all.
        if self.options.keep_partial && free * distance(&from, &to) >= self.step / 4.0 {
            let part: Vec<f64> = from
                .iter()
                .zip(&to)
                .map(|(a, b)| a + (b - a) * free)
                .collect();
            tree.add(&part, near);
        }
        Grown::Trapped
    }

    /// Grow `tree` towards `target` until it gets there or is stopped.
    fn connect(&mut self, tree: &mut Tree, target: &[f64]) -> Grown {
        loop {
            match self.extend(tree, target) {
                Grown::Advanced(_) => continue,
                other => return other,
            }
        }
    }

    fn most_blocking(&self) -> Option<String> {
        self.blocked
            .iter()
            .max_by(|a, b| a.1.cmp(b.1).then_with(|| b.0.cmp(a.0)))
            .map(|(name, _)| name.clone())
    }
}

/// A collision-free path for the arm of `check` from `start` to `goal`.
pub fn plan(
    check: &ArmCheck<'_>,
    start: &[f64],
    goal: &[f64],
    options: &PlanOptions,
) -> Result<JointPath, MotionError> {
    let chain = check.chain();
    for (what, q) in [("start", start), ("goal", goal)] {
        if !chain.within_limits(q) {
            return Err(MotionError::OutsideLimits {
                what,
                arm: chain.tip.clone(),
            });
        }
        if let Some(blocker) = check.blocker(q) {
            return Err(MotionError::NoPath {
                arm: chain.tip.clone(),
                why: format!("the {what} configuration collides with {blocker}"),
                blocker: Some(blocker),
            });
        }
    }
    let across = chain
        .joints
        .iter()
        .map(|j| (j.upper - j.lower).powi(2))
        .sum::<f64>()
        .sqrt();
    let mut search = Search {
        check,
        options: *options,
        step: options.range * across,
        checks: 2,
        blocked: BTreeMap::new(),
    };
    if search.segment_free(start, goal) {
        return Ok(JointPath {
            waypoints: vec![start.to_vec(), goal.to_vec()],
            samples: 0,
            checks: search.checks,
        });
    }
    let mut rng = SplitMix::new(options.seed);
    let (mut a, mut b) = (Tree::new(start), Tree::new(goal));
    let mut a_is_start = true;
    for sample in 1..=options.samples {
        let q: Vec<f64> = chain
            .joints
            .iter()
            .map(|j| j.lower + rng.unit() * (j.upper - j.lower))
            .collect();
        let grown = match search.extend(&mut a, &q) {
            Grown::Reached(i) | Grown::Advanced(i) => Some(i),
            Grown::Trapped => None,
        };
        if let Some(i) = grown {
            let new = a.point(i).to_vec();
            if let Grown::Reached(k) = search.connect(&mut b, &new) {
                let (from_start, from_goal) = if a_is_start {
                    (a.to_root(i), b.to_root(k))
                } else {
                    (b.to_root(k), a.to_root(i))
                };
                let mut waypoints: Vec<Vec<f64>> = from_start.into_iter().rev().collect();
                waypoints.extend(from_goal.into_iter().skip(1));
                let waypoints = shortcut(&mut search, waypoints, &mut rng);
                return Ok(JointPath {
                    waypoints,
                    samples: sample,
                    checks: search.checks,
                });
            }
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    }
    let blocker = search.most_blocking();
    Err(MotionError::NoPath {
        arm: chain.tip.clone(),
        why: format!(
            "{} samples tried{}",
            options.samples,
            blocker
                .as_ref()
                .map_or(String::new(), |b| format!(", most often blocked by {b}"))
        ),
        blocker,
    })
}

/// Join random pairs of the path's points straight where the segment between is free.
fn shortcut(
    search: &mut Search<'_, '_>,
    mut path: Vec<Vec<f64>>,
    rng: &mut SplitMix,
) -> Vec<Vec<f64>> {
    for _ in 0..search.options.shortcuts {
        if path.len() < 3 {
            break;
        }
        let n = path.len();
        let i = (rng.unit() * n as f64) as usize % n;
        let k = (rng.unit() * n as f64) as usize % n;
        let (i, k) = (i.min(k), i.max(k));
        if k < i + 2 {
            continue;
        }
        let (a, b) = (path[i].clone(), path[k].clone());
        if search.segment_free(&a, &b) {
            path.drain(i + 1..k);
        }
    }
    path
}

fn distance_squared(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    distance_squared(a, b).sqrt()
}
