//! The engine's own steps: submitting, planning, ticking, running, resetting the world,
//! undoing and verifying.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::bt::{Outcome as TickOutcome, Tree};
use crate::goal;
use crate::planner::{Plan, Planner, WorldLeaves};
use crate::world;

use super::super::planned::PlanSummary;
use super::super::policy;
use super::super::readings::distinct_readings;
use super::super::submitted::{self, Submitted};
use super::super::types::{Event, SessionError};
use super::{Engine, Failure, Task};

/// Who wrote a goal a person typed as a formula.
const TYPED: &str = "a person, typed as a goal";
/// Who wrote a goal a person chose among the model's readings.
const CHOSEN: &str = "a person, chosen among the model's readings";
/// Who wrote a goal the caller gave with the instruction.
const GIVEN: &str = "given with the instruction";

impl Engine {
    pub(super) fn submit_goal(&mut self, goal: crate::goal::Formula, instruction: String) {
        self.start_task(goal, Some(instruction), GIVEN);
    }

    /// Plan `goal` (from `author`), reporting how it compares with the scenario's goal.
    fn start_task(
        &mut self,
        goal: crate::goal::Formula,
        instruction: Option<String>,
        author: &str,
    ) {
        let matches_expected = self
            .scenario
            .goal
            .as_ref()
            .and_then(|expected| goal::equivalent(expected, &goal).ok());
        self.emit(Event::Goal {
            goal: goal.clone(),
            reasoning: None,
            matches_expected,
            author: author.to_string(),
        });
        self.task = Some(Task { goal, instruction });
        self.plan();
    }

    pub(super) fn submit(&mut self, text: &str) {
        self.choosing = None;
        let text = match submitted::read(&self.scenario, text) {
            Ok(Submitted::Goal(goal)) => return self.start_task(goal, None, TYPED),
            Ok(Submitted::Instruction(text)) => text,
            Err(e) => return self.error(e.to_string()),
        };
        let text = text.as_str();
        if let Some(goal) = self.goal_from_policy(text) {
            self.task = Some(Task {
                goal,
                instruction: Some(text.to_string()),
            });
            return self.plan();
        }
        match self.model.clone() {
            Ok(model) => self.ask_goal(model, text),
            Err(why) => {
                let not_a_goal = self
                    .scenario
                    .parse_goal(text)
                    .err()
                    .map_or_else(String::new, |e| e.to_string());
                self.error(format!(
                    "{} is not a goal formula ({not_a_goal}), and no language model can read it as an instruction: {why}",
                    crate::excerpt::excerpt(text, None)
                ))
            }
        }
    }

    /// Work on what `read` found for `instruction`: its goal, or — when the person chooses
    /// and more than one reading would make the robot do different things — the choice.
    pub(super) fn on_interpretation(
        &mut self,
        read: super::super::interpret::Interpretation,
        instruction: String,
    ) {
        if self.options.choose_reading {
            let readings =
                distinct_readings(&self.scenario, self.planning.as_ref(), &read.readings);
            // Several readings that do different things, or one the checks doubt: a
            // person decides before anything runs.
            let doubt = read.doubt.clone().filter(|_| readings.len() == 1);
            if readings.len() > 1 || doubt.is_some() {
                self.emit(Event::Readings {
                    instruction: instruction.clone(),
                    readings: readings.clone(),
                    doubt,
                });
                self.choosing = Some((instruction, readings));
                return;
            }
        }
        self.task = Some(Task {
            goal: read.answer.goal,
            instruction: Some(instruction),
        });
        self.plan();
    }

    /// Work on reading `index` (from 0) of those offered.
    pub(super) fn choose_reading(&mut self, index: usize) {
        let Some((instruction, readings)) = self.choosing.take() else {
            return self.error("no readings to choose among: type an instruction first (i)");
        };
        let Some(reading) = readings.get(index) else {
            let count = readings.len();
            self.choosing = Some((instruction, readings));
            return self.error(format!(
                "no reading {}: the instruction has {count} readings (1 to {count})",
                index + 1
            ));
        };
        let goal = reading.goal.clone();
        self.notice(format!("reading {} chosen: {goal}", index + 1));
        self.start_task(goal, Some(instruction), CHOSEN);
    }

    /// The goal a saved policy recorded for this instruction (no model call needed).
    fn goal_from_policy(&self, instruction: &str) -> Option<goal::Formula> {
        let store = self.policies.as_ref()?;
        let path = store.find_by_instruction(&self.scenario_path, instruction)?;
        let saved = policy::load(&path, &self.scenario.domain).ok()?;
        let goal = self.scenario.parse_goal(&saved.goal).ok()?;
        self.notice(format!(
            "instruction known from policy {}: goal {goal}, no LLM call needed",
            path.display()
        ));
        self.emit(Event::Goal {
            goal: goal.clone(),
            reasoning: None,
            matches_expected: None,
            author: format!("policy {}", path.display()),
        });
        Some(goal)
    }

