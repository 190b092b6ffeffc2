//! Reading a BehaviorTree.CPP v4 XML tree onto a scenario's skills and predicates.
//!
//! betr's trees are reactive, so `ReactiveSequence` and `ReactiveFallback` map directly.
//! BT.CPP's `Sequence` and `Fallback` remember a running child and resume there without
//! ticking the children before it again; that differs from a reactive node exactly when a
//! child other than the first can be running (contains an action). Such a node is refused
//! with the reason; one where only the first child can run is read as reactive, with a
//! note. Everything else BT.CPP has (subtrees, blackboard ports, scripting attributes,
//! other decorators, parallel nodes) has no betr equivalent and is refused with its line.

use roxmltree::{Document, Node};

use super::{condition_id, condition_ports, positional_port, predicate_for_id, skills_for_id};
use crate::bt::{NodeId, NodeKind, Tree};
use crate::domain::action::parse_value;
use crate::domain::{ActionCall, Atom, Condition, Domain, Value};

use crate::bt::MAX_DEPTH;

/// Attributes any node may carry that change nothing in betr.
const IGNORED_ATTRIBUTES: [&str; 2] = ["name", "_description"];

/// Why a BT.CPP file could not be read: where (1-based line and column), the element's
/// start tag (empty for malformed XML) and the reason.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}{}: {reason}", if element.is_empty() { String::new() } else { format!(", {element}") })]
pub struct XmlError {
    pub line: u32,
    pub column: u32,
    pub element: String,
    pub reason: String,
}

/// A tree read from BT.CPP XML, with notes on what was read differently from how it was
/// written (a memory `Sequence` read as reactive).
#[derive(Debug, Clone)]
pub struct Imported {
    pub tree: Tree,
    pub notes: Vec<String>,
}

/// Read the main tree of a BT.CPP v4 document over `domain`'s skills and predicates.
pub fn from_btcpp(text: &str, domain: &Domain) -> Result<Imported, XmlError> {
    let doc = Document::parse(text).map_err(|e| {
        let pos = e.pos();
        XmlError {
            line: pos.row,
            column: pos.col,
            element: String::new(),
            reason: format!("malformed XML: {e}"),
        }
    })?;
    let reader = Reader {
        doc: &doc,
        text,
        domain,
    };
    let root = doc.root_element();
    if root.tag_name().name() != "root" {
        return Err(reader.error(root, "expected the BT.CPP document element <root>"));
    }
    match root.attribute("BTCPP_format") {
        Some("4") => {}
        Some(other) => {
            return Err(reader.error(
                root,
                &format!("BTCPP_format {other:?} is not read: betr reads BT.CPP version 4"),
            ));
        }
        None => {
            return Err(reader.error(
                root,
                "no BTCPP_format attribute: betr reads BT.CPP version 4 (BTCPP_format=\"4\")",
            ));
        }
    }
    let main = reader.main_tree(root)?;
    let mut elements = main.children().filter(Node::is_element);
    let (Some(top), None) = (elements.next(), elements.next()) else {
        return Err(reader.error(main, "a <BehaviorTree> holds exactly one node (its root)"));
    };
    let mut notes = Vec::new();
    let read = reader.read(top, 0, &mut notes)?;
    let mut tree = Tree::new(read.kind.clone());
    let root_id = tree.root();
    reader.attach(&mut tree, root_id, &read)?;
    Ok(Imported { tree, notes })
}

/// A node read from XML before it is put into a tree.
struct Read<'a, 'i> {
    kind: NodeKind,
    children: Vec<Read<'a, 'i>>,
    element: Node<'a, 'i>,
}

struct Reader<'a, 'i> {
    doc: &'a Document<'i>,
    text: &'i str,
    domain: &'a Domain,
}

impl<'a, 'i> Reader<'a, 'i> {
    fn error(&self, node: Node<'a, 'i>, reason: &str) -> XmlError {
        let pos = self.doc.text_pos_at(node.range().start);
        XmlError {
            line: pos.row,
            column: pos.col,
            element: self.start_tag(node),
            reason: reason.to_string(),
        }
    }

