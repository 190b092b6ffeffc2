//! Hidden `betr policy-save-test PATH`: save a large policy over and over, so a test can
//! kill the process mid-save and check the file is never left empty or cut short.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Result;

use betr::domain::Condition;

use super::PolicySaveTest;

pub fn save_test(args: &PolicySaveTest) -> Result<ExitCode> {
    use betr::bt::{NodeKind, Tree};
    use betr::session::policy::{Approval, Fix, Policy, PolicyStore, now_rfc3339};
    let mut tree = Tree::new(NodeKind::Fallback);
    let condition = Condition::parse("\"blue cube\" on \"green cube\"")?;
    for _ in 1..args.nodes.max(2) {
        tree.add_child(tree.root(), NodeKind::Condition(condition.clone()))?;
    }
    let store = PolicyStore::new(args.path.parent().unwrap_or(Path::new(".")));
    for generation in 0..args.times {
        let policy = Policy {
            scenario: "policy save test".into(),
            instruction: None,
            goal: condition.to_string(),
            saved_at: now_rfc3339(),
            fixes: vec![Fix {
                change: format!("generation {generation}"),
                nodes: Vec::new(),
                model: "none".into(),
                approval: Approval::Edited,
                at: now_rfc3339(),
            }],
            tree: tree.clone(),
        };
        store.save(&args.path, &policy)?;
    }
    Ok(ExitCode::SUCCESS)
}