    /// Plan the task's goal (the scenario's when none was given), or start from its
    /// saved policy.
    pub(super) fn plan(&mut self) {
        let task = match (&self.task, &self.scenario.goal) {
            (Some(t), _) => t.clone(),
            (None, Some(goal)) => Task {
                goal: goal.clone(),
                instruction: self.scenario.instruction.clone(),
            },
            (None, None) => {
                return self.error("no goal: type an instruction or a goal formula first (i)");
            }
        };
        self.task = Some(task.clone());
        self.loaded_from = None;
        self.planned_in_model = false;
        self.cancel_request();
        self.set_running(false);
        self.pending = None;
        self.failure = None;
        self.rounds = 0;
        self.tried.clear();
        self.undo.clear();
        self.fixes.clear();
        if let Some(store) = &self.policies {
            let path = store.path_for(&self.scenario_path, &task.goal);
            if path.is_file() {
                return self.load_policy(Some(path), true);
            }
        }
        let planner = Planner::new(&self.scenario.domain);
        let started = Instant::now();
        match planner.plan(&task.goal.to_dnf(), self.planning.as_ref()) {
            Ok(plan) => {
                let why = format!("planned for {}", task.goal);
                self.planned(&plan, started.elapsed());
                self.replace_tree(plan.tree, Vec::new(), why);
            }
            Err(e) => self.emit(Event::Failed {
                error: SessionError::Plan(e),
            }),
        }
    }

    /// Say what the planner did and what its simulation predicts.
    pub(super) fn planned(&self, plan: &Plan, elapsed: Duration) {
        let summary = PlanSummary::of(plan, elapsed);
        self.notice(summary.log_line());
        self.emit(Event::Planned { summary });
    }

    /// Make a tree that does not grow out of the current one (a plan, an undo, a load)
    /// the tree: forced statuses and breakpoints are cleared, since their ids would name
    /// other nodes.
    pub(super) fn replace_tree(
        &mut self,
        tree: Tree,
        new_nodes: Vec<crate::bt::NodeId>,
        why: String,
    ) {
        self.clear_marks();
        self.set_tree(tree, new_nodes, why);
    }

    /// Make `tree` the tree, tell front ends, and start the execution world afresh.
    /// Forced statuses and breakpoints stay on the nodes it still has.
    pub(super) fn set_tree(&mut self, tree: Tree, new_nodes: Vec<crate::bt::NodeId>, why: String) {
        self.prune_marks(&tree);
        let learned = crate::session::knowledge::learned_in_tree(&self.scenario.domain, &tree)
            .into_iter()
            .map(|l| (l.node, l.rules))
            .collect();
        self.emit(Event::TreeChanged {
            tree: Arc::new(tree.clone()),
            new_nodes,
            learned,
            why,
        });
        self.tree = Some(tree);
        self.gate = None;
        self.reset_world(false);
    }

    pub(super) fn start_running(&mut self) {
        if self.tree.is_none() {
            return self.error("nothing to run: submit an instruction or plan first");
        }
        self.run_ticks = 0;
        self.set_running(true);
    }

    /// The execution cell's scene, when a front end asked for scenes.
    pub(super) fn emit_scene(&self) {
        if !self.scenes {
            return;
        }
        if let Some(scene) = crate::world::CellWorld::scene_of(self.exec.as_ref()) {
            self.emit(Event::Scene {
                scene: Arc::new(scene),
            });
        }
    }

