//! `betr monitor [HOST:PORT]`: a BehaviorTree.CPP process watched live over Groot2's
//! protocol, in a screen of its tree with every node's status, or (`--print`) one line per
//! status change for scripts and terminals without a screen; `--record FILE` keeps what
//! was watched for `betr replay`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context as _, Result, bail};
use tokio::sync::mpsc;

use betr::http_text::printable;
use betr::monitor::protocol::KEPT_CHANGES;
use betr::monitor::{
    Address, Blackboard, LiveTree, WatchEvent, WatchTiming, changed_blackboards, missed_some,
    watch_only,
};
use betr::record::SessionRecorder;

/// What `betr monitor` is asked.
#[derive(clap::Args)]
pub struct MonitorArgs {
    /// The publisher's address: HOST, HOST:PORT or :PORT (BT.CPP's Groot2Publisher
    /// listens on 1667 unless told otherwise).
    #[arg(default_value = "127.0.0.1:1667", value_name = "HOST:PORT")]
    pub address: String,
    /// Print one line per status change (time, node path, name, old → new) instead of
    /// opening the screen.
    #[arg(long)]
    pub print: bool,
    /// Stop after this many seconds (a fraction allowed); without it, watch until stopped.
    #[arg(long = "for", value_name = "SECONDS", value_parser = seconds)]
    pub duration: Option<Duration>,
    /// Show a BehaviorTree.CPP 4 tree file instead of watching: every node of any kind,
    /// its SubTrees under their SubTree nodes, with its ports (nothing runs it).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["duration", "record"])]
    pub file: Option<PathBuf>,
    /// Record the watched run to FILE (the tree as the publisher describes it, every
    /// status change, breakpoints), for `betr replay FILE`.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
}

fn seconds(text: &str) -> Result<Duration, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if s > 0.0 && s <= 1e7 => Ok(Duration::from_secs_f64(s)),
        _ => Err(format!(
            "{text:?} is not a number of seconds above 0 (at most 10000000)"
        )),
    }
}

