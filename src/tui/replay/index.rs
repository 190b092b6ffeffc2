//! Which recorded steps rebuild the workbench at a position, without every tick.
//!
//! The app's state after a step depends on every step before it, except for two kinds of
//! events that only overwrite what they show (see `app/session.rs`): a tick (`Ticked`: the
//! tick count, the tree's statuses, and it clears a run's stop mark, which a later tick
//! clears again) and a change of the world's facts that is not a reset (`WorldChanged`:
//! the facts). The two touch different state, so between two other steps (a *segment*)
//! only the last tick and the last change of facts before the position matter; every other
//! step (commands, tree changes, failures, model calls, resets, notices) is fed, in order.

use crate::record::Step;
use crate::session::Event;

/// Step indices with no tick (or change of facts) before them in their segment.
const NONE: u32 = u32::MAX;

/// The plan of a recording's steps for seeking.
#[derive(Debug, Clone, Default)]
pub struct SeekIndex {
    /// Every step fed when seeking to the end, in order: each step that is neither a tick
    /// nor a change of facts, and the last tick and the last change of facts of each
    /// segment.
    essential: Vec<u32>,
    /// For each position `p` (0 to the number of steps), the last tick before `p` in its
    /// segment, or `NONE`.
    last_tick: Vec<u32>,
    /// Likewise for the last change of facts.
    last_facts: Vec<u32>,
}

/// What a step is to the seek.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Tick,
    Facts,
    /// Anything else: fed always, and it ends a segment.
    Other,
}

fn kind(step: &Step) -> Kind {
    match step {
        Step::Event(Event::Ticked { .. }) => Kind::Tick,
        Step::Event(Event::WorldChanged { reset: false, .. }) => Kind::Facts,
        _ => Kind::Other,
    }
}

/// Step positions as stored (recordings of more than four billion steps are not read).
fn small(i: usize) -> u32 {
    u32::try_from(i).unwrap_or(NONE - 1)
}

impl SeekIndex {
    pub fn new<'a>(steps: impl IntoIterator<Item = &'a Step>) -> SeekIndex {
        let mut index = SeekIndex {
            last_tick: vec![NONE],
            last_facts: vec![NONE],
            ..SeekIndex::default()
        };
        let (mut tick, mut facts) = (NONE, NONE);
        for (i, step) in steps.into_iter().enumerate() {
            match kind(step) {
                Kind::Tick => tick = small(i),
                Kind::Facts => facts = small(i),
                Kind::Other => {
                    index.close(tick, facts);
                    index.essential.push(small(i));
                    (tick, facts) = (NONE, NONE);
                }
            }
            index.last_tick.push(tick);
            index.last_facts.push(facts);
        }
        index.close(tick, facts);
        index
    }

    /// The end of a segment: its last tick and change of facts, in their order.
    fn close(&mut self, tick: u32, facts: u32) {
        let mut last = [tick, facts];
        last.sort_unstable();
        self.essential
            .extend(last.into_iter().filter(|&i| i != NONE));
    }

    /// The number of positions: the steps and one more (the end).
    pub fn positions(&self) -> usize {
        self.last_tick.len()
    }

    /// The steps to feed, in order, for the state after the first `p` steps (`p` past the
    /// end counts as the end).
    pub fn feed(&self, p: usize) -> Vec<usize> {
        let Some(end) = self.positions().checked_sub(1) else {
            return Vec::new();
        };
        let p = p.min(end);
        let before = self.essential.partition_point(|&i| (i as usize) < p);
        let mut out: Vec<usize> = self.essential[..before]
            .iter()
            .map(|&i| i as usize)
            .collect();
        // The segment `p` falls in: its last tick and change of facts before `p`, in
        // order (either may be among the essential steps already, when no step of its kind
        // follows it in the segment).
        for i in [self.last_tick.get(p), self.last_facts.get(p)] {
            let Some(&i) = i.filter(|&&i| i != NONE) else {
                continue;
            };
            let i = i as usize;
            let at = out.partition_point(|&x| x < i);
            if out.get(at) != Some(&i) {
                out.insert(at, i);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::bt::{Outcome, TickRecord};

    fn tick(n: u64) -> Step {
        Step::Event(Event::Ticked {
            record: Arc::new(TickRecord {
                tick: n,
                root: Outcome::Running,
                statuses: Vec::new(),
                visited: Vec::new(),
                halted: Vec::new(),
                failures: Vec::new(),
                completed: Vec::new(),
                forced: Vec::new(),
            }),
        })
    }

    fn facts(reset: bool) -> Step {
        Step::Event(Event::WorldChanged {
            facts: Vec::new(),
            reset,
        })
    }

    fn other() -> Step {
        Step::Command("run".into())
    }

    /// The steps whose effect the fed ones reproduce: all of them, with each tick and
    /// change of facts dropped when another of its kind follows in its segment before `p`.
    fn by_hand(steps: &[Step], p: usize) -> Vec<usize> {
        (0..p)
            .filter(|&i| match kind(&steps[i]) {
                Kind::Other => true,
                k => !steps[i + 1..p]
                    .iter()
                    .take_while(|s| kind(s) != Kind::Other)
                    .any(|s| kind(s) == k),
            })
            .collect()
    }

    #[test]
    fn only_the_last_tick_and_facts_of_each_stretch_are_fed() {
        let steps = vec![
            other(),
            tick(1),
            facts(false),
            tick(2),
            tick(3),
            facts(false),
            tick(4),
            other(),
            facts(true),
            tick(1),
            tick(2),
            facts(false),
        ];
        let index = SeekIndex::new(&steps);
        assert_eq!(index.positions(), steps.len() + 1);
        assert_eq!(index.feed(0), Vec::<usize>::new());
        assert_eq!(index.feed(5), [0, 2, 4]);
        assert_eq!(index.feed(7), [0, 5, 6]);
        assert_eq!(index.feed(12), [0, 5, 6, 7, 8, 10, 11]);
        assert_eq!(index.feed(99), index.feed(12));
        assert_eq!(SeekIndex::default().feed(3), Vec::<usize>::new());
        assert_eq!(SeekIndex::new(&[]).feed(0), Vec::<usize>::new());
        for p in 0..=steps.len() {
            assert_eq!(index.feed(p), by_hand(&steps, p), "at {p}");
        }
    }
}
