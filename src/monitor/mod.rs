//! Watching a BehaviorTree.CPP process live over Groot2's monitor protocol: `protocol` is
//! the wire format, `tree` the tree the publisher describes, `client` one connection, and
//! [`watch`] the loop that follows a publisher — connecting, reading its tree, asking it to
//! keep every status change and collecting them — through restarts and lost connections,
//! as [`WatchEvent`]s for a front end (`betr monitor --print`, the monitor screen).

pub mod client;
pub mod protocol;
pub mod tree;

use std::time::Duration;

use tokio::sync::mpsc;

pub use client::{Address, AddressError, ClientError, DEFAULT_PORT, Publisher, TreeId};
pub use protocol::{Blackboard, NodeStatus, Transition, changed_blackboards};
pub use tree::{NodeKind, WatchedNode, WatchedTree};

/// How the watch talks to the publisher.
#[derive(Clone, Copy, Debug)]
pub struct WatchTiming {
    /// Between two requests for the status changes.
    pub poll: Duration,
    /// For connecting and for each reply.
    pub timeout: Duration,
    /// Between two tries to connect after a failure.
    pub retry: Duration,
    /// Between two reads of the blackboards.
    pub blackboards: Duration,
}

impl Default for WatchTiming {
    fn default() -> Self {
        WatchTiming {
            poll: Duration::from_millis(5),
            timeout: Duration::from_secs(2),
            retry: Duration::from_millis(500),
            blackboards: Duration::from_millis(250),
        }
    }
}

/// What the watch reports, in order; a recording of a watched run is these, as serde
/// writes them.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WatchEvent {
    /// Connected (again) and read the tree: every node's status now, and the moment the
    /// publisher started keeping status changes, as time since the watch began.
    Connected {
        address: Address,
        tree: Box<WatchedTree>,
        statuses: Vec<(u16, NodeStatus)>,
        since: Duration,
        /// The publisher's clock when it began keeping changes (their times count from
        /// it), when it says.
        started: Option<std::time::SystemTime>,
    },
    /// Status changes, each timed from the `since` of the last `Connected`. A batch of
    /// [`protocol::KEPT_CHANGES`] may have lost older ones ([`missed_some`]).
    Changes(Vec<Transition>),
    /// The publisher now runs another tree (the robot restarted); its tree is read again.
    Restarted,
    /// The connection broke, or a reply was not Groot2's; the watch tries again.
    Lost(String),
    /// Not connected: why, as the last try said. Sent when the reason changes.
    Waiting(String),
    /// The node with this uid stopped at its breakpoint; the tree waits for a release.
    Stopped(u16),
    /// The publisher refused a breakpoint command, or its blackboards could not be read:
    /// why.
    Refused(String),
    /// The tree's blackboards and their entries, when they changed.
    Blackboards(Vec<Blackboard>),
}

/// What a front end asks of the publisher while watching.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WatchCommand {
    /// Stop before the node with this uid is ticked, every time.
    Break(u16),
    /// Take that breakpoint away.
    Unbreak(u16),
    /// Let the node stopped at its breakpoint go on: ticked as usual (`forced: None`) or
    /// returning `forced` without being ticked.
    Release {
        uid: u16,
        forced: Option<NodeStatus>,
    },
    /// Take every breakpoint away (before leaving: a breakpoint left behind would stop
    /// the robot with no one watching).
    ClearAll,
}

impl std::fmt::Display for WatchCommand {
    /// In words, as a recording keeps it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WatchCommand::Break(uid) => write!(f, "break before node {uid}"),
            WatchCommand::Unbreak(uid) => write!(f, "no break before node {uid}"),
            WatchCommand::Release { uid, forced: None } => write!(f, "let node {uid} go on"),
            WatchCommand::Release {
                uid,
                forced: Some(status),
            } => write!(f, "make node {uid} return {}", status.name()),
            WatchCommand::ClearAll => f.write_str("clear every breakpoint"),
        }
    }
}

impl WatchCommand {
    fn request(self) -> (protocol::RequestKind, Vec<u8>) {
        use protocol::RequestKind;
        match self {
            WatchCommand::Break(uid) => (RequestKind::HookInsert, protocol::breakpoint_body(uid)),
            WatchCommand::Unbreak(uid) => (
                RequestKind::HookRemove,
                protocol::breakpoint_removal_body(uid),
            ),
            WatchCommand::Release { uid, forced } => (
                RequestKind::BreakpointUnlock,
                protocol::release_body(uid, forced),
            ),
            WatchCommand::ClearAll => (RequestKind::RemoveAllHooks, Vec::new()),
        }
    }
}

