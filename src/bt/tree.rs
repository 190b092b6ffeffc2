//! The behavior tree as an arena: nodes live in a `Vec` and are named by `NodeId`.
//!
//! Ids are stable: edits never renumber nodes. A removed node stays in the arena as a
//! tombstone, so `capacity()` (arena size) can exceed `len()` (live nodes); asking about a
//! removed id is an error. Equality (`==`) compares shape and node kinds from the root and
//! ignores ids, so a tree rebuilt by parsing its text equals the original.

use std::fmt;

use crate::domain::{ActionCall, Condition};

/// The name of one node of a `Tree`; an index into its arena.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(transparent)]
pub struct NodeId(pub u32);

impl NodeId {
    /// The arena index (also the index into `TickRecord::statuses`).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Display for NodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}

/// What a node is: a control node (sequence, fallback) or a leaf (condition, action).
#[derive(Clone, Debug, PartialEq)]
pub enum NodeKind {
    Sequence,
    Fallback,
    Condition(Condition),
    Action(ActionCall),
}

impl NodeKind {
    /// True for `Sequence` and `Fallback`.
    pub fn is_composite(&self) -> bool {
        matches!(self, NodeKind::Sequence | NodeKind::Fallback)
    }

    /// True for `Condition` and `Action`.
    pub fn is_leaf(&self) -> bool {
        !self.is_composite()
    }

    pub fn as_condition(&self) -> Option<&Condition> {
        match self {
            NodeKind::Condition(c) => Some(c),
            _ => None,
        }
    }

    pub fn as_action(&self) -> Option<&ActionCall> {
        match self {
            NodeKind::Action(a) => Some(a),
            _ => None,
        }
    }
}

/// What a composite is for ([`Tree::purpose`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Purpose<'a> {
    /// A fallback that makes this condition hold.
    Achieves(&'a Condition),
    /// A sequence that prepares this action and runs it.
    Runs(&'a ActionCall),
}

impl std::fmt::Display for Purpose<'_> {
    /// As it follows the composite's name: `for "blue cube" on "green cube"`, `to grasp
    /// "blue cube"!`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Purpose::Achieves(c) => write!(f, "for {c}"),
            Purpose::Runs(a) => write!(f, "to {a}!"),
        }
    }
}

/// Why a tree operation was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TreeError {
    #[error("no node {0} in this tree")]
    UnknownNode(NodeId),
    #[error("node {0} was removed")]
    RemovedNode(NodeId),
    #[error("node {parent} has {len} children, so child index {index} is out of range")]
    ChildIndex {
        parent: NodeId,
        index: usize,
        len: usize,
    },
    #[error("the root cannot be removed")]
    RemoveRoot,
    #[error("no node at path {}", fmt_path(.0))]
    NoNodeAtPath(Vec<usize>),
    #[error(
        "no node {0:?} in the tree (name one by its path, like 1.0.1.1, or as a leaf the tree shows, like grasp \"blue cube\"!)"
    )]
    NoNodeNamed(String),
    #[error("{kind} at {} has no children", fmt_path(.path))]
    EmptyComposite {
        path: Vec<usize>,
        kind: &'static str,
    },
    #[error("{kind} at {} has children", fmt_path(.path))]
    LeafWithChildren {
        path: Vec<usize>,
        kind: &'static str,
    },
}

/// A path as `root` or `root/0/2` (child indices from the root).
pub(super) fn fmt_path(path: &[usize]) -> String {
    let mut s = String::from("root");
    for i in path {
        s.push('/');
        s.push_str(&i.to_string());
    }
    s
}

#[derive(Clone, Debug)]
struct Node {
    kind: NodeKind,
    parent: Option<NodeId>,
    children: Vec<NodeId>,
    live: bool,
}

/// A behavior tree: an arena of nodes with one root.
#[derive(Clone, Debug)]
pub struct Tree {
    nodes: Vec<Node>,
    root: NodeId,
}

impl Tree {
    /// A tree holding only a root of `root_kind`.
    pub fn new(root_kind: NodeKind) -> Tree {
        Tree {
            nodes: vec![Node {
                kind: root_kind,
                parent: None,
                children: Vec::new(),
                live: true,
            }],
            root: NodeId(0),
        }
    }

    pub fn root(&self) -> NodeId {
        self.root
    }

    /// Number of live nodes (at least 1: the root).
    #[allow(clippy::len_without_is_empty)] // a tree always has its root
    pub fn len(&self) -> usize {
        self.nodes.iter().filter(|n| n.live).count()
    }

    /// Arena size, tombstones included: every id ever handed out is below this.
    pub fn capacity(&self) -> usize {
        self.nodes.len()
    }

    /// True when `id` names a live node.
    pub fn contains(&self, id: NodeId) -> bool {
        self.nodes.get(id.index()).is_some_and(|n| n.live)
    }

    fn node(&self, id: NodeId) -> Result<&Node, TreeError> {
        match self.nodes.get(id.index()) {
            Some(n) if n.live => Ok(n),
            Some(_) => Err(TreeError::RemovedNode(id)),
            None => Err(TreeError::UnknownNode(id)),
        }
    }

    fn node_mut(&mut self, id: NodeId) -> Result<&mut Node, TreeError> {
        match self.nodes.get_mut(id.index()) {
            Some(n) if n.live => Ok(n),
            Some(_) => Err(TreeError::RemovedNode(id)),
            None => Err(TreeError::UnknownNode(id)),
        }
    }

    pub fn kind(&self, id: NodeId) -> Result<&NodeKind, TreeError> {
        Ok(&self.node(id)?.kind)
    }

