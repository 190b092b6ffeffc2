//! Read-only questions about a `Tree`'s shape: paths, depths, ancestry, traversals,
//! validation, and structural equality (a child module of `tree.rs`, split off for size).

use super::{NodeId, NodeKind, Tree, TreeError};
use crate::domain::{ActionCall, Condition};

impl Tree {
    /// Child indices from the root down to `id` (empty for the root).
    pub fn path(&self, id: NodeId) -> Result<Vec<usize>, TreeError> {
        let mut path = Vec::new();
        let mut at = id;
        while let Some(i) = self.index_in_parent(at)? {
            path.push(i);
            at = self.node(at)?.parent.ok_or(TreeError::UnknownNode(at))?;
        }
        path.reverse();
        Ok(path)
    }

    /// The node reached by following child indices from the root.
    pub fn node_at_path(&self, path: &[usize]) -> Result<NodeId, TreeError> {
        let mut at = self.root;
        for &i in path {
            at = *self
                .node(at)?
                .children
                .get(i)
                .ok_or_else(|| TreeError::NoNodeAtPath(path.to_vec()))?;
        }
        Ok(at)
    }

    /// The nodes `text` names: a node path as `path_text` writes it (`1.0.1.1`, `root`),
    /// or a leaf as the tree shows it (`grasp "blue cube"!`, `"blue cube" grasped?`; the
    /// suffix may be left out), which names every leaf with that text, in preorder.
    pub fn find(&self, text: &str) -> Result<Vec<NodeId>, TreeError> {
        let text = text.trim();
        let missing = || TreeError::NoNodeNamed(text.to_string());
        if text == "root" {
            return Ok(vec![self.root]);
        }
        let is_path = text
            .split('.')
            .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
        if is_path {
            let path = text
                .split('.')
                .map(str::parse)
                .collect::<Result<Vec<usize>, _>>()
                .map_err(|_| missing())?;
            return self
                .node_at_path(&path)
                .map(|n| vec![n])
                .map_err(|_| missing());
        }
        let (body, action, condition) = match (text.strip_suffix('!'), text.strip_suffix('?')) {
            (Some(body), _) => (body, true, false),
            (None, Some(body)) => (body, false, true),
            (None, None) => (text, true, true),
        };
        let action = action.then(|| ActionCall::parse(body).ok()).flatten();
        let condition = condition.then(|| Condition::parse(body).ok()).flatten();
        let found: Vec<NodeId> = self
            .preorder()
            .into_iter()
            .filter(|&n| match self.kind(n) {
                Ok(NodeKind::Action(a)) => action.as_ref() == Some(a),
                Ok(NodeKind::Condition(c)) => condition.as_ref() == Some(c),
                _ => false,
            })
            .collect();
        if found.is_empty() {
            Err(missing())
        } else {
            Ok(found)
        }
    }

    /// Distance from the root (the root has depth 0).
    pub fn depth(&self, id: NodeId) -> Result<usize, TreeError> {
        Ok(self.ancestors(id)?.len())
    }

    /// Proper ancestors of `id`, nearest first.
    fn ancestors(&self, id: NodeId) -> Result<Vec<NodeId>, TreeError> {
        let mut out = Vec::new();
        let mut at = self.node(id)?.parent;
        while let Some(p) = at {
            out.push(p);
            at = self.node(p)?.parent;
        }
        Ok(out)
    }

    /// True when `a` is a proper ancestor of `of` (a node is not its own ancestor).
    pub fn is_ancestor(&self, a: NodeId, of: NodeId) -> Result<bool, TreeError> {
        self.node(a)?;
        Ok(self.ancestors(of)?.contains(&a))
    }

    /// The deepest node that is `a` or an ancestor of `a` and also `b` or an ancestor of `b`.
    pub fn lowest_common_ancestor(&self, a: NodeId, b: NodeId) -> Result<NodeId, TreeError> {
        let mut of_b = self.ancestors(b)?;
        of_b.push(b);
        let mut chain = vec![a];
        chain.extend(self.ancestors(a)?);
        Ok(chain
            .into_iter()
            .find(|x| of_b.contains(x))
            .unwrap_or(self.root))
    }

    /// `id` and all nodes under it, in preorder.
    pub fn subtree(&self, id: NodeId) -> Result<Vec<NodeId>, TreeError> {
        Ok(self
            .subtree_with_depth(id)?
            .into_iter()
            .map(|(n, _)| n)
            .collect())
    }

    /// `id` and all nodes under it in preorder, each with its depth below `id`.
    pub(in crate::bt) fn subtree_with_depth(
        &self,
        id: NodeId,
    ) -> Result<Vec<(NodeId, usize)>, TreeError> {
        let mut out = Vec::new();
        let mut stack = vec![(id, 0)];
        while let Some((n, d)) = stack.pop() {
            out.push((n, d));
            for &c in self.node(n)?.children.iter().rev() {
                stack.push((c, d + 1));
            }
        }
        Ok(out)
    }

    /// All live nodes in preorder from the root.
    pub fn preorder(&self) -> Vec<NodeId> {
        self.subtree(self.root).unwrap_or_default()
    }

    /// Action nodes in preorder.
    pub fn actions(&self) -> Vec<(NodeId, &ActionCall)> {
        self.preorder()
            .into_iter()
            .filter_map(|id| Some((id, self.kind(id).ok()?.as_action()?)))
            .collect()
    }

    /// Condition nodes in preorder.
    pub fn conditions(&self) -> Vec<(NodeId, &Condition)> {
        self.preorder()
            .into_iter()
            .filter_map(|id| Some((id, self.kind(id).ok()?.as_condition()?)))
            .collect()
    }

    /// Check that every composite has children and no leaf has any; the error names the
    /// first offending node (preorder) by its path.
    pub fn validate(&self) -> Result<(), TreeError> {
        for id in self.preorder() {
            let node = self.node(id)?;
            let (kind, composite) = match &node.kind {
                NodeKind::Sequence => ("sequence", true),
                NodeKind::Fallback => ("fallback", true),
                NodeKind::Condition(_) => ("condition", false),
                NodeKind::Action(_) => ("action", false),
            };
            if composite && node.children.is_empty() {
                let path = self.path(id)?;
                return Err(TreeError::EmptyComposite { path, kind });
            }
            if !composite && !node.children.is_empty() {
                let path = self.path(id)?;
                return Err(TreeError::LeafWithChildren { path, kind });
            }
        }
        Ok(())
    }
}

impl PartialEq for Tree {
    fn eq(&self, other: &Tree) -> bool {
        let mut stack = vec![(self.root, other.root)];
        while let Some((a, b)) = stack.pop() {
            let (Ok(na), Ok(nb)) = (self.node(a), other.node(b)) else {
                return false;
            };
            if na.kind != nb.kind || na.children.len() != nb.children.len() {
                return false;
            }
            stack.extend(na.children.iter().copied().zip(nb.children.iter().copied()));
        }
        true
    }
}
