//! The tree a Groot2 publisher describes (`FULLTREE`): BehaviorTree.CPP's XML with each
//! node's `_uid`, the main tree first, each SubTree instance as its own `<BehaviorTree>`
//! named by `_fullpath`, and the `<TreeNodesModel>` saying each node ID's kind. Read into a
//! tree of every node as written — whatever its kind, with its ports — and each SubTree
//! instance hung under its SubTree node, so a tree of any BT.CPP 4 node kinds is shown
//! whole.

use std::collections::HashMap;

use thiserror::Error;

/// The largest tree description read: BT.CPP numbers nodes with 16 bits, and a tree of
/// 65,535 nodes with long ports stays well under this.
pub const MAX_TREE_BYTES: usize = 32 << 20;

/// A node's kind, from the publisher's `<TreeNodesModel>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NodeKind {
    Action,
    Condition,
    Control,
    Decorator,
    SubTree,
    /// An ID the model does not describe.
    Unknown,
}

impl NodeKind {
    fn of_model_tag(tag: &str) -> Option<NodeKind> {
        Some(match tag {
            "Action" => NodeKind::Action,
            "Condition" => NodeKind::Condition,
            "Control" => NodeKind::Control,
            "Decorator" => NodeKind::Decorator,
            "SubTree" => NodeKind::SubTree,
            _ => return None,
        })
    }

    fn of_builtin(kind: crate::interop::BuiltinKind) -> NodeKind {
        use crate::interop::BuiltinKind;
        match kind {
            BuiltinKind::Control => NodeKind::Control,
            BuiltinKind::Decorator => NodeKind::Decorator,
            BuiltinKind::Action => NodeKind::Action,
            BuiltinKind::Condition => NodeKind::Condition,
            BuiltinKind::SubTree => NodeKind::SubTree,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            NodeKind::Action => "Action",
            NodeKind::Condition => "Condition",
            NodeKind::Control => "Control",
            NodeKind::Decorator => "Decorator",
            NodeKind::SubTree => "SubTree",
            NodeKind::Unknown => "node",
        }
    }
}

/// One node as the publisher wrote it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WatchedNode {
    pub uid: u16,
    pub kind: NodeKind,
    /// The registration ID (the element's name: `Fallback`, `OpenDoor`, `SubTree`).
    pub id: String,
    /// The instance's name (a SubTree's is the ID of the tree it runs).
    pub name: String,
    /// Its ports and other attributes as written (`{goal}` is a blackboard entry).
    pub ports: Vec<(String, String)>,
    pub children: Vec<usize>,
    pub parent: Option<usize>,
    /// Where it sits: `root`, then child indices from the root (`0`, `0.1`), as betr
    /// names nodes everywhere.
    pub path: String,
    pub depth: usize,
    /// The blackboard of the tree instance it is in, by the name the publisher exports it
    /// under (the main tree's ID, a SubTree instance's path such as `Work::5`).
    pub blackboard: String,
}

/// A watched tree: its nodes in depth-first order (index 0 the root). Written to a
/// recording as the publisher's description itself and read back through [`Self::parse`],
/// so a recorded tree is checked as a received one is.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "Description", into = "Description")]
pub struct WatchedTree {
    /// The main tree's ID.
    pub main: String,
    pub nodes: Vec<WatchedNode>,
    by_uid: HashMap<u16, usize>,
    /// The description as the publisher sent it.
    xml: String,
}

/// A tree as a recording holds it: the publisher's description.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(transparent)]
struct Description(String);

impl TryFrom<Description> for WatchedTree {
    type Error = TreeError;
    fn try_from(description: Description) -> Result<WatchedTree, TreeError> {
        WatchedTree::parse(description.0.as_bytes())
    }
}

impl From<WatchedTree> for Description {
    fn from(tree: WatchedTree) -> Description {
        Description(tree.xml)
    }
}

/// The name a `<BehaviorTree>` instance's blackboard is exported under: its path, or the
/// tree's ID for the main tree (whose path is empty), as BT.CPP's publisher names it.
fn blackboard_name(tree: roxmltree::Node) -> String {
    match tree.attribute("_fullpath") {
        Some(path) if !path.is_empty() => path.to_string(),
        _ => tree.attribute("ID").unwrap_or_default().to_string(),
    }
}