/// Follows the publisher at `address` until the receiver is dropped, sending it
/// `commands` as they come.
pub async fn watch(
    address: Address,
    timing: WatchTiming,
    events: mpsc::Sender<WatchEvent>,
    mut commands: mpsc::UnboundedReceiver<WatchCommand>,
) {
    let began = tokio::time::Instant::now();
    let mut last_wait: Option<String> = None;
    loop {
        let outcome = follow(&address, timing, began, &events, &mut commands).await;
        if events.is_closed() {
            return;
        }
        let event = match outcome {
            Ok(Ended::Restarted) => WatchEvent::Restarted,
            Ok(Ended::Closed) => return,
            Err(Failure::BeforeConnecting(e)) => {
                let reason = e.to_string();
                if last_wait.as_ref() != Some(&reason) {
                    last_wait = Some(reason.clone());
                    if events.send(WatchEvent::Waiting(reason)).await.is_err() {
                        return;
                    }
                }
                tokio::time::sleep(timing.retry).await;
                continue;
            }
            Err(Failure::AfterConnecting(e)) => WatchEvent::Lost(e.to_string()),
        };
        last_wait = None;
        if events.send(event).await.is_err() {
            return;
        }
    }
}

/// [`watch`] for a front end that only looks: no breakpoints are set.
pub async fn watch_only(address: Address, timing: WatchTiming, events: mpsc::Sender<WatchEvent>) {
    let (_, no_commands) = mpsc::unbounded_channel();
    watch(address, timing, events, no_commands).await;
}

enum Ended {
    Restarted,
    Closed,
}

enum Failure {
    BeforeConnecting(ClientError),
    AfterConnecting(ClientError),
}

/// One connection's life: connect, read the tree, start recording, collect changes until
/// the tree changes or the connection fails.
async fn follow(
    address: &Address,
    timing: WatchTiming,
    began: tokio::time::Instant,
    events: &mpsc::Sender<WatchEvent>,
    commands: &mut mpsc::UnboundedReceiver<WatchCommand>,
) -> Result<Ended, Failure> {
    let before = Failure::BeforeConnecting;
    let mut publisher = Publisher::connect(address, timing.timeout)
        .await
        .map_err(before)?;
    let (tree_id, tree) = publisher.tree().await.map_err(before)?;
    let since = began.elapsed();
    let after = Failure::AfterConnecting;
    // A new watch starts with no breakpoints, whatever an earlier one left.
    let (clear, body) = WatchCommand::ClearAll.request();
    publisher.command(clear, Some(&body)).await.map_err(after)?;
    let mut notifications = publisher.notifications().await.map_err(after)?;
    let (_, started) = publisher.start_recording().await.map_err(after)?;
    let (_, statuses) = publisher.statuses().await.map_err(after)?;
    let mut boards = Boards::new(&tree);
    let connected = WatchEvent::Connected {
        address: address.clone(),
        tree: Box::new(tree),
        statuses,
        since,
        started,
    };
    if events.send(connected).await.is_err() {
        return Ok(Ended::Closed);
    }
    // Polled on a fixed beat rather than a pause after each read, and read again at once
    // when a read came back a quarter full: the publisher drops its oldest changes past
    // `protocol::KEPT_CHANGES`.
    let mut beat = tokio::time::interval(timing.poll);
    beat.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut board_beat = tokio::time::interval(timing.blackboards);
    board_beat.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut busy = false;
    let mut commanded = true;
    loop {
        if !busy {
            tokio::select! {
                _ = beat.tick() => {}
                _ = board_beat.tick(), if boards.reading => {
                    if let Some(event) = boards.read(&mut publisher).await.map_err(after)?
                        && events.send(event).await.is_err()
                    {
                        return Ok(Ended::Closed);
                    }
                    continue;
                }
                command = commands.recv(), if commanded => {
                    match command {
                        Some(command) => {
                            let (kind, body) = command.request();
                            if let Err(e) = publisher.command(kind, Some(&body)).await {
                                let refused = WatchEvent::Refused(e.to_string());
                                if events.send(refused).await.is_err() {
                                    return Ok(Ended::Closed);
                                }
                            }
                        }
                        None => commanded = false,
                    }
                    continue;
                }
                stopped = notifications.stopped() => {
                    let uid = stopped.map_err(after)?;
                    if events.send(WatchEvent::Stopped(uid)).await.is_err() {
                        return Ok(Ended::Closed);
                    }
                    continue;
                }
            }
        }
        let (id, changes) = publisher.transitions().await.map_err(after)?;
        if id != tree_id {
            return Ok(Ended::Restarted);
        }
        busy = changes.len() >= protocol::KEPT_CHANGES / 4;
        if !changes.is_empty() && events.send(WatchEvent::Changes(changes)).await.is_err() {
            return Ok(Ended::Closed);
        }
    }
}

