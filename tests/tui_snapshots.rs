//! Whole-screen snapshots of the workbench (ratatui `TestBackend` + insta), reached the
//! way a person reaches them: key events into the app, its commands into a real session
//! engine on scenario 1, the engine's events back into the app. The model is in-process
//! and answers from the hand-written fixtures.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

mod support;

use std::sync::Arc;
use std::time::Duration;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Terminal;
use ratatui::backend::TestBackend;

use betr::domain::Scenario;
use betr::session::{Engine, EngineHandle, Event, Setup};
use betr::tui::{App, Info, KeyBindings, Theme, ui};
use support::fake_model::FixtureModel;
use support::fixtures;
use tokio::sync::mpsc::UnboundedReceiver;

struct Bench {
    engine: EngineHandle,
    events: UnboundedReceiver<Event>,
    app: App,
}

impl Bench {
    fn start() -> Bench {
        let path = fixtures::root().join("scenarios/cell/red_on_blue.toml");
        let scenario = Arc::new(Scenario::load(&path).unwrap());
        let info = Info {
            scenario: "red_on_blue".into(),
            backend: "openai".into(),
            model: "fixture-model".into(),
            auto_approve: false,
            objects: scenario
                .domain
                .vocabulary
                .objects
                .iter()
                .map(|o| o.name.clone())
                .collect(),
            no_model: None,
            keys_error: None,
        };
        let model = FixtureModel::new(fixtures::every_reply());
        let setup = Setup::new(scenario, path, Ok(Arc::new(model)));
        let (engine, events) = Engine::spawn(setup).unwrap();
        Bench {
            engine,
            events,
            app: App::new(info, KeyBindings::default(), Theme::default()),
        }
    }

    fn key(&mut self, code: KeyCode) {
        self.app.on_key(KeyEvent::new(code, KeyModifiers::NONE));
        for c in self.app.take_commands() {
            assert!(self.engine.send(c));
        }
    }

    fn type_text(&mut self, text: &str) {
        for c in text.chars() {
            self.key(KeyCode::Char(c));
        }
    }

    /// Feed events to the app until one matches, then whatever follows within 100 ms.
    async fn until(&mut self, pred: impl Fn(&Event) -> bool) {
        let wait = async {
            loop {
                let e = self.events.recv().await.unwrap();
                let hit = pred(&e);
                self.app.on_session(e);
                if hit {
                    break;
                }
            }
        };
        tokio::time::timeout(Duration::from_secs(20), wait)
            .await
            .expect("timed out");
        while let Ok(Some(e)) =
            tokio::time::timeout(Duration::from_millis(100), self.events.recv()).await
        {
            self.app.on_session(e);
        }
    }

    fn screen(&mut self, width: u16, height: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
        terminal.draw(|f| ui::draw(f, &mut self.app)).unwrap();
        terminal.backend().to_string()
    }

    /// Type the instruction of scenario 1 and step until the grasp fails and the
    /// proposal is shown.
    async fn step_to_failure(&mut self) {
        self.key(KeyCode::Char('i'));
        self.type_text("Put the blue cube on the green cube");
        self.key(KeyCode::Enter);
        self.until(|e| matches!(e, Event::TreeChanged { .. })).await;
        for _ in 0..10 {
            self.key(KeyCode::Char(' '));
            self.until(|e| matches!(e, Event::Ticked { .. })).await;
            if self.app.llm.proposal.is_some() {
                return;
            }
        }
        panic!("no proposal after 10 ticks:\n{}", self.screen(120, 40));
    }
}

fn rt() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap()
}

#[test]
fn planned_tree() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('i'));
        b.type_text("Put the blue cube on the green cube");
        b.key(KeyCode::Enter);
        b.until(|e| matches!(e, Event::TreeChanged { .. })).await;
        insta::assert_snapshot!("planned_tree", b.screen(120, 40));
    });
}

#[test]
fn failure_with_a_pending_proposal_then_approval() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("◀ failed"), "{screen}");
        assert!(
            screen.contains("Proposal for grasp \"blue cube\"!"),
            "{screen}"
        );
        insta::assert_snapshot!("failure_with_pending_proposal", screen);

        b.key(KeyCode::Char('a'));
        b.until(|e| matches!(e, Event::TreeChanged { .. })).await;
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("+[-] ~\"any object\" on \"blue cube\"?"),
            "{screen}"
        );
        insta::assert_snapshot!("after_approval", screen);

        b.key(KeyCode::Char('r'));
        b.until(|e| matches!(e, Event::Success { .. })).await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("SUCCESS"), "{screen}");
        insta::assert_snapshot!("after_run_to_success", screen);
    });
}

#[test]
fn help_overlay_lists_every_binding() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('?'));
        let screen = b.screen(120, 40);
        for (key, what) in KeyBindings::default().help_lines() {
            assert!(screen.contains(&key), "{key} missing:\n{screen}");
            assert!(screen.contains(what), "{what} missing:\n{screen}");
        }
        insta::assert_snapshot!("help_overlay", screen);
        // Any key closes it.
        b.key(KeyCode::Esc);
        assert!(!b.screen(120, 40).contains("Press any key to close"));
    });
}

#[test]
fn small_terminal_stays_usable() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        let screen = b.screen(80, 24);
        assert!(screen.contains("Proposal for"), "{screen}");
        assert!(screen.contains("tick"), "{screen}");
        insta::assert_snapshot!("small_terminal_80x24", screen);
        // Even tinier terminals draw without panicking.
        for (w, h) in [(40, 12), (20, 6), (1, 1)] {
            b.screen(w, h);
        }
    });
}
