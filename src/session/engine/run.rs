//! The run: the planning world (the planner ticks trees in forks of it), the execution
//! world with its ticker (what "tick" and "run" advance), the debugger's marks, and what
//! the last tick showed; ticking, running and resetting the world.

use std::sync::Arc;

use crate::bt::{Outcome as TickOutcome, TickRecord, Ticker};
use crate::domain::Condition;
use crate::executor::{Divergence, ExecutorError, Findings, Reality};
use crate::planner::WorldLeaves;
use crate::world::cell::snapshot::MotionView;
use crate::world::{self, World};

use super::super::types::Event;
use super::Engine;
use super::debug::Debugger;
use super::phase::{Failure, Phase};

pub(super) struct Run {
    pub(super) planning: Box<dyn World>,
    /// The world a tree runs in: it performs the actions, or is the twin of `reality`.
    pub(super) exec: Box<dyn World>,
    /// The executor that performs the actions, when it is not `exec`.
    pub(super) reality: Option<Reality>,
    pub(super) ticker: Ticker,
    /// Forced statuses and breakpoints.
    pub(super) debug: Debugger,
    /// Ticks since the last Run command (for the limit).
    pub(super) ticks: u64,
    pub(super) facts: Vec<Condition>,
    /// The last arm motion told (`Event::ArmMotion`).
    pub(super) motion: Option<MotionView>,
    pub(super) last: Option<Arc<TickRecord>>,
}

impl Run {
    pub(super) fn new(
        planning: Box<dyn World>,
        exec: Box<dyn World>,
        reality: Option<Reality>,
    ) -> Run {
        let facts = exec.facts();
        Run {
            planning,
            exec,
            reality,
            ticker: Ticker::new(),
            debug: Debugger::default(),
            ticks: 0,
            facts,
            motion: None,
            last: None,
        }
    }
}

impl Engine {
    pub(super) fn start_running(&mut self) {
        if self.task.tree.is_none() {
            return self.error("nothing to run: submit an instruction or plan first");
        }
        self.run.ticks = 0;
        self.enter(Phase::Running);
    }

    /// The execution cell's scene, when a front end asked for scenes.
    pub(super) fn emit_scene(&self) {
        if !self.settings.scenes {
            return;
        }
        if let Some(scene) = crate::world::CellWorld::scene_of(self.run.exec.as_ref()) {
            self.emit(Event::Scene {
                scene: Arc::new(scene),
            });
        }
    }

    /// One tick in the execution world.
    pub(super) fn tick(&mut self) {
        // Once the tree runs, a goal typed is a new task, not a correction of the reading.
        self.task.reading = None;
        let Some(tree) = &self.task.tree else {
            self.stop_running();
            return self.error("nothing to tick: submit an instruction or plan first");
        };
        let domain = &self.settings.scenario.domain;
        let forced = &self.run.debug.forced;
        let (record, found) = match self.run.reality.as_mut() {
            Some(reality) => {
                let mut leaves = reality.leaves(&mut self.run.exec, domain);
                let record = self.run.ticker.tick_forced(tree, &mut leaves, forced);
                (record, leaves.found)
            }
            None => {
                let mut leaves = WorldLeaves {
                    world: self.run.exec.as_mut(),
                    domain,
                };
                let record = self.run.ticker.tick_forced(tree, &mut leaves, forced);
                (record, Findings::default())
            }
        };
        let record = Arc::new(record);
        self.run.ticks += 1;
        let failed = record.failures.first().and_then(|(node, error)| {
            let action = tree.kind(*node).ok()?.as_action()?.clone();
            Some(Failure {
                node: *node,
                action,
                error: error.clone(),
            })
        });
        // Where the failed action failed: in the executor (reality), or in betr's world
        // (the world itself, or the twin refusing before anything was sent).
        let failed_in = failed.as_ref().and_then(|f| {
            let in_reality = found.diverged.iter().any(|d| d.action == f.action);
            let reality = self.run.reality.as_ref().filter(|_| in_reality)?;
            Some(reality.name().to_string())
        });
        // Reality showed one of its objects elsewhere than the scene: the scene was wrong,
        // not the tree (a grasp planned at the scene's pose that closed on nothing).
        let scene_was_wrong = failed_in.is_some()
            && failed
                .as_ref()
                .is_some_and(|f| f.action.args.iter().any(|a| found.learned.contains(a)));
        self.run.last = Some(record.clone());
        self.emit(Event::Ticked {
            record: record.clone(),
        });
        self.emit_scene();
        self.tell_world_change();
        if let Some(broken) = self.take_findings(found) {
            return self.executor_broke(&broken);
        }
        if scene_was_wrong && record.root == TickOutcome::Failure {
            return self.run_again_as_reality_showed(failed, failed_in);
        }
        self.end_of_tick(&record, failed, failed_in);
        if self.is_running() && self.run.ticks >= self.settings.max_ticks {
            self.stop_running();
            self.emit(Event::GaveUp {
                reason: format!("the tree still runs after {} ticks", self.run.ticks),
            });
        }
    }

    /// Tell front ends what a tick changed in the world: its facts, the arm's motion.
    fn tell_world_change(&mut self) {
        let facts = self.run.exec.facts();
        if facts != self.run.facts {
            self.run.facts = facts;
            self.emit(Event::WorldChanged {
                facts: self.run.facts.clone(),
                reset: false,
            });
        }
        let motion = crate::world::CellWorld::motion_of(self.run.exec.as_ref());
        if motion.is_some() && motion != self.run.motion {
            self.run.motion.clone_from(&motion);
            if let Some(motion) = motion {
                self.emit(Event::ArmMotion { motion });
            }
        }
    }

