//! Logging the behavior tree: a graph whose node colours follow the tick's statuses, and
//! the same tree as a text document (`bt::render`).

use rerun::{Color, GraphEdges, GraphNodes, RecordingStream, RecordingStreamResult, TextDocument};

use crate::bt::{self, NodeKind, Status, TickRecord, Tree};

pub const TREE_GRAPH: &str = "tree/graph";
pub const TREE_TEXT: &str = "tree/text";

/// The colour of a node that showed `status`.
pub fn status_colour(status: Status) -> [u8; 3] {
    match status {
        Status::Idle => [150, 150, 150],
        Status::Running => [240, 190, 40],
        Status::Success => [50, 180, 80],
        Status::Failure => [220, 50, 47],
        Status::Halted => [120, 120, 200],
    }
}

fn label(kind: &NodeKind) -> String {
    match kind {
        NodeKind::Sequence => "→ sequence".into(),
        NodeKind::Fallback => "? fallback".into(),
        NodeKind::Condition(c) => format!("{c}?"),
        NodeKind::Action(a) => format!("{a}!"),
    }
}

/// Log the nodes (with colours from `record`, grey without) and, when `edges` is true,
/// the edges, plus the text rendering.
pub fn log_tree(
    rec: &RecordingStream,
    tree: &Tree,
    record: Option<&TickRecord>,
    edges: bool,
) -> RecordingStreamResult<()> {
    let order = tree.preorder();
    let ids: Vec<String> = order.iter().map(|n| n.0.to_string()).collect();
    let labels: Vec<String> = order
        .iter()
        .map(|n| tree.kind(*n).map(label).unwrap_or_default())
        .collect();
    let colours: Vec<Color> = order
        .iter()
        .map(|n| {
            let [r, g, b] = status_colour(record.map_or(Status::Idle, |r| r.status(*n)));
            Color::from_rgb(r, g, b)
        })
        .collect();
    rec.log(
        TREE_GRAPH,
        &GraphNodes::new(ids)
            .with_labels(labels)
            .with_colors(colours),
    )?;
    if edges {
        let pairs: Vec<(String, String)> = order
            .iter()
            .flat_map(|n| {
                tree.children(*n)
                    .unwrap_or_default()
                    .iter()
                    .map(|c| (n.0.to_string(), c.0.to_string()))
                    .collect::<Vec<_>>()
            })
            .collect();
        rec.log(TREE_GRAPH, &GraphEdges::new(pairs).with_directed_edges())?;
    }
    let text = bt::render(tree, record, &bt::UNICODE).join("\n");
    rec.log(TREE_TEXT, &TextDocument::new(text))?;
    Ok(())
}
