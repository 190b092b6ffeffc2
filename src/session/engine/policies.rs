//! Saving the tree as a policy with its provenance, and loading one back as the tree.

use std::path::PathBuf;

use crate::bt::path_text;
use crate::interop::{self, TreeFormat};
use crate::planner::Planner;

use super::super::policy::{self, Fix, Policy};
use super::super::types::Event;
use super::{AppliedFix, Engine, Task};

impl Engine {
    /// Save the tree as a policy at `to`, else where the policy directory keeps the task's.
    pub(super) fn save_policy_to(&mut self, to: Option<PathBuf>) {
        let (Some(tree), Some(task)) = (&self.tree, &self.task) else {
            return self.error("nothing to save: plan a tree first");
        };
        let path = match (to, &self.policies) {
            (Some(path), _) => path,
            (None, Some(store)) => store.path_for(&self.scenario_path, &task.goal),
            (None, None) => {
                return self.error("policies are not kept in this session (no policy directory)");
            }
        };
        let fixes: Vec<Fix> = self
            .fixes
            .iter()
            .map(|f| Fix {
                change: f.change.clone(),
                nodes: f
                    .nodes
                    .iter()
                    .filter_map(|n| tree.path(*n).ok())
                    .map(|p| path_text(&p))
                    .collect(),
                model: f.author.clone(),
                approval: f.approval,
                at: f.at.clone(),
            })
            .collect();
        let saved = Policy {
            scenario: format!("{} ({})", self.scenario_path.display(), self.scenario.name),
            instruction: task.instruction.clone(),
            goal: task.goal.to_string(),
            saved_at: policy::now_rfc3339(),
            fixes,
            tree: tree.clone(),
        };
        match policy::save(&path, &saved) {
            Ok(()) => self.emit(Event::PolicySaved {
                path,
                fixes: saved.fixes.len(),
            }),
            Err(e) => self.emit(Event::Failed { error: e.into() }),
        }
    }

    /// Write the tree beside its policy file as BT.CPP XML (`.xml`) and Graphviz DOT
    /// (`.dot`, coloured by the last tick, the last change's nodes marked).
    pub(super) fn export(&mut self) {
        let (Some(tree), Some(task)) = (&self.tree, &self.task) else {
            return self.error("nothing to export: plan a tree first");
        };
        let Some(store) = &self.policies else {
            return self.error(
                "trees are exported beside the policies, and this session keeps none (no policy directory)",
            );
        };
        let base = store.path_for(&self.scenario_path, &task.goal);
        let name = self
            .scenario_path
            .file_stem()
            .map_or_else(|| "tree".to_string(), |s| s.to_string_lossy().into_owned());
        let xml = match interop::to_btcpp(tree, &self.scenario.domain, &name) {
            Ok(xml) => xml,
            Err(e) => return self.error(format!("cannot export as BT.CPP XML: {e}")),
        };
        let added = self
            .fixes
            .last()
            .map(|f| f.nodes.clone())
            .unwrap_or_default();
        let dot = interop::to_dot(tree, self.last.as_deref(), &added, &name);
        let mut paths = Vec::new();
        for (extension, text) in [("xml", xml), ("dot", dot)] {
            let path = base.with_extension(extension);
            if let Err(e) = crate::store::write_atomic(&path, text.as_bytes()) {
                return self.error(format!("cannot write {}: {e}", path.display()));
            }
            paths.push(path);
        }
        self.emit(Event::Exported { paths });
    }

    /// Load a policy file (default: the saved policy of the current task) as the tree;
    /// `grow`: expand what it leaves unachieved in this world.
    pub(super) fn load_policy(&mut self, path: Option<PathBuf>, grow: bool) {
        let path = match (path, &self.policies, &self.task) {
            (Some(p), _, _) => p,
            (None, Some(store), Some(task)) => store.path_for(&self.scenario_path, &task.goal),
            (None, None, _) => return self.error("no policy directory in this session"),
            (None, _, None) => return self.error("no task yet: submit an instruction first"),
        };
        // Any tree file: a policy (its header kept), betr text, or BT.CPP XML.
        let loaded = match interop::load_tree_file(&path, &self.scenario.domain) {
            Ok(l) => l,
            Err(e) => return self.emit(Event::Failed { error: e.into() }),
        };
        let saved = match loaded.format {
            TreeFormat::Text => match policy::load(&path, &self.scenario.domain) {
                Ok(p) => p,
                Err(e) => return self.emit(Event::Failed { error: e.into() }),
            },
            TreeFormat::BtCpp => Policy {
                scenario: String::new(),
                instruction: None,
                goal: String::new(),
                saved_at: String::new(),
                fixes: Vec::new(),
                tree: loaded.tree,
            },
        };
        for note in loaded.notes {
            self.emit(Event::Notice {
                message: format!("{}: {note}", path.display()),
            });
        }
        if let Ok(goal) = self.scenario.parse_goal(&saved.goal) {
            let instruction = self.task.as_ref().and_then(|t| t.instruction.clone());
            self.task = Some(Task {
                goal,
                instruction: instruction.or(saved.instruction.clone()),
            });
        } else if let (None, Some(goal)) = (&self.task, &self.scenario.goal) {
            // A tree that does not say its goal (BT.CPP XML) works on the scenario's task.
            self.task = Some(Task {
                goal: goal.clone(),
                instruction: self.scenario.instruction.clone(),
            });
        }
        self.cancel_request();
        self.pending = None;
        self.failure = None;
        self.rounds = 0;
        self.tried.clear();
        self.undo.clear();
        self.fixes = saved
            .fixes
            .iter()
            .map(|f| AppliedFix {
                change: f.change.clone(),
                nodes: f
                    .nodes
                    .iter()
                    .filter_map(|p| policy::parse_node_path(p))
                    .filter_map(|p| saved.tree.node_at_path(&p).ok())
                    .collect(),
                author: f.model.clone(),
                approval: f.approval,
                at: f.at.clone(),
            })
            .collect();
        self.emit(Event::PolicyLoaded {
            path: path.clone(),
            fixes: self.fixes.len(),
        });
        self.loaded_from = Some(path.clone());
        self.planned_in_model = false;
        let why = format!("loaded policy {}", path.display());
        if grow {
            // A saved tree may need more expansion in this world (a variant); usually none.
            let started = std::time::Instant::now();
            let plan = Planner::new(&self.scenario.domain).grow(saved.tree, self.planning.as_ref());
            self.planned(&plan, started.elapsed());
            self.replace_tree(plan.tree, plan.new_nodes, why);
        } else {
            self.replace_tree(saved.tree, Vec::new(), why);
        }
    }
}
