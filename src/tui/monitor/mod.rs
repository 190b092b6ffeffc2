//! The monitor screen (`betr monitor`): a BehaviorTree.CPP process's tree, live, as its
//! Groot2 publisher reports it. The tree pane shows every node with its status, following
//! the node the tree is busy in unless the person moves; the side pane the selected
//! node's kind, ports (a `{name}` port is a blackboard entry, shown with its value) and
//! its tree's blackboard, and the latest status changes; the status bar the connection.
//! Live, the person's breakpoints go to the robot through Groot2's hooks; the same screen
//! replays a recorded watch (`replay.rs`) and shows a tree file, sending nothing.

mod replay;
mod view;

pub use replay::{FileView, Looking, WatchPlayer, run as look};
pub use view::draw;

use std::collections::{HashSet, VecDeque};
use std::path::Path;
use std::time::Duration;

use crossterm::event::{Event as TermEvent, KeyCode, KeyEvent, KeyModifiers};
use tokio::sync::mpsc;
use tui_tree_widget::TreeState;

use crate::bt::render::{ASCII, Glyphs, UNICODE};
use crate::monitor::{
    Address, Blackboard, Change, LiveTree, NodeStatus, Transition, WatchCommand, WatchEvent,
    WatchTiming, missed_some, watch,
};

use crate::record::SessionRecorder;

use super::event_loop::{QueueEvent, spawn_input_reader};
use super::theme::Theme;
use super::{TerminalGuard, TuiError};

/// The shortest time between two drawings while changes stream in.
const FRAME: Duration = Duration::from_millis(15);

/// How many status changes the side pane keeps.
const RECENT: usize = 200;

/// Where the connection stands.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Connection {
    /// Never connected yet, or not since the last loss: the last try's reason.
    Waiting(Option<String>),
    Watching,
    /// The connection broke; the tree shown is as it was last seen.
    Lost(String),
}

/// What the screen is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// A publisher watched live: breakpoints can be set and released.
    Live,
    /// A recorded watch, stepped or played.
    Replay,
    /// A tree file: nothing runs it.
    File,
}

/// What the screen shows and where the person is in it.
pub struct MonitorScreen {
    address: Address,
    connection: Connection,
    live: Option<LiveTree>,
    /// When the publisher began keeping changes, since the watch began.
    since: Duration,
    state: TreeState<u16>,
    /// The selection follows the node the tree is busy in.
    follow: bool,
    /// The latest status changes of the tree shown, each with the `since` of its
    /// connection.
    recent: VecDeque<(Duration, Change)>,
    changes: u64,
    /// Reads that came back as full as the publisher keeps: changes before them were lost.
    missed: u64,
    /// The search being typed after `/`.
    typing: Option<String>,
    /// The last search: its matches are marked, `n` goes to the next.
    query: Option<String>,
    /// A search that matched nothing, said until the next one.
    not_found: Option<String>,
    /// The nodes with a breakpoint before their tick.
    breakpoints: HashSet<u16>,
    /// The node stopped at its breakpoint, the tree waiting for the person.
    stopped: Option<u16>,
    /// What the publisher refused, or why the recording stopped: said until the next key.
    said: Option<String>,
    /// The tree's blackboards as last read.
    blackboards: Vec<Blackboard>,
    /// Watching live, replaying, or showing a file.
    mode: Mode,
    /// In a replay: where it stands, said in the status bar instead of the connection.
    playback: Option<String>,
    /// A file shown because betr's engine was asked to run it and does not: why.
    not_run: Option<String>,
    /// Commands for the publisher, taken by the terminal loop.
    outbox: Vec<WatchCommand>,
    quit: bool,
    glyphs: &'static Glyphs,
    theme: Theme,
}

impl MonitorScreen {
    pub fn new(address: Address, ascii: bool) -> MonitorScreen {
        let glyphs = if ascii { &ASCII } else { &UNICODE };
        MonitorScreen {
            address,
            connection: Connection::Waiting(None),
            live: None,
            since: Duration::ZERO,
            state: TreeState::default(),
            follow: true,
            recent: VecDeque::new(),
            changes: 0,
            missed: 0,
            typing: None,
            query: None,
            not_found: None,
            breakpoints: HashSet::new(),
            stopped: None,
            said: None,
            blackboards: Vec::new(),
            mode: Mode::Live,
            playback: None,
            not_run: None,
            outbox: Vec::new(),
            quit: false,
            glyphs,
            theme: Theme::new(glyphs),
        }
    }

