//! What a Groot2 publisher sends `betr monitor`: the tree description
//! (`monitor::WatchedTree::parse`), the status and transition payloads and the blackboard
//! payload (MessagePack). Each input is given to every reader.
//!
//! Properties: an accepted tree is consistent (every node found by its uid, children after
//! their parent one level deeper, a path that leads back to the root) and reads back the
//! same from a recording; a refused one names a line of the input; a fixed-size payload
//! is refused exactly when its length is not a whole number of entries; accepted
//! blackboards written again as MessagePack read back the same.

use super::{Rng, Target, Violation, ensure, strings};
use crate::fuzz::Material;
use crate::monitor::protocol::{read_blackboards, read_statuses, read_transitions};
use crate::monitor::tree::TreeError;
use crate::monitor::{Blackboard, WatchedTree};

/// A description as BehaviorTree.CPP 4.8's publisher writes one: the main tree, a SubTree
/// instance under its own `<BehaviorTree>`, and the node model.
const PUBLISHED: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4">
    <BehaviorTree ID="Main" _fullpath="">
        <Fallback name="serve" _uid="1">
            <ReactiveSequence name="ready" _uid="2">
                <Inverter name="not_blocked" _uid="3">
                    <IsBlocked name="blocked" _uid="4"/>
                </Inverter>
                <SubTree ID="Work" _fullpath="Work::5" _uid="5" target="{goal}"/>
            </ReactiveSequence>
            <Recover name="recover" _uid="8"/>
        </Fallback>
    </BehaviorTree>
    <BehaviorTree ID="Work" _fullpath="Work">
        <RetryUntilSuccessful name="retry" _uid="6" num_attempts="3">
            <Grasp name="grasp" _uid="7"/>
        </RetryUntilSuccessful>
    </BehaviorTree>
    <TreeNodesModel>
        <Action ID="Grasp"/>
        <Condition ID="IsBlocked"/>
        <Action ID="Recover"/>
    </TreeNodesModel>
</root>"#;

pub struct Groot2Target {
    material: Material,
}

impl Groot2Target {
    pub fn new() -> Groot2Target {
        let boards = rmp_serde::to_vec(&serde_json::json!({
            "Main": {"target": "red cube", "grasps": 2},
            "Work": null,
        }))
        .unwrap_or_default();
        Groot2Target {
            material: Material {
                seeds: vec![
                    PUBLISHED.as_bytes().to_vec(),
                    boards,
                    vec![1, 0, 2, 0, 3, 0],
                    vec![1, 0, 0, 0, 0, 0, 7, 0, 2],
                ],
                tokens: strings(&[
                    " _uid=\"9\"",
                    " _uid=\"65535\"",
                    " _uid=\"65536\"",
                    " _uid=\"-1\"",
                    " _fullpath=\"Work::5\"",
                    " _fullpath=\"\"",
                    "<SubTree ID=\"Work\" _fullpath=\"Work::9\" _uid=\"9\"/>",
                    "<BehaviorTree ID=\"Work\" _fullpath=\"Work\">",
                    "</BehaviorTree>",
                    "<TreeNodesModel>",
                    "<Control ID=\"Fallback\"/>",
                    " port=\"{bb}\"",
                    "&amp;",
                    "\u{c0}",
                    "\u{80}",
                    "\u{81}",
                    "\u{c1}",
                ]),
                brackets: super::pairs(&[
                    ("<Sequence _uid=\"10\">", "</Sequence>"),
                    ("<Inverter _uid=\"11\">", "</Inverter>"),
                    ("<BehaviorTree ID=\"X\">", "</BehaviorTree>"),
                ]),
            },
        }
    }
}

/// An accepted tree is consistent and reads back the same from a recording.
fn check_tree(tree: &WatchedTree) -> Result<(), Violation> {
    for (i, node) in tree.nodes.iter().enumerate() {
        ensure(
            tree.index_of(node.uid) == Some(i),
            "every node is found by its uid",
            || {
                format!(
                    "node {i} ({}) found at {:?}",
                    node.uid,
                    tree.index_of(node.uid)
                )
            },
        )?;
        for &child in &node.children {
            let below = tree.nodes.get(child);
            ensure(
                child > i
                    && below.is_some_and(|c| c.parent == Some(i) && c.depth == node.depth + 1),
                "a child comes after its parent, one level deeper, and names it",
                || format!("node {i}'s child {child}: {below:?}"),
            )?;
        }
        let path = tree.uid_path(i);
        ensure(
            path.first() == tree.nodes.first().map(|r| r.uid).as_ref()
                && path.last() == Some(&node.uid)
                && path.len() == node.depth + 1,
            "a node's uid path leads from the root to it",
            || format!("node {i}: {path:?}"),
        )?;
    }
    let written = serde_json::to_string(tree).unwrap_or_default();
    let back: Result<WatchedTree, _> = serde_json::from_str(&written);
    ensure(
        back.as_ref().ok() == Some(tree),
        "a tree recorded reads back the same",
        || format!("{written:?}: {:?}", back.err()),
    )
}