pub fn monitor(args: &MonitorArgs, ascii: bool) -> Result<ExitCode> {
    if let Some(file) = &args.file {
        return show_file(file, args.print, ascii);
    }
    let address = Address::parse(&args.address)?;
    use std::io::IsTerminal as _;
    if !args.print && !std::io::stdout().is_terminal() {
        bail!(
            "standard output is not a terminal, and the monitor opens a screen; --print prints the status changes as text"
        );
    }
    let mut recorder = match &args.record {
        Some(file) => Some(SessionRecorder::create_watched(file, &address).context("--record")?),
        None => None,
    };
    if args.print {
        super::runtime()?.block_on(print(address, args.duration, ascii, recorder.as_mut()))?;
    } else {
        betr::tui::monitor::run(
            address,
            args.duration,
            ascii,
            super::tui_cmd::log_path().as_deref(),
            recorder.as_mut(),
        )?;
    }
    if let Some(stopped) = recorder.as_ref().and_then(SessionRecorder::stopped) {
        bail!("{stopped}");
    }
    if let Some(file) = &args.record {
        errln!("Recorded to {}", file.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// A BehaviorTree.CPP tree file as written, whatever its node kinds, read with the
/// monitor's size cap; errors name the file.
pub(super) fn read_tree_file(file: &std::path::Path) -> Result<betr::monitor::WatchedTree> {
    let text = betr::store::read_text(file, betr::monitor::tree::MAX_TREE_BYTES as u64)
        .with_context(|| format!("reading tree file {}", file.display()))?;
    betr::monitor::WatchedTree::parse_file(text.as_bytes())
        .with_context(|| file.display().to_string())
}

/// A tree file shown on the monitor's screen, or printed one node a line.
fn show_file(file: &std::path::Path, print: bool, ascii: bool) -> Result<ExitCode> {
    let tree = read_tree_file(file)?;
    if print {
        outln!(
            "# {}: tree {}, {} nodes",
            file.display(),
            printable(&tree.main),
            tree.nodes.len()
        );
        for node in &tree.nodes {
            outln!(
                "{:<10} {}{}",
                node.path,
                "  ".repeat(node.depth),
                tree.describe(node)
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    use std::io::IsTerminal as _;
    if !std::io::stdout().is_terminal() {
        bail!(
            "standard output is not a terminal, and the monitor opens a screen; --print prints the tree as text"
        );
    }
    let label = file.display().to_string();
    let view = betr::tui::monitor::FileView::new(tree, &label, None, ascii);
    betr::tui::monitor::look(view, super::tui_cmd::log_path().as_deref())?;
    Ok(ExitCode::SUCCESS)
}

/// Prints what the watch reports until `duration` has passed (or forever); an error when
/// no publisher ever answered.
async fn print(
    address: Address,
    duration: Option<Duration>,
    ascii: bool,
    mut recorder: Option<&mut SessionRecorder>,
) -> Result<()> {
    let (events, mut received) = mpsc::channel(256);
    let watcher = tokio::spawn(watch_only(address.clone(), WatchTiming::default(), events));
    let deadline = duration.map(|d| tokio::time::Instant::now() + d);
    let mut printer = Printer::new(ascii);
    loop {
        let event = match deadline {
            Some(at) => match tokio::time::timeout_at(at, received.recv()).await {
                Ok(event) => event,
                Err(_) => break,
            },
            None => received.recv().await,
        };
        let Some(event) = event else { break };
        if let Some(recorder) = recorder.as_deref_mut() {
            recorder.watched(&event);
        }
        printer.on(event);
    }
    watcher.abort();
    if printer.live.is_none() {
        let waited = duration.map_or(String::new(), |d| format!(" for {} s", d.as_secs_f64()));
        match printer.last_wait {
            Some(reason) => bail!("{reason} (tried{waited})"),
            None => bail!("no Groot2 publisher answered at {address}{waited}"),
        }
    }
    Ok(())
}

/// The lines `--print` writes (and `betr replay --print` of a watched run): `#` lines about
/// the connection and the tree, then one line per status change.
pub(super) struct Printer {
    live: Option<LiveTree>,
    since: Duration,
    arrow: &'static str,
    last_wait: Option<String>,
    boards: Vec<Blackboard>,
}

impl Printer {
    pub(super) fn new(ascii: bool) -> Printer {
        Printer {
            live: None,
            since: Duration::ZERO,
            arrow: if ascii { "->" } else { "→" },
            last_wait: None,
            boards: Vec::new(),
        }
    }

    pub(super) fn on(&mut self, event: WatchEvent) {
        match event {
            WatchEvent::Connected {
                address,
                tree,
                statuses,
                since,
                ..
            } => {
                outln!(
                    "# watching {address}: tree {}, {} nodes",
                    printable(&tree.main),
                    tree.nodes.len()
                );
                let live = LiveTree::new(*tree, &statuses);
                for (node, status) in live.tree.nodes.iter().zip(&live.statuses) {
                    outln!(
                        "# {:<10} {}{}  {}",
                        node.path,
                        "  ".repeat(node.depth),
                        live.tree.describe(node),
                        status.name()
                    );
                }
                self.live = Some(live);
                self.since = since;
            }
            WatchEvent::Changes(transitions) => {
                let Some(live) = self.live.as_mut() else {
                    return;
                };
                if missed_some(&transitions) {
                    outln!(
                        "# the publisher kept only its last {KEPT_CHANGES} changes since the last read: some before these were missed"
                    );
                }
                for transition in transitions {
                    let Some(change) = live.apply(transition) else {
                        outln!(
                            "# a status change of node {}, which the tree does not have",
                            transition.uid
                        );
                        continue;
                    };
                    outln!("{}", live.describe_change(self.since, &change, self.arrow));
                }
            }
            WatchEvent::Restarted => {
                outln!("# the publisher runs a new tree (restarted): reading it again");
            }
            WatchEvent::Lost(reason) => outln!("# {reason}; trying again"),
            // Nothing sets breakpoints while printing; another client's stop is said.
            WatchEvent::Stopped(uid) => outln!("# node {uid} stopped at a breakpoint"),
            WatchEvent::Refused(reason) => outln!("# {reason}"),
            WatchEvent::Blackboards(boards) => {
                for board in changed_blackboards(&self.boards, &boards) {
                    outln!("# blackboard {}", board.describe());
                }
                self.boards = boards;
            }
            WatchEvent::Waiting(reason) => {
                outln!("# {reason}; trying again");
                self.last_wait = Some(reason);
            }
        }
    }
}
