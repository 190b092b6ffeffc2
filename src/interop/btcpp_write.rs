//! Writing a tree as BehaviorTree.CPP v4 XML, leaves in the compact form (`<grasp x=…/>`,
//! which BT.CPP 4.x loads once the node types are registered; its parser refuses an
//! `<Action>` element), with a `<TreeNodesModel>` that declares every condition and action
//! of the scenario and their ports, so Groot2 opens the file without the robot's plugins
//! and a robot's code knows what to register.

use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesText, Event};

use super::{condition_id, condition_ports, slot_types};
use crate::bt::{NodeId, NodeKind, Tree};
use crate::domain::{Domain, Value};

/// Why a tree could not be written as BT.CPP XML.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExportError {
    #[error("{action}! names no skill of the scenario that accepts its objects")]
    UnknownSkill { action: String },
    #[error("{condition}? names no predicate of the scenario")]
    UnknownPredicate { condition: String },
    #[error(
        "the predicates {first:?} and {second:?} would both be the node ID {id:?}; BT.CPP needs one ID per node type"
    )]
    IdClash {
        first: String,
        second: String,
        id: String,
    },
    #[error("writing XML: {0}")]
    Xml(String),
}

type Out = Writer<Vec<u8>>;

/// An element to write: its tag (a leaf's node ID), its ports and its children.
struct Element {
    tag: String,
    ports: Vec<(String, String)>,
    children: Vec<Element>,
}

/// `tree` as a BT.CPP v4 XML document whose one `<BehaviorTree>` is `tree_id`.
pub fn to_btcpp(tree: &Tree, domain: &Domain, tree_id: &str) -> Result<String, ExportError> {
    let mut seen: Vec<(String, &str)> = Vec::new();
    for p in &domain.vocabulary.predicates {
        let id = condition_id(domain, &p.name);
        if let Some((_, other)) = seen.iter().find(|(i, _)| *i == id) {
            return Err(ExportError::IdClash {
                first: (*other).to_string(),
                second: p.name.clone(),
                id,
            });
        }
        seen.push((id, &p.name));
    }
    let top = element(tree, domain, tree.root())?;
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    w.create_element("root")
        .with_attribute(("BTCPP_format", "4"))
        .with_attribute(("main_tree_to_execute", tree_id))
        .write_inner_content(|w| {
            w.create_element("BehaviorTree")
                .with_attribute(("ID", tree_id))
                .write_inner_content(|w| write_element(w, &top))?;
            w.create_element("TreeNodesModel")
                .write_inner_content(|w| write_model(w, domain))?;
            Ok::<(), std::io::Error>(())
        })?;
    let mut text =
        String::from_utf8(w.into_inner()).map_err(|e| ExportError::Xml(e.to_string()))?;
    text.push('\n');
    Ok(text)
}

impl From<std::io::Error> for ExportError {
    fn from(e: std::io::Error) -> Self {
        ExportError::Xml(e.to_string())
    }
}

fn element(tree: &Tree, domain: &Domain, id: NodeId) -> Result<Element, ExportError> {
    let kind = tree.kind(id).map_err(|e| ExportError::Xml(e.to_string()))?;
    let leaf = |id: &str, ports| Element {
        tag: id.to_string(),
        ports,
        children: Vec::new(),
    };
    Ok(match kind {
        NodeKind::Sequence | NodeKind::Fallback => Element {
            tag: if matches!(kind, NodeKind::Sequence) {
                "ReactiveSequence"
            } else {
                "ReactiveFallback"
            }
            .to_string(),
            ports: Vec::new(),
            children: tree
                .children(id)
                .unwrap_or_default()
                .iter()
                .map(|&c| element(tree, domain, c))
                .collect::<Result<_, _>>()?,
        },
        NodeKind::Condition(c) => {
            let predicate = domain
                .vocabulary
                .predicates
                .iter()
                .find(|p| p.name == c.atom.predicate)
                .ok_or_else(|| ExportError::UnknownPredicate {
                    condition: c.to_string(),
                })?;
            let ports = condition_ports(predicate)
                .into_iter()
                .zip(&c.atom.args)
                .map(|(port, a)| (port, a.clone()))
                .collect();
            let condition = leaf(&condition_id(domain, &c.atom.predicate), ports);
            if c.negated {
                Element {
                    tag: "Inverter".to_string(),
                    ports: Vec::new(),
                    children: vec![condition],
                }
            } else {
                condition
            }
        }
        NodeKind::Action(a) => {
            let skill = domain
                .skill_for(a)
                .ok_or_else(|| ExportError::UnknownSkill {
                    action: a.to_string(),
                })?;
            let mut ports: Vec<(String, String)> = skill
                .params
                .iter()
                .zip(&a.args)
                .map(|(p, arg)| (p.name.clone(), arg.clone()))
                .collect();
            ports.extend(a.values.iter().map(|(n, v)| (n.clone(), value_text(v))));
            leaf(&a.skill, ports)
        }
    })
}

