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

/// Positions of the nodes of `order` (preorder, any part of the tree that holds its root)
/// with these labels: only children in `order` count.
fn positions_of(tree: &Tree, order: &[NodeId], labels: &[String]) -> Vec<(f32, f32)> {
    let index: std::collections::HashMap<NodeId, usize> =
        order.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let nodes: Vec<(Vec<usize>, usize)> = order
        .iter()
        .zip(labels)
        .map(|(&id, label)| {
            let children = tree.children(id).unwrap_or_default();
            (
                children
                    .iter()
                    .filter_map(|c| index.get(c).copied())
                    .collect(),
                label.chars().count(),
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

/// Above this many nodes the graph shows the way from the root to where the tick is
/// (the running node, else the failed one, else the change's first new node), with the
/// children of each node on it; every other composite is folded into one node that says
/// what it is for and how many nodes it holds. A whole tree of 60 nodes side by side is
/// thousands of units wide: unreadable in the viewer at any zoom that shows it whole.
pub const WHOLE_GRAPH_NODES: usize = 40;

/// The node the graph of a large tree is opened to.
fn focus(tree: &Tree, order: &[NodeId], record: Option<&TickRecord>, new: &[NodeId]) -> NodeId {
    let running = record.and_then(|r| {
        // In preorder the deepest running node comes last.
        order
            .iter()
            .rev()
            .find(|&&n| {
                r.status(n) == Status::Running && tree.children(n).is_ok_and(<[_]>::is_empty)
            })
            .copied()
    });
    let failed = record.and_then(|r| r.failures.first().map(|(n, _)| *n));
    running
        .or(failed)
        .or_else(|| new.first().copied())
        .unwrap_or_else(|| tree.root())
}

/// What the graph shows of a tree: the nodes in preorder, and for each folded composite
/// how many nodes hang below it.
struct Shown {
    nodes: Vec<NodeId>,
    folded: std::collections::HashMap<NodeId, usize>,
}

fn shown(tree: &Tree, order: &[NodeId], focus: NodeId) -> Shown {
    if order.len() <= WHOLE_GRAPH_NODES {
        return Shown {
            nodes: order.to_vec(),
            folded: std::collections::HashMap::new(),
        };
    }
    let mut way = std::collections::HashSet::new();
    let mut at = Some(focus);
    while let Some(n) = at {
        way.insert(n);
        at = tree.parent(n).ok().flatten();
    }
    // Nodes below each node: its children's counts, gathered in reverse preorder.
    let mut below: std::collections::HashMap<NodeId, usize> = std::collections::HashMap::new();
    for &n in order.iter().rev() {
        let count = tree
            .children(n)
            .unwrap_or_default()
            .iter()
            .map(|c| 1 + below.get(c).copied().unwrap_or(0))
            .sum();
        below.insert(n, count);
    }
    let nodes: Vec<NodeId> = order
        .iter()
        .copied()
        .filter(|&n| {
            n == tree.root()
                || tree
                    .parent(n)
                    .ok()
                    .flatten()
                    .is_some_and(|p| way.contains(&p))
        })
        .collect();
    let folded = nodes
        .iter()
        .filter(|n| !way.contains(n))
        .filter_map(|&n| below.get(&n).filter(|&&c| c > 0).map(|&c| (n, c)))
        .collect();
    Shown { nodes, folded }
}

/// A node's label in a large tree's graph: a composite with what it is for, and a folded
/// one with how many nodes it holds.
fn large_label(tree: &Tree, node: NodeId, kind: &NodeKind, folded: Option<usize>) -> String {
    let purpose = tree
        .purpose(node)
        .map(|p| format!(" {p}"))
        .unwrap_or_default();
    match folded {
        Some(n) => format!("▸ {}{purpose} ({n} more)", label(kind)),
        None => format!("{}{purpose}", label(kind)),
    }
}

/// The graph of `tree` as the viewer shows it: the nodes (with colours and marks from
/// `record`, grey without; `+` before the nodes the last change added) at their tidy
/// positions, and the edges when `edges` is true or the tree is too large to show whole
/// (the nodes shown then change with the tick).
pub fn graph_of(
    tree: &Tree,
    record: Option<&TickRecord>,
    edges: bool,
    new: &[NodeId],
) -> (Graph, Option<Vec<(String, String)>>) {
    let order = tree.preorder();
    let large = order.len() > WHOLE_GRAPH_NODES;
    let shown = shown(tree, &order, focus(tree, &order, record, new));
    let status = |n: NodeId| record.map_or(Status::Idle, |r| r.status(n));
    let ids: Vec<String> = shown.nodes.iter().map(|n| n.0.to_string()).collect();
    let plain: Vec<String> = shown
        .nodes
        .iter()
        .map(|&n| {
            let Ok(kind) = tree.kind(n) else {
                return String::new();
            };
            let text = if large {
                large_label(tree, n, kind, shown.folded.get(&n).copied())
            } else {
                label(kind)
            };
            if new.contains(&n) {
                format!("+ {text}")
            } else {
                text
            }
        })
        .collect();
    let positions = positions_of(tree, &shown.nodes, &plain);
    let labels: Vec<String> = shown
        .nodes
        .iter()
        .zip(plain)
        .map(|(&n, text)| match status(n) {
            Status::Idle => text,
            s => format!("{} {text}", VIEWER_GLYPHS.status(s)),
        })
        .collect();
    let colours: Vec<Color> = shown
        .nodes
        .iter()
        .map(|n| {
            let [r, g, b] = status_colour(status(*n));
            Color::from_rgb(r, g, b)
        })
        .collect();
    let edges = (edges || large).then(|| {
        shown
            .nodes
            .iter()
            .filter_map(|&n| {
                let parent = tree.parent(n).ok().flatten()?;
                Some((parent.0.to_string(), n.0.to_string()))
            })
            .collect()
    });
    let graph = Graph {
        ids,
        labels,
        colours,
        positions,
    };
    (graph, edges)
}

/// Log the tree's graph ([`graph_of`]) and its text rendering.
pub fn log_tree(
    rec: &RecordingStream,
    tree: &Tree,
    record: Option<&TickRecord>,
    edges: bool,
    new: &[NodeId],
) -> RecordingStreamResult<()> {
    let (graph, edges) = graph_of(tree, record, edges, new);
    graph.log(rec, edges)?;
    let text = bt::render(tree, record, &VIEWER_GLYPHS).join("\n");
    rec.log(TREE_TEXT, &TextDocument::new(text))?;
    Ok(())
}
