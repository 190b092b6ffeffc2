//! The workbench: a ratatui + crossterm front end over a session [`Engine`].
//!
//! Laid out like gitui: one app state (`app`), pure drawing of that state (`ui` and the
//! components' `draw`), components that handle keys and queue app events, key bindings
//! that also generate the help overlay (`keys`), colours (`theme`) and every user-facing
//! text (`strings`). The session knows nothing of this module. Push-to-talk runs beside the
//! session: `dictation` owns the microphone and the speech-to-text model. Everything the
//! app reacts to (keys, session events, dictation events, animation ticks) arrives on the
//! event loop's one queue (`event_loop`). A recording is replayed read-only on the same
//! app and drawing, with no engine (`replay`).
//!
//! The terminal is restored on every exit path: a guard's `Drop` on normal returns and
//! errors, and a panic hook (installed before raw mode is entered) on panics.

pub mod app;
pub mod components;
pub mod dictation;
pub mod event_loop;
pub mod keys;
pub mod monitor;
pub mod replay;
pub mod stderr;
pub mod strings;
pub mod theme;
pub mod ui;

pub use event_loop::Tap;

use std::io::{Stdout, stdout};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crossterm::cursor::{Hide, Show};
use crossterm::event::{DisableMouseCapture, EnableMouseCapture};
use crossterm::execute;
use crossterm::terminal::{
    EnterAlternateScreen, LeaveAlternateScreen, disable_raw_mode, enable_raw_mode,
};
use ratatui::Terminal;
use ratatui::backend::CrosstermBackend;

use crate::session::{Engine, EngineHandle, Event, SessionError, Setup};
use tokio::sync::mpsc::UnboundedReceiver;

use dictation::{DictationService, Microphone, SttLoader};

pub use app::{App, Info, ModelArrival, Pane, Request, Summary};
pub use keys::{KeyBindings, KeyMode};
pub use theme::Theme;

#[derive(Debug, thiserror::Error)]
pub enum TuiError {
    #[error("terminal: {0}")]
    Terminal(#[from] std::io::Error),
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error("starting the session engine's threads: {0}")]
    EngineThreads(std::io::Error),
}

/// The session engine on threads of its own, apart from the screen's: a step that
/// computes for seconds (planning, moving the arms, screening fixes) never holds up the
/// screen, and closing the workbench does not wait for it to end. What the engine writes
/// is written whole or not at all, so leaving a step unfinished loses nothing written.
struct EngineThreads {
    handle: tokio::runtime::Handle,
    /// Taken when dropped, to shut the threads down.
    runtime: Option<tokio::runtime::Runtime>,
}

impl EngineThreads {
    fn start() -> Result<EngineThreads, TuiError> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .thread_name("betr-engine")
            .enable_all()
            .build()
            .map_err(TuiError::EngineThreads)?;
        Ok(EngineThreads {
            handle: runtime.handle().clone(),
            runtime: Some(runtime),
        })
    }

    /// Start the session on these threads.
    fn spawn(&self, setup: Setup) -> Result<(EngineHandle, UnboundedReceiver<Event>), TuiError> {
        Ok(Engine::spawn_on(setup, &self.handle)?)
    }
}

impl Drop for EngineThreads {
    fn drop(&mut self) {
        // Without waiting: a step under way ends with the process.
        if let Some(runtime) = self.runtime.take() {
            runtime.shutdown_background();
        }
    }
}

/// Puts the terminal back as it was (raw mode off, main screen, cursor shown) when
/// dropped; safe to run more than once.
pub struct TerminalGuard;

impl TerminalGuard {
    /// Raw mode, alternate screen, hidden cursor, standard error to `stderr_to` (when
    /// given); and a panic hook that restores them.
    pub fn enter(
        stderr_to: Option<&Path>,
    ) -> std::io::Result<(TerminalGuard, Terminal<CrosstermBackend<Stdout>>)> {
        install_panic_hook();
        let guard = TerminalGuard;
        enable_raw_mode()?;
        discard_typed_ahead();
        execute!(stdout(), EnterAlternateScreen, Hide, EnableMouseCapture)?;
        if let Some(file) = stderr_to
            && let Err(e) = stderr::redirect(file)
        {
            tracing::warn!(error = %e, file = %file.display(), "standard error stays on the screen");
        }
        let terminal = Terminal::new(CrosstermBackend::new(stdout()))?;
        Ok((guard, terminal))
    }
}

impl Drop for TerminalGuard {
    fn drop(&mut self) {
        restore();
    }
}

/// Leave raw mode and the alternate screen and show the cursor; errors are ignored (this
/// runs on the way out, where nothing better can be done).
pub fn restore() {
    stderr::restore();
    let _ = disable_raw_mode();
    let _ = execute!(stdout(), DisableMouseCapture, LeaveAlternateScreen, Show);
}

