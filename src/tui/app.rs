//! The one state of the workbench. Keys become commands for the session (queued, sent
//! by the event loop); session events update the components. Drawing reads this state
//! (`ui::draw`); nothing here talks to a terminal. What session events do is in
//! `session`. In a replay (`KeyMode::Replay`) the same state is built from a recording's
//! events, and keys become moves in the recording instead of commands.

mod panes;
mod services;
mod session;

pub use panes::{Pane, PaneAreas};
pub use services::ModelArrival;

use std::sync::Arc;

use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

use crate::scenario::Scenario;
use crate::session::{Command, PhaseKind, parse_edit};

use super::components::dictation::DictationPanel;
use super::components::input::{InputLine, Mode, Submitted};
use super::components::llm_pane::LlmPane;
use super::components::status_bar::{Message, StatusBar};
use super::components::tree_pane::TreePane;
use super::components::world_pane::WorldPane;
use super::dictation::DictationRequest;
use super::keys::{Action, KeyBindings, KeyMode};
use super::replay::Move;
use super::strings;
use super::theme::Theme;

/// What the status bar says about the session, fixed at start.
#[derive(Debug, Clone, Default)]
pub struct Info {
    /// The scenario's file stem or name.
    pub scenario: String,
    pub backend: crate::llm::config::Backend,
    pub model: String,
    pub auto_approve: bool,
    /// The scenario's objects, for the world pane.
    pub objects: Vec<String>,
    /// Why there is no model, if there is none.
    pub no_model: Option<String>,
    /// Why the key bindings file was not used, if it was not.
    pub keys_error: Option<String>,
}

/// What a component asks of the app (the event queue between them).
#[derive(Debug, Clone, PartialEq)]
pub enum AppEvent {
    Command(Command),
    Dictation(DictationRequest),
    Replay(Move),
    Quit,
}

/// A request the event loop passes on: to the session engine or to push-to-talk; in a
/// replay, a move in the recording.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    Session(Command),
    Dictation(DictationRequest),
    Replay(Move),
}

/// Rows of the key list a page key scrolls by.
const HELP_PAGE: usize = 10;

#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    /// The keys, shown from this row of their list on (the list scrolls where the screen
    /// is too small for it).
    Help(usize),
    /// Lines in a box, under a title that says what they are.
    Report {
        title: &'static str,
        lines: Vec<String>,
    },
    /// The readings of an instruction, waiting for the person to choose one.
    Readings(Vec<crate::session::Reading>, Option<String>),
    /// Quitting would lose what these lines say: the quit key again quits, any other
    /// key stays.
    ConfirmQuit(Vec<String>),
    /// Planning again with fixes refused: keep them or forget them (these lines ask).
    PlanAgain(Vec<String>),
}

/// A failure nothing more is asked about (`Event::PersonDecides`).
#[derive(Debug, Clone, PartialEq)]
struct Stuck {
    action: String,
    why: String,
    rounds_left: bool,
    undoable: bool,
}

/// What a session of the workbench left behind, for the lines printed after it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Policies saved, in order.
    pub policies: Vec<std::path::PathBuf>,
    /// Files the tree was exported to.
    pub exported: Vec<std::path::PathBuf>,
    /// Approved fixes in the tree that no saved policy holds.
    pub unsaved_fixes: usize,
}

pub struct App {
    /// The session's scenario: what a person types is read over its vocabulary.
    scenario: Arc<Scenario>,
    pub keys: KeyBindings,
    pub theme: Theme,
    pub tree: TreePane,
    pub llm: LlmPane,
    pub world: WorldPane,
    pub input: InputLine,
    pub status: StatusBar,
    pub dictation: DictationPanel,
    pub overlay: Option<Overlay>,
    /// The live workbench, or a replay (whose keys move in the recording).
    pub mode: KeyMode,
    /// The pane navigation keys go to.
    pub focus: Pane,
    /// Where the panes were drawn last (for the mouse).
    areas: PaneAreas,
    /// What components asked, in order, until the event loop takes it.
    queue: Vec<AppEvent>,
    /// Fixes refused for the goal's failures, as the engine last told.
    pub refused_fixes: usize,
    /// The failure nothing more is asked about, while it waits for the person.
    stuck: Option<Stuck>,
    /// What was saved, exported, and is not saved yet.
    pub summary: Summary,
    /// The web page of the 3D view, when betr started a web viewer: in the log and in `?`.
    pub viewer_page: Option<String>,
    quit: bool,
}