/// The line a refusal names is a line of the input.
fn check_refusal(text: &str, error: &TreeError) -> Result<(), Violation> {
    let line = match error {
        TreeError::Uid { line, .. } | TreeError::SameUid { line, .. } => *line as usize,
        _ => return Ok(()),
    };
    let lines = text.split('\n').count();
    ensure(
        line >= 1 && line <= lines,
        "a refused tree names a line of the input",
        || format!("line {line} of {lines}: {error}"),
    )
}

/// Accepted blackboards written again read back the same.
fn check_boards(boards: &[Blackboard]) -> Result<(), Violation> {
    let mut map = serde_json::Map::new();
    for board in boards {
        let entries: serde_json::Map<String, serde_json::Value> = board
            .entries
            .iter()
            .map(|(k, v)| (k.clone(), serde_json::from_str(v).unwrap_or_default()))
            .collect();
        map.insert(board.name.clone(), serde_json::Value::Object(entries));
    }
    let again = rmp_serde::to_vec(&serde_json::Value::Object(map)).unwrap_or_default();
    let back = read_blackboards(&again);
    ensure(
        back.as_deref() == Ok(boards),
        "blackboards written again read back the same",
        || format!("{boards:?} read back as {back:?}"),
    )
}

impl Target for Groot2Target {
    fn name(&self) -> &'static str {
        "groot2"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        match rng.below(4) {
            // A deep or wide tree, each node numbered.
            0 => {
                let count = rng.small(3000).max(1);
                let deep = rng.chance(50);
                let mut xml = String::from("<root><BehaviorTree ID=\"T\">");
                for uid in 0..count {
                    xml.push_str(&format!("<Sequence _uid=\"{uid}\">"));
                    if !deep {
                        xml.push_str("</Sequence>");
                    }
                }
                if deep {
                    xml.push_str(&"</Sequence>".repeat(count));
                }
                xml.push_str("</BehaviorTree></root>");
                xml.into_bytes()
            }
            // A status or transition payload of any length.
            1 => (0..rng.small(60))
                .map(|_| u8::try_from(rng.below(256)).unwrap_or_default())
                .collect(),
            2 => {
                let boards = serde_json::json!({
                    "Main": {"n": rng.below(1000), "s": "x", "f": 0.5, "l": [1, "a"], "m": {"k": null}},
                    "Sub::3": if rng.chance(50) { serde_json::Value::Null } else { serde_json::json!({}) },
                });
                rmp_serde::to_vec(&boards).unwrap_or_default()
            }
            _ => PUBLISHED.as_bytes().to_vec(),
        }
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        match WatchedTree::parse(input) {
            Ok(tree) => check_tree(&tree)?,
            Err(e) => check_refusal(&String::from_utf8_lossy(input), &e)?,
        }
        let statuses = read_statuses(input);
        ensure(
            statuses.is_ok() == input.len().is_multiple_of(3)
                || matches!(
                    statuses,
                    Err(crate::monitor::protocol::ProtocolError::Status { .. })
                ),
            "a status payload is refused when it is not whole 3-byte entries or a status is unknown",
            || format!("{} bytes: {statuses:?}", input.len()),
        )?;
        let transitions = read_transitions(input);
        ensure(
            transitions
                .as_ref()
                .is_ok_and(|t| t.len() * 9 == input.len())
                || (!input.len().is_multiple_of(9) && transitions.is_err())
                || matches!(
                    transitions,
                    Err(crate::monitor::protocol::ProtocolError::Status { .. })
                ),
            "a transitions payload reads one change per 9 bytes",
            || format!("{} bytes: {transitions:?}", input.len()),
        )?;
        if let Ok(boards) = read_blackboards(input) {
            check_boards(&boards)?;
        }
        Ok(())
    }
}
