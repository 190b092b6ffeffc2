//! Unit tests for `tree.rs`.

use super::*;
use crate::bt::test_util::{act, cond};

/// root: Sequence(Fallback(c, Sequence(a)), b)
fn sample() -> (Tree, [NodeId; 6]) {
    let mut t = Tree::new(NodeKind::Sequence);
    let root = t.root();
    let f = t.add_child(root, NodeKind::Fallback).unwrap();
    let c = t
        .add_child(f, cond("\"blue cube\" on \"green cube\""))
        .unwrap();
    let s = t.add_child(f, NodeKind::Sequence).unwrap();
    let a = t.add_child(s, act("grasp \"blue cube\"")).unwrap();
    let b = t
        .add_child(root, act("PutDown \"Coffee\" \"Table1\""))
        .unwrap();
    (t, [root, f, c, s, a, b])
}

#[test]
fn navigation() {
    let (t, [root, f, c, s, a, b]) = sample();
    assert_eq!(t.len(), 6);
    assert_eq!(t.capacity(), 6);
    assert_eq!(t.children(root).unwrap(), &[f, b]);
    assert_eq!(t.parent(a).unwrap(), Some(s));
    assert_eq!(t.parent(root).unwrap(), None);
    assert_eq!(t.index_in_parent(s).unwrap(), Some(1));
    assert_eq!(t.index_in_parent(root).unwrap(), None);
    assert_eq!(t.path(a).unwrap(), vec![0, 1, 0]);
    assert_eq!(t.path(root).unwrap(), Vec::<usize>::new());
    assert_eq!(t.node_at_path(&[0, 1, 0]).unwrap(), a);
    assert_eq!(
        t.node_at_path(&[0, 2]).unwrap_err(),
        TreeError::NoNodeAtPath(vec![0, 2])
    );
    assert_eq!(t.preorder(), vec![root, f, c, s, a, b]);
    assert_eq!(t.depth(a).unwrap(), 3);
    assert_eq!(t.depth(root).unwrap(), 0);
    assert!(t.is_ancestor(f, a).unwrap());
    assert!(!t.is_ancestor(a, a).unwrap());
    assert!(!t.is_ancestor(b, a).unwrap());
    assert_eq!(t.lowest_common_ancestor(c, a).unwrap(), f);
    assert_eq!(t.lowest_common_ancestor(a, b).unwrap(), root);
    assert_eq!(t.lowest_common_ancestor(s, a).unwrap(), s);
    assert_eq!(t.lowest_common_ancestor(a, a).unwrap(), a);
    assert_eq!(t.subtree(f).unwrap(), vec![f, c, s, a]);
    let actions: Vec<_> = t.actions().into_iter().map(|(id, _)| id).collect();
    assert_eq!(actions, vec![a, b]);
    let conditions: Vec<_> = t
        .conditions()
        .into_iter()
        .map(|(id, c)| (id, c.to_string()))
        .collect();
    assert_eq!(
        conditions,
        vec![(c, "\"blue cube\" on \"green cube\"".to_string())]
    );
    assert!(t.validate().is_ok());
}

#[test]
fn wrap_replaces_in_parent_and_at_root() {
    let (mut t, [root, f, c, _s, _a, _b]) = sample();
    let w = t.wrap(c, NodeKind::Fallback).unwrap();
    assert_eq!(t.children(f).unwrap()[0], w);
    assert_eq!(t.children(w).unwrap(), &[c]);
    assert_eq!(t.parent(c).unwrap(), Some(w));
    assert_eq!(t.parent(w).unwrap(), Some(f));
    assert_eq!(t.path(c).unwrap(), vec![0, 0, 0]);
    let new_root = t.wrap(root, NodeKind::Sequence).unwrap();
    assert_eq!(t.root(), new_root);
    assert_eq!(t.parent(root).unwrap(), Some(new_root));
    assert_eq!(t.path(c).unwrap(), vec![0, 0, 0, 0]);
    assert_eq!(t.len(), 8);
}

