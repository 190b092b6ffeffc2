//! The event loop, one queue as in gitui: the terminal's reader thread, a task forwarding
//! the session's events, the push-to-talk service and the animation ticker all send
//! [`QueueEvent`]s into one channel. The loop draws, waits for the next event, takes in
//! everything already waiting (dispatching each to the app and passing on what the app
//! asks), then draws again. A draw error is logged, not fatal.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use crossterm::event::Event as TermEvent;
use ratatui::Terminal;
use ratatui::backend::Backend;
use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};
use tokio::task::JoinHandle;

use crate::session::{Command, EngineHandle, Event};

use super::app::{App, ModelArrival, Request};
use super::dictation::{DictationEvent, DictationService, DictationSink};
use super::ui;

/// How often an animation (the model's spinner, a recording's clock) moves on.
const ANIMATION: Duration = Duration::from_millis(150);

/// Everything the event loop reacts to.
#[derive(Debug)]
pub enum QueueEvent {
    /// From the terminal: a key, or a resize (drawn at the next draw).
    Input(TermEvent),
    /// The terminal can no longer be read: the loop ends.
    InputEnded,
    /// From the session engine.
    Session(Event),
    /// The engine stopped (its channel closed): the loop ends.
    SessionEnded,
    /// From the push-to-talk service.
    Dictation(DictationEvent),
    /// From a model fetched or loaded while the workbench is open.
    Model(ModelArrival),
    /// Time to move animations on; sent only while something animates.
    Tick,
}

/// The loop's one queue: each source sends through a [`Queue::sender`]; the loop drains
/// the receiver.
pub struct Queue {
    sender: UnboundedSender<QueueEvent>,
    receiver: UnboundedReceiver<QueueEvent>,
}

impl Default for Queue {
    fn default() -> Self {
        let (sender, receiver) = unbounded_channel();
        Queue { sender, receiver }
    }
}

impl Queue {
    pub fn new() -> Queue {
        Queue::default()
    }

    /// A sender for one more source.
    pub fn sender(&self) -> UnboundedSender<QueueEvent> {
        self.sender.clone()
    }

    /// Where the push-to-talk service reports: into this queue.
    pub fn dictation_sink(&self) -> DictationSink {
        let sender = self.sender();
        Arc::new(move |event| {
            // The loop is gone only when the workbench is closing: nothing is left to tell.
            let _ = sender.send(QueueEvent::Dictation(event));
        })
    }
}

/// Read terminal events on a thread of their own (crossterm's reads block) into the
/// queue, until `stop` or until the loop is gone.
pub fn spawn_input_reader(queue: UnboundedSender<QueueEvent>, stop: Arc<AtomicBool>) {
    std::thread::spawn(move || {
        if !read_input(&queue, &stop) {
            let _ = queue.send(QueueEvent::InputEnded);
        }
    });
}

/// False when the terminal could not be read.
fn read_input(queue: &UnboundedSender<QueueEvent>, stop: &AtomicBool) -> bool {
    while !stop.load(Ordering::Relaxed) {
        match crossterm::event::poll(Duration::from_millis(50)) {
            Ok(true) => match crossterm::event::read() {
                Ok(e) => {
                    if queue.send(QueueEvent::Input(e)).is_err() {
                        return true;
                    }
                }
                Err(e) => {
                    tracing::warn!(error = %e, "cannot read the terminal");
                    return false;
                }
            },
            Ok(false) => {}
            Err(e) => {
                tracing::warn!(error = %e, "cannot poll the terminal");
                return false;
            }
        }
    }
    true
}

/// Pass a model's arrival into the queue until it has arrived or failed.
pub fn forward_model(
    mut arrivals: UnboundedReceiver<ModelArrival>,
    queue: UnboundedSender<QueueEvent>,
) -> JoinHandle<()> {
    tokio::spawn(async move {
        while let Some(a) = arrivals.recv().await {
            if queue.send(QueueEvent::Model(a)).is_err() {
                return;
            }
        }
    })
}

/// Pass the session's events into the queue, then say that the session ended.
fn forward_session(
    mut events: UnboundedReceiver<Event>,
    queue: UnboundedSender<QueueEvent>,
) -> JoinHandle<()> {
    tokio::spawn(async move {
        while let Some(e) = events.recv().await {
            if queue.send(QueueEvent::Session(e)).is_err() {
                return;
            }
        }
        let _ = queue.send(QueueEvent::SessionEnded);
    })
}