    pub fn kind_mut(&mut self, id: NodeId) -> Result<&mut NodeKind, TreeError> {
        Ok(&mut self.node_mut(id)?.kind)
    }

    /// The kind a node has or had before it was removed (tombstones keep theirs), so the
    /// ticker can halt a running action that an edit removed.
    pub(super) fn kind_any(&self, id: NodeId) -> Option<&NodeKind> {
        self.nodes.get(id.index()).map(|n| &n.kind)
    }

    pub fn children(&self, id: NodeId) -> Result<&[NodeId], TreeError> {
        Ok(&self.node(id)?.children)
    }

    /// What a composite is for, so that folded away it still says it: a fallback whose
    /// first child is a condition achieves that condition (its other children run when it
    /// is false); a sequence whose last child is an action prepares and runs that action.
    pub fn purpose(&self, id: NodeId) -> Option<Purpose<'_>> {
        let children = self.children(id).ok()?;
        match self.kind(id).ok()? {
            NodeKind::Fallback => self
                .kind(*children.first()?)
                .ok()?
                .as_condition()
                .map(Purpose::Achieves),
            NodeKind::Sequence => self
                .kind(*children.last()?)
                .ok()?
                .as_action()
                .map(Purpose::Runs),
            _ => None,
        }
    }

    /// The parent, or `None` for the root.
    pub fn parent(&self, id: NodeId) -> Result<Option<NodeId>, TreeError> {
        Ok(self.node(id)?.parent)
    }

    /// Position of `id` among its parent's children; `None` for the root.
    pub fn index_in_parent(&self, id: NodeId) -> Result<Option<usize>, TreeError> {
        match self.node(id)?.parent {
            None => Ok(None),
            Some(p) => Ok(self.node(p)?.children.iter().position(|&c| c == id)),
        }
    }

    fn push_node(&mut self, kind: NodeKind, parent: Option<NodeId>) -> NodeId {
        let id = NodeId(u32::try_from(self.nodes.len()).unwrap_or(u32::MAX));
        self.nodes.push(Node {
            kind,
            parent,
            children: Vec::new(),
            live: true,
        });
        id
    }

    /// Append a child to `parent`, which the caller knows is live (the parser uses ids it
    /// just got from this tree).
    pub(super) fn push_child(&mut self, parent: NodeId, kind: NodeKind) -> NodeId {
        let id = self.push_node(kind, Some(parent));
        if let Some(p) = self.nodes.get_mut(parent.index()) {
            p.children.push(id);
        }
        id
    }

    /// Append a new last child of `parent`.
    pub fn add_child(&mut self, parent: NodeId, kind: NodeKind) -> Result<NodeId, TreeError> {
        let len = self.node(parent)?.children.len();
        self.insert_child(parent, len, kind)
    }

    /// Insert a new child of `parent` at `index` (`0..=children.len()`).
    pub fn insert_child(
        &mut self,
        parent: NodeId,
        index: usize,
        kind: NodeKind,
    ) -> Result<NodeId, TreeError> {
        let len = self.node(parent)?.children.len();
        if index > len {
            return Err(TreeError::ChildIndex { parent, index, len });
        }
        let id = self.push_node(kind, Some(parent));
        self.node_mut(parent)?.children.insert(index, id);
        Ok(id)
    }

    /// Put a new node of `kind` where `id` is (in its parent, or as the root) and make `id`
    /// its only child. Returns the new node. Turns a condition `c` into `Fallback(c)`.
    pub fn wrap(&mut self, id: NodeId, kind: NodeKind) -> Result<NodeId, TreeError> {
        let parent = self.node(id)?.parent;
        let slot = self.index_in_parent(id)?;
        let wrapper = self.push_node(kind, parent);
        self.node_mut(wrapper)?.children.push(id);
        self.node_mut(id)?.parent = Some(wrapper);
        match (parent, slot) {
            (Some(p), Some(i)) => {
                if let Some(c) = self.node_mut(p)?.children.get_mut(i) {
                    *c = wrapper;
                }
            }
            _ => self.root = wrapper,
        }
        Ok(wrapper)
    }

    /// Move the child at `from` to position `to` among `parent`'s children.
    pub fn move_child(&mut self, parent: NodeId, from: usize, to: usize) -> Result<(), TreeError> {
        let children = &mut self.node_mut(parent)?.children;
        let len = children.len();
        for index in [from, to] {
            if index >= len {
                return Err(TreeError::ChildIndex { parent, index, len });
            }
        }
        let id = children.remove(from);
        children.insert(to, id);
        Ok(())
    }

    /// Remove `id` and everything under it; returns the removed ids in preorder. Their ids
    /// are never reused.
    pub fn remove_subtree(&mut self, id: NodeId) -> Result<Vec<NodeId>, TreeError> {
        let Some(parent) = self.node(id)?.parent else {
            return Err(TreeError::RemoveRoot);
        };
        let removed = self.subtree(id)?;
        self.node_mut(parent)?.children.retain(|&c| c != id);
        for r in &removed {
            if let Some(n) = self.nodes.get_mut(r.index()) {
                n.live = false;
            }
        }
        Ok(removed)
    }
}

#[path = "tree_query.rs"]
mod query;

#[path = "tree_serde.rs"]
mod serde_impl;

#[cfg(test)]
#[path = "tree_tests.rs"]
mod tests;

/// A node path (child indices from the root, as `Tree::path` gives) as `0.2.1`; the root
/// is `root`.
pub fn path_text(path: &[usize]) -> String {
    if path.is_empty() {
        "root".to_string()
    } else {
        path.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(".")
    }
}