    /// The element's start tag as written, cut to a readable length.
    fn start_tag(&self, node: Node) -> String {
        let from = &self.text[node.range()];
        let tag = from.find('>').map_or(from, |end| &from[..=end]);
        crate::excerpt::shortened(&tag.split_whitespace().collect::<Vec<_>>().join(" "), 80)
    }

    fn line(&self, node: Node) -> u32 {
        self.doc.text_pos_at(node.range().start).row
    }

    /// The `<BehaviorTree>` to read: the one `main_tree_to_execute` names, or the only one.
    fn main_tree(&self, root: Node<'a, 'i>) -> Result<Node<'a, 'i>, XmlError> {
        let mut trees = Vec::new();
        for child in root.children().filter(Node::is_element) {
            match child.tag_name().name() {
                "BehaviorTree" => trees.push(child),
                "TreeNodesModel" => {}
                "include" => {
                    return Err(self.error(
                        child,
                        "<include> is not read: betr reads one file holding the whole tree",
                    ));
                }
                other => {
                    return Err(self.error(
                        child,
                        &format!(
                            "unknown element <{other}> under <root> (expected <BehaviorTree> or <TreeNodesModel>)"
                        ),
                    ));
                }
            }
        }
        match (root.attribute("main_tree_to_execute"), trees.as_slice()) {
            (Some(id), _) => trees
                .iter()
                .copied()
                .find(|t| t.attribute("ID") == Some(id))
                .ok_or_else(|| {
                    self.error(
                        root,
                        &format!(
                            "main_tree_to_execute names {id:?}, but no <BehaviorTree> has that ID"
                        ),
                    )
                }),
            (None, [one]) => Ok(*one),
            (None, []) => Err(self.error(root, "no <BehaviorTree> in the file")),
            (None, _) => Err(self.error(
                root,
                &format!(
                    "{} <BehaviorTree>s and no main_tree_to_execute saying which one to read",
                    trees.len()
                ),
            )),
        }
    }

    fn read(
        &self,
        node: Node<'a, 'i>,
        depth: usize,
        notes: &mut Vec<String>,
    ) -> Result<Read<'a, 'i>, XmlError> {
        if depth > MAX_DEPTH {
            return Err(self.error(node, &format!("nested deeper than {MAX_DEPTH} levels")));
        }
        let tag = node.tag_name().name();
        match tag {
            "ReactiveSequence" | "ReactiveFallback" | "Sequence" | "Fallback" => {
                self.no_ports(node, &[])?;
                let children = self.children(node, depth, notes)?;
                if children.is_empty() {
                    return Err(self.error(node, "a control node needs at least one child"));
                }
                if tag == "Sequence" || tag == "Fallback" {
                    self.memory(node, &children, notes)?;
                }
                let kind = if tag.ends_with("Sequence") {
                    NodeKind::Sequence
                } else {
                    NodeKind::Fallback
                };
                Ok(Read {
                    kind,
                    children,
                    element: node,
                })
            }
            "Inverter" => {
                self.no_ports(node, &[])?;
                let mut children = self.children(node, depth, notes)?;
                let (Some(child), true) = (children.pop(), children.is_empty()) else {
                    return Err(self.error(node, "an <Inverter> has exactly one child"));
                };
                match child.kind {
                    NodeKind::Condition(c) => Ok(Read {
                        kind: NodeKind::Condition(c.negate()),
                        children: Vec::new(),
                        element: node,
                    }),
                    _ => Err(self.error(
                        node,
                        "an <Inverter> is read over a condition only (a negated condition); betr has no node that inverts an action or a control node",
                    )),
                }
            }
            "SubTree" => Err(self.error(
                node,
                "<SubTree> is not read: betr reads one tree; put the subtree's nodes in its place",
            )),
            "Condition" | "Action" => {
                let Some(id) = node.attribute("ID") else {
                    return Err(self.error(node, &format!("<{tag}> without an ID")));
                };
                self.leaf(node, id, Some(tag))
            }
            other if !self.names_a_leaf(other) && btcpp_builtin(other).is_some() => {
                Err(self.error(node, &builtin_refusal(other)))
            }
            // BT.CPP's compact form: the node ID as the element name.
            other => self.leaf(node, other, None),
        }
    }