/// A tree description that cannot be shown, with where.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum TreeError {
    #[error("the tree description is {len} bytes; betr reads at most {MAX_TREE_BYTES}")]
    TooLarge { len: usize },
    #[error("the tree description is not XML: {0}")]
    Xml(String),
    #[error("the tree description has no <BehaviorTree> with a root node")]
    NoTree,
    #[error("line {line}: <{element}> has no _uid, or one that is not a number from 0 to 65535")]
    Uid { line: u32, element: String },
    #[error("line {line}: <{element}> has the _uid {uid} of another node")]
    SameUid {
        line: u32,
        element: String,
        uid: u16,
    },
    #[error("main_tree_to_execute names {id:?}, but no <BehaviorTree> has that ID")]
    NoMain { id: String },
    #[error("line {line}: the SubTree {id:?} runs a tree that is already running it")]
    Recursive { line: u32, id: String },
    #[error("the tree has more than 65,535 nodes, as many as BehaviorTree.CPP numbers")]
    TooMany,
}

/// How a description numbers its nodes and finds the tree a SubTree runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    /// As a Groot2 publisher sends it: each node's `_uid`, each SubTree instance as its
    /// own `<BehaviorTree>` named by `_fullpath`, the main tree first.
    Published,
    /// As a person writes a tree file: nodes numbered in order from 1, a SubTree runs the
    /// `<BehaviorTree>` of its `ID`, the main tree the one `main_tree_to_execute` names
    /// (or the first).
    Written,
}

/// One node waiting to be read: its element, parent, path, blackboard, and the trees
/// the SubTrees above it run (a written tree that runs itself would never end).
struct Pending<'a, 'input> {
    element: roxmltree::Node<'a, 'input>,
    parent: Option<usize>,
    path: String,
    board: String,
    running: std::rc::Rc<Vec<String>>,
}

impl WatchedTree {
    /// Reads the publisher's description.
    pub fn parse(xml: &[u8]) -> Result<WatchedTree, TreeError> {
        Self::read(xml, Layout::Published)
    }

    /// Reads a BehaviorTree.CPP 4 tree file as a person writes one: any node kind, its
    /// SubTrees hung under their SubTree nodes, its nodes numbered in order. A tree read
    /// this way is shown, not recorded (a recording holds a publisher's description).
    pub fn parse_file(xml: &[u8]) -> Result<WatchedTree, TreeError> {
        Self::read(xml, Layout::Written)
    }

    fn read(xml: &[u8], layout: Layout) -> Result<WatchedTree, TreeError> {
        if xml.len() > MAX_TREE_BYTES {
            return Err(TreeError::TooLarge { len: xml.len() });
        }
        let text = std::str::from_utf8(xml).map_err(|e| TreeError::Xml(e.to_string()))?;
        let doc = roxmltree::Document::parse(text).map_err(|e| TreeError::Xml(e.to_string()))?;
        let kinds = model_kinds(&doc);
        let trees: Vec<roxmltree::Node> = doc
            .descendants()
            .filter(|n| n.has_tag_name("BehaviorTree"))
            .collect();
        let main = match (layout, doc.root_element().attribute("main_tree_to_execute")) {
            (Layout::Written, Some(id)) => trees
                .iter()
                .find(|t| t.attribute("ID") == Some(id))
                .ok_or_else(|| TreeError::NoMain { id: id.to_string() })?,
            _ => trees.first().ok_or(TreeError::NoTree)?,
        };
        let instances: HashMap<&str, roxmltree::Node> = match layout {
            Layout::Published => trees
                .iter()
                .skip(1)
                .filter_map(|t| Some((t.attribute("_fullpath")?, *t)))
                .collect(),
            Layout::Written => trees
                .iter()
                .filter_map(|t| Some((t.attribute("ID")?, *t)))
                .collect(),
        };
        let root = main
            .children()
            .find(|n| n.is_element())
            .ok_or(TreeError::NoTree)?;
        let mut tree = WatchedTree {
            main: main.attribute("ID").unwrap_or_default().to_string(),
            nodes: Vec::new(),
            by_uid: HashMap::new(),
            xml: text.to_string(),
        };
        // Depth first without recursion, so a deep description cannot exhaust the stack.
        let mut stack = vec![Pending {
            element: root,
            parent: None,
            path: "root".to_string(),
            board: blackboard_name(*main),
            running: std::rc::Rc::new(vec![tree.main.clone()]),
        }];
        while let Some(at) = stack.pop() {
            let index = tree.add(&doc, &at, &kinds, layout)?;
            let mut board = at.board;
            let mut running = at.running;
            let children: Vec<roxmltree::Node> = if tree.nodes[index].kind == NodeKind::SubTree {
                let instance = match layout {
                    Layout::Published => at
                        .element
                        .attribute("_fullpath")
                        .and_then(|p| instance_of(&instances, p)),
                    Layout::Written => {
                        let id = at.element.attribute("ID").unwrap_or_default();
                        if running.iter().any(|r| r == id) {
                            return Err(TreeError::Recursive {
                                line: doc.text_pos_at(at.element.range().start).row,
                                id: id.to_string(),
                            });
                        }
                        let mut deeper = (*running).clone();
                        deeper.push(id.to_string());
                        running = std::rc::Rc::new(deeper);
                        instances.get(id).copied()
                    }
                };
                if let Some(instance) = instance {
                    board = blackboard_name(instance);
                }
                instance
                    .and_then(|t| t.children().find(|n| n.is_element()))
                    .into_iter()
                    .collect()
            } else {
                at.element.children().filter(|n| n.is_element()).collect()
            };
            for (i, child) in children.into_iter().enumerate().rev() {
                let path = if at.path == "root" {
                    i.to_string()
                } else {
                    format!("{}.{i}", at.path)
                };
                stack.push(Pending {
                    element: child,
                    parent: Some(index),
                    path,
                    board: board.clone(),
                    running: running.clone(),
                });
            }
        }
        Ok(tree)
    }

