//! A recording replayed in the workbench, read-only: the screen at a position is the
//! [`App`] after the recorded steps up to it, built by feeding it the recorded events
//! (`App::on_session`) and commands, so stepping back shows exactly what stepping forward
//! showed. There is no engine and no model: nothing is sent anywhere.
//!
//! Every move rebuilds the app from the start ([`Player::seek`]); `index` keeps that fast
//! by leaving out the ticks the screen cannot show any more, and `moves` finds where each
//! key goes. `screen` is the terminal loop.

pub mod index;
pub mod moves;
pub mod screen;

use std::sync::Arc;

use crate::record::{Replay, Step};
use crate::scenario::Scenario;

use super::app::{App, Info};
use super::components::status_bar::Timeline;
use super::keys::KeyBindings;
use super::strings;
use super::theme::Theme;

pub use index::SeekIndex;
pub use moves::{Move, Stops};
pub use screen::{ReplayScreen, run};

/// A recording's steps with what seeking and moving need, and what every rebuilt app is
/// made of.
pub struct Player {
    steps: Vec<(u64, Step)>,
    index: SeekIndex,
    stops: Stops,
    scenario: Arc<Scenario>,
    info: Info,
    keys: KeyBindings,
    theme: Theme,
}

impl Player {
    pub fn new(
        steps: Vec<(u64, Step)>,
        scenario: Arc<Scenario>,
        info: Info,
        keys: KeyBindings,
        theme: Theme,
    ) -> Player {
        let index = SeekIndex::new(steps.iter().map(|(_, s)| s));
        let stops = Stops::new(steps.iter().map(|(_, s)| s));
        Player {
            steps,
            index,
            stops,
            scenario,
            info,
            keys,
            theme,
        }
    }

    /// The player of a recording read back: the status bar names its scenario file.
    pub fn of(replay: Replay, keys: KeyBindings, theme: Theme) -> Player {
        let info = Info {
            scenario: replay.scenario_file.file_stem().map_or_else(
                || replay.scenario.name.clone(),
                |s| s.to_string_lossy().into_owned(),
            ),
            objects: replay.scenario.domain.vocabulary.object_names(),
            ..Info::default()
        };
        Player::new(replay.steps, replay.scenario, info, keys, theme)
    }

    /// How many steps the recording has (the last position).
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Where `m` goes from position `p`, if anywhere.
    pub fn target(&self, p: usize, m: Move) -> Option<usize> {
        self.stops.target(p, m)
    }

    /// The app before any step.
    pub fn fresh(&self) -> App {
        App::replaying(
            self.scenario.clone(),
            self.info.clone(),
            self.keys.clone(),
            self.theme,
        )
    }

    /// Step `i` applied to `app`.
    pub fn apply(&self, app: &mut App, i: usize) {
        match self.steps.get(i).map(|(_, s)| s) {
            Some(Step::Command(text)) => app.on_replayed_command(text),
            Some(Step::Event(event)) => app.on_session(event.clone()),
            None => {}
        }
    }

    /// How many steps a seek to `p` feeds.
    pub fn fed(&self, p: usize) -> usize {
        self.index.feed(p).len()
    }

    /// The app after the first `p` steps (the end when `p` is past it), with its timeline.
    pub fn seek(&self, p: usize) -> App {
        let p = p.min(self.len());
        let mut app = self.fresh();
        for i in self.index.feed(p) {
            self.apply(&mut app, i);
        }
        self.finish(&mut app, p);
        app
    }

    /// The timeline of position `p` in `app`'s status bar. The messages events leave
    /// there (a run stopped, a rule kept) are in the log and the step's own words.
    pub fn finish(&self, app: &mut App, p: usize) {
        let last = p.checked_sub(1).and_then(|i| self.steps.get(i));
        app.status.message = None;
        app.status.replay = Some(Timeline {
            step: p,
            steps: self.len(),
            ms: last.map_or(0, |(ms, _)| *ms),
            what: last.map_or_else(
                || strings::REPLAY_AT_START.to_string(),
                |(_, step)| crate::record::brief(step).replace('\n', " "),
            ),
        });
    }
}

#[cfg(test)]
mod tests;