/// The blackboards of the watched tree, read on their own beat.
struct Boards {
    names: Vec<String>,
    last: Option<Vec<Blackboard>>,
    /// False once a read failed: the publisher (or the build of BT.CPP) does not offer
    /// them, said once.
    reading: bool,
}

impl Boards {
    fn new(tree: &WatchedTree) -> Boards {
        Boards {
            names: tree.blackboards().into_iter().map(str::to_string).collect(),
            last: None,
            reading: true,
        }
    }

    /// The blackboards when they changed since the last read; why not, once, when the
    /// publisher does not answer with them. A lost connection is the watch's error.
    async fn read(&mut self, publisher: &mut Publisher) -> Result<Option<WatchEvent>, ClientError> {
        let names: Vec<&str> = self.names.iter().map(String::as_str).collect();
        match publisher.blackboards(&names).await {
            Ok(boards) if self.last.as_ref() != Some(&boards) => {
                self.last = Some(boards.clone());
                Ok(Some(WatchEvent::Blackboards(boards)))
            }
            Ok(_) => Ok(None),
            Err(e @ (ClientError::Protocol { .. } | ClientError::Empty { .. })) => {
                self.reading = false;
                Ok(Some(WatchEvent::Refused(format!(
                    "the blackboards cannot be read ({e}); the statuses are still followed"
                ))))
            }
            Err(e) => Err(e),
        }
    }
}

/// Whether a batch of changes is as long as the publisher keeps, so older changes may
/// have been dropped before betr read them.
pub fn missed_some(batch: &[Transition]) -> bool {
    batch.len() >= protocol::KEPT_CHANGES
}

/// A watched tree with every node's status, kept up to date from the watch's events.
#[derive(Clone, Debug)]
pub struct LiveTree {
    pub tree: WatchedTree,
    pub statuses: Vec<NodeStatus>,
}

/// One node's status change, resolved to the node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Change {
    pub micros: u64,
    pub index: usize,
    pub old: NodeStatus,
    pub new: NodeStatus,
}

impl LiveTree {
    pub fn new(tree: WatchedTree, statuses: &[(u16, NodeStatus)]) -> LiveTree {
        let mut live = LiveTree {
            statuses: vec![NodeStatus::Idle; tree.nodes.len()],
            tree,
        };
        for &(uid, status) in statuses {
            if let Some(i) = live.tree.index_of(uid) {
                live.statuses[i] = status;
            }
        }
        live
    }

    /// Applies a status change; `None` for a node the tree does not have.
    pub fn apply(&mut self, transition: Transition) -> Option<Change> {
        let index = self.tree.index_of(transition.uid)?;
        let old = std::mem::replace(&mut self.statuses[index], transition.status);
        Some(Change {
            micros: transition.micros,
            index,
            old,
            new: transition.status,
        })
    }
}

impl LiveTree {
    /// The node the tree is busy in: the deepest running node (the last running one in
    /// depth-first order lies on the running path's end).
    pub fn busy(&self) -> Option<usize> {
        self.statuses
            .iter()
            .rposition(|s| *s == NodeStatus::Running)
    }

    /// A status change as one line: the time since the watch began, the node's path and
    /// name, the old and the new status.
    pub fn describe_change(&self, since: Duration, change: &Change, arrow: &str) -> String {
        let node = &self.tree.nodes[change.index];
        let time = since + Duration::from_micros(change.micros);
        format!(
            "{:>10.3}  {}  {}  {} {arrow} {}",
            time.as_secs_f64(),
            node.path,
            crate::http_text::printable(&node.name),
            change.old.name(),
            change.new.name()
        )
    }
}
