//! Writing a tree as a Graphviz graph: control nodes as boxes (`→` sequence, `?`
//! fallback), conditions as ellipses, actions as boxes, each filled with its status in a
//! tick, and the nodes a repair added drawn with a thick blue border and a `+`.

use std::fmt::Write as _;

use crate::bt::{NodeId, NodeKind, Status, TickRecord, Tree};

/// Fill colours of the statuses (light, so black labels stay readable).
fn fill(status: Status) -> &'static str {
    match status {
        Status::Success => "#b7e4b0",
        Status::Failure => "#f4a6a6",
        Status::Running => "#fde68a",
        Status::Halted => "#d4d4d8",
        Status::Idle => "#ffffff",
    }
}

const NEW_BORDER: &str = "#1f6feb";

/// `tree` as a DOT digraph named `name`; `record` colours the nodes by the statuses of one
/// tick, `new_nodes` are marked as added by the last repair.
pub fn to_dot(
    tree: &Tree,
    record: Option<&TickRecord>,
    new_nodes: &[NodeId],
    name: &str,
) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "digraph {} {{", quoted(name));
    out.push_str("  ordering=out;\n  nodesep=0.25;\n  ranksep=0.45;\n");
    out.push_str(
        "  node [fontname=\"DejaVu Sans\", fontsize=11, style=\"filled\", fillcolor=\"#ffffff\", color=\"#555555\"];\n",
    );
    out.push_str("  edge [color=\"#777777\", arrowsize=0.6];\n");
    for id in tree.preorder() {
        let Ok(kind) = tree.kind(id) else { continue };
        let (label, shape) = match kind {
            NodeKind::Sequence => ("→".to_string(), "box"),
            NodeKind::Fallback => ("?".to_string(), "box"),
            NodeKind::Condition(c) => (c.to_string(), "ellipse"),
            NodeKind::Action(a) => (a.to_string(), "box"),
        };
        let status = record.map_or(Status::Idle, |r| r.status(id));
        let new = new_nodes.contains(&id);
        let label = if new { format!("+ {label}") } else { label };
        let _ = write!(
            out,
            "  n{} [label={}, shape={shape}, fillcolor=\"{}\"",
            id.0,
            quoted(&label),
            fill(status)
        );
        if kind.is_composite() {
            out.push_str(", width=0.4, fontsize=14");
        }
        if new {
            let _ = write!(out, ", penwidth=3, color=\"{NEW_BORDER}\"");
        }
        out.push_str("];\n");
        for child in tree.children(id).unwrap_or_default() {
            let _ = writeln!(out, "  n{} -> n{};", id.0, child.0);
        }
    }
    let tick = record.map_or_else(
        || "not ticked".to_string(),
        |r| format!("tick {}: {:?}", r.tick, r.root),
    );
    let mut legend = format!(
        "{tick} · green success · red failure · yellow running · grey halted · white not reached"
    );
    if !new_nodes.is_empty() {
        legend.push_str(" · blue border: added by the last repair");
    }
    let _ = writeln!(
        out,
        "  labelloc=b;\n  fontname=\"DejaVu Sans\";\n  fontsize=10;\n  label={};",
        quoted(&legend)
    );
    out.push_str("}\n");
    out
}

/// A DOT string literal. Rust's debug quoting escapes exactly what DOT needs here (`"`,
/// `\`, newlines) and keeps other characters (`→`, `~`) as they are.
fn quoted(text: &str) -> String {
    format!("{text:?}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bt;

    #[test]
    fn statuses_colour_nodes_and_new_nodes_are_marked() {
        let tree = bt::parse(
            "fallback\n  \"blue cube\" on \"green cube\"?\n  sequence\n    grasp \"blue cube\"!\n",
        )
        .expect("tree");
        let ids = tree.preorder();
        let mut statuses = vec![Status::Idle; tree.capacity()];
        statuses[ids[1].index()] = Status::Failure;
        statuses[ids[3].index()] = Status::Running;
        let record = TickRecord {
            tick: 3,
            root: bt::Outcome::Running,
            statuses,
            visited: ids.clone(),
            halted: Vec::new(),
            failures: Vec::new(),
            completed: Vec::new(),
            forced: Vec::new(),
        };
        let dot = to_dot(&tree, Some(&record), &[ids[3]], "red_on_blue");
        assert!(dot.starts_with("digraph \"red_on_blue\" {"), "{dot}");
        assert!(
            dot.contains(
                r##"label="\"blue cube\" on \"green cube\"", shape=ellipse, fillcolor="#f4a6a6""##
            ),
            "{dot}"
        );
        assert!(
            dot.contains(
                r##"label="+ grasp \"blue cube\"", shape=box, fillcolor="#fde68a", penwidth=3"##
            ),
            "{dot}"
        );
        assert!(
            dot.contains("n0 -> n1;") && dot.contains("n2 -> n3;"),
            "{dot}"
        );
        assert!(dot.contains("tick 3: Running"), "{dot}");
    }
}
