//! The layout the viewer opens with: the cell in 3D taking most of the window, the tree
//! beside it (the graph over its text), the event log below, and the time panel on the
//! session's `step` timeline; with no cell to draw (a symbolic world, a watched
//! BT.CPP process), the tree beside the log. Sent with every recording as the active and the default
//! blueprint: a viewer shows it at once, and resetting a rearranged layout comes back
//! to it.

use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintPanel, GraphView, Horizontal, SelectionPanel, Spatial3DView,
    TextDocumentView, TextLogView, TimePanel, Vertical,
};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    ForceCenter, ForceCollisionRadius, ForceLink, ForceManyBody, ForcePosition,
};

use super::tree::{TREE_GRAPH, TREE_TEXT};
use super::{EVENTS, STEPS};

/// Root of the cell's entities.
pub const WORLD: &str = "world";

/// Names of the views, as the viewer titles them.
pub const VIEW_3D: &str = "cell";
pub const VIEW_GRAPH: &str = "tree";
pub const VIEW_TEXT: &str = "tree (text)";
pub const VIEW_LOG: &str = "events";

/// The layout of a tree with no cell to draw (a symbolic world, a watched BT.CPP process):
/// the tree (the graph over its text) beside the event log, the time panel on `timeline`.
pub fn tree_and_log(timeline: &str) -> Blueprint {
    let tree = Vertical::new([
        still_graph(VIEW_GRAPH).with_origin(TREE_GRAPH).into(),
        TextDocumentView::new(VIEW_TEXT)
            .with_origin(TREE_TEXT)
            .into(),
    ])
    .with_row_shares(vec![3.0, 2.0]);
    let root = Horizontal::new([
        tree.into(),
        TextLogView::new(VIEW_LOG).with_origin(EVENTS).into(),
    ])
    .with_column_shares(vec![3.0, 2.0]);
    Blueprint::new(root)
        .with_auto_views(false)
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(TimePanel::new().with_timeline(timeline))
}

/// A graph view with every force off: the nodes stay where betr's tidy layout puts them.
pub fn still_graph(name: &str) -> GraphView {
    GraphView::new(name)
        .with_force_link(&ForceLink::new().with_enabled(false))
        .with_force_many_body(&ForceManyBody::new().with_enabled(false))
        .with_force_position(&ForcePosition::new().with_enabled(false))
        .with_force_collision_radius(&ForceCollisionRadius::new().with_enabled(false))
        .with_force_center(&ForceCenter::new().with_enabled(false))
}

/// The default layout. The graph view's forces are all off: the nodes stay where betr's
/// tidy layout puts them (`tree::graph_of`) instead of being pushed apart. The
/// blueprint and selection panels start collapsed, leaving the window to the views.
pub fn default_blueprint() -> Blueprint {
    let graph = still_graph(VIEW_GRAPH).with_origin(TREE_GRAPH);
    let tree = Vertical::new([
        graph.into(),
        TextDocumentView::new(VIEW_TEXT)
            .with_origin(TREE_TEXT)
            .into(),
    ])
    .with_row_shares(vec![3.0, 2.0]);
    let top = Horizontal::new([
        Spatial3DView::new(VIEW_3D).with_origin(WORLD).into(),
        tree.into(),
    ])
    .with_column_shares(vec![1.0, 1.0]);
    let root = Vertical::new([
        top.into(),
        TextLogView::new(VIEW_LOG).with_origin(EVENTS).into(),
    ])
    .with_row_shares(vec![4.0, 1.0]);
    Blueprint::new(root)
        .with_auto_views(false)
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(TimePanel::new().with_timeline(STEPS))
}
