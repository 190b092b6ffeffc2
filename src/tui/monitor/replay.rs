//! A watched run replayed on the monitor screen (`betr replay` of a `betr monitor
//! --record` file): the screen at a position is the screen after the recorded events up
//! to it, one status change at a time, so stepping back shows what stepping forward
//! showed. It plays at the robot's own pace or is stepped by hand; nothing is sent
//! anywhere.

use std::path::Path;
use std::time::Duration;

use crossterm::event::{Event as TermEvent, KeyCode, KeyEvent, KeyModifiers};
use tokio::sync::mpsc;
use tokio::time::Instant;

use crate::monitor::{NodeStatus, Transition, WatchEvent, missed_some};
use crate::record::WatchedRun;
use crate::record::watched::WatchStep;

use super::super::event_loop::{QueueEvent, spawn_input_reader};
use super::super::{TerminalGuard, TuiError};
use super::{FRAME, MonitorScreen, view};

/// One thing the replay applies: a watch event, or one status change of a batch.
#[derive(Clone, Copy, Debug)]
enum Atom {
    Event(usize),
    Change { step: usize, index: usize },
}

/// A watched run with the screen at a position in it.
pub struct WatchPlayer {
    run: WatchedRun,
    atoms: Vec<Atom>,
    /// When each atom happened, since the watch began (never earlier than the one
    /// before).
    times: Vec<Duration>,
    /// How many atoms are applied.
    at: usize,
    /// How many of those are status changes.
    changes_at: usize,
    changes: usize,
    /// Playing since that moment, from that position's time.
    playing: Option<(Instant, Duration)>,
    pub screen: MonitorScreen,
}

impl WatchPlayer {
    /// The run where there is something to see: just after its first tree arrived (at
    /// its start when none did).
    pub fn at_first_tree(run: WatchedRun, ascii: bool) -> WatchPlayer {
        let mut player = Self::new(run, ascii);
        let first = (0..player.atoms.len()).find(|&i| player.is_tree(i));
        if let Some(first) = first {
            player.seek(first + 1);
        }
        player
    }

    /// The run at its start (nothing applied yet).
    pub fn new(run: WatchedRun, ascii: bool) -> WatchPlayer {
        let mut atoms = Vec::new();
        let mut times = Vec::new();
        let mut since = Duration::ZERO;
        let mut last = Duration::ZERO;
        for (step, (ms, entry)) in run.steps.iter().enumerate() {
            let WatchStep::Watched(event) = entry else {
                continue;
            };
            let arrived = Duration::from_millis(*ms);
            match event {
                WatchEvent::Changes(batch) => {
                    for (index, transition) in batch.iter().enumerate() {
                        // The robot's own time of the change, not when betr read it.
                        last = last.max(since + Duration::from_micros(transition.micros));
                        atoms.push(Atom::Change { step, index });
                        times.push(last);
                    }
                }
                other => {
                    if let WatchEvent::Connected { since: s, .. } = other {
                        since = *s;
                    }
                    last = last.max(arrived);
                    atoms.push(Atom::Event(step));
                    times.push(last);
                }
            }
        }
        let changes = atoms
            .iter()
            .filter(|a| matches!(a, Atom::Change { .. }))
            .count();
        let mut screen = MonitorScreen::new(run.address.clone(), ascii);
        screen.mode = super::Mode::Replay;
        let mut player = WatchPlayer {
            run,
            atoms,
            times,
            at: 0,
            changes_at: 0,
            changes,
            playing: None,
            screen,
        };
        player.tell();
        player
    }

    /// How many atoms the run has (the last position).
    pub fn len(&self) -> usize {
        self.atoms.len()
    }

    pub fn is_empty(&self) -> bool {
        self.atoms.is_empty()
    }

    pub fn position(&self) -> usize {
        self.at
    }

    /// Goes to position `to`: forward by applying what lies between, back by applying
    /// everything up to it again on a rewound screen.
    pub fn seek(&mut self, to: usize) {
        let to = to.min(self.atoms.len());
        if to < self.at {
            self.screen.rewind();
            self.at = 0;
            self.changes_at = 0;
        }
        while self.at < to {
            self.apply(self.atoms[self.at]);
            self.at += 1;
        }
        if self.screen.live.is_some() && !self.applied_a_tree() {
            self.screen.live = None;
        }
        self.screen.follow_busy();
        self.tell();
    }

