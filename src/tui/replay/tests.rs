//! Seeking on a real recording: a session of scenario 1 driven through the engine (an
//! instruction, a run to the failure, the model's proposal approved, a run to success)
//! recorded as the workbench records it, read back, and replayed.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use ratatui::Terminal;
use ratatui::backend::TestBackend;

use super::*;
use crate::llm::{ChatFuture, ChatReply, ChatRequest, LanguageModel, ReplySource, TokenUsage};
use crate::record::SessionRecorder;
use crate::session::{Command, Engine, Event, Setup};

/// Answers scenario 1's two questions as the hand-written fixtures do
/// (tests/fixtures/replies/red_on_blue.toml).
struct Scenario1;

impl LanguageModel for Scenario1 {
    fn model(&self) -> &str {
        "fixture-model"
    }

    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        let prompt: String = request
            .messages
            .iter()
            .map(|m| m.content.as_str())
            .collect();
        let text = if prompt.contains("# Task: failure resolution") {
            "Reasoning: Something lies on the blue cube.\nConditions:\n~\"any object\" on \"blue cube\"\n"
        } else {
            "Goal: \"blue cube\" on \"green cube\"\n"
        };
        Box::pin(std::future::ready(Ok(ChatReply {
            ranked: Vec::new(),
            text: text.into(),
            model: "fixture-model".into(),
            usage: TokenUsage {
                prompt_tokens: 100,
                completion_tokens: 20,
            },
            latency: Duration::ZERO,
            source: ReplySource::HandWritten {
                note: "the replay's tests".into(),
            },
        })))
    }
}

fn scenario_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml")
}

/// Record scenario 1 resolved through the engine into `file`.
fn record(file: &Path) {
    let path = scenario_path();
    let scenario = Arc::new(Scenario::load(&path).expect("scenario 1"));
    let mut recorder =
        SessionRecorder::create(file, &path, &scenario.name, None).expect("a recording");
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("a runtime");
    runtime.block_on(async {
        let setup = Setup::new(scenario, path, Ok(Arc::new(Scenario1)));
        let (engine, mut events) = Engine::spawn(setup).expect("an engine");
        let send = |recorder: &mut SessionRecorder, command: Command| {
            recorder.command(&command);
            engine.send(command);
        };
        send(
            &mut recorder,
            Command::Submit("Put the blue cube on the green cube".into()),
        );
        loop {
            let event = tokio::time::timeout(Duration::from_secs(30), events.recv())
                .await
                .expect("the session went on")
                .expect("the engine is there");
            recorder.event(&event);
            match event {
                Event::TreeChanged { .. } => send(&mut recorder, Command::Run),
                Event::Proposal { .. } => send(&mut recorder, Command::Approve),
                Event::Success { .. } => break,
                Event::ChangeViolates { .. } | Event::GaveUp { .. } | Event::Failed { .. } => {
                    panic!("scenario 1 did not resolve: {event:?}")
                }
                _ => {}
            }
        }
        send(&mut recorder, Command::Shutdown);
    });
}

fn player() -> Player {
    // One file per call: tests run as threads of one process under `cargo test`.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let file = std::env::temp_dir().join(format!(
        "betr-replay-seek-{}-{call}.jsonl",
        std::process::id()
    ));
    record(&file);
    let replay = Replay::load(&file, None).expect("the recording reads back");
    let _ = std::fs::remove_file(&file);
    Player::of(replay, KeyBindings::default(), Theme::default())
}

fn screen(app: &mut App) -> String {
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).expect("a test terminal");
    terminal
        .draw(|f| super::super::ui::draw(f, app))
        .expect("drawn");
    terminal.backend().to_string()
}