impl App {
    pub fn new(scenario: Arc<Scenario>, info: Info, keys: KeyBindings, theme: Theme) -> App {
        let mut llm = LlmPane::default();
        if let Some(why) = &info.no_model {
            llm.error = Some(strings::no_model(why));
        }
        if let Some(e) = &info.keys_error {
            llm.log(strings::keys_file_error(e));
        }
        App {
            scenario,
            keys,
            theme,
            tree: TreePane::default(),
            llm,
            world: WorldPane::of(info.objects.clone()),
            input: InputLine::default(),
            status: StatusBar {
                scenario: info.scenario,
                backend: info.backend.name().to_string(),
                model: info.model,
                auto_approve: info.auto_approve,
                ..StatusBar::default()
            },
            dictation: DictationPanel::default(),
            overlay: None,
            mode: KeyMode::Workbench,
            focus: Pane::default(),
            areas: PaneAreas::default(),
            queue: Vec::new(),
            refused_fixes: 0,
            viewer_page: None,
            stuck: None,
            summary: Summary::default(),
            quit: false,
        }
    }

    /// The app of a replay: nothing it does reaches an engine; the input line lists the
    /// replay's keys.
    pub fn replaying(scenario: Arc<Scenario>, info: Info, keys: KeyBindings, theme: Theme) -> App {
        let mut app = App::new(scenario, info, keys, theme);
        app.mode = KeyMode::Replay;
        app.world.unmarked = true;
        let key = |a: Action| app.keys.key(a).map(|k| k.to_string()).unwrap_or_default();
        let pair = |a: Action, b: Action| format!("{} {}", key(a), key(b));
        let hint = strings::replay_hint(&[
            ("step", pair(Action::EventForward, Action::EventBack)),
            ("tick", pair(Action::TickForward, Action::TickBack)),
            (
                "failure",
                pair(Action::NextFailure, Action::PreviousFailure),
            ),
            (
                "model call",
                pair(Action::NextModelCall, Action::PreviousModelCall),
            ),
            ("start/end", pair(Action::Start, Action::End)),
            ("help", key(Action::Help)),
            ("quit", key(Action::Quit)),
        ]);
        app.input.set_idle(strings::REPLAY_INPUT_TITLE, hint);
        app.tree.empty_text = Some(strings::REPLAY_TREE_EMPTY);
        app
    }

    /// A command of the replayed session, in the log as the person gave it.
    pub fn on_replayed_command(&mut self, text: &str) {
        self.llm.log(strings::replayed_command(text));
    }

    /// Keep what the person did to the view of `previous` (the tree's folds, selection
    /// and scroll, the log's scroll) in this app of the same replay at another position.
    pub fn adopt_view(&mut self, previous: &mut App) {
        self.tree.adopt_view(&mut previous.tree);
        self.llm.adopt_scroll(&previous.llm);
    }

    pub fn should_quit(&self) -> bool {
        self.quit
    }

    /// What the app asks of the session and of the push-to-talk service, in the order
    /// it was asked (a quit request sets `should_quit` instead).
    pub fn take_requests(&mut self) -> Vec<Request> {
        let mut out = Vec::new();
        for e in std::mem::take(&mut self.queue) {
            match e {
                AppEvent::Command(c) => out.push(Request::Session(c)),
                AppEvent::Dictation(r) => out.push(Request::Dictation(r)),
                AppEvent::Replay(m) => out.push(Request::Replay(m)),
                AppEvent::Quit => self.quit = true,
            }
        }
        out
    }

    /// Whether something animates (a model call under way, a recording's clock).
    pub fn animating(&self) -> bool {
        self.llm.asking.is_some() || self.dictation.is_shown()
    }

    pub fn on_animation(&mut self) {
        self.llm.animate();
        self.dictation.animate();
    }

    pub fn on_key(&mut self, key: KeyEvent) {
        if key.kind == KeyEventKind::Release {
            return;
        }
        if key.code == KeyCode::Char('c') && key.modifiers.contains(KeyModifiers::CONTROL) {
            self.queue.push(AppEvent::Quit);
            return;
        }
        if self.input.is_open() {
            if key.code == KeyCode::Enter || key.code == KeyCode::Esc {
                self.status.message = None;
            }
            if let Some(submitted) = self.input.event(&key) {
                self.on_submitted(submitted);
            }
            return;
        }
        self.status.message = None;
        if self.dictation.is_recording() && key.code == KeyCode::Esc {
            self.queue
                .push(AppEvent::Dictation(DictationRequest::Cancel));
            self.dictation.idle();
            return;
        }
        if self.overlay.is_some() {
            return self.on_overlay_key(&key);
        }
        match self.keys.action_in(self.mode, &key) {
            Some(action) => self.on_action(action),
            None => self.on_navigation(&key),
        }
    }