    fn applied_a_tree(&self) -> bool {
        (0..self.at).any(|i| self.is_tree(i))
    }

    /// Whether atom `i` is a tree read (a connection).
    fn is_tree(&self, i: usize) -> bool {
        match self.atoms[i] {
            Atom::Event(step) => matches!(
                self.run.steps[step].1,
                WatchStep::Watched(WatchEvent::Connected { .. })
            ),
            Atom::Change { .. } => false,
        }
    }

    fn apply(&mut self, atom: Atom) {
        match atom {
            Atom::Event(step) => {
                if let WatchStep::Watched(event) = &self.run.steps[step].1 {
                    self.screen.on_watch(event.clone());
                }
            }
            Atom::Change { step, index } => {
                let Some(batch) = self.batch(step) else {
                    return;
                };
                let transition = batch[index];
                if index == 0 && missed_some(batch) {
                    self.screen.missed += 1;
                }
                self.screen.apply(transition);
                self.changes_at += 1;
            }
        }
    }

    fn batch(&self, step: usize) -> Option<&[Transition]> {
        match &self.run.steps[step].1 {
            WatchStep::Watched(WatchEvent::Changes(batch)) => Some(batch),
            _ => None,
        }
    }

    /// The status change at `atom`, if it is one.
    fn change(&self, atom: usize) -> Option<Transition> {
        match self.atoms[atom] {
            Atom::Change { step, index } => self.batch(step).map(|b| b[index]),
            Atom::Event(_) => None,
        }
    }

    /// The position just after the next status change `wanted` picks.
    fn next_change(&self, wanted: impl Fn(Transition) -> bool) -> Option<usize> {
        (self.at..self.atoms.len())
            .find(|&i| self.change(i).is_some_and(&wanted))
            .map(|i| i + 1)
    }

    /// The position just after the last such change before the one the replay stands on.
    fn previous_change(&self, wanted: impl Fn(Transition) -> bool) -> Option<usize> {
        (0..self.at.saturating_sub(1))
            .rev()
            .find(|&i| self.change(i).is_some_and(&wanted))
            .map(|i| i + 1)
    }

    /// The time at the current position, since the watch began.
    fn now(&self) -> Duration {
        self.at
            .checked_sub(1)
            .map_or(Duration::ZERO, |i| self.times[i])
    }

    /// Says where the replay stands in the status bar.
    fn tell(&mut self) {
        let name = self
            .run
            .path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let dot = if self.screen.glyphs.success.is_ascii() {
            " | "
        } else {
            " · "
        };
        let state = if self.playing.is_some() {
            "playing"
        } else if self.at == self.atoms.len() {
            "at the end"
        } else {
            "paused"
        };
        self.screen.playback = Some(format!(
            " replay {}{dot}watched {}{dot}change {}/{}{dot}{:.3} s{dot}{state}",
            crate::http_text::printable(&name),
            self.run.address,
            self.changes_at,
            self.changes,
            self.now().as_secs_f64()
        ));
    }

    /// A key pressed: the replay's own keys move in time, the others go to the screen.
    pub fn on_key(&mut self, key: KeyEvent) {
        if self.screen.typing.is_some() || key.modifiers.contains(KeyModifiers::CONTROL) {
            self.screen.on_key(key);
            return;
        }
        let target = match key.code {
            KeyCode::Char('.') => self.next_change(|_| true).unwrap_or(self.atoms.len()),
            KeyCode::Char(',') => self.previous_change(|_| true).unwrap_or(0),
            KeyCode::Char('g') => 0,
            KeyCode::Char('G') => self.atoms.len(),
            KeyCode::Char(']') | KeyCode::Char('[') => {
                let failed = |t: Transition| t.status == NodeStatus::Failure;
                let found = if key.code == KeyCode::Char(']') {
                    self.next_change(failed)
                } else {
                    self.previous_change(failed)
                };
                match found {
                    Some(at) => at,
                    None => {
                        self.screen
                            .say("no status change to FAILURE that way".into());
                        return;
                    }
                }
            }
            KeyCode::Char(' ') => {
                self.playing = match self.playing {
                    Some(_) => None,
                    None if self.at < self.atoms.len() => Some((Instant::now(), self.now())),
                    None => None,
                };
                self.tell();
                return;
            }
            _ => {
                self.screen.on_key(key);
                return;
            }
        };
        self.playing = None;
        self.seek(target);
    }

