//! The replay on the terminal: a position in the recording and the app there. A key goes
//! to the app as in the workbench; a move it asks for rebuilds the app at the new
//! position, keeping what the person did to the view (folds, selection, the log's
//! scroll). The loop reads the terminal directly: there is no engine, no model and
//! nothing else to wait for.

use std::path::Path;

use crossterm::event::{Event as TermEvent, KeyEvent};

use super::super::app::{App, Request};
use super::super::components::status_bar::Message;
use super::super::{TerminalGuard, TuiError, strings, ui};
use super::{Move, Player};

pub struct ReplayScreen {
    player: Player,
    position: usize,
    /// The app at `position`.
    pub app: App,
}

impl ReplayScreen {
    /// The replay at `position` (the end when past it).
    pub fn open(player: Player, position: usize) -> ReplayScreen {
        let position = position.min(player.len());
        ReplayScreen {
            app: player.seek(position),
            player,
            position,
        }
    }

    /// Steps applied so far.
    pub fn position(&self) -> usize {
        self.position
    }

    pub fn should_quit(&self) -> bool {
        self.app.should_quit()
    }

    /// A line in the status bar until the next key.
    pub fn say(&mut self, text: String, error: bool) {
        self.app.status.message = Some(Message { text, error });
    }

    /// A key pressed: to the app, and the move it asks for, if any.
    pub fn key(&mut self, key: KeyEvent) {
        self.app.on_key(key);
        for request in self.app.take_requests() {
            if let Request::Replay(m) = request {
                self.go(m);
            }
        }
    }

    /// Make a move; a move that finds nothing says so and stays.
    pub fn go(&mut self, m: Move) {
        match self.player.target(self.position, m) {
            Some(p) => self.move_to(p),
            None => self.say(strings::replay_nothing(m.looks_for()), false),
        }
    }

    /// The app after the first `p` steps, in the view the person left.
    pub fn move_to(&mut self, p: usize) {
        let mut app = self.player.seek(p);
        app.adopt_view(&mut self.app);
        self.app = app;
        self.position = p.min(self.player.len());
    }
}

/// Show `screen` until the person quits; standard error goes to `stderr_to` meanwhile.
pub fn run(mut screen: ReplayScreen, stderr_to: Option<&Path>) -> Result<(), TuiError> {
    let (_guard, mut terminal) = TerminalGuard::enter(stderr_to)?;
    while !screen.should_quit() {
        if let Err(e) = terminal.draw(|f| ui::draw(f, &mut screen.app)) {
            tracing::warn!(error = %e, "cannot draw the screen");
        }
        // A resize is drawn by the next draw.
        if let TermEvent::Key(key) = crossterm::event::read()? {
            screen.key(key);
        }
    }
    Ok(())
}