#[test]
fn seeking_anywhere_shows_what_stepping_there_shows() {
    let player = player();
    let n = player.len();
    let ticks = player
        .steps
        .iter()
        .filter(|(_, s)| matches!(s, Step::Event(Event::Ticked { .. })))
        .count();
    assert!(ticks > 5, "{ticks} ticks in {n} steps");
    // Seeking leaves ticks out: otherwise this test would show nothing.
    assert!(
        player.index.feed(n).len() < n,
        "{} of {n} steps fed",
        player.index.feed(n).len()
    );
    // Forward one step at a time, every step fed; each position against a seek there.
    let mut stepped = player.fresh();
    for p in 0..=n {
        if p > 0 {
            player.apply(&mut stepped, p - 1);
        }
        player.finish(&mut stepped, p);
        let expected = screen(&mut stepped);
        assert_eq!(screen(&mut player.seek(p)), expected, "at step {p} of {n}");
    }
    // Back again: seeking does not depend on where it comes from.
    let mut screen_at = ReplayScreen::open(player, usize::MAX);
    assert_eq!(screen_at.position(), n);
    for p in (0..n).rev() {
        screen_at.go(Move::EventBack);
        assert_eq!(screen_at.position(), p);
    }
}

#[test]
fn keys_move_to_the_failure_the_proposal_and_back_to_the_end() {
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    let key = |c: KeyCode| KeyEvent::new(c, KeyModifiers::NONE);
    let mut s = ReplayScreen::open(player(), usize::MAX);
    let end = screen(&mut s.app);
    assert!(end.contains("SUCCESS"), "{end}");
    assert!(end.contains("REPLAY  step"), "{end}");
    assert!(
        end.contains("> run"),
        "the person's commands are in the log:\n{end}"
    );

    s.key(key(KeyCode::Char('N')));
    let failure = screen(&mut s.app);
    assert!(failure.contains("◀ failed"), "{failure}");
    assert!(failure.contains("FAILED"), "{failure}");
    assert!(failure.contains("No proposal pending"), "{failure}");
    assert!(!failure.contains("repaired:"), "{failure}");
    // The question about the failure, its reply, then on to the proposal.
    s.key(key(KeyCode::Char('m')));
    assert!(screen(&mut s.app).contains("asking the model for"));
    s.key(key(KeyCode::Char('m')));
    for _ in 0..20 {
        if s.app.llm.proposal.is_some() {
            break;
        }
        s.key(key(KeyCode::Right));
    }
    let proposal = screen(&mut s.app);
    assert!(
        proposal.contains("Proposal for grasp \"blue cube\"!"),
        "{proposal}"
    );
    assert!(
        proposal.contains(strings::REPLAY_PROPOSAL_HINT),
        "{proposal}"
    );
    // Editing and approving do nothing in a replay.
    let at = s.position();
    for c in ['a', 'x', 'e', 'r', ' ', 'u', 'i'] {
        s.key(key(KeyCode::Char(c)));
        assert!(s.app.take_requests().is_empty());
    }
    assert_eq!(s.position(), at);
    assert!(!s.app.input.is_open());
    // Ticks: forward to the first tick after the approval, back to the failure's.
    s.key(key(KeyCode::Char('.')));
    assert!(s.position() > at);
    s.key(key(KeyCode::Char(',')));
    assert!(s.position() < at);
    s.key(key(KeyCode::Char('g')));
    assert_eq!(s.position(), 0);
    assert!(screen(&mut s.app).contains(strings::REPLAY_AT_START));
    s.key(key(KeyCode::Left));
    assert!(screen(&mut s.app).contains("no earlier step"));
    s.key(key(KeyCode::Char('G')));
    assert_eq!(screen(&mut s.app), end);
    // Small terminals draw without panicking.
    for (w, h) in [(80, 24), (40, 12), (20, 6), (1, 1)] {
        let mut terminal = Terminal::new(TestBackend::new(w, h)).expect("a test terminal");
        terminal
            .draw(|f| super::super::ui::draw(f, &mut s.app))
            .expect("drawn");
    }
    s.key(key(KeyCode::Char('q')));
    assert!(s.should_quit());
}