    /// When the next atom is due while playing.
    fn due(&self) -> Option<Instant> {
        let (started, from) = self.playing?;
        let next = *self.times.get(self.at)?;
        Some(started + next.saturating_sub(from))
    }

    /// Applies what has come due while playing; stops at the end.
    fn play(&mut self) {
        let Some((started, from)) = self.playing else {
            return;
        };
        let now = from + started.elapsed();
        let to = self.times[self.at..].partition_point(|t| *t <= now) + self.at;
        if to == self.atoms.len() {
            self.playing = None;
        }
        self.seek(to);
    }
}

/// A screen that only looks back: a watched run replayed, or a tree file shown.
pub trait Looking {
    fn screen(&mut self) -> &mut MonitorScreen;
    fn on_key(&mut self, key: KeyEvent);
    /// When something is next due without a key (a replay playing).
    fn due(&self) -> Option<Instant>;
    /// Applies what has come due.
    fn play(&mut self);
}

impl Looking for WatchPlayer {
    fn screen(&mut self) -> &mut MonitorScreen {
        &mut self.screen
    }
    fn on_key(&mut self, key: KeyEvent) {
        WatchPlayer::on_key(self, key);
    }
    fn due(&self) -> Option<Instant> {
        WatchPlayer::due(self)
    }
    fn play(&mut self) {
        WatchPlayer::play(self);
    }
}

/// A tree file shown whole, every node idle: nothing runs it.
pub struct FileView(pub MonitorScreen);

impl FileView {
    /// `tree`, read from `file`, on a screen with no connection; `not_run`: why betr's
    /// engine does not run it, when the workbench was asked to (shown beside the tree).
    pub fn new(
        tree: crate::monitor::WatchedTree,
        file: &str,
        not_run: Option<String>,
        ascii: bool,
    ) -> FileView {
        let address = crate::monitor::Address {
            host: String::new(),
            port: 0,
        };
        let mut screen = MonitorScreen::new(address, ascii);
        screen.mode = super::Mode::File;
        let nodes = tree.nodes.len();
        screen.live = Some(crate::monitor::LiveTree::new(tree, &[]));
        screen.open_all();
        screen.follow = false;
        screen.select_index(0);
        let dot = if ascii { " | " } else { " · " };
        let what = if not_run.is_some() {
            "a file betr's engine does not run"
        } else {
            "a file, not running"
        };
        screen.playback = Some(format!(
            " {}{dot}{nodes} nodes{dot}{what}",
            crate::http_text::printable(file)
        ));
        screen.not_run = not_run;
        FileView(screen)
    }
}

impl Looking for FileView {
    fn screen(&mut self) -> &mut MonitorScreen {
        &mut self.0
    }
    fn on_key(&mut self, key: KeyEvent) {
        self.0.on_key(key);
    }
    fn due(&self) -> Option<Instant> {
        None
    }
    fn play(&mut self) {}
}