    /// What the input line gave when Enter was pressed: an instruction or a fix is read
    /// over the scene's vocabulary first, and stays in the line with why when it cannot be.
    fn on_submitted(&mut self, submitted: Submitted) {
        match submitted {
            Submitted::Instruction(text) => {
                self.llm.error = None;
                // A goal formula the scene cannot hold stays in the line with why under
                // it, as an edit does; the engine would refuse it the same way.
                match crate::session::interpret::submitted::read(&self.scenario, &text) {
                    Err(e) => {
                        self.show_error(e.to_string());
                        self.input
                            .reopen_with_error(Mode::Instruction, &text, e.reason());
                    }
                    Ok(_) => self.queue.push(AppEvent::Command(Command::Submit(text))),
                }
            }
            Submitted::Edit(text) => {
                self.llm.error = None;
                match parse_edit(&self.scenario, &text) {
                    Ok(edit) => self.queue.push(AppEvent::Command(Command::Edit(edit))),
                    // Shown as the engine's errors are, and the line stays as typed
                    // with the error under it; nothing reaches the session.
                    Err(e) => {
                        self.show_error(e.to_string());
                        self.input
                            .reopen_with_error(Mode::Edit, &text, e.to_string());
                    }
                }
            }
            Submitted::Filter(text) => self.world.set_filter(Some(text)),
            Submitted::Search(text) => {
                self.tree.query = (!text.is_empty()).then(|| text.clone());
                self.search(true);
            }
        }
    }

    /// A key while an overlay is shown: its own keys (a reading's number, the quit and
    /// save keys of the quit question, keep or forget before planning again, scrolling the
    /// help); any other key closes it.
    fn on_overlay_key(&mut self, key: &KeyEvent) {
        match &self.overlay {
            Some(Overlay::Readings(readings, _)) => {
                let count = readings.len();
                self.on_reading_key(key, count);
            }
            Some(Overlay::ConfirmQuit(_)) => {
                self.overlay = None;
                // The question names the save key for the unsaved fixes: it saves them, and
                // the person quits after (any other key stays).
                match self.keys.action_in(self.mode, key) {
                    Some(Action::Quit) => self.queue.push(AppEvent::Quit),
                    Some(Action::Save) => self.on_action(Action::Save),
                    _ => {}
                }
            }
            Some(Overlay::PlanAgain(_)) => {
                self.overlay = None;
                let command = match key.code {
                    KeyCode::Char(strings::KEEP_REFUSED_KEY) => Some(Command::PlanKeepingRefused),
                    KeyCode::Char(strings::FORGET_REFUSED_KEY) => Some(Command::Plan),
                    _ => None,
                };
                if let Some(command) = command {
                    self.queue.push(AppEvent::Command(command));
                }
            }
            Some(Overlay::Help(first)) => {
                let first = *first;
                let last = self.keys.help_lines(self.mode).len().saturating_sub(1);
                self.overlay = match key.code {
                    KeyCode::Down | KeyCode::Char('j') => {
                        Some(Overlay::Help((first + 1).min(last)))
                    }
                    KeyCode::Up | KeyCode::Char('k') => {
                        Some(Overlay::Help(first.saturating_sub(1)))
                    }
                    KeyCode::PageDown => Some(Overlay::Help((first + HELP_PAGE).min(last))),
                    KeyCode::PageUp => Some(Overlay::Help(first.saturating_sub(HELP_PAGE))),
                    _ => None,
                };
            }
            Some(Overlay::Report { .. }) | None => self.overlay = None,
        }
    }

    /// A key while readings wait to be chosen: a number chooses one, Esc none; other keys
    /// leave the choice open.
    fn on_reading_key(&mut self, key: &KeyEvent, count: usize) {
        match key.code {
            KeyCode::Char(c) => {
                let Some(n) = c.to_digit(10).map(|n| n as usize) else {
                    return;
                };
                if (1..=count).contains(&n) {
                    self.overlay = None;
                    self.queue
                        .push(AppEvent::Command(Command::ChooseReading(n - 1)));
                }
            }
            KeyCode::Esc => {
                self.overlay = None;
                self.message(strings::NO_READING_CHOSEN.to_string(), false);
            }
            _ => {}
        }
    }

