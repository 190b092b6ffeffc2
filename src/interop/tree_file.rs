//! One way in for tree files: betr's text format (a saved policy is one: its header is
//! comments) or BT.CPP v4 XML, told apart by the extension `.xml` or a first character
//! `<`, and checked against the scenario's vocabulary and skills either way.

use std::path::Path;

use super::btcpp_read::{XmlError, from_btcpp};
use crate::bt::{self, Tree};
use crate::domain::Domain;
use crate::planner::{self, TreeCheckError};

/// The format a tree was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TreeFormat {
    /// betr's indented text (`.bt`, a policy).
    Text,
    /// BehaviorTree.CPP v4 XML.
    BtCpp,
}

impl TreeFormat {
    /// The format of a file: XML by its extension or its first character.
    pub fn of(path: &Path, text: &str) -> TreeFormat {
        let xml_name = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
        if xml_name || text.trim_start().starts_with('<') {
            TreeFormat::BtCpp
        } else {
            TreeFormat::Text
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            TreeFormat::Text => "betr text",
            TreeFormat::BtCpp => "BT.CPP XML",
        }
    }
}

/// A tree read from a file, with notes on what was read differently from how it was
/// written.
#[derive(Debug, Clone)]
pub struct LoadedTree {
    pub tree: Tree,
    pub format: TreeFormat,
    pub notes: Vec<String>,
}

/// Why a tree file could not be used; every message starts with the file's path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TreeFileError {
    #[error("cannot read tree file {path}: {detail}")]
    Read { path: String, detail: String },
    #[error("{path}: {error}")]
    Text { path: String, error: bt::ParseError },
    #[error("{path}: {error}")]
    Xml { path: String, error: XmlError },
    #[error("{path}: {error}")]
    Check { path: String, error: TreeCheckError },
}

/// Read a tree file and check it against `domain`.
pub fn load_tree_file(path: &Path, domain: &Domain) -> Result<LoadedTree, TreeFileError> {
    let name = path.display().to_string();
    let text = crate::store::read_text(path, crate::store::TREE_FILE_BYTES).map_err(|e| {
        TreeFileError::Read {
            path: name.clone(),
            detail: e.to_string(),
        }
    })?;
    read_tree(&text, TreeFormat::of(path, &text), domain, &name)
}

/// Read a tree's text in `format` and check it against `domain`; `name` says where the
/// text came from in errors.
pub fn read_tree(
    text: &str,
    format: TreeFormat,
    domain: &Domain,
    name: &str,
) -> Result<LoadedTree, TreeFileError> {
    let (tree, notes) = match format {
        TreeFormat::Text => (
            bt::parse(text).map_err(|error| TreeFileError::Text {
                path: name.to_string(),
                error,
            })?,
            Vec::new(),
        ),
        TreeFormat::BtCpp => {
            let imported = from_btcpp(text, domain).map_err(|error| TreeFileError::Xml {
                path: name.to_string(),
                error,
            })?;
            (imported.tree, imported.notes)
        }
    };
    planner::check_tree(domain, &tree).map_err(|error| TreeFileError::Check {
        path: name.to_string(),
        error,
    })?;
    Ok(LoadedTree {
        tree,
        format,
        notes,
    })
}