    pub fn should_quit(&self) -> bool {
        self.quit
    }

    pub fn connection(&self) -> &Connection {
        &self.connection
    }

    /// What the watch reported.
    pub fn on_watch(&mut self, event: WatchEvent) {
        match event {
            WatchEvent::Connected {
                tree,
                statuses,
                since,
                ..
            } => {
                let live = LiveTree::new(*tree, &statuses);
                // A new tree opens whole; the same tree again keeps the person's folds.
                let new_tree = self.live.as_ref().map(|l| &l.tree) != Some(&live.tree);
                self.live = Some(live);
                if new_tree {
                    self.state = TreeState::default();
                    self.recent.clear();
                    self.blackboards.clear();
                    self.open_all();
                }
                self.since = since;
                self.connection = Connection::Watching;
                self.follow_busy();
            }
            WatchEvent::Changes(transitions) => {
                if missed_some(&transitions) {
                    self.missed += 1;
                }
                for transition in transitions {
                    self.apply(transition);
                }
                self.follow_busy();
            }
            WatchEvent::Restarted => {
                self.connection = Connection::Waiting(None);
                self.stopped = None;
            }
            WatchEvent::Lost(reason) => {
                self.connection = Connection::Lost(reason);
                self.stopped = None;
            }
            WatchEvent::Stopped(uid) => {
                self.stopped = Some(uid);
                self.follow = false;
                self.select_uid(uid);
            }
            WatchEvent::Refused(reason) => self.said = Some(reason),
            WatchEvent::Blackboards(boards) => self.blackboards = boards,
            WatchEvent::Waiting(reason) => {
                if !matches!(self.connection, Connection::Lost(_)) {
                    self.connection = Connection::Waiting(Some(reason));
                }
            }
        }
    }

    /// One status change, kept among the latest.
    fn apply(&mut self, transition: Transition) {
        let Some(change) = self.live.as_mut().and_then(|l| l.apply(transition)) else {
            return;
        };
        self.changes += 1;
        if self.recent.len() == RECENT {
            self.recent.pop_front();
        }
        self.recent.push_back((self.since, change));
    }

    /// Back to before anything was watched, but for the tree, which stays until the next
    /// one is compared with it (so a replay stepping back keeps the person's folds).
    fn rewind(&mut self) {
        self.connection = Connection::Waiting(None);
        self.since = Duration::ZERO;
        self.recent.clear();
        self.changes = 0;
        self.missed = 0;
        self.stopped = None;
        self.blackboards.clear();
    }

    /// Says `text` in the status bar until the next key.
    pub fn say(&mut self, text: String) {
        self.said = Some(text);
    }

    /// Selects the node the tree is busy in, its branch opened, when following.
    fn follow_busy(&mut self) {
        if !self.follow {
            return;
        }
        let Some(busy) = self.live.as_ref().and_then(LiveTree::busy) else {
            return;
        };
        self.select_index(busy);
    }

    /// Selects node `index`, its branch opened.
    fn select_index(&mut self, index: usize) {
        let Some(live) = &self.live else { return };
        let path = live.tree.uid_path(index);
        for depth in 1..path.len() {
            self.state.open(path[..depth].to_vec());
        }
        self.state.select(path);
    }

    /// Selects the node the publisher numbers `uid`.
    fn select_uid(&mut self, uid: u16) {
        if let Some(index) = self.live.as_ref().and_then(|l| l.tree.index_of(uid)) {
            self.select_index(index);
        }
    }

    /// The commands for the publisher since the last call.
    pub fn take_commands(&mut self) -> Vec<WatchCommand> {
        std::mem::take(&mut self.outbox)
    }

    /// Toggles the breakpoint before the selected node; taking away the one the tree is
    /// stopped at lets it go on.
    fn toggle_breakpoint(&mut self) {
        let Some(index) = self.selected() else { return };
        let Some(uid) = self.live.as_ref().map(|l| l.tree.nodes[index].uid) else {
            return;
        };
        if self.breakpoints.remove(&uid) {
            // Released first: the publisher no longer knows a node whose hook is gone.
            if self.stopped == Some(uid) {
                self.release(None);
            }
            self.outbox.push(WatchCommand::Unbreak(uid));
        } else {
            self.breakpoints.insert(uid);
            self.outbox.push(WatchCommand::Break(uid));
        }
    }