    /// One tick in the execution world.
    pub(super) fn tick(&mut self) {
        let Some(tree) = &self.tree else {
            self.set_running(false);
            return self.error("nothing to tick: submit an instruction or plan first");
        };
        let mut leaves = WorldLeaves {
            world: self.exec.as_mut(),
            domain: &self.scenario.domain,
        };
        let record = Arc::new(
            self.ticker
                .tick_forced(tree, &mut leaves, &self.debug.forced),
        );
        self.run_ticks += 1;
        let failed = record.failures.first().and_then(|(node, error)| {
            let action = tree.kind(*node).ok()?.as_action()?.clone();
            Some(Failure {
                node: *node,
                action,
                error: error.clone(),
            })
        });
        self.last = Some(record.clone());
        self.emit(Event::Ticked {
            record: record.clone(),
        });
        self.emit_scene();
        let facts = self.exec.facts();
        if facts != self.facts {
            self.facts = facts;
            self.emit(Event::WorldChanged {
                facts: self.facts.clone(),
                reset: false,
            });
        }
        let motion = crate::world::CellWorld::motion_of(self.exec.as_ref());
        if motion.is_some() && motion != self.motion {
            self.motion.clone_from(&motion);
            if let Some(motion) = motion {
                self.emit(Event::ArmMotion { motion });
            }
        }
        match (record.root, failed) {
            (TickOutcome::Running, _) => {}
            (TickOutcome::Success, _) if !record.completed.is_empty() => {}
            (TickOutcome::Success, _) => {
                self.set_running(false);
                self.emit(Event::Success {
                    ticks: self.ticker.tick_count(),
                });
            }
            (TickOutcome::Failure, Some(failure)) => {
                self.set_running(false);
                self.on_failure(failure);
            }
            (TickOutcome::Failure, None) if !record.forced.is_empty() => {
                self.set_running(false);
                self.emit(Event::GaveUp {
                    reason: format!(
                        "the tree failed with {} forced status(es) and no action failing",
                        record.forced.len()
                    ),
                });
            }
            (TickOutcome::Failure, None) => {
                self.set_running(false);
                self.emit(Event::GaveUp {
                    reason: "the tree failed without an action failing: a condition it needs is false and nothing achieves it".into(),
                });
            }
        }
        if self.running && self.run_ticks >= self.max_ticks {
            self.set_running(false);
            self.emit(Event::GaveUp {
                reason: format!("the tree still runs after {} ticks", self.run_ticks),
            });
        }
    }

    fn on_failure(&mut self, failure: Failure) {
        let node_path = self
            .tree
            .as_ref()
            .and_then(|t| t.path(failure.node).ok())
            .unwrap_or_default();
        self.emit(Event::ActionFailed {
            action: failure.action.clone(),
            node: failure.node,
            node_path,
            error: failure.error.clone(),
        });
        if failure.error.contains(world::DISAGREEMENT_NOTE) {
            self.tell_disagreement();
        }
        let known = self.failure.as_ref() == Some(&failure)
            && (self.pending.is_some() || self.request.is_some());
        self.failure = Some(failure.clone());
        if !known {
            self.ask_about(failure);
        }
    }

    /// The planning world predicted a motion the arm cannot make: say so. The planning
    /// world keeps its abstraction (re-planning every candidate with the arms costs
    /// seconds per candidate); the fix approved is checked by running it with the arms.
    fn tell_disagreement(&self) {
        self.notice(
            "planning and execution disagree: the planning world found the way clear and the \
             arm found no path; a fix is checked in the planning world, then by the arm",
        );
    }

    /// A fresh execution world and ticker (the tree stays).
    pub(super) fn reset_world(&mut self, announce: bool) {
        self.set_running(false);
        match world::load_execution(&self.scenario, self.variant.as_deref()) {
            Ok(e) => self.exec = e.world,
            Err(e) => return self.error(format!("cannot reset the world: {e}")),
        }
        self.ticker = crate::bt::Ticker::new();
        self.debug.forget_stop();
        self.last = None;
        self.run_ticks = 0;
        self.motion = None;
        self.facts = self.exec.facts();
        self.emit(Event::WorldChanged {
            facts: self.facts.clone(),
            reset: true,
        });
        self.emit_scene();
        if announce {
            self.notice("world reset: the tree starts again from the scenario's first state");
        }
    }

    /// The arms' description is in the cache now. A world not ticked yet is rebuilt with
    /// the arms at once; one in the middle of a run keeps its abstraction until it is
    /// reset (by the person, or by the next tree), so no run changes its physics halfway.
    pub(super) fn robot_arrived(&mut self) {
        if self.ticker.tick_count() == 0 && !self.running {
            self.reset_world(false);
            self.notice("the robot description is in the cache: the cell now moves the real arms");
        } else {
            self.notice(
                "the robot description is in the cache: the real arms move from the next \
                 world reset or the next tree",
            );
        }
    }

    pub(super) fn undo(&mut self) {
        let Some(entry) = self.undo.pop() else {
            return self.error("nothing to undo: no change has been applied");
        };
        self.cancel_request();
        self.pending = None;
        self.failure = None;
        self.drop_offers();
        let undone = self.fixes.len().saturating_sub(entry.fixes);
        self.fixes.truncate(entry.fixes);
        // Undoing is not rejecting: the undone change may be proposed again.
        if let Some(proposal) = &entry.proposal {
            self.tried.retain(|(_, t)| &t.proposal != proposal);
        }
        let why = format!("undid the last change ({undone} fix(es) removed)");
        self.replace_tree(entry.tree, Vec::new(), why);
    }
}
