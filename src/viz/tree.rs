//! Logging the behavior tree: a graph laid out as a tidy tree (node positions logged, so
//! the viewer does not push the nodes around), its colours and status marks following the
//! tick's statuses, and the same tree as a text document (`bt::render`).

use rerun::{
    Color, GraphEdges, GraphNodes, Position2D, RecordingStream, RecordingStreamResult, TextDocument,
};

use crate::bt::{self, Glyphs, NodeId, NodeKind, Status, TickRecord, Tree};

pub const TREE_GRAPH: &str = "tree/graph";
pub const TREE_TEXT: &str = "tree/text";

/// The marks the viewer's fonts have: `bt::UNICODE` but for failure (`✕` is missing from
/// them and shows as an empty box; the multiplication sign `×` is in every text font) and
/// halted (`=`, as in ASCII).
pub const VIEWER_GLYPHS: Glyphs = Glyphs {
    failure: "×",
    halted: "=",
    ..bt::UNICODE
};

/// Vertical distance between the levels of the graph, in the graph view's units.
const LEVEL: f32 = 90.0;
/// Horizontal room a leaf takes: its label's characters at this width each, with a gap,
/// and never less than `MIN_SLOT`.
const CHAR_WIDTH: f32 = 7.5;
const GAP: f32 = 30.0;
const MIN_SLOT: f32 = 90.0;

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

/// A node's label in the graph: its status mark first once the tick reached it.
fn graph_label(kind: &NodeKind, status: Status) -> String {
    match status {
        Status::Idle => label(kind),
        shown => format!("{} {}", VIEWER_GLYPHS.status(shown), label(kind)),
    }
}

/// Positions of the nodes of `order` (the tree's preorder) as a tidy tree ([`tidy`]).
pub fn tidy_positions(tree: &Tree, order: &[NodeId]) -> Vec<(f32, f32)> {
    let index: std::collections::HashMap<NodeId, usize> =
        order.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let nodes: Vec<(Vec<usize>, usize)> = order
        .iter()
        .map(|&id| {
            let children = tree.children(id).unwrap_or_default();
            let chars = tree.kind(id).map_or(0, |k| label(k).chars().count());
            (
                children
                    .iter()
                    .filter_map(|c| index.get(c).copied())
                    .collect(),
                chars,
            )
        })
        .collect();
    tidy(&nodes)
}

/// Positions of a tree's nodes given in preorder (index 0 the root), each with its
/// children's indices and its label's length: each leaf in its own slot, left to right,
/// as wide as its label; each parent centred over its first and last child; one level
/// per depth, the root on top (the graph view's y grows downwards). No recursion, so a
/// deep tree cannot exhaust the stack.
pub fn tidy(nodes: &[(Vec<usize>, usize)]) -> Vec<(f32, f32)> {
    let mut depth = vec![0usize; nodes.len()];
    let mut x = vec![0.0_f32; nodes.len()];
    let mut cursor = 0.0_f32;
    // Preorder meets the leaves left to right, and every parent before its children.
    for (i, (children, chars)) in nodes.iter().enumerate() {
        let below = depth[i] + 1;
        for &c in children {
            if let Some(d) = depth.get_mut(c) {
                *d = below;
            }
        }
        if children.is_empty() {
            let width = ((chars + 2) as f32 * CHAR_WIDTH + GAP).max(MIN_SLOT);
            x[i] = cursor + width / 2.0;
            cursor += width;
        }
    }
    // Reverse preorder places every child before its parent.
    for (i, (children, _)) in nodes.iter().enumerate().rev() {
        if let (Some(&first), Some(&last)) = (children.first(), children.last()) {
            x[i] = (x.get(first).copied().unwrap_or_default()
                + x.get(last).copied().unwrap_or_default())
                / 2.0;
        }
    }
    x.into_iter()
        .zip(depth)
        .map(|(x, d)| (x, d as f32 * LEVEL))
        .collect()
}

/// A tree's graph as the viewer draws it: each node's id, label and colour, at its
/// position.
pub struct Graph {
    pub ids: Vec<String>,
    pub labels: Vec<String>,
    pub colours: Vec<Color>,
    pub positions: Vec<(f32, f32)>,
}

impl Graph {
    /// Logs the nodes and, when given, the edges (parent, child) between them.
    pub fn log(
        self,
        rec: &RecordingStream,
        edges: Option<Vec<(String, String)>>,
    ) -> RecordingStreamResult<()> {
        let positions: Vec<Position2D> = self
            .positions
            .into_iter()
            .map(|(x, y)| Position2D::new(x, y))
            .collect();
        rec.log(
            TREE_GRAPH,
            &GraphNodes::new(self.ids)
                .with_labels(self.labels)
                .with_colors(self.colours)
                .with_positions(positions),
        )?;
        if let Some(pairs) = edges {
            rec.log(TREE_GRAPH, &GraphEdges::new(pairs).with_directed_edges())?;
        }
        Ok(())
    }
}

/// Log the nodes (with colours and marks from `record`, grey without) at their tidy
/// positions and, when `edges` is true, the edges, plus the text rendering.
pub fn log_tree(
    rec: &RecordingStream,
    tree: &Tree,
    record: Option<&TickRecord>,
    edges: bool,
) -> RecordingStreamResult<()> {
    let order = tree.preorder();
    let status = |n: NodeId| record.map_or(Status::Idle, |r| r.status(n));
    let ids: Vec<String> = order.iter().map(|n| n.0.to_string()).collect();
    let labels: Vec<String> = order
        .iter()
        .map(|n| {
            tree.kind(*n)
                .map(|k| graph_label(k, status(*n)))
                .unwrap_or_default()
        })
        .collect();
    let colours: Vec<Color> = order
        .iter()
        .map(|n| {
            let [r, g, b] = status_colour(status(*n));
            Color::from_rgb(r, g, b)
        })
        .collect();
    let edges = edges.then(|| {
        order
            .iter()
            .flat_map(|n| {
                tree.children(*n)
                    .unwrap_or_default()
                    .iter()
                    .map(|c| (n.0.to_string(), c.0.to_string()))
                    .collect::<Vec<_>>()
            })
            .collect()
    });
    let graph = Graph {
        ids,
        labels,
        colours,
        positions: tidy_positions(tree, &order),
    };
    graph.log(rec, edges)?;
    let text = bt::render(tree, record, &VIEWER_GLYPHS).join("\n");
    rec.log(TREE_TEXT, &TextDocument::new(text))?;
    Ok(())
}
