//! The event loop: wait on terminal input, session events and an animation ticker;
//! dispatch; draw once per iteration. A draw error is logged, not fatal.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use crossterm::event::Event as TermEvent;
use ratatui::Terminal;
use ratatui::backend::Backend;
use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};

use crate::session::{Command, EngineHandle, Event};

use super::app::{App, Request};
use super::dictation::{DictationEvent, DictationService};
use super::ui;

/// Read terminal events on a thread of their own (crossterm's reads block) until `stop`.
pub fn spawn_input_reader(stop: Arc<AtomicBool>) -> UnboundedReceiver<TermEvent> {
    let (tx, rx) = unbounded_channel();
    std::thread::spawn(move || read_input(&tx, &stop));
    rx
}

fn read_input(tx: &UnboundedSender<TermEvent>, stop: &AtomicBool) {
    while !stop.load(Ordering::Relaxed) {
        match crossterm::event::poll(Duration::from_millis(50)) {
            Ok(true) => match crossterm::event::read() {
                Ok(e) => {
                    if tx.send(e).is_err() {
                        return;
                    }
                }
                Err(e) => {
                    tracing::warn!(error = %e, "cannot read the terminal");
                    return;
                }
            },
            Ok(false) => {}
            Err(e) => {
                tracing::warn!(error = %e, "cannot poll the terminal");
                return;
            }
        }
    }
}

/// Something that follows the session besides the screen (the 3D view): it sees every
/// session event and every command sent.
pub trait Tap {
    fn event(&mut self, event: &Event);
    fn command(&mut self, command: &Command);
    /// A line for the status bar (a viewer that is not connected).
    fn notice(&self) -> Option<String>;
}

/// What the loop waits on besides the animation ticker.
pub struct Inputs<'a> {
    pub session: &'a mut UnboundedReceiver<Event>,
    pub terminal: &'a mut UnboundedReceiver<TermEvent>,
    pub dictation: &'a mut UnboundedReceiver<DictationEvent>,
}

/// Run until the app quits or the session ends.
pub async fn run<B: Backend>(
    terminal: &mut Terminal<B>,
    app: &mut App,
    engine: &EngineHandle,
    inputs: Inputs<'_>,
    dictation: &mut DictationService,
    tap: &mut Option<&mut dyn Tap>,
) {
    let mut animation = tokio::time::interval(Duration::from_millis(150));
    animation.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let Inputs {
        session: events,
        terminal: input,
        dictation: heard,
    } = inputs;
    loop {
        if let Err(e) = terminal.draw(|f| ui::draw(f, app)) {
            tracing::warn!(error = %e, "cannot draw the screen");
        }
        tokio::select! {
            term = input.recv() => match term {
                Some(TermEvent::Key(key)) => app.on_key(key),
                // A resize is drawn at the next iteration.
                Some(_) => {}
                None => break,
            },
            event = events.recv() => match event {
                Some(e) => {
                    if let Some(t) = tap.as_mut() {
                        t.event(&e);
                    }
                    app.on_session(e);
                    // Take in everything already waiting before drawing again.
                    while let Ok(e) = events.try_recv() {
                        if let Some(t) = tap.as_mut() {
                            t.event(&e);
                        }
                        app.on_session(e);
                    }
                }
                None => break,
            },
            // The service holds a sender, so this channel never closes while it lives.
            Some(event) = heard.recv() => {
                app.on_dictation(event);
                while let Ok(e) = heard.try_recv() {
                    app.on_dictation(e);
                }
            },
            _ = animation.tick(), if app.animating() => app.on_animation(),
        }
        for request in app.take_requests() {
            match request {
                Request::Session(command) => {
                    if let Some(t) = tap.as_mut() {
                        t.command(&command);
                    }
                    engine.send(command);
                }
                Request::Dictation(request) => dictation.handle(request),
            }
        }
        if app.should_quit() {
            engine.send(Command::Shutdown);
            break;
        }
    }
}