    fn on_action(&mut self, action: Action) {
        match self.command_of(action) {
            Some(command) => self.queue.push(AppEvent::Command(command)),
            None => self.on_screen_action(action),
        }
    }

    /// The engine command a key's action asks for; none for the actions on the screen
    /// itself (and for a node's marks when no node is selected).
    fn command_of(&mut self, action: Action) -> Option<Command> {
        Some(match action {
            Action::Step => Command::Tick,
            Action::Run if self.status.phase == PhaseKind::Running => Command::Pause,
            Action::Run => Command::Run,
            // With fixes refused, the person says whether planning again keeps them.
            Action::Plan if self.refused_fixes > 0 => return None,
            Action::Plan => Command::Plan,
            Action::Approve => Command::Approve,
            Action::Reject => Command::Reject,
            Action::Cancel => Command::Cancel,
            Action::Undo => {
                self.llm.offer = None;
                Command::Undo
            }
            Action::Verify => Command::Verify,
            Action::Save => Command::SavePolicy,
            Action::Load => Command::LoadPolicy(None),
            Action::Export => Command::Export,
            Action::KeepRule => Command::KeepRule { only: false },
            Action::KeepRuleOnly => Command::KeepRule { only: true },
            Action::DeclineRule => {
                self.llm.offer = None;
                Command::DeclineRule
            }
            Action::Knowledge => Command::ShowKnowledge,
            Action::Reset => Command::ResetWorld,
            Action::Breakpoint | Action::Force => {
                let node = self.tree.selected()?;
                if action == Action::Breakpoint {
                    Command::ToggleBreakpoint(node)
                } else {
                    Command::CycleForce(node)
                }
            }
            Action::BreakOnFailure => Command::BreakOnFailure(!self.status.break_on_failure),
            _ => return None,
        })
    }

    /// A key's action on the screen: the input line, overlays, panes, moves in a replay.
    fn on_screen_action(&mut self, action: Action) {
        match action {
            Action::Breakpoint | Action::Force => {
                self.message(strings::SELECT_A_NODE.to_string(), true);
            }
            // The recording panel holds the input line's place until the recording ends.
            Action::Instruction | Action::Edit if self.dictation.is_recording() => {
                self.message(strings::STOP_RECORDING_FIRST.to_string(), true);
            }
            Action::Instruction => {
                self.set_vocabulary();
                self.input.open(Mode::Instruction, "");
            }
            Action::Dictate => self.on_dictate_key(),
            Action::Edit => self.open_edit(),
            Action::Help => {
                self.overlay = Some(Overlay::Help(0));
            }
            Action::Details => self.show_details(),
            Action::Follow => {
                self.tree.follow = !self.tree.follow;
                if self.tree.follow {
                    self.tree.show_running(false);
                }
                self.message(strings::follow(self.tree.follow).to_string(), false);
            }
            Action::Search => self.input.open(Mode::Search, ""),
            Action::SearchNext => self.search(true),
            Action::SearchPrevious => self.search(false),
            Action::CollapseAll => self.tree.collapse_all(),
            Action::ExpandAll => self.tree.expand_all(),
            Action::ScrollLeft => self.tree.scroll_left(),
            Action::ScrollRight => self.tree.scroll_right(),
            Action::FocusNext => {
                self.focus = self.focus.next();
            }
            Action::WorldUp => self.world.scroll_up(),
            Action::WorldDown => self.world.scroll_down(),
            Action::WorldFilter => {
                let now = self.world.filter.clone().unwrap_or_default();
                self.input.open(Mode::Filter, &now);
            }
            Action::ExpandToRunning => {
                if !self.tree.show_running(true) {
                    self.message(strings::NOTHING_RUNNING.to_string(), true);
                }
            }
            Action::LogUp => self.llm.scroll_log_up(),
            Action::LogDown => self.llm.scroll_log_down(),
            Action::Plan => {
                self.overlay = Some(Overlay::PlanAgain(strings::plan_again(self.refused_fixes)));
            }
            Action::Quit => {
                let lost = self.would_be_lost();
                if lost.is_empty() {
                    self.queue.push(AppEvent::Quit);
                } else {
                    self.overlay = Some(Overlay::ConfirmQuit(lost));
                }
            }
            // Bound in a replay only: moves in the recording.
            Action::EventForward
            | Action::EventBack
            | Action::TickForward
            | Action::TickBack
            | Action::NextFailure
            | Action::PreviousFailure
            | Action::NextModelCall
            | Action::PreviousModelCall
            | Action::Start
            | Action::End => {
                if let Some(m) = Move::of(action) {
                    self.queue.push(AppEvent::Replay(m));
                }
            }
            // Sent to the engine by `command_of`.
            Action::Step
            | Action::Run
            | Action::Approve
            | Action::Reject
            | Action::Cancel
            | Action::Undo
            | Action::Verify
            | Action::Save
            | Action::Load
            | Action::Export
            | Action::KeepRule
            | Action::KeepRuleOnly
            | Action::DeclineRule
            | Action::Knowledge
            | Action::Reset
            | Action::BreakOnFailure => {}
        }
    }