    fn children(
        &self,
        node: Node<'a, 'i>,
        depth: usize,
        notes: &mut Vec<String>,
    ) -> Result<Vec<Read<'a, 'i>>, XmlError> {
        node.children()
            .filter(Node::is_element)
            .map(|c| self.read(c, depth + 1, notes))
            .collect()
    }

    /// A memory `Sequence`/`Fallback` is read as reactive only when that changes nothing:
    /// no child but the first can be running.
    fn memory(
        &self,
        node: Node<'a, 'i>,
        children: &[Read<'a, 'i>],
        notes: &mut Vec<String>,
    ) -> Result<(), XmlError> {
        let tag = node.tag_name().name();
        if let Some((later, action)) = children
            .iter()
            .skip(1)
            .find_map(|c| first_action(c).map(|a| (c, a)))
        {
            return Err(self.error(
                node,
                &format!(
                    "<{tag}> has memory: while {action}! (line {}) runs, BT.CPP does not tick the children before it again, and betr's trees re-check them every tick; write <Reactive{tag}> if re-checking them is meant",
                    self.line(later.element)
                ),
            ));
        }
        notes.push(format!(
            "line {}: <{tag}> read as <Reactive{tag}>: only its first child can be running, so memory changes nothing",
            self.line(node)
        ));
        Ok(())
    }

    /// Attributes other than `ID`, the ignored ones and `ports` are refused.
    fn no_ports(&self, node: Node<'a, 'i>, ports: &[String]) -> Result<(), XmlError> {
        for a in node.attributes() {
            let name = a.name();
            if name == "ID" || IGNORED_ATTRIBUTES.contains(&name) || ports.iter().any(|p| p == name)
            {
                continue;
            }
            let reason = if name.starts_with('_') {
                format!(
                    "attribute {name}: BT.CPP's scripted pre- and post-conditions have no betr equivalent"
                )
            } else if ports.is_empty() {
                format!(
                    "port {name}=\"{}\" has no mapping: <{}> takes no ports",
                    a.value(),
                    node.tag_name().name()
                )
            } else {
                format!(
                    "port {name}=\"{}\" has no mapping: this node's ports are {}",
                    a.value(),
                    ports.join(", ")
                )
            };
            return Err(self.error(node, &reason));
        }
        Ok(())
    }

