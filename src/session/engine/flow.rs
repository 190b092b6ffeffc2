//! From instruction to tree: submitting, choosing a reading, planning, replacing the tree
//! and undoing a change.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::bt::Tree;
use crate::goal;
use crate::planner::{Plan, Planner};

use super::super::interpret::readings::distinct_readings;
use super::super::interpret::submitted::{self, Submitted};
use super::super::planned::PlanSummary;
use super::super::policy;
use super::super::types::{Event, SessionError};
use super::Engine;
use super::phase::Phase;
use super::task::{Goal, Origin};

/// Who wrote a goal a person typed as a formula.
const TYPED: &str = "a person, typed as a goal";
/// Who wrote a goal a person chose among the model's readings.
const CHOSEN: &str = "a person, chosen among the model's readings";
/// Who wrote a goal the caller gave with the instruction.
const GIVEN: &str = "given with the instruction";
/// Who kept a correction made by choosing a reading.
const CORRECTED_BY_CHOICE: &str = "a person, choosing a reading not offered first";
/// Who kept a correction made by typing the goal.
const CORRECTED_BY_TYPING: &str = "a person, typing the goal the instruction meant";

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
            .settings
            .scenario
            .goal
            .as_ref()
            .and_then(|expected| goal::equivalent(expected, &goal).ok());
        self.emit(Event::Goal {
            goal: goal.clone(),
            reasoning: None,
            matches_expected,
            author: author.to_string(),
            first_answer: None,
            doubt: None,
        });
        self.task.goal = Some(Goal {
            formula: goal,
            instruction,
        });
        self.plan();
    }

    pub(super) fn submit(&mut self, text: &str) {
        // A goal typed while readings wait, or before the reading taken has run, is what
        // the instruction meant.
        let correcting = match &self.phase {
            Phase::Choosing {
                instruction,
                readings,
            } => Some((
                instruction.clone(),
                readings.first().map(|r| r.goal.clone()),
            )),
            _ => self.task.reading.clone().map(|(i, g)| (i, Some(g))),
        };
        if matches!(self.phase, Phase::Choosing { .. }) {
            self.enter(self.settled());
        }
        self.task.reading = None;
        let text = match submitted::read(&self.settings.scenario, text) {
            Ok(Submitted::Goal(goal)) => {
                let Some((instruction, replaced)) = correcting else {
                    return self.start_task(goal, None, TYPED);
                };
                self.keep_correction(&instruction, &goal, replaced.as_ref(), CORRECTED_BY_TYPING);
                return self.start_task(goal, Some(instruction), TYPED);
            }
            Ok(Submitted::Instruction(text)) => text,
            Err(e) => return self.error(e.to_string()),
        };
        let text = text.as_str();
        if let Some(goal) = self.goal_from_policy(text) {
            self.task.goal = Some(Goal {
                formula: goal,
                instruction: Some(text.to_string()),
            });
            return self.plan();
        }
        match self.settings.model.clone() {
            Ok(model) => self.ask_goal(model, text),
            Err(why) => {
                let not_a_goal = self
                    .settings
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
        if self.settings.options.choose_reading {
            let readings = distinct_readings(
                &self.settings.scenario,
                self.run.planning.as_ref(),
                &read.readings,
            );
            // Several readings that do different things, or one the checks doubt: a
            // person decides before anything runs.
            let doubt = read.doubt().filter(|_| readings.len() == 1);
            if readings.len() > 1 || doubt.is_some() {
                self.emit(Event::Readings {
                    instruction: instruction.clone(),
                    readings: readings.clone(),
                    doubt,
                });
                return self.enter(Phase::Choosing {
                    instruction,
                    readings,
                });
            }
        }
        self.task.goal = Some(Goal {
            formula: read.answer.goal.clone(),
            instruction: Some(instruction.clone()),
        });
        self.plan();
        self.task.reading = Some((instruction, read.answer.goal));
    }

    /// Work on reading `index` (from 0) of those offered.
    pub(super) fn choose_reading(&mut self, index: usize) {
        let Phase::Choosing {
            instruction,
            readings,
        } = &self.phase
        else {
            return self.error("no readings to choose among: type an instruction first (i)");
        };
        let Some(reading) = readings.get(index) else {
            let count = readings.len();
            return self.error(format!(
                "no reading {}: the instruction has {count} readings (1 to {count})",
                index + 1
            ));
        };
        let (goal, instruction) = (reading.goal.clone(), instruction.clone());
        let offered_first = readings.first().map(|r| r.goal.clone());
        self.notice(format!("reading {} chosen: {goal}", index + 1));
        if index > 0 {
            self.keep_correction(
                &instruction,
                &goal,
                offered_first.as_ref(),
                CORRECTED_BY_CHOICE,
            );
        }
        self.start_task(goal, Some(instruction), CHOSEN);
    }

    /// The goal a saved policy recorded for this instruction (no model call needed).
    fn goal_from_policy(&self, instruction: &str) -> Option<goal::Formula> {
        let settings = &self.settings;
        let store = settings.policies.as_ref()?;
        let path = store.find_by_instruction(&settings.scenario_path, instruction)?;
        let saved = policy::load(&path, &settings.scenario.domain).ok()?;
        let goal = settings.scenario.parse_goal(&saved.goal).ok()?;
        self.notice(format!(
            "instruction known from policy {}: goal {goal}, no LLM call needed",
            path.display()
        ));
        self.emit(Event::Goal {
            goal: goal.clone(),
            reasoning: None,
            matches_expected: None,
            author: format!("policy {}", path.display()),
            first_answer: None,
            doubt: None,
        });
        Some(goal)
    }

    /// Plan the task's goal (the scenario's when none was given), or start from its
    /// saved policy.
    /// Plan afresh as [`Self::plan`] does, keeping the fixes refused for the goal's
    /// failures: planning (and a saved policy it loads) starts the history afresh, so
    /// they are put back after.
    pub(super) fn plan_keeping_refused(&mut self) {
        let refused = std::mem::take(&mut self.task.tried);
        self.plan();
        self.task.tried = refused;
    }

    /// Tell the front end what it shows of the engine's state when that changed: the
    /// phase, and how many fixes are refused and unsaved. Told after each command, answer
    /// and tick, so a front end's status lines follow the engine's and nothing else.
    pub(super) fn tell_state(&mut self) {
        self.tell_phase();
        let counts = self.task.counts();
        if counts != self.task.told {
            self.task.told = counts;
            self.emit(Event::FixCounts(counts));
        }
    }

    /// Tell the front end the phase, when it changed since it was last told.
    pub(super) fn tell_phase(&mut self) {
        let kind = self.phase.kind();
        if kind != self.told_phase {
            self.told_phase = kind;
            self.emit(Event::Phase(kind));
        }
    }

    pub(super) fn plan(&mut self) {
        let scenario = &self.settings.scenario;
        let goal = match (&self.task.goal, &scenario.goal) {
            (Some(g), _) => g.clone(),
            (None, Some(goal)) => Goal {
                formula: goal.clone(),
                instruction: scenario.instruction.clone(),
            },
            (None, None) => {
                return self.error("no goal: type an instruction or a goal formula first (i)");
            }
        };
        self.task.goal = Some(goal.clone());
        self.task.restart(Origin::Simulation);
        self.enter(self.settled());
        if let Some(store) = &self.settings.policies {
            let path = store.path_for(&self.settings.scenario_path, &goal.formula);
            if path.is_file() {
                return self.load_policy(Some(path), true);
            }
        }
        let planner = Planner::new(&self.settings.scenario.domain);
        let started = Instant::now();
        match planner.plan(&goal.formula.to_dnf(), self.run.planning.as_ref()) {
            Ok(plan) => {
                let why = format!("planned for {}", goal.formula);
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

    /// Make `tree` the tree, tell front ends, and start the execution world afresh: the
    /// engine is ready with it, whatever it waited for. Forced statuses and breakpoints
    /// stay on the nodes it still has.
    pub(super) fn set_tree(&mut self, tree: Tree, new_nodes: Vec<crate::bt::NodeId>, why: String) {
        self.prune_marks(&tree);
        let domain = &self.settings.scenario.domain;
        let learned = crate::session::knowledge::learned_in_tree(domain, &tree)
            .into_iter()
            .map(|l| (l.node, l.rules))
            .collect();
        self.emit(Event::TreeChanged {
            tree: Arc::new(tree.clone()),
            new_nodes,
            learned,
            why,
        });
        self.task.tree = Some(tree);
        self.enter(Phase::Ready);
        self.reset_world(false);
    }

    pub(super) fn undo(&mut self) {
        let Some(entry) = self.task.undo.pop() else {
            return self.error("nothing to undo: no change has been applied");
        };
        self.drop_waiting();
        self.drop_offers();
        let undone = self.task.fixes.len().saturating_sub(entry.fixes);
        self.task.fixes.truncate(entry.fixes);
        self.task.saved = self.task.saved.min(entry.fixes);
        // Undoing is not rejecting: the undone change may be proposed again.
        if let Some(proposal) = &entry.proposal {
            self.task.tried.retain(|(_, t)| &t.proposal != proposal);
        }
        let why = format!("undid the last change ({undone} fix(es) removed)");
        self.replace_tree(entry.tree, Vec::new(), why);
    }
}
