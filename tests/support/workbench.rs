//! The workbench on a real session engine for whole-screen tests: key events into the
//! app, its commands into the engine on scenario 1, the engine's events back into the app,
//! a dictation service with a microphone and words the test chooses.

use std::sync::Arc;
use std::time::Duration;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Terminal;
use ratatui::backend::TestBackend;

use betr::scenario::Scenario;
use betr::session::{Command, Engine, EngineHandle, Event, Setup};
use betr::tui::dictation::{DictationEvent, DictationService, Microphone, SttLoader};
use betr::tui::{App, Info, KeyBindings, Request, Theme, ui};
use betr::voice::{Audio16k, SpeechToText, SttFuture, Transcript};
use tokio::sync::mpsc::UnboundedReceiver;

use super::fake_model::FixtureModel;
use super::fixtures::{self, FixtureReply};
use super::microphone::AudioMicrophone;

pub struct Bench {
    pub engine: EngineHandle,
    pub events: UnboundedReceiver<Event>,
    pub app: App,
    pub dictation: DictationService,
    pub heard: UnboundedReceiver<DictationEvent>,
    /// Commands the app sent, in order.
    pub sent: Vec<Command>,
}

/// Hears the same words in any audio, after 300 ms.
pub struct FixedWords(&'static str);

impl SpeechToText for FixedWords {
    fn describe(&self) -> String {
        "fixed words (test)".into()
    }
    fn transcribe<'a>(&'a self, audio: &'a Audio16k) -> SttFuture<'a> {
        Box::pin(async move {
            Ok(Transcript {
                text: self.0.into(),
                audio_seconds: audio.seconds(),
                elapsed: Duration::from_millis(300),
                source: self.describe(),
            })
        })
    }
}

pub fn fixed_words(words: &'static str) -> SttLoader {
    Arc::new(
        move |_: &mut dyn FnMut(&str)| Ok(Arc::new(FixedWords(words)) as Arc<dyn SpeechToText>),
    )
}

impl Bench {
    pub fn start() -> Bench {
        Bench::with_microphone(AudioMicrophone::missing(), fixed_words("unused"))
    }

    pub fn with_microphone(microphone: Arc<dyn Microphone>, loader: SttLoader) -> Bench {
        Bench::with_knowledge(microphone, loader, None)
    }

    /// A bench whose engine offers approved fixes as rules, kept in `knowledge`.
    pub fn with_knowledge(
        microphone: Arc<dyn Microphone>,
        loader: SttLoader,
        knowledge: Option<betr::session::Knowledge>,
    ) -> Bench {
        Bench::build(
            microphone,
            loader,
            knowledge,
            FixtureModel::new(fixtures::every_reply()),
        )
    }

    /// A bench whose model takes `delay` to answer a question about a failure (goals are
    /// read at once).
    pub fn slow_to_propose(delay: Duration) -> Bench {
        let mut model = FixtureModel::new(fixtures::every_reply());
        model.delay = delay;
        Bench::build(
            AudioMicrophone::missing(),
            fixed_words("unused"),
            None,
            model,
        )
    }

    /// A bench whose model answers with `replies` (the first that fits a prompt).
    pub fn answering(replies: Vec<FixtureReply>) -> Bench {
        Bench::build(
            AudioMicrophone::missing(),
            fixed_words("unused"),
            None,
            FixtureModel::new(replies),
        )
    }

    fn build(
        microphone: Arc<dyn Microphone>,
        loader: SttLoader,
        knowledge: Option<betr::session::Knowledge>,
        model: FixtureModel,
    ) -> Bench {
        // Scenario 1 moves the real arms when the YuMi's description is in the cache: have
        // it there, so the screens do not depend on which tests ran before.
        super::verify::fetch_yumi();
        let path = fixtures::root().join("scenarios/cell/red_on_blue.toml");
        let scenario = Arc::new(Scenario::load(&path).unwrap());
        let info = Info {
            scenario: "red_on_blue".into(),
            backend: betr::llm::config::Backend::Openai,
            model: "fixture-model".into(),
            auto_approve: false,
            objects: scenario.domain.vocabulary.object_names(),
            no_model: None,
            keys_error: None,
        };
        let setup = Setup {
            knowledge,
            ..Setup::new(scenario.clone(), path, Ok(Arc::new(model)))
        };
        let (engine, events) = Engine::spawn(setup).unwrap();
        let (dictation, heard) = DictationService::new(microphone, Ok(loader));
        Bench {
            engine,
            events,
            app: App::new(scenario, info, KeyBindings::default(), Theme::default()),
            dictation,
            heard,
            sent: Vec::new(),
        }
    }

    /// A key, as the event loop handles it (must run inside the runtime).
    pub fn key(&mut self, code: KeyCode) {
        self.app.on_key(KeyEvent::new(code, KeyModifiers::NONE));
        for request in self.app.take_requests() {
            match request {
                Request::Session(c) => {
                    self.sent.push(c.clone());
                    assert!(self.engine.send(c));
                }
                Request::Dictation(r) => self.dictation.handle(r),
                Request::Replay(m) => panic!("a move in the live workbench: {m:?}"),
            }
        }
    }

    /// Feed dictation events to the app until one matches.
    pub async fn until_heard(&mut self, pred: impl Fn(&DictationEvent) -> bool) {
        feed_until(&mut self.heard, &mut self.app, App::on_dictation, pred).await;
    }

    pub fn type_text(&mut self, text: &str) {
        for c in text.chars() {
            self.key(KeyCode::Char(c));
        }
    }

    /// Feed events to the app until one matches, then whatever follows within 100 ms.
    pub async fn until(&mut self, pred: impl Fn(&Event) -> bool) {
        feed_until(&mut self.events, &mut self.app, on_session_steady, pred).await;
        while let Ok(Some(e)) =
            tokio::time::timeout(Duration::from_millis(100), self.events.recv()).await
        {
            on_session_steady(&mut self.app, e);
        }
    }

    pub fn screen(&mut self, width: u16, height: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
        terminal.draw(|f| ui::draw(f, &mut self.app)).unwrap();
        terminal.backend().to_string()
    }

    /// Type the instruction of scenario 1 and wait for its tree.
    async fn plan_scenario_instruction(&mut self) {
        self.key(KeyCode::Char('i'));
        self.type_text("Put the blue cube on the green cube");
        self.key(KeyCode::Enter);
        self.until(|e| matches!(e, Event::TreeChanged { .. })).await;
    }

    /// Type the instruction of scenario 1 and step until the grasp fails and the
    /// proposal is shown.
    pub async fn step_to_failure(&mut self) {
        self.plan_scenario_instruction().await;
        for _ in 0..10 {
            self.key(KeyCode::Char(' '));
            self.until(|e| matches!(e, Event::Ticked { .. })).await;
            // Once the grasp has failed, the conditions are tried and the model asked
            // before the proposal arrives: wait for it rather than tick again.
            if self.app.llm.proposal.is_none() && self.screen(120, 40).contains("◀ failed") {
                self.until(|e| matches!(e, Event::Proposal { .. })).await;
            }
            if self.app.llm.proposal.is_some() {
                return;
            }
        }
        panic!("no proposal after 10 ticks:\n{}", self.screen(120, 40));
    }

    /// Type the instruction of scenario 1 and step until the grasp fails and the model is
    /// asked about it (the model must be slow to answer: see [`Bench::slow_to_propose`]).
    pub async fn step_to_question(&mut self) {
        self.plan_scenario_instruction().await;
        for _ in 0..10 {
            self.key(KeyCode::Char(' '));
            self.until(|e| matches!(e, Event::Ticked { .. })).await;
            if self.screen(120, 40).contains("◀ failed") {
                return self.until(|e| matches!(e, Event::Asking { .. })).await;
            }
        }
        panic!("no failure after 10 ticks:\n{}", self.screen(120, 40));
    }
}

/// A session event to the app as the screens show it on every run (see [`steady`]).
fn on_session_steady(app: &mut App, mut event: Event) {
    steady(&mut event);
    app.on_session(event);
}

/// `event` as it is in every run: an arm motion's planning time is measured, so it is
/// fixed at 12.5 ms (the attempts and the path are the seeded planner's own).
pub fn steady(event: &mut Event) {
    if let Event::ArmMotion { motion } = event {
        motion.seconds = 0.0125;
    }
}

/// Hand what arrives on `rx` to the app until one matches; panics after 120 s (a guard
/// against a hang, not a speed check: on a loaded 2-core machine a step with the real arms
/// has taken over 20 s).
pub async fn feed_until<T>(
    rx: &mut UnboundedReceiver<T>,
    app: &mut App,
    apply: fn(&mut App, T),
    pred: impl Fn(&T) -> bool,
) {
    let wait = async {
        loop {
            let e = rx.recv().await.unwrap();
            let hit = pred(&e);
            apply(app, e);
            if hit {
                break;
            }
        }
    };
    tokio::time::timeout(Duration::from_secs(120), wait)
        .await
        .expect("timed out");
}