    fn add(
        &mut self,
        doc: &roxmltree::Document,
        at: &Pending,
        kinds: &HashMap<String, NodeKind>,
        layout: Layout,
    ) -> Result<usize, TreeError> {
        let element = at.element;
        let tag = element.tag_name().name().to_string();
        // Found only for an error: finding a line scans the text up to the element.
        let line = || doc.text_pos_at(element.range().start).row;
        let index = self.nodes.len();
        let uid = match layout {
            Layout::Published => element
                .attribute("_uid")
                .and_then(|u| u.parse::<u16>().ok())
                .ok_or_else(|| TreeError::Uid {
                    line: line(),
                    element: tag.clone(),
                })?,
            Layout::Written => u16::try_from(index + 1).map_err(|_| TreeError::TooMany)?,
        };
        if self.by_uid.insert(uid, index).is_some() {
            return Err(TreeError::SameUid {
                line: line(),
                element: tag,
                uid,
            });
        }
        // The explicit form names the kind by the element and the node by its ID
        // (`<Action ID="Grasp"/>`); a SubTree's ID is the tree it runs.
        let explicit = NodeKind::of_model_tag(&tag).filter(|k| *k != NodeKind::SubTree);
        let id = match explicit {
            Some(_) => element.attribute("ID").unwrap_or(&tag).to_string(),
            None => tag.clone(),
        };
        let kind = explicit
            .or_else(|| kinds.get(&id).copied())
            .or_else(|| {
                (layout == Layout::Written || id == "SubTree")
                    .then(|| crate::interop::btcpp_builtin_kind(&id).map(NodeKind::of_builtin))
                    .flatten()
            })
            .unwrap_or(NodeKind::Unknown);
        let name = element
            .attribute("name")
            .or_else(|| element.attribute("ID"))
            .unwrap_or(&tag)
            .to_string();
        let ports = element
            .attributes()
            .filter(|a| !matches!(a.name(), "name" | "_uid" | "_fullpath"))
            .filter(|a| !((kind == NodeKind::SubTree || explicit.is_some()) && a.name() == "ID"))
            .map(|a| (a.name().to_string(), a.value().to_string()))
            .collect();
        let depth = at.parent.map_or(0, |p| self.nodes[p].depth + 1);
        self.nodes.push(WatchedNode {
            uid,
            kind,
            id,
            name,
            ports,
            children: Vec::new(),
            parent: at.parent,
            path: at.path.clone(),
            depth,
            blackboard: at.board.clone(),
        });
        if let Some(p) = at.parent {
            self.nodes[p].children.push(index);
        }
        Ok(index)
    }