    /// The value of port `name`, refused when it is a blackboard reference.
    fn port(&self, node: Node<'a, 'i>, name: &str) -> Result<&'a str, XmlError> {
        let Some(value) = node.attribute(name) else {
            return Err(self.error(node, &format!("port {name} is missing")));
        };
        let trimmed = value.trim();
        if trimmed.starts_with('{') && trimmed.ends_with('}') {
            return Err(self.error(
                node,
                &format!(
                    "port {name}=\"{value}\" is a blackboard reference; betr's trees name their objects (write the object's name)"
                ),
            ));
        }
        Ok(value)
    }

    /// A condition's argument: its named port or its positional one, not both.
    fn slot(&self, node: Node<'a, 'i>, name: &str, position: &str) -> Result<&'a str, XmlError> {
        match (node.attribute(name), node.attribute(position)) {
            (Some(_), Some(_)) if name != position => Err(self.error(
                node,
                &format!("ports {name} and {position} name the same argument; write one"),
            )),
            (None, Some(_)) => self.port(node, position),
            (_, None) | (Some(_), Some(_)) => self.port(node, name),
        }
    }

    /// Whether `id` names a predicate or a skill of the scenario (which then wins over a
    /// BT.CPP built-in of the same name).
    fn names_a_leaf(&self, id: &str) -> bool {
        predicate_for_id(self.domain, id).is_some() || !skills_for_id(self.domain, id).is_empty()
    }

    /// A condition or an action: `id` names a predicate or a skill of the scenario.
    fn leaf(
        &self,
        node: Node<'a, 'i>,
        id: &str,
        declared: Option<&str>,
    ) -> Result<Read<'a, 'i>, XmlError> {
        if node.children().any(|c| c.is_element()) {
            return Err(self.error(node, &format!("{id} is a leaf and cannot have children")));
        }
        let predicate = predicate_for_id(self.domain, id).filter(|_| declared != Some("Action"));
        let skills = skills_for_id(self.domain, id);
        let kind = match (
            predicate,
            skills.is_empty() || declared == Some("Condition"),
        ) {
            (Some(p), _) => {
                let named = condition_ports(p);
                let positional: Vec<String> = (0..p.arg_types.len()).map(positional_port).collect();
                let accepted: Vec<String> = named.iter().chain(&positional).cloned().collect();
                self.no_ports(node, &accepted)?;
                let args = named
                    .iter()
                    .zip(&positional)
                    .map(|(name, position)| self.slot(node, name, position).map(str::to_string))
                    .collect::<Result<Vec<_>, _>>()?;
                let condition = Condition::pos(Atom::new(p.name.clone(), args));
                self.domain
                    .vocabulary
                    .check_condition(&condition)
                    .map_err(|e| self.error(node, &e.to_string()))?;
                NodeKind::Condition(condition)
            }
            (None, false) => NodeKind::Action(self.action(node, id, &skills)?),
            (None, true) => return Err(self.error(node, &self.unknown_id(id, declared))),
        };
        Ok(Read {
            kind,
            children: Vec::new(),
            element: node,
        })
    }

    fn unknown_id(&self, id: &str, declared: Option<&str>) -> String {
        let conditions: Vec<String> = self
            .domain
            .vocabulary
            .predicates
            .iter()
            .map(|p| condition_id(self.domain, &p.name))
            .collect();
        let mut actions: Vec<&str> = self.domain.skills.iter().map(|s| s.name.as_str()).collect();
        actions.dedup();
        let what = match declared {
            Some(tag) => format!("unknown {} ID {id:?}", tag.to_lowercase()),
            None => format!("unknown node {id:?}"),
        };
        format!(
            "{what}: betr reads ReactiveSequence, ReactiveFallback, Sequence, Fallback, Inverter, and the scenario's conditions ({}) and actions ({})",
            conditions.join(", "),
            actions.join(", ")
        )
    }

    /// An action: the signature of the skill whose parameter names are the ports given,
    /// then its value parameters in the order written.
    fn action(
        &self,
        node: Node<'a, 'i>,
        id: &str,
        skills: &[&crate::domain::Skill],
    ) -> Result<ActionCall, XmlError> {
        let given: Vec<&str> = node
            .attributes()
            .map(|a| a.name())
            .filter(|n| *n != "ID" && !IGNORED_ATTRIBUTES.contains(n) && !n.starts_with('_'))
            .collect();
        let fits = |s: &&&crate::domain::Skill| {
            s.params.iter().all(|p| given.contains(&p.name.as_str()))
                && given.iter().all(|g| {
                    s.params.iter().any(|p| p.name == *g) || s.values.iter().any(|v| v.name == *g)
                })
        };
        let Some(shape) = skills.iter().find(fits) else {
            let signatures: Vec<String> = skills
                .iter()
                .map(|s| {
                    let mut ports: Vec<String> = s.params.iter().map(|p| p.name.clone()).collect();
                    ports.extend(s.values.iter().map(|v| format!("[{}]", v.name)));
                    ports.join(", ")
                })
                .collect();
            // Name the first port that is out of place, or the first missing one.
            let stray = given.iter().find(|g| {
                !skills.iter().any(|s| {
                    s.params.iter().any(|p| p.name == **g) || s.values.iter().any(|v| v.name == **g)
                })
            });
            let reason = match stray {
                Some(g) => format!(
                    "port {g}=\"{}\" has no mapping: {id} takes {}",
                    node.attribute(*g).unwrap_or_default(),
                    signatures.join(" | ")
                ),
                None => format!(
                    "the ports {} match no signature of {id} ({})",
                    given.join(", "),
                    signatures.join(" | ")
                ),
            };
            return Err(self.error(node, &reason));
        };
        self.no_ports(
            node,
            &given.iter().map(|g| (*g).to_string()).collect::<Vec<_>>(),
        )?;
        let args = shape
            .params
            .iter()
            .map(|p| self.port(node, &p.name).map(str::to_string))
            .collect::<Result<Vec<_>, _>>()?;
        let mut call = ActionCall::new(id, args);
        for a in node.attributes() {
            let Some(param) = shape.values.iter().find(|v| v.name == a.name()) else {
                continue;
            };
            let text = self.port(node, a.name())?;
            let value = match &param.unit {
                None => Value::Category(text.trim().to_string()),
                Some(unit) => match parse_value(text) {
                    Ok(Value::Number { value, unit: u }) if u == *unit => {
                        Value::Number { value, unit: u }
                    }
                    _ => {
                        return Err(self.error(
                            node,
                            &format!(
                                "port {}=\"{text}\" is not a number in {unit} (such as \"5 {unit}\")",
                                a.name(),
                            ),
                        ));
                    }
                },
            };
            call.values.push((param.name.clone(), value));
        }
        if self.domain.resolve(&call).is_none() {
            return Err(self.error(
                node,
                &format!("{call}!: the skill {id} does not accept these objects"),
            ));
        }
        Ok(call)
    }

    fn attach(&self, tree: &mut Tree, at: NodeId, read: &Read<'a, 'i>) -> Result<(), XmlError> {
        for child in &read.children {
            let id = tree
                .add_child(at, child.kind.clone())
                .map_err(|e| self.error(child.element, &e.to_string()))?;
            self.attach(tree, id, child)?;
        }
        Ok(())
    }
}

