//! A tree as a file writes it: its text, which a person can read and the parser checks,
//! with the id of each node, so the events that name nodes by id name the same nodes in
//! the tree read back (edits leave removed ids unused, so ids are not positions).

use serde::{Deserialize, Serialize};

use super::{Node, NodeId, NodeKind, Tree};

#[derive(Serialize, Deserialize)]
struct Written {
    /// The tree in betr's tree text.
    text: String,
    /// The id of each node, in the text's order (pre-order).
    ids: Vec<NodeId>,
    /// The arena's size, removed nodes included.
    capacity: usize,
}

/// The most slots (live and removed nodes) a tree read back may claim: far beyond any
/// tree a session grows, and a bound on what a damaged or hostile file makes betr allocate
/// (the arena is made before the ids are checked against it).
pub const MAX_SLOTS: usize = 1 << 20;

impl Serialize for Tree {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Written {
            text: crate::bt::to_text(self),
            ids: self.preorder(),
            capacity: self.capacity(),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for Tree {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let written = Written::deserialize(d)?;
        let parsed = crate::bt::parse(&written.text)
            .map_err(|e| serde::de::Error::custom(format!("the tree: {e}")))?;
        with_ids(&parsed, &written.ids, written.capacity)
    }
}

/// `parsed` with its nodes renumbered: the `i`th node in pre-order gets `ids[i]`, in an
/// arena of `capacity` nodes whose other slots are removed nodes.
fn with_ids<E: serde::de::Error>(
    parsed: &Tree,
    ids: &[NodeId],
    capacity: usize,
) -> Result<Tree, E> {
    if capacity > MAX_SLOTS {
        return Err(E::custom(format!(
            "the tree claims {capacity} node slots; betr reads trees of at most {MAX_SLOTS}"
        )));
    }
    let order = parsed.preorder();
    if order.len() != ids.len() {
        return Err(E::custom(format!(
            "{} node ids for a tree of {} nodes",
            ids.len(),
            order.len()
        )));
    }
    let mut renamed = vec![None; parsed.capacity()];
    for (old, new) in order.iter().zip(ids) {
        if new.index() >= capacity {
            return Err(E::custom(format!(
                "node id {new} is past the tree's {capacity} slots"
            )));
        }
        renamed[old.index()] = Some(*new);
    }
    let rename = |id: NodeId| renamed.get(id.index()).copied().flatten();
    let removed = || Node {
        kind: NodeKind::Sequence,
        parent: None,
        children: Vec::new(),
        live: false,
    };
    let mut nodes: Vec<Node> = (0..capacity).map(|_| removed()).collect();
    for (old, new) in order.iter().zip(ids) {
        let node = &parsed.nodes[old.index()];
        let slot = &mut nodes[new.index()];
        if slot.live {
            return Err(E::custom(format!("node id {new} is given twice")));
        }
        *slot = Node {
            kind: node.kind.clone(),
            parent: node.parent.and_then(rename),
            children: node.children.iter().filter_map(|c| rename(*c)).collect(),
            live: true,
        };
    }
    let root = rename(parsed.root).ok_or_else(|| E::custom("the tree's root has no id"))?;
    Ok(Tree { nodes, root })
}

#[cfg(test)]
mod tests {
    use crate::bt::{NodeKind, Tree, parse, to_text};

    #[test]
    fn a_tree_read_back_keeps_its_node_ids() {
        let mut tree = parse(
            "fallback\n  \"a\" on \"b\"?\n  sequence\n    grasp \"a\"!\n    place \"a\" \"b\"!\n",
        )
        .unwrap();
        // A removed node leaves its id unused: the ids are not pre-order positions.
        let seq = tree.children(tree.root()).unwrap()[1];
        let first = tree.children(seq).unwrap()[0];
        tree.remove_subtree(first).unwrap();
        let json = serde_json::to_string(&tree).unwrap();
        let back: Tree = serde_json::from_str(&json).unwrap();
        assert_eq!(back, tree);
        assert_eq!(back.preorder(), tree.preorder());
        assert_eq!(back.capacity(), tree.capacity());
        for id in tree.preorder() {
            assert_eq!(back.kind(id).unwrap(), tree.kind(id).unwrap());
        }
        assert!(!back.contains(first));
        assert!(matches!(back.kind(back.root()), Ok(NodeKind::Fallback)));
        assert_eq!(to_text(&back), to_text(&tree));
    }

    #[test]
    fn ids_that_do_not_fit_the_tree_are_refused() {
        for json in [
            r#"{"text":"fallback\n  \"a\" on \"b\"?\n","ids":[0],"capacity":2}"#,
            r#"{"text":"fallback\n  \"a\" on \"b\"?\n","ids":[0,5],"capacity":2}"#,
            r#"{"text":"fallback\n  \"a\" on \"b\"?\n","ids":[1,1],"capacity":2}"#,
            r#"{"text":"fallback\n  oops(\n","ids":[0,1],"capacity":2}"#,
        ] {
            assert!(serde_json::from_str::<Tree>(json).is_err(), "{json}");
        }
        // A capacity no session reaches is refused before anything is allocated for it.
        let huge =
            r#"{"text":"fallback\n  \"a\" on \"b\"?\n","ids":[0,1],"capacity":240518168576}"#;
        let err = serde_json::from_str::<Tree>(huge).unwrap_err().to_string();
        assert!(
            err.starts_with(
                "the tree claims 240518168576 node slots; betr reads trees of at most 1048576"
            ),
            "{err}"
        );
    }
}