fn write_element(w: &mut Out, e: &Element) -> std::io::Result<()> {
    let start = w
        .create_element(e.tag.as_str())
        .with_attributes(e.ports.iter().map(|(k, v)| (k.as_str(), v.as_str())));
    if e.children.is_empty() {
        start.write_empty()?;
    } else {
        start.write_inner_content(|w| {
            for c in &e.children {
                write_element(w, c)?;
            }
            Ok::<(), std::io::Error>(())
        })?;
    }
    Ok(())
}

/// A value as a port holds it: `5 N`, `0.2 m/s`, a category bare (`sponge`).
fn value_text(value: &Value) -> String {
    match value {
        Value::Category(c) => c.clone(),
        number => number.to_string(),
    }
}

/// Every predicate as a `<Condition>` and every skill name as an `<Action>`, with their
/// ports described. A skill name with several signatures declares the union of their
/// parameter names.
fn write_model(w: &mut Out, domain: &Domain) -> std::io::Result<()> {
    for p in &domain.vocabulary.predicates {
        let ports: Vec<(String, String)> = condition_ports(p)
            .into_iter()
            .zip(&p.arg_types)
            .map(|(port, types)| (port, format!("{}, or any object", slot_types(types))))
            .collect();
        model_entry(w, "Condition", &condition_id(domain, &p.name), &ports)?;
    }
    let mut seen = std::collections::HashSet::new();
    let names = domain.skills.iter().map(|s| s.name.as_str());
    for name in names.filter(|n| seen.insert(*n)) {
        let overloads: Vec<_> = domain.skills.iter().filter(|s| s.name == name).collect();
        let mut ports: Vec<(String, String)> = Vec::new();
        for skill in &overloads {
            for p in &skill.params {
                let text = slot_types(&p.types);
                match ports.iter_mut().find(|(n, _)| *n == p.name) {
                    Some((_, d)) if !d.split(" or ").any(|t| t == text) => {
                        d.push_str(" or ");
                        d.push_str(&text);
                    }
                    Some(_) => {}
                    None => ports.push((p.name.clone(), text)),
                }
            }
            for v in &skill.values {
                if ports.iter().any(|(n, _)| *n == v.name) {
                    continue;
                }
                let what = match &v.unit {
                    Some(unit) => format!("{}: a number in {unit}, optional", v.description),
                    None => format!(
                        "{}: one of {}, optional",
                        v.description,
                        v.categories.join(", ")
                    ),
                };
                ports.push((v.name.clone(), what));
            }
        }
        model_entry(w, "Action", name, &ports)?;
    }
    Ok(())
}

fn model_entry(
    w: &mut Out,
    tag: &str,
    id: &str,
    ports: &[(String, String)],
) -> std::io::Result<()> {
    w.create_element(tag)
        .with_attribute(("ID", id))
        .write_inner_content(|w| {
            for (name, what) in ports {
                w.create_element("input_port")
                    .with_attribute(("name", name.as_str()))
                    .with_attribute(("type", "std::string"))
                    .write_text_content(BytesText::new(what))?;
            }
            Ok::<(), std::io::Error>(())
        })?;
    Ok(())
}
