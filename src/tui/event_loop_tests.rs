//! The event loop on a test terminal with a real engine (scenario 1, no model): keys and
//! session events arrive through the one queue, the tap sees every session event and
//! every command, and the loop ends when the person quits or the session ends.

use std::path::Path;
use std::sync::Arc;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;

use super::*;
use crate::scenario::Scenario;
use crate::session::{Engine, Setup};
use crate::tui::dictation::{DefaultMicrophone, DictationEvent};
use crate::tui::{Info, KeyBindings, Theme};

fn setup() -> Setup {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml");
    let scenario = Arc::new(Scenario::load(&path).unwrap());
    Setup::new(
        scenario,
        path,
        Err(crate::session::NoModel::NotUsed("this test")),
    )
}

fn app(setup: &Setup) -> App {
    App::new(
        setup.scenario.clone(),
        Info::default(),
        KeyBindings::default(),
        Theme::default(),
    )
}

fn press(c: char) -> QueueEvent {
    QueueEvent::Input(TermEvent::Key(KeyEvent::new(
        KeyCode::Char(c),
        KeyModifiers::NONE,
    )))
}

/// Records what it sees; presses `q` once the planned tree arrives.
struct Recorder {
    queue: UnboundedSender<QueueEvent>,
    events: Vec<Event>,
    commands: Vec<Command>,
}

impl Tap for Recorder {
    fn event(&mut self, event: &Event) {
        if matches!(event, Event::TreeChanged { .. }) {
            self.queue.send(press('q')).unwrap();
        }
        self.events.push(event.clone());
    }
    fn command(&mut self, command: &Command) {
        self.commands.push(command.clone());
    }
    fn notice(&self) -> Option<String> {
        None
    }
}

struct Bench {
    terminal: Terminal<TestBackend>,
    app: App,
    dictation: DictationService,
}

impl Bench {
    fn new(app: App, queue: &Queue) -> Bench {
        // Dictation is unavailable, so the microphone is never opened.
        let dictation = DictationService::reporting_to(
            Arc::new(DefaultMicrophone),
            Err(crate::tui::dictation::DictationError::Settings {
                reason: "not in this test".into(),
            }),
            queue.dictation_sink(),
        );
        Bench {
            terminal: Terminal::new(TestBackend::new(100, 30)).unwrap(),
            app,
            dictation,
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn keys_and_session_events_share_the_queue_and_quitting_stops_the_engine() {
    let setup = setup();
    let app = app(&setup);
    let (engine, events) = Engine::spawn(setup).unwrap();
    let queue = Queue::new();
    let mut bench = Bench::new(app, &queue);
    let mut recorder = Recorder {
        queue: queue.sender(),
        events: Vec::new(),
        commands: Vec::new(),
    };
    queue.sender().send(press('p')).unwrap();
    let mut tap: Option<&mut dyn Tap> = Some(&mut recorder);
    let ran = run(
        &mut bench.terminal,
        &mut bench.app,
        &engine,
        events,
        queue,
        &mut bench.dictation,
        &mut tap,
    );
    tokio::time::timeout(Duration::from_secs(120), ran)
        .await
        .expect("the loop did not end on q");
    assert_eq!(recorder.commands, [Command::Plan]);
    assert!(
        matches!(recorder.events.first(), Some(Event::WorldChanged { .. })),
        "{:?}",
        recorder.events
    );
    assert!(
        recorder
            .events
            .iter()
            .any(|e| matches!(e, Event::TreeChanged { .. }))
    );
    assert!(bench.app.should_quit());
    // The engine was told to stop: its command channel closes.
    tokio::time::timeout(Duration::from_secs(5), async {
        while engine.send(Command::Pause) {
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    })
    .await
    .expect("the engine is still running");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_loop_ends_with_the_session_and_takes_in_what_was_waiting() {
    let setup = setup();
    let app = app(&setup);
    let (engine, events) = Engine::spawn(setup).unwrap();
    let queue = Queue::new();
    let mut bench = Bench::new(app, &queue);
    let sender = queue.sender();
    // Queued before the session's events, so taken in before the session ends.
    sender
        .send(QueueEvent::Input(TermEvent::Resize(80, 24)))
        .unwrap();
    sender
        .send(QueueEvent::Dictation(DictationEvent::Failed(
            "no microphone".into(),
        )))
        .unwrap();
    assert!(engine.send(Command::Shutdown));
    let mut no_tap = None;
    let ran = run(
        &mut bench.terminal,
        &mut bench.app,
        &engine,
        events,
        queue,
        &mut bench.dictation,
        &mut no_tap,
    );
    tokio::time::timeout(Duration::from_secs(120), ran)
        .await
        .expect("the loop did not end with the session");
    assert!(!bench.app.should_quit());
    let message = bench.app.status.message.as_ref().map(|m| m.text.clone());
    assert!(
        message.is_some_and(|m| m.contains("no microphone")),
        "{:?}",
        bench.app.status.message
    );
}
