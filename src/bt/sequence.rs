//! Sequence (`->`, drawn `[-]`): do the children in order.
//!
//! Reactive and memoryless: every tick starts again at the first child (BT.CPP
//! `ReactiveSequence`, py_trees `Sequence(memory=False)`), so earlier conditions are
//! re-checked while a later action runs.
//!
//! Returns `Failure` at the first child that fails, `Running` at the first child that is
//! running (later children are not ticked), and `Success` when every child succeeds. A
//! sequence without children succeeds (`Tree::validate` rejects it anyway).

use super::status::Outcome;
use super::tree::NodeId;

/// Tick `children` in order with `tick_child`, stopping as described in the module docs.
pub(super) fn tick(children: &[NodeId], mut tick_child: impl FnMut(NodeId) -> Outcome) -> Outcome {
    for &child in children {
        match tick_child(child) {
            Outcome::Success => {}
            Outcome::Running => return Outcome::Running,
            Outcome::Failure => return Outcome::Failure,
        }
    }
    Outcome::Success
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
    fn stops_at_first_non_success() {
        assert_eq!(run(&[Success, Success]), (Success, 2));
        assert_eq!(run(&[Success, Failure, Success]), (Failure, 2));
        assert_eq!(run(&[Running, Failure]), (Running, 1));
        assert_eq!(run(&[Success, Running, Success]), (Running, 2));
        assert_eq!(run(&[]), (Success, 0));
    }
}
