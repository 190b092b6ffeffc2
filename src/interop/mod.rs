//! Trees in other tools' formats: BehaviorTree.CPP v4 XML (written and read, so a tree
//! planned in betr runs in BT.CPP and opens in Groot2, and a BT.CPP tree can be checked
//! and stepped here) and Graphviz DOT (written, with the statuses of a tick).
//!
//! How betr's nodes meet BT.CPP's:
//!
//! | betr | BT.CPP v4 |
//! |---|---|
//! | `sequence` | `<ReactiveSequence>` (a memory `<Sequence>` is read when memory changes nothing) |
//! | `fallback` | `<ReactiveFallback>` (likewise `<Fallback>`) |
//! | `"blue cube" on "green cube"?` | `<on item="blue cube" item_or_fixture="green cube"/>` |
//! | `~On_Coffee_Table1?` | `<Inverter><On item="Coffee" place="Table1"/></Inverter>` |
//! | `grasp "egg" {force = 5 N}!` | `<grasp x="egg" force="5 N"/>` |
//!
//! Leaves are written in BT.CPP's compact form (the node ID as the element's name), which
//! every 4.x release loads; the explicit `<Condition ID=…>` and `<Action ID=…>` are read
//! too. A condition's ID is its predicate with `_` for spaces (`near robot` →
//! `near_robot`), prefixed with `is_` when a skill has the same name (`open` → `is_open`),
//! and its ports are named after its argument slots' types (`item`, `item_or_fixture`; a
//! repeated name numbered, `item_2`); the positional `arg1`, `arg2` are read as well. An
//! action's ID is its skill and its ports are the skill's parameter names, then its value
//! parameters.

mod btcpp_read;
mod btcpp_write;
mod dot;
mod tree_file;

pub use btcpp_read::{BuiltinKind, Imported, XmlError, btcpp_builtin_kind, from_btcpp};
pub use btcpp_write::{ExportError, to_btcpp};
pub use dot::to_dot;
pub use tree_file::{LoadedTree, TreeFileError, TreeFormat, load_tree_file, read_tree};

use crate::domain::condition::is_word_predicate;
use crate::domain::vocabulary::Predicate;
use crate::domain::{Domain, Skill};

/// The BT.CPP node ID of a predicate: its name with `_` for each space, prefixed with
/// `is_` (`Is` for identifier-form predicates) while a skill has the same name, since
/// conditions and actions share one namespace in BT.CPP (`open` → `is_open` when `open`
/// is also a skill).
pub fn condition_id(domain: &Domain, predicate: &str) -> String {
    let prefix = if is_word_predicate(predicate) {
        "is_"
    } else {
        "Is"
    };
    let mut id = predicate.replace(' ', "_");
    while domain.skills.iter().any(|s| s.name == id) {
        id = format!("{prefix}{id}");
    }
    id
}

/// The ports of a predicate's condition, one per argument slot, named after the slot's
/// types (`item|fixture` → `item_or_fixture`), a name already taken numbered (`item_2`).
/// A name BT.CPP would refuse as a port (`name`, `ID`, not starting with a letter) is
/// the positional one instead.
pub fn condition_ports(predicate: &Predicate) -> Vec<String> {
    let mut ports: Vec<String> = Vec::new();
    for (index, types) in predicate.arg_types.iter().enumerate() {
        let base: String = types
            .join("_or_")
            .chars()
            .map(|c| if c.is_alphanumeric() { c } else { '_' })
            .collect();
        let allowed =
            base.starts_with(|c: char| c.is_ascii_alphabetic()) && base != "name" && base != "ID";
        let mut name = if allowed {
            base.clone()
        } else {
            positional_port(index)
        };
        let mut n = 2;
        while ports.contains(&name) {
            name = format!("{base}_{n}");
            n += 1;
        }
        ports.push(name);
    }
    ports
}

/// The positional port of argument `index` (0-based) of a condition: `arg1`, `arg2`;
/// read besides the named ones, for files written by hand.
pub fn positional_port(index: usize) -> String {
    format!("arg{}", index + 1)
}

/// The predicate a condition ID names in `domain`.
fn predicate_for_id<'d>(domain: &'d Domain, id: &str) -> Option<&'d Predicate> {
    domain
        .vocabulary
        .predicates
        .iter()
        .find(|p| condition_id(domain, &p.name) == id)
}

/// The skills (one name may have several signatures) an action ID names in `domain`.
fn skills_for_id<'d>(domain: &'d Domain, id: &str) -> Vec<&'d Skill> {
    domain.skills.iter().filter(|s| s.name == id).collect()
}

/// Type names of a slot as words: `item`, `place or item`.
fn slot_types(types: &[String]) -> String {
    types.join(" or ")
}

#[cfg(test)]
mod tests;
