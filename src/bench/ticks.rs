//! The tick loop against py_trees on the same tree.
//!
//! `../shared/anchors/bench_pytrees.py` builds a root sequence of planned-BT-shaped goal
//! subtrees (a fallback of a condition and a sequence of preconditions and an action,
//! nested three deep) until it has about 1000 nodes, and ticks it for some seconds;
//! conditions answer from a fixed pattern, actions keep running. `pytrees_shape` builds
//! the identical tree here, so both loops visit the same 23 nodes per tick.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use super::BenchError;
use crate::bt::{ActionStep, Leaves, NodeId, NodeKind, Ticker, Tree, TreeError};
use crate::domain::{ActionCall, Condition};

/// The py_trees release compared against.
pub const PY_TREES: &str = "py_trees==2.6.0";

/// Ticks per second of one loop on one tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickRate {
    pub nodes: usize,
    pub ticks_per_s: f64,
    pub visited_per_tick: usize,
}

/// The anchor's tree: goal subtrees three deep under a root sequence until `target` nodes;
/// every second goal's conditions fail down one branch, so a tick ends at a running
/// action of the second goal.
pub fn pytrees_shape(target: usize) -> Result<Tree, TreeError> {
    let mut tree = Tree::new(NodeKind::Sequence);
    let root = tree.root();
    let mut count = 0usize;
    let mut goals = 0usize;
    while count < target {
        subtree(&mut tree, root, 3, goals % 2 == 1, &mut count)?;
        goals += 1;
    }
    Ok(tree)
}

/// `Fallback(condition, Sequence(...))` as the anchor builds it; `count` follows the
/// anchor's own node count.
fn subtree(
    tree: &mut Tree,
    parent: NodeId,
    depth: u32,
    fail: bool,
    count: &mut usize,
) -> Result<(), TreeError> {
    let fallback = tree.add_child(parent, NodeKind::Fallback)?;
    tree.add_child(fallback, condition(!fail, *count))?;
    *count += 1;
    let sequence = tree.add_child(fallback, NodeKind::Sequence)?;
    if depth == 0 {
        tree.add_child(sequence, condition(true, *count))?;
        tree.add_child(sequence, action(*count))?;
        *count += 3;
    } else {
        subtree(tree, sequence, depth - 1, false, count)?;
        subtree(tree, sequence, depth - 1, fail, count)?;
        tree.add_child(sequence, action(*count))?;
        *count += 2;
    }
    *count += 1;
    Ok(())
}

/// A condition that holds when its name starts with `Ok`.
fn condition(ok: bool, n: usize) -> NodeKind {
    let name = if ok {
        format!("Ok_{n}")
    } else {
        format!("No_{n}")
    };
    NodeKind::Condition(Condition::pos(crate::domain::Atom {
        predicate: name,
        args: Vec::new(),
    }))
}

fn action(n: usize) -> NodeKind {
    NodeKind::Action(ActionCall::new("Act", [format!("a{n}")]))
}

/// The anchor's leaves: conditions from their names, actions always running.
struct FixedLeaves;

impl Leaves for FixedLeaves {
    fn check(&mut self, condition: &Condition) -> bool {
        condition.atom.predicate.starts_with("Ok")
    }
    fn step(&mut self, _: NodeId, _: &ActionCall, _: bool) -> ActionStep {
        ActionStep::Running
    }
    fn halt(&mut self, _: NodeId, _: &ActionCall) {}
}

/// Tick `tree` for `time` with betr's ticker (each tick records every node's status, as
/// the workbench and the recording need).
pub fn betr_ticks(tree: &Tree, time: Duration) -> TickRate {
    let mut ticker = Ticker::new();
    let mut leaves = FixedLeaves;
    let visited = ticker.tick(tree, &mut leaves).visited.len();
    let started = Instant::now();
    let mut ticks = 0u64;
    // Checking the clock every 256 ticks keeps it out of the measure.
    while started.elapsed() < time {
        for _ in 0..256 {
            std::hint::black_box(ticker.tick(tree, &mut leaves));
        }
        ticks += 256;
    }
    TickRate {
        nodes: tree.len(),
        ticks_per_s: ticks as f64 / started.elapsed().as_secs_f64(),
        visited_per_tick: visited,
    }
}

/// A Python with py_trees in a virtual environment under `venv` (made the first time).
pub fn pytrees_python(venv: &Path) -> Result<PathBuf, BenchError> {
    super::anchor_venv(
        venv,
        &[PY_TREES],
        &[],
        "import py_trees, importlib.metadata as m; assert m.version('py_trees') == '2.6.0'",
    )
}

/// Run the anchor script for `time` on about `nodes` nodes.
pub fn pytrees_ticks(
    python: &Path,
    script: &Path,
    nodes: usize,
    time: Duration,
) -> Result<TickRate, BenchError> {
    let what = format!("py_trees ({})", script.display());
    let out = super::run_anchor(
        &what,
        Command::new(python)
            .arg(script)
            .arg(nodes.to_string())
            .arg(format!("{:.3}", time.as_secs_f64())),
    )?;
    parse_pytrees(&out).ok_or_else(|| BenchError::Anchor {
        what,
        detail: format!("unexpected output: {}", out.trim()),
    })
}

/// `py_trees nodes=1021 ticks=… ticks_per_s=3021.5 visited_per_tick=23 …`
fn parse_pytrees(out: &str) -> Option<TickRate> {
    let line = out.lines().find(|l| l.starts_with("py_trees "))?;
    let field = |name: &str| {
        line.split_whitespace()
            .find_map(|f| f.strip_prefix(name)?.strip_prefix('='))
    };
    Some(TickRate {
        nodes: field("nodes")?.parse().ok()?,
        ticks_per_s: field("ticks_per_s")?.parse().ok()?,
        visited_per_tick: field("visited_per_tick")?.parse().ok()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The anchor's tree has 1021 nodes for a target of 1000 (15 goals of 68 and the root)
    /// and a tick visits 23 of them, ending at a running action.
    #[test]
    fn the_shape_is_the_anchors() -> Result<(), TreeError> {
        let tree = pytrees_shape(1000)?;
        assert_eq!(tree.len(), 1021);
        let record = Ticker::new().tick(&tree, &mut FixedLeaves);
        assert_eq!(record.visited.len(), 23);
        assert_eq!(record.root, crate::bt::Outcome::Running);
        Ok(())
    }

    #[test]
    fn the_anchors_line_is_read() {
        let line = "py_trees nodes=1021 ticks=9000 ticks_per_s=3001.5 visited_per_tick=23 node_visits_per_s=69034\n";
        assert_eq!(
            parse_pytrees(line),
            Some(TickRate {
                nodes: 1021,
                ticks_per_s: 3001.5,
                visited_per_tick: 23
            })
        );
        assert_eq!(parse_pytrees("Traceback ..."), None);
    }
}