    /// The tree as a Graphviz digraph named `name`, drawn as written: controls as boxes,
    /// decorators as rounded boxes, SubTrees as folders, conditions as ellipses, actions
    /// as boxes, each labelled with its ID, name, kind and ports.
    pub fn to_dot(&self, name: &str) -> String {
        let mut out = format!("digraph {name:?} {{\n  ordering=out;\n");
        out.push_str(
            "  node [fontname=\"DejaVu Sans\", fontsize=11, color=\"#555555\"];\n  edge [color=\"#777777\", arrowsize=0.6];\n",
        );
        for node in &self.nodes {
            let shape = match node.kind {
                NodeKind::Condition => "shape=ellipse",
                NodeKind::Decorator => "shape=box, style=rounded",
                NodeKind::SubTree => "shape=folder",
                NodeKind::Control | NodeKind::Action | NodeKind::Unknown => "shape=box",
            };
            out.push_str(&format!(
                "  n{} [label={:?}, {shape}];\n",
                node.uid,
                self.describe(node)
            ));
        }
        for node in &self.nodes {
            for &child in &node.children {
                out.push_str(&format!("  n{} -> n{};\n", node.uid, self.nodes[child].uid));
            }
        }
        out.push_str("}\n");
        out
    }

    /// The names of the tree's blackboards, the main tree's first.
    pub fn blackboards(&self) -> Vec<&str> {
        let mut names: Vec<&str> = Vec::new();
        for node in &self.nodes {
            if !names.contains(&node.blackboard.as_str()) {
                names.push(&node.blackboard);
            }
        }
        names
    }

    /// The node the publisher numbers `uid`.
    pub fn by_uid(&self, uid: u16) -> Option<&WatchedNode> {
        self.by_uid.get(&uid).map(|&i| &self.nodes[i])
    }

    /// The index of the node the publisher numbers `uid`.
    pub fn index_of(&self, uid: u16) -> Option<usize> {
        self.by_uid.get(&uid).copied()
    }

    /// The uids from the root down to node `index`, itself included.
    pub fn uid_path(&self, index: usize) -> Vec<u16> {
        let mut path = Vec::with_capacity(self.nodes[index].depth + 1);
        let mut at = Some(index);
        while let Some(i) = at {
            path.push(self.nodes[i].uid);
            at = self.nodes[i].parent;
        }
        path.reverse();
        path
    }

    /// One line for a node: its ID, its name when it has its own, its kind and ports.
    pub fn describe(&self, node: &WatchedNode) -> String {
        let mut line = node.id.clone();
        if node.name != node.id {
            line.push_str(&format!(" {:?}", node.name));
        }
        if node.kind != NodeKind::Unknown && node.kind.name() != node.id {
            line.push_str(&format!(" ({})", node.kind.name()));
        }
        for (port, value) in &node.ports {
            line.push_str(&format!(" {port}={value:?}"));
        }
        crate::http_text::printable(&line).into_owned()
    }
}

/// The `<BehaviorTree>` a SubTree node runs: the one whose `_fullpath` is the node's, or
/// the node's without the `::UID` that BT.CPP 4 appends to a node's path
/// (`<SubTree _fullpath="Work::5">` runs `<BehaviorTree _fullpath="Work">`).
fn instance_of<'a, 'input>(
    instances: &HashMap<&str, roxmltree::Node<'a, 'input>>,
    path: &str,
) -> Option<roxmltree::Node<'a, 'input>> {
    instances.get(path).copied().or_else(|| {
        let (instance, uid) = path.rsplit_once("::")?;
        uid.bytes().all(|b| b.is_ascii_digit()).then_some(())?;
        instances.get(instance).copied()
    })
}

