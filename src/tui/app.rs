//! The one state of the workbench. Keys become commands for the session (queued, sent
//! by the event loop); session events update the components. Drawing reads this state
//! (`ui::draw`); nothing here talks to a terminal.

use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

use crate::session::{Command, Event};

use super::components::dictation::DictationPanel;
use super::components::help::report_lines;
use super::components::input::{InputLine, Mode, Submitted};
use super::components::llm_pane::{LlmPane, ProposalView};
use super::components::status_bar::{Ending, Message, StatusBar};
use super::components::tree_pane::TreePane;
use super::components::world_pane::WorldPane;
use super::dictation::{DictationEvent, DictationRequest};
use super::keys::{Action, KeyBindings};
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
    Quit,
}

/// A request the event loop passes on: to the session engine or to push-to-talk.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    Session(Command),
    Dictation(DictationRequest),
}

#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    Help,
    Report(Vec<String>),
}

pub struct App {
    pub keys: KeyBindings,
    pub theme: Theme,
    pub tree: TreePane,
    pub llm: LlmPane,
    pub world: WorldPane,
    pub input: InputLine,
    pub status: StatusBar,
    pub dictation: DictationPanel,
    pub overlay: Option<Overlay>,
    queue: Vec<AppEvent>,
    /// Requests for the push-to-talk service, in order.
    quit: bool,
}