    /// Lets the stopped node go on: ticked, or returning `forced`.
    fn release(&mut self, forced: Option<NodeStatus>) {
        if let Some(uid) = self.stopped.take() {
            self.outbox.push(WatchCommand::Release { uid, forced });
        }
    }

    /// A key pressed.
    pub fn on_key(&mut self, key: KeyEvent) {
        if let Some(typed) = self.typing.as_mut() {
            match key.code {
                KeyCode::Enter => {
                    self.query = Some(std::mem::take(typed)).filter(|q| !q.trim().is_empty());
                    self.typing = None;
                    self.find_next();
                }
                KeyCode::Esc => self.typing = None,
                KeyCode::Backspace => {
                    typed.pop();
                }
                KeyCode::Char(c) if !key.modifiers.contains(KeyModifiers::CONTROL) => {
                    typed.push(c);
                }
                _ => {}
            }
            return;
        }
        self.said = None;
        let moved = match key.code {
            KeyCode::Char('q') | KeyCode::Esc => {
                self.quit = true;
                return;
            }
            KeyCode::Char('c') if key.modifiers.contains(KeyModifiers::CONTROL) => {
                self.quit = true;
                return;
            }
            KeyCode::Char('f') => {
                self.follow = !self.follow;
                self.follow_busy();
                return;
            }
            KeyCode::Up | KeyCode::Char('k') => self.state.key_up(),
            KeyCode::Down | KeyCode::Char('j') => self.state.key_down(),
            KeyCode::Left | KeyCode::Char('h') => self.state.key_left(),
            KeyCode::Right | KeyCode::Char('l') => self.state.key_right(),
            KeyCode::Home => self.state.select_first(),
            KeyCode::End => self.state.select_last(),
            KeyCode::Char('E') => {
                self.open_all();
                true
            }
            KeyCode::Char('/') => {
                self.typing = Some(String::new());
                return;
            }
            KeyCode::Char('n') => {
                self.find_next();
                return;
            }
            KeyCode::Char('b') if self.mode == Mode::Live => {
                self.toggle_breakpoint();
                return;
            }
            KeyCode::Char('c') if self.mode == Mode::Live && self.stopped.is_some() => {
                self.release(None);
                return;
            }
            KeyCode::Char('s') if self.mode == Mode::Live && self.stopped.is_some() => {
                self.release(Some(NodeStatus::Success));
                return;
            }
            KeyCode::Char('x') if self.mode == Mode::Live && self.stopped.is_some() => {
                self.release(Some(NodeStatus::Failure));
                return;
            }
            KeyCode::Char('C') => {
                self.state.close_all();
                self.state.select_first()
            }
            _ => false,
        };
        // Moving through the tree by hand stops following the robot.
        if moved {
            self.follow = false;
        }
    }

    /// Opens every branch.
    fn open_all(&mut self) {
        let Some(live) = &self.live else { return };
        for (i, node) in live.tree.nodes.iter().enumerate() {
            if !node.children.is_empty() {
                self.state.open(live.tree.uid_path(i));
            }
        }
    }

    /// Whether node `index` matches the search (its ID, name or a port, any case).
    fn matches(&self, index: usize) -> bool {
        let (Some(live), Some(query)) = (&self.live, &self.query) else {
            return false;
        };
        let query = query.to_lowercase();
        let node = &live.tree.nodes[index];
        [&node.id, &node.name]
            .into_iter()
            .chain(node.ports.iter().map(|(_, v)| v))
            .any(|text| text.to_lowercase().contains(&query))
    }

    /// Selects the next node after the selection that matches the search (from the top
    /// past the last), its branch opened; following stops.
    fn find_next(&mut self) {
        let Some(live) = &self.live else { return };
        let count = live.tree.nodes.len();
        let from = self.selected().map_or(0, |i| i + 1);
        let Some(found) = (0..count)
            .map(|k| (from + k) % count)
            .find(|&i| self.matches(i))
        else {
            self.not_found = self.query.clone();
            return;
        };
        self.not_found = None;
        self.select_index(found);
        self.follow = false;
    }