#[test]
fn insert_move_remove_keep_ids() {
    let (mut t, [root, f, c, s, a, b]) = sample();
    let x = t.insert_child(root, 0, cond("Holding_Nothing")).unwrap();
    assert_eq!(t.children(root).unwrap(), &[x, f, b]);
    assert_eq!(
        t.insert_child(root, 4, cond("A")).unwrap_err(),
        TreeError::ChildIndex {
            parent: root,
            index: 4,
            len: 3
        }
    );
    t.move_child(root, 0, 2).unwrap();
    assert_eq!(t.children(root).unwrap(), &[f, b, x]);
    assert!(t.move_child(root, 0, 3).is_err());
    assert_eq!(t.remove_subtree(f).unwrap(), vec![f, c, s, a]);
    assert_eq!(t.children(root).unwrap(), &[b, x]);
    assert_eq!(t.len(), 3);
    assert_eq!(t.capacity(), 7);
    assert_eq!(t.kind(a).unwrap_err(), TreeError::RemovedNode(a));
    assert_eq!(
        t.kind(NodeId(99)).unwrap_err(),
        TreeError::UnknownNode(NodeId(99))
    );
    assert!(!t.contains(s));
    assert_eq!(t.remove_subtree(root).unwrap_err(), TreeError::RemoveRoot);
    let y = t.add_child(root, cond("B")).unwrap();
    assert_eq!(y, NodeId(7));
    assert_eq!(t.preorder(), vec![root, b, x, y]);
}

#[test]
fn equality_ignores_ids() {
    let (t, _) = sample();
    // Build the same shape in another order of id allocation.
    let mut u = Tree::new(NodeKind::Sequence);
    let root = u.root();
    let b = u
        .add_child(root, act("PutDown \"Coffee\" \"Table1\""))
        .unwrap();
    let s = u.add_child(root, NodeKind::Sequence).unwrap();
    u.add_child(s, act("grasp \"blue cube\"")).unwrap();
    let c = u
        .insert_child(root, 0, cond("\"blue cube\" on \"green cube\""))
        .unwrap();
    assert_ne!(t, u);
    let f = u.wrap(c, NodeKind::Fallback).unwrap();
    u.remove_subtree(s).unwrap();
    let s2 = u.add_child(f, NodeKind::Sequence).unwrap();
    u.add_child(s2, act("grasp \"blue cube\"")).unwrap();
    assert_eq!(u.children(root).unwrap(), &[f, b]);
    assert_eq!(t, u);
    *u.kind_mut(b).unwrap() = act("PutDown \"Coffee\" \"Table2\"");
    assert_ne!(t, u);
}

#[test]
fn validate_names_the_path() {
    let (mut t, [_root, _f, c, s, _a, _b]) = sample();
    t.add_child(c, act("grasp \"x\"")).unwrap();
    let e = t.validate().unwrap_err();
    assert_eq!(
        e,
        TreeError::LeafWithChildren {
            path: vec![0, 0],
            kind: "condition"
        }
    );
    assert_eq!(e.to_string(), "condition at root/0/0 has children");
    let (mut t, _) = sample();
    t.add_child(s, NodeKind::Fallback).unwrap();
    let e = t.validate().unwrap_err();
    assert_eq!(e.to_string(), "fallback at root/0/1/1 has no children");
    assert!(Tree::new(act("Sweep")).validate().is_ok());
    assert!(Tree::new(NodeKind::Sequence).validate().is_err());
}

#[test]
fn nodes_are_found_by_path_or_by_their_text() {
    let (mut t, [root, _, c, _, a, b]) = sample();
    assert_eq!(t.find("root").unwrap(), [root]);
    assert_eq!(t.find("0.1.0").unwrap(), [a]);
    assert_eq!(t.find("grasp \"blue cube\"!").unwrap(), [a]);
    assert_eq!(t.find(" grasp  \"blue cube\" ").unwrap(), [a]);
    assert_eq!(t.find("\"blue cube\" on \"green cube\"?").unwrap(), [c]);
    assert_eq!(t.find("PutDown \"Coffee\" \"Table1\"!").unwrap(), [b]);
    // A condition's text with an action's mark names no condition.
    assert!(t.find("\"blue cube\" on \"green cube\"!").is_err());
    let e = t.find("0.7").unwrap_err();
    assert_eq!(e, TreeError::NoNodeNamed("0.7".into()));
    assert!(e.to_string().contains("1.0.1.1"), "{e}");
    assert!(t.find("").is_err());
    // Every leaf with the text.
    let again = t.add_child(root, act("grasp \"blue cube\"")).unwrap();
    assert_eq!(t.find("grasp \"blue cube\"!").unwrap(), [a, again]);
}