/// Drop what was typed while betr started: the terminal echoed it already, and read now
/// it would act as keys nobody pressed in the workbench (a `q` typed ahead would quit it;
/// an Enter typed in line mode would arrive as Ctrl-J).
fn discard_typed_ahead() {
    let stdin = std::io::stdin();
    if std::io::IsTerminal::is_terminal(&stdin)
        && let Err(e) = nix::sys::termios::tcflush(&stdin, nix::sys::termios::FlushArg::TCIFLUSH)
    {
        tracing::warn!(error = %e, "cannot discard the keys typed before the workbench opened");
    }
    while matches!(crossterm::event::poll(std::time::Duration::ZERO), Ok(true)) {
        if crossterm::event::read().is_err() {
            break;
        }
    }
}

fn install_panic_hook() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        restore();
        previous(info);
    }));
}

/// Everything the workbench needs besides the session.
pub struct Workbench {
    pub info: Info,
    pub keys: KeyBindings,
    pub theme: Theme,
    /// Push-to-talk: where recordings come from.
    pub microphone: Arc<dyn Microphone>,
    /// Push-to-talk: how the speech-to-text model is loaded, or why dictation cannot work.
    pub stt: Result<SttLoader, dictation::DictationError>,
    /// Where standard error goes while the screen is up (the log file).
    pub stderr_to: Option<PathBuf>,
    /// A tree file to open instead of planning (betr text, a policy, BT.CPP XML).
    pub tree: Option<PathBuf>,
    /// How a model fetched or loaded while the workbench is open comes along (shown in the
    /// status bar); the model itself reaches the session by the setup's model.
    pub model_arrival: Option<tokio::sync::mpsc::UnboundedReceiver<app::ModelArrival>>,
}

/// Open the workbench on `setup` until the person quits; what the session saved and left
/// unsaved.
pub async fn run(
    setup: Setup,
    workbench: Workbench,
    mut tap: Option<&mut dyn Tap>,
) -> Result<app::Summary, TuiError> {
    let Workbench {
        info,
        keys,
        theme,
        microphone,
        stt,
        stderr_to,
        tree,
        model_arrival,
    } = workbench;
    let scenario = setup.scenario.clone();
    let engine_threads = EngineThreads::start()?;
    let (engine, events) = engine_threads.spawn(setup)?;
    if let Some(path) = tree {
        engine.send(crate::session::Command::LoadPolicy(Some(path)));
    }
    let mut app = App::new(scenario, info, keys, theme);
    app.status.viewer = tap.as_ref().and_then(|t| t.notice());
    if let Some(page) = tap.as_ref().and_then(|t| t.viewer_page()) {
        app.llm.log(strings::VIEWER_PAGE);
        app.llm.log(page.clone());
        app.viewer_page = Some(page);
    }
    let (_guard, mut terminal) = TerminalGuard::enter(stderr_to.as_deref())?;
    let queue = event_loop::Queue::new();
    let mut dictation = DictationService::reporting_to(microphone, stt, queue.dictation_sink());
    let stop = Arc::new(AtomicBool::new(false));
    event_loop::spawn_input_reader(queue.sender(), stop.clone());
    let arrivals = model_arrival.map(|a| event_loop::forward_model(a, queue.sender()));
    event_loop::run(
        &mut terminal,
        &mut app,
        &engine,
        events,
        queue,
        &mut dictation,
        &mut tap,
    )
    .await;
    stop.store(true, Ordering::Relaxed);
    if let Some(a) = arrivals {
        a.abort();
    }
    // A recording still open is discarded with the service, before the screen goes.
    drop(dictation);
    drop(engine_threads);
    Ok(app.summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Closing the workbench while the engine computes a step returns at once, from
    /// inside the screen's runtime as `run` closes it; the step is left, not waited for.
    #[test]
    fn closing_does_not_wait_for_a_step_under_way() {
        let threads = EngineThreads::start().expect("the engine's threads");
        let (started_tx, started_rx) = std::sync::mpsc::channel();
        let finished = Arc::new(AtomicBool::new(false));
        let done = finished.clone();
        threads.handle.spawn(async move {
            let _ = started_tx.send(());
            // A step that computes without yielding, as planning or an arm's motion does.
            std::thread::sleep(Duration::from_secs(20));
            done.store(true, Ordering::SeqCst);
        });
        started_rx.recv().expect("the step started");
        let screen = tokio::runtime::Builder::new_current_thread()
            .build()
            .expect("a runtime");
        screen.block_on(async { drop(threads) });
        assert!(!finished.load(Ordering::SeqCst), "the step was waited for");
    }
}
