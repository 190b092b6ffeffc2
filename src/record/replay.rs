//! A recording read back as the session it was: its scenario loaded, every entry turned
//! back into the command or event it stands for, in order, with its time. Replaying needs
//! no model: the model's replies are in the recording.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::bt::{ForcedStatuses, Ticker, Tree};
use crate::planner::WorldLeaves;
use crate::scenario::{Scenario, ScenarioError};
use crate::session::Event;
use crate::world::{CellWorld, World};

use super::{Entry, Header, RecordError, Source};

/// One step of a replayed session.
#[derive(Debug, Clone)]
pub enum Step {
    /// What a front end asked, in words.
    Command(String),
    Event(Event),
}

/// A replayed session.
pub struct Replay {
    pub path: PathBuf,
    pub header: Header,
    /// The scenario file as the recording names it.
    pub scenario_file: PathBuf,
    pub variant: Option<String>,
    pub scenario: Arc<Scenario>,
    /// The steps with their times (milliseconds since the session started).
    pub steps: Vec<(u64, Step)>,
    /// The line of a partial last entry that was left out (the session did not end
    /// cleanly).
    pub cut_at: Option<usize>,
}

/// Why a recording cannot be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error(transparent)]
    Record(#[from] RecordError),
    #[error("{path}: a BehaviorTree.CPP process watched at {address}, not a session on a scenario")]
    Watched {
        path: PathBuf,
        address: crate::monitor::Address,
    },
    #[error("{path}: the recorded scenario {scenario}: {source}")]
    Scenario {
        path: PathBuf,
        scenario: PathBuf,
        #[source]
        source: ScenarioError,
    },
    #[error(
        "{path}: recorded on the scenario {recorded:?}, but {scenario} is {found:?}; give the scenario it was recorded on"
    )]
    OtherScenario {
        path: PathBuf,
        scenario: PathBuf,
        recorded: String,
        found: String,
    },
}

impl Replay {
    /// Read `path`; the scenario is the recorded one, or `scenario` when given (a
    /// recording made elsewhere).
    pub fn load(path: &Path, scenario: Option<&Path>) -> Result<Replay, ReplayError> {
        Replay::of(super::read(path)?, scenario)
    }

    /// A recording read back; the scenario is the recorded one, or `scenario` when given.
    pub fn of(recording: super::Recording, scenario: Option<&Path>) -> Result<Replay, ReplayError> {
        let (scenario_file, name, variant) = match &recording.header.source {
            Source::Session {
                scenario,
                name,
                variant,
            } => (scenario.clone(), name.clone(), variant.clone()),
            Source::Watched { watched } => {
                return Err(ReplayError::Watched {
                    path: recording.path.clone(),
                    address: watched.clone(),
                });
            }
        };
        let mut steps = Vec::with_capacity(recording.entries.len());
        for (line, entry) in recording.entries {
            steps.push(match entry {
                Entry::Command { ms, command } => (ms, Step::Command(command)),
                Entry::Event { ms, event } => (ms, Step::Event(event)),
                Entry::Watched { .. } => {
                    return Err(ReplayError::Record(RecordError::Line {
                        path: recording.path,
                        line,
                        reason: "a watched process's event in the recording of a session".into(),
                    }));
                }
            });
        }
        let scenario_path = scenario.map_or_else(|| scenario_file.clone(), Path::to_path_buf);
        let loaded = Scenario::load(&scenario_path).map_err(|source| ReplayError::Scenario {
            path: recording.path.clone(),
            scenario: scenario_path.clone(),
            source,
        })?;
        if loaded.name != name {
            return Err(ReplayError::OtherScenario {
                path: recording.path.clone(),
                scenario: scenario_path,
                recorded: name,
                found: loaded.name,
            });
        }
        Ok(Replay {
            path: recording.path,
            header: recording.header,
            scenario_file,
            variant,
            scenario: Arc::new(loaded),
            steps,
            cut_at: recording.cut_at,
        })
    }
}

/// The recorded session's cell, re-simulated: each recorded tick is ticked again in a
/// world of the scenario, so a 3D view can show the scene after it (recordings keep the
/// statuses, not the scenes). The world is deterministic, so the statuses come out as
/// recorded; when they do not (a scenario file changed since), `diverged` says at which
/// tick.
pub struct Resimulation {
    scenario: Arc<Scenario>,
    variant: Option<String>,
    world: Option<Box<dyn World>>,
    ticker: Ticker,
    tree: Option<Arc<Tree>>,
    forced: ForcedStatuses,
    pub diverged: Option<u64>,
}

impl Resimulation {
    pub fn new(scenario: Arc<Scenario>, variant: Option<String>) -> Resimulation {
        let mut sim = Resimulation {
            scenario,
            variant,
            world: None,
            ticker: Ticker::new(),
            tree: None,
            forced: ForcedStatuses::new(),
            diverged: None,
        };
        sim.reset();
        sim
    }

    fn reset(&mut self) {
        // The world the session ticked: with the robot's real arms when they moved then.
        self.world = crate::world::load_execution(&self.scenario, self.variant.as_deref())
            .ok()
            .map(|e| e.world);
        self.ticker = Ticker::new();
    }

    /// Follow `event`; the cell's scene when it changed (a cell world only).
    pub fn follow(&mut self, event: &Event) -> Option<Event> {
        match event {
            Event::TreeChanged { tree, .. } => {
                self.tree = Some(tree.clone());
                self.forced.clear();
                self.reset();
            }
            Event::WorldChanged { reset: true, .. } => self.reset(),
            Event::Forced { forced } => self.forced = forced.iter().copied().collect(),
            Event::Ticked { record } => {
                let (Some(tree), Some(world)) = (&self.tree, self.world.as_mut()) else {
                    return None;
                };
                let mut leaves = WorldLeaves {
                    world: world.as_mut(),
                    domain: &self.scenario.domain,
                };
                let again = self.ticker.tick_forced(tree, &mut leaves, &self.forced);
                if again.statuses != record.statuses && self.diverged.is_none() {
                    self.diverged = Some(record.tick);
                }
            }
            _ => return None,
        }
        let world = self.world.as_ref()?;
        CellWorld::scene_of(world.as_ref()).map(|scene| Event::Scene {
            scene: Arc::new(scene),
        })
    }
}