/// Each node ID's kind, from `<TreeNodesModel>`.
fn model_kinds(doc: &roxmltree::Document) -> HashMap<String, NodeKind> {
    doc.descendants()
        .filter(|n| n.has_tag_name("TreeNodesModel"))
        .flat_map(|m| m.children().filter(|n| n.is_element()))
        .filter_map(|entry| {
            let kind = NodeKind::of_model_tag(entry.tag_name().name())?;
            Some((entry.attribute("ID")?.to_string(), kind))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What BT.CPP 4's `WriteTreeToXML(tree, true, true)` writes for a main tree with a
    /// SubTree (the shape the publisher sends: the SubTree node's path ends in its uid,
    /// its tree's does not).
    const FULLTREE: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4">
    <BehaviorTree ID="MainTree" _fullpath="">
        <Fallback name="root" _uid="1">
            <Inverter name="not_open" _uid="2">
                <IsDoorOpen name="open" _uid="3"/>
            </Inverter>
            <SubTree ID="Walk" _fullpath="walk::4" _uid="4" target="{goal}"/>
        </Fallback>
    </BehaviorTree>
    <BehaviorTree ID="Walk" _fullpath="walk">
        <RetryUntilSuccessful name="retry" _uid="5" num_attempts="3">
            <Move name="move" _uid="6" target="{target}"/>
        </RetryUntilSuccessful>
    </BehaviorTree>
    <TreeNodesModel>
        <Condition ID="IsDoorOpen"/>
        <Action ID="Move"><input_port name="target"/></Action>
        <Control ID="Fallback"/>
        <Decorator ID="Inverter"/>
        <Decorator ID="RetryUntilSuccessful"><input_port name="num_attempts"/></Decorator>
        <SubTree ID="SubTree"/>
    </TreeNodesModel>
</root>"#;

    #[test]
    fn a_publisher_tree_is_read_whole_with_its_subtree_hung_under_it() {
        let tree = WatchedTree::parse(FULLTREE.as_bytes()).expect("reads");
        assert_eq!(tree.main, "MainTree");
        let lines: Vec<String> = tree
            .nodes
            .iter()
            .map(|n| format!("{} {}", n.path, tree.describe(n)))
            .collect();
        assert_eq!(
            lines,
            [
                "root Fallback \"root\" (Control)",
                "0 Inverter \"not_open\" (Decorator)",
                "0.0 IsDoorOpen \"open\" (Condition)",
                "1 SubTree \"Walk\" target=\"{goal}\"",
                "1.0 RetryUntilSuccessful \"retry\" (Decorator) num_attempts=\"3\"",
                "1.0.0 Move \"move\" (Action) target=\"{target}\"",
            ]
        );
        assert_eq!(tree.by_uid(6).map(|n| n.depth), Some(3));
        assert_eq!(tree.uid_path(5), vec![1, 4, 5, 6]);
        // Each node reads the blackboard of the tree instance it is written in: the
        // SubTree node its parent's, the subtree's nodes the instance's.
        let boards: Vec<&str> = tree.nodes.iter().map(|n| n.blackboard.as_str()).collect();
        assert_eq!(
            boards,
            [
                "MainTree", "MainTree", "MainTree", "MainTree", "walk", "walk"
            ]
        );
        assert_eq!(tree.blackboards(), ["MainTree", "walk"]);
    }

    /// A tree file with every node kind BT.CPP 4 ships, written as its documentation
    /// writes trees (no uids, the explicit `<Action ID=…>` form, a SubTree with ports).
    const EVERY_KIND: &str = include_str!("../../tests/fixtures/btcpp/every_kind.xml");

    #[test]
    fn a_written_tree_of_every_kind_is_read_whole() {
        let tree = WatchedTree::parse_file(EVERY_KIND.as_bytes()).expect("reads");
        assert_eq!(tree.main, "Main");
        assert_eq!(
            tree.nodes.len(),
            55,
            "every element, the SubTree's tree once"
        );
        let unknown: Vec<&str> = tree
            .nodes
            .iter()
            .filter(|n| n.kind == NodeKind::Unknown)
            .map(|n| n.id.as_str())
            .collect();
        assert!(unknown.is_empty(), "{unknown:?}");
        let kind = |id: &str| tree.nodes.iter().find(|n| n.id == id).map(|n| n.kind);
        assert_eq!(kind("Parallel"), Some(NodeKind::Control));
        assert_eq!(kind("Timeout"), Some(NodeKind::Decorator));
        assert_eq!(kind("ScriptCondition"), Some(NodeKind::Condition));
        assert_eq!(kind("Script"), Some(NodeKind::Action));
        assert_eq!(kind("Grasp"), Some(NodeKind::Action), "the explicit form");
        assert_eq!(kind("Holding"), Some(NodeKind::Condition));
        assert_eq!(kind("Place"), Some(NodeKind::Action), "from the model");
        let sub = tree.nodes.iter().find(|n| n.id == "SubTree").unwrap();
        assert_eq!(sub.name, "PickPlace");
        assert_eq!(
            sub.ports,
            [
                ("object".to_string(), "{target}".to_string()),
                ("_autoremap".to_string(), "false".to_string())
            ]
        );
        let under = &tree.nodes[sub.children[0]];
        assert_eq!(
            (under.id.as_str(), under.path.as_str()),
            ("RetryUntilSuccessful", "2.0.1.0")
        );
        assert_eq!(under.blackboard, "PickPlace");
        assert_eq!(tree.blackboards(), ["Main", "PickPlace"]);
        for (i, node) in tree.nodes.iter().enumerate() {
            assert_eq!(tree.index_of(node.uid), Some(i));
        }
    }

    #[test]
    fn a_written_tree_is_drawn_whole() {
        let tree = WatchedTree::parse_file(EVERY_KIND.as_bytes()).expect("reads");
        let dot = tree.to_dot("every kind");
        assert!(dot.starts_with("digraph \"every kind\" {"), "{dot}");
        assert_eq!(dot.matches(" [label=").count(), 55);
        assert_eq!(
            dot.matches(" -> ").count(),
            54,
            "every node but the root has a parent"
        );
        assert!(
            dot.contains(r#"[label="SubTree \"PickPlace\" object=\"{target}\" _autoremap=\"false\"", shape=folder]"#),
            "{dot}"
        );
        assert!(dot.contains(
            r#"label="ScriptCondition (Condition) code=\"attempts < 3\"", shape=ellipse"#
        ));
    }

    #[test]
    fn a_written_tree_that_runs_itself_or_a_missing_main_is_refused() {
        let looped = r#"<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Main"/>
    </Sequence>
  </BehaviorTree>
</root>"#;
        let e = WatchedTree::parse_file(looped.as_bytes()).unwrap_err();
        assert_eq!(
            e,
            TreeError::Recursive {
                line: 4,
                id: "Main".into()
            }
        );
        let elsewhere = EVERY_KIND.replace(
            "main_tree_to_execute=\"Main\"",
            "main_tree_to_execute=\"Nope\"",
        );
        let e = WatchedTree::parse_file(elsewhere.as_bytes()).unwrap_err();
        assert_eq!(e, TreeError::NoMain { id: "Nope".into() });
    }

    #[test]
    fn a_bad_description_is_refused_naming_the_line() {
        let no_uid = FULLTREE.replace(r#" _uid="3""#, "");
        assert_eq!(
            WatchedTree::parse(no_uid.as_bytes()),
            Err(TreeError::Uid {
                line: 6,
                element: "IsDoorOpen".into()
            })
        );
        let twice = FULLTREE.replace(r#"_uid="6""#, r#"_uid="2""#);
        assert!(matches!(
            WatchedTree::parse(twice.as_bytes()),
            Err(TreeError::SameUid { uid: 2, .. })
        ));
        assert!(matches!(
            WatchedTree::parse(b"<root><BehaviorTree ID=\"x\">"),
            Err(TreeError::Xml(_))
        ));
        assert_eq!(WatchedTree::parse(b"<root/>"), Err(TreeError::NoTree));
        let huge = vec![b' '; MAX_TREE_BYTES + 1];
        assert!(matches!(
            WatchedTree::parse(&huge),
            Err(TreeError::TooLarge { .. })
        ));
    }

    #[test]
    fn a_deep_tree_does_not_exhaust_the_stack() {
        let depth = 5_000;
        let mut xml = String::from("<root><BehaviorTree ID=\"deep\">");
        for i in 0..depth {
            xml.push_str(&format!("<Inverter _uid=\"{i}\">"));
        }
        for _ in 0..depth {
            xml.push_str("</Inverter>");
        }
        xml.push_str("</BehaviorTree></root>");
        // roxmltree refuses very deep documents itself; either way nothing overflows.
        match WatchedTree::parse(xml.as_bytes()) {
            Ok(tree) => assert_eq!(tree.nodes.len(), depth),
            Err(e) => assert!(matches!(e, TreeError::Xml(_)), "{e}"),
        }
    }
}