    /// The fix line, completing the scenario's words: on the proposal's conditions, else
    /// on the first fix betr's screening found for the failure waiting, else empty.
    fn open_edit(&mut self) {
        let screened = self
            .llm
            .screened
            .as_ref()
            .and_then(|(_, s)| s.fixes.first());
        let text = match (&self.llm.proposal, screened) {
            (Some(p), _) => p.edit_text.clone(),
            (None, Some(fix)) => fix.to_string(),
            (None, None) => String::new(),
        };
        self.set_vocabulary();
        self.input.open(Mode::Edit, &text);
    }

    /// Give the input line the scene's conditions to complete, read from the scenario once.
    fn set_vocabulary(&mut self) {
        if !self.input.has_vocabulary() {
            self.input
                .set_vocabulary(crate::session::vocabulary_words(&self.scenario));
        }
    }

    /// Push-to-talk: the same key starts and stops a recording.
    fn on_dictate_key(&mut self) {
        use super::components::dictation::Dictation;
        let request = match self.dictation.state {
            Dictation::Idle => {
                self.dictation.state = Dictation::Starting;
                DictationRequest::Start
            }
            Dictation::Recording { .. } => {
                self.dictation.transcribing(None);
                DictationRequest::Stop
            }
            // The microphone is still opening: the press that stops comes later.
            Dictation::Starting => return,
            Dictation::Transcribing { .. } => {
                return self.message(strings::DICTATION_BUSY.to_string(), true);
            }
        };
        self.queue.push(AppEvent::Dictation(request));
    }

    /// The next (or previous) match of the tree search, said in the status bar.
    fn search(&mut self, forward: bool) {
        let Some(query) = self.tree.query.clone() else {
            return;
        };
        let text = match self.tree.search(&query, forward, &self.theme) {
            Some(found) => strings::found(&query, found.at, found.of),
            None => strings::not_found(&query),
        };
        self.message(text, false);
    }

    /// What quitting now would lose, one line each (nothing in a replay).
    fn would_be_lost(&self) -> Vec<String> {
        if self.mode == KeyMode::Replay {
            return Vec::new();
        }
        let key = |a: Action| self.keys.key(a).map(|k| k.to_string()).unwrap_or_default();
        let mut lost = Vec::new();
        if self.summary.unsaved_fixes > 0 {
            lost.push(strings::unsaved_fixes(
                self.summary.unsaved_fixes,
                &key(Action::Save),
            ));
        }
        if let Some(p) = &self.llm.proposal {
            lost.push(strings::pending_lost(&p.target));
        }
        if !lost.is_empty() {
            lost.push(String::new());
            lost.push(strings::confirm_quit(&key(Action::Quit)));
        }
        lost
    }

    /// Everything the panes may cut: the pending proposal whole (betr's findings, the
    /// proposal, its author's reasoning), else the selected node's whole label.
    fn show_details(&mut self) {
        let (title, lines) = match (&self.llm.proposal, self.tree.selected_details(&self.theme)) {
            (Some(p), _) => (strings::PROPOSAL_DETAILS_TITLE, p.details()),
            (None, Some(lines)) => (strings::NODE_DETAILS_TITLE, lines),
            (None, None) => return self.message(strings::NOTHING_TO_DETAIL.to_string(), true),
        };
        self.overlay = Some(Overlay::Report { title, lines });
    }

    fn message(&mut self, text: String, error: bool) {
        self.status.message = Some(Message { text, error });
    }

    /// An error of something the person asked for: above the log, and in it.
    fn show_error(&mut self, message: String) {
        self.llm.log(format!("error: {message}"));
        self.llm.error = Some(message);
    }
}