/// A looking screen on the terminal until the person quits.
pub fn run(mut looking: impl Looking, stderr_to: Option<&Path>) -> Result<(), TuiError> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    runtime.block_on(async {
        let (_guard, mut terminal) = TerminalGuard::enter(stderr_to)?;
        let (keys, mut input) = mpsc::unbounded_channel();
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        spawn_input_reader(keys, stop.clone());
        let result = loop {
            if let Err(e) = terminal.draw(|f| view::draw(f, looking.screen())) {
                break Err(TuiError::Terminal(e));
            }
            // Playing draws at most once a frame, however close the changes come.
            let wake = looking.due().map(|due| due.max(Instant::now() + FRAME));
            let ended = tokio::select! {
                input = input.recv() => match input {
                    Some(QueueEvent::Input(TermEvent::Key(key))) => {
                        looking.on_key(key);
                        false
                    }
                    Some(QueueEvent::InputEnded) | None => true,
                    Some(_) => false,
                },
                () = super::sleep_until(wake) => {
                    looking.play();
                    false
                }
            };
            if ended || looking.screen().should_quit() {
                break Ok(());
            }
        };
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
        result
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::{Recorder, Source, read};

    const TREE: &str = r#"<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence _uid="1"><AlwaysSuccess _uid="2"/><AlwaysFailure _uid="3"/></Sequence></BehaviorTree></root>"#;

    /// A run of one connection and three changes, written and read back as a file.
    fn run_of(name: &str) -> WatchedRun {
        let path = std::env::temp_dir().join(format!(
            "betr-watch-replay-{name}-{}.jsonl",
            std::process::id()
        ));
        let address = crate::monitor::Address::parse("127.0.0.1:1667").unwrap();
        let mut recorder = Recorder::start(
            &path,
            Source::Watched {
                watched: address.clone(),
            },
        )
        .unwrap();
        let tree = crate::monitor::WatchedTree::parse(TREE.as_bytes()).unwrap();
        let t = |micros, uid, status| Transition {
            micros,
            uid,
            status,
        };
        let events = [
            WatchEvent::Connected {
                address,
                tree: Box::new(tree),
                statuses: Vec::new(),
                since: Duration::from_millis(10),
                started: None,
            },
            WatchEvent::Changes(vec![
                t(1_000, 1, NodeStatus::Running),
                t(2_000, 2, NodeStatus::Success),
            ]),
            WatchEvent::Changes(vec![t(3_000, 3, NodeStatus::Failure)]),
        ];
        for (ms, watched) in events.into_iter().enumerate() {
            let entry = crate::record::Entry::Watched {
                ms: ms as u64,
                watched,
            };
            recorder.write(&entry).unwrap();
        }
        let run = WatchedRun::of(read(&path).unwrap()).unwrap();
        let _ = std::fs::remove_file(&path);
        run
    }

    fn statuses(player: &WatchPlayer) -> Vec<NodeStatus> {
        player
            .screen
            .live
            .as_ref()
            .map(|l| l.statuses.clone())
            .unwrap_or_default()
    }

    fn key(c: char) -> KeyEvent {
        KeyEvent::from(KeyCode::Char(c))
    }

    #[test]
    fn stepping_back_shows_what_stepping_forward_showed() {
        let mut player = WatchPlayer::new(run_of("stepping"), true);
        assert_eq!(player.len(), 4, "one tree and three changes");
        assert!(player.screen.live.is_none(), "nothing before the tree");
        let mut forward = vec![statuses(&player)];
        while player.position() < player.len() {
            player.on_key(key('.'));
            forward.push(statuses(&player));
        }
        use NodeStatus::*;
        assert_eq!(
            forward,
            [
                vec![],
                vec![Running, Idle, Idle],
                vec![Running, Success, Idle],
                vec![Running, Success, Failure]
            ],
            "one status change a step"
        );
        let mut back = Vec::new();
        while player.position() > 0 {
            player.on_key(key(','));
            back.push(statuses(&player));
        }
        forward.pop();
        forward.reverse();
        assert_eq!(back, forward);
        assert!(player.screen.live.is_none(), "back at the start");
    }

    #[test]
    fn failures_are_found_both_ways() {
        let mut player = WatchPlayer::new(run_of("failures"), true);
        player.on_key(key(']'));
        assert_eq!(player.position(), 4, "just after the change to FAILURE");
        player.on_key(key(']'));
        assert!(player.screen.said.is_some(), "none after it is said");
        player.on_key(key('['));
        assert_eq!(
            player.position(),
            4,
            "the one before the position is the same"
        );
        player.on_key(key('g'));
        assert_eq!(player.position(), 0);
        player.on_key(key('G'));
        assert_eq!(player.changes_at, 3);
        assert!(
            player
                .screen
                .playback
                .as_deref()
                .is_some_and(|p| p.contains("change 3/3") && p.contains("at the end")),
            "{:?}",
            player.screen.playback
        );
    }

    #[test]
    fn a_replay_opens_on_its_first_tree() {
        let player = WatchPlayer::at_first_tree(run_of("first_tree"), true);
        assert_eq!(player.position(), 1);
        assert!(player.screen.live.is_some());
    }

    #[test]
    fn breakpoint_keys_do_nothing_in_a_replay() {
        let mut player = WatchPlayer::new(run_of("breakpoint_keys"), true);
        player.on_key(key('G'));
        player.on_key(key('b'));
        assert!(player.screen.breakpoints.is_empty());
        assert!(player.screen.take_commands().is_empty());
    }
}