/// A tick every [`ANIMATION`] while `animating` holds, so an idle workbench sleeps.
fn spawn_ticker(queue: UnboundedSender<QueueEvent>, animating: Arc<AtomicBool>) -> JoinHandle<()> {
    tokio::spawn(async move {
        let mut interval = tokio::time::interval(ANIMATION);
        interval.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
        loop {
            interval.tick().await;
            if queue.is_closed() {
                return;
            }
            if animating.load(Ordering::Relaxed) && queue.send(QueueEvent::Tick).is_err() {
                return;
            }
        }
    })
}

/// Something that follows the session besides the screen (the 3D view): it sees every
/// session event and every command sent.
pub trait Tap {
    fn event(&mut self, event: &Event);
    fn command(&mut self, command: &Command);
    /// A line for the status bar (a viewer that is not connected).
    fn notice(&self) -> Option<String>;
    /// The page of a web viewer showing the session, to open in a browser.
    fn viewer_page(&self) -> Option<String> {
        None
    }
}

/// Where the app's requests go.
struct Outlets<'a, 'b> {
    engine: &'a EngineHandle,
    dictation: &'a mut DictationService,
    tap: &'a mut Option<&'b mut dyn Tap>,
}

/// Run until the app quits, the session ends or the terminal can no longer be read.
/// `session` is the engine's event receiver; the terminal's reader and the push-to-talk
/// service send into `queue` already.
pub async fn run<B: Backend>(
    terminal: &mut Terminal<B>,
    app: &mut App,
    engine: &EngineHandle,
    session: UnboundedReceiver<Event>,
    queue: Queue,
    dictation: &mut DictationService,
    tap: &mut Option<&mut dyn Tap>,
) {
    let Queue {
        sender,
        receiver: mut queue,
    } = queue;
    let animating = Arc::new(AtomicBool::new(false));
    let forwarder = forward_session(session, sender.clone());
    let ticker = spawn_ticker(sender, animating.clone());
    let mut outlets = Outlets {
        engine,
        dictation,
        tap,
    };
    'draw: loop {
        if let Err(e) = terminal.draw(|f| ui::draw(f, app)) {
            tracing::warn!(error = %e, "cannot draw the screen");
        }
        animating.store(app.animating(), Ordering::Relaxed);
        let Some(first) = queue.recv().await else {
            break;
        };
        // Take in everything already waiting before drawing again; ticks that piled up
        // move the animations on once.
        let mut animated = false;
        let mut next = Some(first);
        while let Some(event) = next {
            if !dispatch(app, event, &mut outlets, &mut animated) {
                break 'draw;
            }
            next = queue.try_recv().ok();
        }
    }
    forwarder.abort();
    ticker.abort();
}

/// Hand one event to the app and pass on what it asks; false when the loop should end
/// (asking the engine to stop when the person quit).
fn dispatch(app: &mut App, event: QueueEvent, out: &mut Outlets, animated: &mut bool) -> bool {
    match event {
        QueueEvent::Input(TermEvent::Key(key)) => app.on_key(key),
        QueueEvent::Input(TermEvent::Mouse(mouse)) => app.on_mouse(mouse),
        // A resize is drawn at the next draw.
        QueueEvent::Input(_) => {}
        QueueEvent::InputEnded | QueueEvent::SessionEnded => return false,
        QueueEvent::Session(e) => {
            crate::record::trace(&e);
            if let Some(t) = out.tap.as_mut() {
                t.event(&e);
            }
            app.on_session(e);
        }
        QueueEvent::Dictation(e) => app.on_dictation(e),
        QueueEvent::Model(m) => app.on_model(m),
        QueueEvent::Tick => {
            // The ticker may not know yet that the animation stopped.
            if !*animated && app.animating() {
                app.on_animation();
                *animated = true;
            }
        }
    }
    for request in app.take_requests() {
        match request {
            Request::Session(command) => {
                if let Some(t) = out.tap.as_mut() {
                    t.command(&command);
                }
                out.engine.send(command);
            }
            Request::Dictation(request) => out.dictation.handle(request),
            // Asked only in a replay, which has no event loop of this kind.
            Request::Replay(_) => {}
        }
    }
    if app.should_quit() {
        out.engine.send(Command::Shutdown);
        return false;
    }
    true
}

#[cfg(test)]
#[path = "event_loop_tests.rs"]
mod tests;