/// The first action in `read`'s subtree, if it has one (only actions can be running).
/// The kind of a node BehaviorTree.CPP 4 registers itself that betr's engine does not run
/// (Sequence, Fallback, their reactive forms, Inverter over a condition and SubTree are
/// read above).
fn btcpp_builtin(id: &str) -> Option<&'static str> {
    Some(match id {
        "AsyncFallback" | "AsyncSequence" | "SequenceWithMemory" | "SequenceStar" | "Parallel"
        | "ParallelAll" | "IfThenElse" | "WhileDoElse" | "TryCatch" | "Switch2" | "Switch3"
        | "Switch4" | "Switch5" | "Switch6" => "control node",
        "RetryUntilSuccessful"
        | "KeepRunningUntilFailure"
        | "Repeat"
        | "Timeout"
        | "Delay"
        | "RunOnce"
        | "ForceSuccess"
        | "ForceFailure"
        | "Precondition"
        | "LoopInt"
        | "LoopBool"
        | "LoopDouble"
        | "LoopString"
        | "SkipUnlessUpdated"
        | "WaitValueUpdate" => "decorator",
        "AlwaysSuccess" | "AlwaysFailure" | "Script" | "SetBlackboard" | "Sleep"
        | "UnsetBlackboard" => "action",
        "ScriptCondition" | "WasEntryUpdated" => "condition",
        _ => return None,
    })
}

/// What kind of node BehaviorTree.CPP 4 registers `id` as, for the node kinds it ships.
pub fn btcpp_builtin_kind(id: &str) -> Option<BuiltinKind> {
    Some(match id {
        "Sequence" | "Fallback" | "ReactiveSequence" | "ReactiveFallback" => BuiltinKind::Control,
        "Inverter" => BuiltinKind::Decorator,
        "SubTree" => BuiltinKind::SubTree,
        other => match btcpp_builtin(other)? {
            "control node" => BuiltinKind::Control,
            "decorator" => BuiltinKind::Decorator,
            "condition" => BuiltinKind::Condition,
            _ => BuiltinKind::Action,
        },
    })
}

/// The kinds of node BehaviorTree.CPP 4 ships.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuiltinKind {
    Control,
    Decorator,
    Action,
    Condition,
    SubTree,
}

/// Why a BT.CPP built-in is not read, and what would show or run the tree.
fn builtin_refusal(id: &str) -> String {
    format!(
        "{id} is a BehaviorTree.CPP {} that betr's engine does not run (it runs Sequence, \
         Fallback, their reactive forms, Inverter over a condition, and the scenario's \
         skills and conditions); nothing of the tree is changed or dropped, so it is not \
         read; `betr monitor --file FILE` shows it whole, and `betr monitor` while it \
         runs in BehaviorTree.CPP",
        btcpp_builtin(id).unwrap_or("node")
    )
}

fn first_action(read: &Read) -> Option<String> {
    match &read.kind {
        NodeKind::Action(a) => Some(a.to_string()),
        _ => read.children.iter().find_map(first_action),
    }
}