    /// Take in what a tick over the executor found: what reality showed of the first state
    /// goes into the planning world (before the failure is asked about, so the repair is
    /// screened in it) and is said, and so is each action the twin predicted that reality
    /// did otherwise; the executor's breakdown, if any, is returned.
    fn take_findings(&mut self, found: Findings) -> Option<ExecutorError> {
        let Some(reality) = &self.run.reality else {
            return found.broken;
        };
        if !found.learned.is_empty() {
            if let Err(e) = self.run.planning.take_observation(reality.learned()) {
                tracing::warn!("the planning world cannot take in what reality showed: {e}");
            }
            self.notice(format!(
                "reality showed {} elsewhere than the scene said, untouched by the robot: the \
                 scene's first state now has it there, and repairs are tried in it",
                found.learned.join(", ")
            ));
        }
        for Divergence {
            action,
            reality: what,
            predicted,
        } in found.diverged
        {
            self.emit(Event::Diverged {
                executor: reality.name().to_string(),
                action,
                reality: what,
                predicted: predicted.filter(|_| self.settings.scenes),
            });
        }
        found.broken
    }

    /// The executor failed itself: nothing it reported this tick is taken as done, and
    /// the run stops instead of asking how to repair the tree.
    fn executor_broke(&mut self, error: &ExecutorError) {
        self.stop_running();
        self.emit(Event::GaveUp {
            reason: format!(
                "{error}; the run stops, and nothing this tick reported is taken as done"
            ),
        });
    }

    /// What the root's status means: running goes on; success ends a run; a failure is
    /// asked about, or told when no action failed.
    fn end_of_tick(
        &mut self,
        record: &TickRecord,
        failed: Option<Failure>,
        failed_in: Option<String>,
    ) {
        match (record.root, failed) {
            (TickOutcome::Running, _) => {}
            (TickOutcome::Success, _) if !record.completed.is_empty() => {}
            (TickOutcome::Success, _) => {
                self.stop_running();
                self.emit(Event::Success {
                    ticks: self.run.ticker.tick_count(),
                    executor: self.run.reality.as_ref().map(|r| r.name().to_string()),
                });
            }
            (TickOutcome::Failure, Some(failure)) => {
                self.stop_running();
                self.on_failure(failure, failed_in);
            }
            (TickOutcome::Failure, None) => {
                self.stop_running();
                let reason = if record.forced.is_empty() {
                    "the tree failed without an action failing: a condition it needs is false and nothing achieves it".to_string()
                } else {
                    format!(
                        "the tree failed with {} forced status(es) and no action failing",
                        record.forced.len()
                    )
                };
                self.emit(Event::GaveUp { reason });
            }
        }
    }

    /// The failed action's object was not where the scene said, and reality showed where
    /// it is: nothing is missing from the tree, the scene was wrong. The failure is told,
    /// and the tree runs again from the first state as reality has it, without asking.
    fn run_again_as_reality_showed(&mut self, failed: Option<Failure>, failed_in: Option<String>) {
        self.stop_running();
        if let Some(failure) = &failed {
            self.tell_failure(failure, failed_in);
        }
        self.notice(
            "the action failed on an object the scene had elsewhere: nothing is asked; the tree \
             runs again from the first state as reality showed it",
        );
        self.reset_world(false);
        self.start_running();
    }

    /// Say which action failed, where in the tree, in which executor (none: in betr's
    /// world), and why.
    fn tell_failure(&self, failure: &Failure, executor: Option<String>) {
        let node_path = self
            .task
            .tree
            .as_ref()
            .and_then(|t| t.path(failure.node).ok())
            .unwrap_or_default();
        self.emit(Event::ActionFailed {
            action: failure.action.clone(),
            node: failure.node,
            node_path,
            error: failure.error.clone(),
            executor,
        });
    }

    fn on_failure(&mut self, failure: Failure, failed_in: Option<String>) {
        self.tell_failure(&failure, failed_in);
        if failure.error.contains(world::DISAGREEMENT_NOTE) {
            // The planning world keeps its abstraction (re-planning every candidate with
            // the arms costs seconds per candidate); the fix approved is checked by
            // running it with the arms.
            self.notice(
                "planning and execution disagree: the planning world found the way clear and the \
                 arm found no path; a fix is checked in the planning world, then by the arm",
            );
        }
        self.ask_about(failure);
    }

    /// A fresh execution world and ticker (the tree stays).
    pub(super) fn reset_world(&mut self, announce: bool) {
        self.stop_running();
        let settings = &self.settings;
        match world::load_execution(&settings.scenario, settings.variant.as_deref()) {
            Ok(e) => self.run.exec = e.world,
            Err(e) => return self.error(format!("cannot reset the world: {e}")),
        }
        if let Some(reality) = &mut self.run.reality
            && let Err(e) = reality.reset(self.run.exec.as_mut())
        {
            self.error(format!("cannot reset the executor: {e}"));
        }
        self.run.ticker = Ticker::new();
        self.run.debug.forget_stop();
        self.run.last = None;
        self.run.ticks = 0;
        self.run.motion = None;
        self.run.facts = self.run.exec.facts();
        self.emit(Event::WorldChanged {
            facts: self.run.facts.clone(),
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
        if self.run.ticker.tick_count() == 0 && !self.is_running() {
            self.reset_world(false);
            self.notice("the robot description is in the cache: the cell now moves the real arms");
        } else {
            self.notice(
                "the robot description is in the cache: the real arms move from the next \
                 world reset or the next tree",
            );
        }
    }
}
