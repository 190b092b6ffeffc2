//! Fallback (`?`, drawn `[o]`, a.k.a. selector): try the children in order until one works.
//!
//! Reactive and memoryless: every tick starts again at the first child (BT.CPP
//! `ReactiveFallback`, py_trees `Selector(memory=False)`), so once a higher-priority child
//! succeeds (e.g. the goal condition now holds) the lower ones are no longer ticked.
//!
//! Returns `Success` at the first child that succeeds, `Running` at the first child that is
//! running (later children are not ticked), and `Failure` when every child fails. A
//! fallback without children fails (`Tree::validate` rejects it anyway).

use super::status::Outcome;
use super::tree::NodeId;

/// Tick `children` in order with `tick_child`, stopping as described in the module docs.
pub(super) fn tick(children: &[NodeId], mut tick_child: impl FnMut(NodeId) -> Outcome) -> Outcome {
    for &child in children {
        match tick_child(child) {
            Outcome::Failure => {}
            Outcome::Running => return Outcome::Running,
            Outcome::Success => return Outcome::Success,
        }
    }
    Outcome::Failure
}

#[cfg(test)]
mod tests {
    use super::*;
    use Outcome::{Failure, Running, Success};

    fn run(results: &[Outcome]) -> (Outcome, usize) {
        let ids: Vec<NodeId> = (0..results.len() as u32).map(NodeId).collect();
        let mut ticked = 0;
        let out = tick(&ids, |id| {
            ticked += 1;
            results[id.index()]
        });
        (out, ticked)
    }

    #[test]
    fn stops_at_first_non_failure() {
        assert_eq!(run(&[Failure, Failure]), (Failure, 2));
        assert_eq!(run(&[Failure, Success, Failure]), (Success, 2));
        assert_eq!(run(&[Running, Success]), (Running, 1));
        assert_eq!(run(&[Failure, Running, Success]), (Running, 2));
        assert_eq!(run(&[]), (Failure, 0));
    }
}