    /// The selected node's index in the tree.
    fn selected(&self) -> Option<usize> {
        let live = self.live.as_ref()?;
        live.tree.index_of(*self.state.selected().last()?)
    }
}

/// Show the monitor until the person quits or `duration` has passed, recording what is
/// watched into `recorder` when given; standard error goes to `stderr_to` meanwhile.
pub fn run(
    address: Address,
    duration: Option<Duration>,
    ascii: bool,
    stderr_to: Option<&Path>,
    mut recorder: Option<&mut SessionRecorder>,
) -> Result<(), TuiError> {
    // The watch runs on a worker thread of its own, so drawing never delays a read (the
    // publisher drops changes past the 1000 it keeps between two reads).
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    runtime.block_on(async {
        let (_guard, mut terminal) = TerminalGuard::enter(stderr_to)?;
        let (events, mut watched) = mpsc::channel(256);
        let (commands, to_publisher) = mpsc::unbounded_channel();
        let watcher = tokio::spawn(watch(
            address.clone(),
            WatchTiming::default(),
            events,
            to_publisher,
        ));
        let (keys, mut input) = mpsc::unbounded_channel();
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        spawn_input_reader(keys, stop.clone());
        let mut screen = MonitorScreen::new(address, ascii);
        let deadline = duration.map(|d| tokio::time::Instant::now() + d);
        let mut told_stop = false;
        let result = loop {
            if let Err(e) = terminal.draw(|f| view::draw(f, &mut screen)) {
                break Err(TuiError::Terminal(e));
            }
            let last_draw = tokio::time::Instant::now();
            let ended = tokio::select! {
                Some(event) = watched.recv() => {
                    let record = |event: &WatchEvent| {
                        if let Some(recorder) = recorder.as_deref_mut() {
                            recorder.watched(event);
                        }
                    };
                    gather(&mut screen, event, &mut watched, last_draw, record).await;
                    false
                }
                input = input.recv() => match input {
                    Some(QueueEvent::Input(TermEvent::Key(key))) => {
                        screen.on_key(key);
                        false
                    }
                    Some(QueueEvent::InputEnded) | None => true,
                    Some(_) => false,
                },
                _ = sleep_until(deadline) => true,
            };
            for command in screen.take_commands() {
                if let Some(recorder) = recorder.as_deref_mut() {
                    recorder.asked(command);
                }
                // The watch ends only after this loop does.
                let _ = commands.send(command);
            }
            if let Some(stopped) = recorder.as_deref().and_then(SessionRecorder::stopped)
                && screen.said.is_none()
                && !told_stop
            {
                screen.say(stopped.to_string());
                told_stop = true;
            }
            if ended || screen.should_quit() {
                break Ok(());
            }
        };
        // No breakpoint is left to stop the robot with no one watching: the watch sends
        // the clearing before it is stopped.
        if let Some(recorder) = recorder.as_deref_mut() {
            recorder.asked(WatchCommand::ClearAll);
        }
        let _ = commands.send(WatchCommand::ClearAll);
        tokio::time::sleep(Duration::from_millis(200)).await;
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
        watcher.abort();
        result
    })
}

/// Applies `first` and every event that arrives until a frame after `last_draw` (at
/// once when that is past), so a stream of changes is drawn at most once a frame;
/// `observe` sees each event before the screen does.
pub async fn gather(
    screen: &mut MonitorScreen,
    first: WatchEvent,
    watched: &mut mpsc::Receiver<WatchEvent>,
    last_draw: tokio::time::Instant,
    mut observe: impl FnMut(&WatchEvent),
) {
    observe(&first);
    screen.on_watch(first);
    let until = last_draw + FRAME;
    if until > tokio::time::Instant::now() {
        while let Ok(Some(event)) = tokio::time::timeout_at(until, watched.recv()).await {
            observe(&event);
            screen.on_watch(event);
        }
    } else {
        while let Ok(event) = watched.try_recv() {
            observe(&event);
            screen.on_watch(event);
        }
    }
}

/// Waits until `deadline`, or for ever without one.
async fn sleep_until(deadline: Option<tokio::time::Instant>) {
    match deadline {
        Some(at) => tokio::time::sleep_until(at).await,
        None => std::future::pending().await,
    }
}

#[cfg(test)]
mod tests;
