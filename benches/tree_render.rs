//! The tree pane drawing a 5000-node tree in a 120×40 terminal (ratatui's test backend):
//! the first frame (the tree is laid out) and the median of 50 frames after it, against a
//! 60 Hz frame (16.7 ms). Run with `cargo bench --bench tree_render`.

use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use ratatui::Terminal;
use ratatui::backend::TestBackend;

use betr::bt::{NodeKind, Tree};
use betr::domain::{ActionCall, Condition};
use betr::tui::components::tree_pane::TreePane;
use betr::tui::theme::Theme;

/// A fallback of sequences, each a condition and an action, nested every 300 nodes.
fn big(n: usize) -> Result<Tree> {
    let mut t = Tree::new(NodeKind::Fallback);
    let mut count = 1;
    let mut parent = t.root();
    while count < n {
        let seq = t.add_child(parent, NodeKind::Sequence)?;
        t.add_child(
            seq,
            NodeKind::Condition(Condition::parse(&format!("Done_{count}"))?),
        )?;
        t.add_child(
            seq,
            NodeKind::Action(ActionCall::parse(&format!("Do \"thing {count}\""))?),
        )?;
        count += 3;
        if count % 300 == 1 {
            parent = seq;
        }
    }
    Ok(t)
}

fn main() -> Result<()> {
    let tree = Arc::new(big(5000)?);
    let theme = Theme::default();
    let mut pane = TreePane::default();
    let mut terminal = Terminal::new(TestBackend::new(120, 40))?;
    let start = Instant::now();
    pane.set_tree(tree.clone(), vec![tree.root()], Vec::new());
    terminal.draw(|f| pane.draw(f, f.area(), &theme))?;
    let first = start.elapsed().as_secs_f64() * 1e3;
    let mut frames: Vec<f64> = (0..50)
        .map(|_| {
            let t = Instant::now();
            terminal
                .draw(|f| pane.draw(f, f.area(), &theme))
                .map(|_| ())?;
            Ok(t.elapsed().as_secs_f64() * 1e3)
        })
        .collect::<Result<_>>()?;
    frames.sort_by(f64::total_cmp);
    let median = frames[frames.len() / 2];
    println!(
        "| nodes | first frame (ms) | later frames, median of 50 (ms) | frames per 60 Hz frame |"
    );
    println!(
        "|------:|-----------------:|--------------------------------:|----------------------:|"
    );
    println!(
        "| {} | {first:.2} | {median:.3} | {:.0} |",
        tree.len(),
        (1000.0 / 60.0) / median
    );
    Ok(())
}