impl App {
    pub fn new(info: Info, keys: KeyBindings, theme: Theme) -> App {
        let mut llm = LlmPane::default();
        if let Some(why) = &info.no_model {
            llm.error = Some(strings::no_model(why));
        }
        if let Some(e) = &info.keys_error {
            llm.log(strings::keys_file_error(e));
        }
        App {
            keys,
            theme,
            tree: TreePane::default(),
            llm,
            world: WorldPane {
                objects: info.objects.clone(),
                ..WorldPane::default()
            },
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
            queue: Vec::new(),
            quit: false,
        }
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
            match self.input.event(&key) {
                Some(Submitted::Instruction(text)) => {
                    self.llm.error = None;
                    self.queue.push(AppEvent::Command(Command::Submit(text)));
                }
                Some(Submitted::Edit(text)) => {
                    self.llm.error = None;
                    self.queue.push(AppEvent::Command(Command::Edit(text)));
                }
                None => {}
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
        if self.overlay.take().is_some() {
            return;
        }
        match self.keys.action(&key) {
            Some(action) => self.on_action(action),
            None => {
                self.tree.event(&key);
            }
        }
    }

    fn on_action(&mut self, action: Action) {
        let command = match action {
            Action::Step => Command::Tick,
            Action::Run if self.status.running => Command::Pause,
            Action::Run => Command::Run,
            Action::Plan => Command::Plan,
            Action::Approve => Command::Approve,
            Action::Reject => Command::Reject,
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
            // The recording panel holds the input line's place until the recording ends.
            Action::Instruction | Action::Edit if self.dictation.is_recording() => {
                return self.message(strings::STOP_RECORDING_FIRST.to_string(), true);
            }
            Action::Instruction => {
                return self.input.open(Mode::Instruction, "");
            }
            Action::Dictate => return self.on_dictate_key(),
            Action::Edit => {
                let text = self
                    .llm
                    .proposal
                    .as_ref()
                    .map(|p| p.edit_text.clone())
                    .unwrap_or_default();
                return self.input.open(Mode::Edit, &text);
            }
            Action::Help => {
                self.overlay = Some(Overlay::Help);
                return;
            }
            Action::LogUp => return self.llm.scroll_log_up(),
            Action::LogDown => return self.llm.scroll_log_down(),
            Action::Quit => {
                self.queue.push(AppEvent::Quit);
                return;
            }
        };
        self.queue.push(AppEvent::Command(command));
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

    fn message(&mut self, text: String, error: bool) {
        self.status.message = Some(Message { text, error });
    }

    /// What the push-to-talk service reports.
    pub fn on_dictation(&mut self, event: DictationEvent) {
        match event {
            DictationEvent::Recording { device } => {
                // A cancel that arrived before the microphone opened wins.
                if self.dictation.is_recording() {
                    self.dictation.recording(device);
                }
            }
            DictationEvent::Level(level) => self.dictation.level(level),
            DictationEvent::Preparing(what) => self.dictation.preparing = Some(what),
            DictationEvent::Transcribing { seconds } => {
                self.dictation.preparing = None;
                self.dictation.transcribing(Some(seconds));
            }
            DictationEvent::Heard(transcript) => {
                self.dictation.idle();
                self.llm.log(format!("dictated: {}", transcript.text));
                // Into the input line, for the person to read and correct: never submitted
                // from here.
                if !self.input.is_open() {
                    self.input.open(Mode::Instruction, &transcript.text);
                } else if !self.input.insert_dictation(&transcript.text) {
                    let text = strings::transcript_not_placed(&transcript.text);
                    self.llm.log(text.clone());
                    return self.message(text, true);
                }
                self.message(
                    strings::dictated(
                        transcript.audio_seconds,
                        transcript.elapsed.as_secs_f64(),
                        &transcript.source,
                    ),
                    false,
                );
            }
            DictationEvent::Failed(why) => {
                self.dictation.idle();
                let text = strings::dictation_failed(&why);
                self.llm.log(text.clone());
                self.message(text, true);
            }
            DictationEvent::Cancelled => {
                self.dictation.idle();
                self.message(strings::RECORDING_DISCARDED.to_string(), false);
            }
        }
    }

    pub fn on_session(&mut self, event: Event) {
        match event {
            Event::TreeChanged {
                tree,
                new_nodes,
                learned,
                why,
            } => {
                let added = new_nodes.len();
                self.tree.set_tree(tree, new_nodes, learned);
                self.status.ending = None;
                self.llm.log(if added > 0 {
                    format!("{why}: {added} new node(s)")
                } else {
                    why
                });
            }
            Event::Ticked { record } => {
                self.status.ticks = record.tick;
                self.tree.set_record(record);
            }
            Event::WorldChanged { facts, reset } => {
                let mut facts: Vec<String> = facts.iter().map(ToString::to_string).collect();
                // Relations between objects first: they change; "near robot" rarely does.
                facts.sort_by_key(|f| std::cmp::Reverse(f.matches('"').count()));
                self.world.facts = facts;
                if reset {
                    self.status.ticks = 0;
                    self.status.ending = None;
                    self.world.last_error = None;
                    self.tree.clear_statuses();
                }
            }
            Event::ActionFailed {
                action,
                node,
                error,
                ..
            } => {
                let text = strings::failed(&action.to_string(), &error);
                self.tree.set_failing(node);
                self.world.last_error = Some(text.clone());
                self.world.error_resolved = false;
                self.status.ending = Some(Ending::Failed);
                self.llm.log(text);
            }
            Event::Asking { what } => {
                self.status.awaiting = Some(&strings::AWAITING_MODEL);
                self.llm.error = None;
                self.llm.asking = Some(what);
            }
            Event::Replied { attribution, .. } => {
                self.llm.asking = None;
                self.llm.replied_by = Some(attribution);
            }
            Event::InvalidReply { error } => self.llm.log(format!("unusable reply: {error}")),
            Event::CandidateRejected {
                candidate, reason, ..
            } => {
                self.llm.log(format!("set aside {candidate}: {reason}"));
            }
            Event::Goal {
                goal, reasoning, ..
            } => {
                self.status.awaiting = None;
                self.llm.goal = Some(goal.to_string());
                self.llm.reasoning = reasoning;
            }
            Event::Proposal {
                proposal,
                reasoning,
                ..
            } => {
                self.llm.asking = None;
                self.llm.reasoning = reasoning;
                self.llm.proposal = Some(ProposalView::of(&proposal));
                self.status.awaiting = Some(&strings::AWAITING_APPROVAL);
            }
            Event::Approved => {
                self.status.awaiting = None;
                self.llm.proposal = None;
                self.llm.log("approved");
            }
            Event::Rejected => {
                self.status.awaiting = None;
                self.llm.proposal = None;
                self.llm
                    .log("rejected: the tree is unchanged (e to type conditions)");
            }
            Event::Repaired {
                added_nodes,
                valued_nodes,
            } => self.llm.log(strings::repaired(added_nodes, valued_nodes)),
            Event::DidNotHelp { reason } => {
                self.status.awaiting = None;
                self.llm
                    .log(format!("the change did not help and was undone: {reason}"));
            }
            Event::Success { ticks } => {
                self.status.ending = Some(Ending::Success);
                self.world.error_resolved = true;
                self.llm.log(strings::success(ticks));
            }
            Event::GaveUp { reason } => {
                self.status.awaiting = None;
                self.llm.log(reason);
            }
            Event::Usage { totals } => self.status.usage = totals,
            Event::RunState { running } => self.status.running = running,
            Event::Verified { report, origin } => {
                let holds = report.holds();
                let mut lines = vec![strings::verified_tree(&origin)];
                lines.extend(report_lines(&report, &self.theme));
                self.overlay = Some(Overlay::Report(lines));
                self.llm
                    .log(if holds { "verified" } else { "NOT verified" });
            }
            Event::ChangeViolates { report } => {
                self.status.awaiting = Some(&strings::AWAITING_VIOLATION);
                let mut lines = vec![strings::CHANGE_VIOLATES.to_string()];
                lines.extend(report_lines(&report, &self.theme));
                self.overlay = Some(Overlay::Report(lines));
                self.llm.log(strings::CHANGE_VIOLATES);
            }
            Event::PolicySaved { path, fixes } => {
                self.llm
                    .log(strings::policy_saved(&path.display().to_string(), fixes));
            }
            Event::Exported { paths } => {
                let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
                self.llm.log(strings::exported(&names));
            }
            Event::PolicyLoaded { path, fixes } => {
                self.llm
                    .log(strings::policy_loaded(&path.display().to_string(), fixes));
            }
            Event::Error { message } => {
                self.llm.error = Some(message.clone());
                self.llm.log(format!("error: {message}"));
            }
            Event::Failed { error } => {
                self.status.awaiting = None;
                self.llm.asking = None;
                self.llm.error = Some(error.to_string());
                self.llm.log(format!("error: {error}"));
            }
            Event::Notice { message } => self.llm.log(message),
            Event::RuleOffered { rule, only, .. } => {
                let key = |a: Action| self.keys.key(a).map(|k| k.to_string()).unwrap_or_default();
                let text = strings::rule_offer(
                    &rule,
                    only.as_deref(),
                    (
                        &key(Action::KeepRule),
                        &key(Action::KeepRuleOnly),
                        &key(Action::DeclineRule),
                    ),
                );
                // Shown where a proposal would be, until it is answered: the log keeps the
                // steps of the repair in view.
                self.llm.offer = Some(text);
            }
            Event::RuleKept { id, rule, path } => {
                self.llm.offer = None;
                let text = strings::rule_kept(&id, &rule, &path.display().to_string());
                self.llm.log(text.clone());
                self.message(text, false);
            }
            Event::RuleRefused { rule, reason } => {
                self.llm.offer = None;
                let text = strings::rule_refused(&rule, &reason);
                self.llm.log(text.clone());
                self.message(text, true);
            }
            Event::Knowledge { path, rules } => {
                let mut lines = vec![strings::knowledge_title(
                    &path.display().to_string(),
                    rules.len(),
                )];
                if rules.is_empty() {
                    lines.push(strings::NO_RULES.to_string());
                }
                lines.extend(rules);
                self.overlay = Some(Overlay::Report(lines));
            }
            // For the 3D view; the world pane shows facts.
            Event::Scene { .. } => {}
            // The engine's notices say these in the log; the report shows what was checked.
            Event::Planned { .. } | Event::Verifying { .. } => {}
        }
    }
}
