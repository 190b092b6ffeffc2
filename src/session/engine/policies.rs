//! Saving the tree as a policy with its provenance, and loading one back as the tree.

use std::path::PathBuf;

use crate::bt::path_text;
use crate::interop::{self, TreeFormat};
use crate::planner::Planner;

use super::super::policy::{self, Fix, Policy};
use super::super::types::{Event, SessionError};
use super::Engine;
use super::task::{AppliedFix, Goal, Origin};

impl Engine {
    /// Save the tree as a policy at `to`, else where the policy directory keeps the task's.
    pub(super) fn save_policy_to(&mut self, to: Option<PathBuf>) {
        let (Some(tree), Some(goal)) = (&self.task.tree, &self.task.goal) else {
            return self.error("nothing to save: plan a tree first");
        };
        let settings = &self.settings;
        let path = match (to, &settings.policies) {
            (Some(path), _) => path,
            (None, Some(store)) => store.path_for(&settings.scenario_path, &goal.formula),
            (None, None) => {
                return self.error("policies are not kept in this session (no policy directory)");
            }
        };
        let fixes: Vec<Fix> = self
            .task
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
            scenario: format!(
                "{} ({})",
                settings.scenario_path.display(),
                settings.scenario.name
            ),
            instruction: goal.instruction.clone(),
            goal: goal.formula.to_string(),
            saved_at: policy::now_rfc3339(),
            fixes,
            tree: tree.clone(),
        };
        match policy::save(&path, &saved) {
            Ok(()) => {
                self.task.saved = self.task.fixes.len();
                self.emit(Event::PolicySaved {
                    path,
                    fixes: saved.fixes.len(),
                });
            }
            Err(e) => self.emit(Event::Failed { error: e.into() }),
        }
    }

    /// Write the tree beside its policy file as BT.CPP XML (`.xml`) and Graphviz DOT
    /// (`.dot`, coloured by the last tick, the last change's nodes marked).
    pub(super) fn export(&mut self) {
        let (Some(tree), Some(goal)) = (&self.task.tree, &self.task.goal) else {
            return self.error("nothing to export: plan a tree first");
        };
        let settings = &self.settings;
        let Some(store) = &settings.policies else {
            return self.error(
                "trees are exported beside the policies, and this session keeps none (no policy directory)",
            );
        };
        let base = store.path_for(&settings.scenario_path, &goal.formula);
        let name = settings
            .scenario_path
            .file_stem()
            .map_or_else(|| "tree".to_string(), |s| s.to_string_lossy().into_owned());
        let xml = match interop::to_btcpp(tree, &settings.scenario.domain, &name) {
            Ok(xml) => xml,
            Err(e) => return self.error(format!("cannot export as BT.CPP XML: {e}")),
        };
        let added = self
            .task
            .fixes
            .last()
            .map(|f| f.nodes.clone())
            .unwrap_or_default();
        let dot = interop::to_dot(tree, self.run.last.as_deref(), &added, &name);
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
        let settings = &self.settings;
        let path = match (path, &settings.policies, &self.task.goal) {
            (Some(p), _, _) => p,
            (None, Some(store), Some(goal)) => {
                store.path_for(&settings.scenario_path, &goal.formula)
            }
            (None, None, _) => return self.error("no policy directory in this session"),
            (None, _, None) => return self.error("no task yet: submit an instruction first"),
        };
        let saved = match self.read_tree_file(&path) {
            Ok(saved) => saved,
            Err(error) => return self.emit(Event::Failed { error }),
        };
        self.adopt_goal(&saved);
        self.drop_waiting();
        self.task.restart(Origin::File(path.clone()));
        self.task.fixes = saved
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
        self.task.saved = self.task.fixes.len();
        self.emit(Event::PolicyLoaded {
            path: path.clone(),
            fixes: self.task.fixes.len(),
        });
        let why = format!("loaded policy {}", path.display());
        if grow {
            // A saved tree may need more expansion in this world (a variant); usually none.
            let started = std::time::Instant::now();
            let plan = Planner::new(&self.settings.scenario.domain)
                .grow(saved.tree, self.run.planning.as_ref());
            self.planned(&plan, started.elapsed());
            self.replace_tree(plan.tree, plan.new_nodes, why);
        } else {
            self.replace_tree(saved.tree, Vec::new(), why);
        }
    }

    /// Any tree file as a policy: a policy (its header kept), betr text, or BT.CPP XML
    /// (no header); what loading noticed is told.
    fn read_tree_file(&self, path: &std::path::Path) -> Result<Policy, SessionError> {
        let domain = &self.settings.scenario.domain;
        let loaded = interop::load_tree_file(path, domain)?;
        let saved = match loaded.format {
            TreeFormat::Text => policy::load(path, domain)?,
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
        Ok(saved)
    }

    /// Work on the goal a loaded policy names (the instruction being worked on stays);
    /// a tree that does not say its goal (BT.CPP XML) works on the scenario's task.
    fn adopt_goal(&mut self, saved: &Policy) {
        let scenario = &self.settings.scenario;
        if let Ok(formula) = scenario.parse_goal(&saved.goal) {
            let instruction = self.task.goal.as_ref().and_then(|g| g.instruction.clone());
            self.task.goal = Some(Goal {
                formula,
                instruction: instruction.or(saved.instruction.clone()),
            });
        } else if let (None, Some(formula)) = (&self.task.goal, &scenario.goal) {
            self.task.goal = Some(Goal {
                formula: formula.clone(),
                instruction: scenario.instruction.clone(),
            });
        }
    }
}
