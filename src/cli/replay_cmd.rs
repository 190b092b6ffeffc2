//! `betr replay FILE`: a recorded session told again, step by step, without the model;
//! `--to-rrd OUT` converts it into a rerun recording with its tick timeline.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context as _, Result};

use betr::record::{Replay, Resimulation, Step};
use betr::session::Event;
use betr::viz::{Sinks, Viz};

/// What `betr replay` is asked.
#[derive(clap::Args)]
pub struct ReplayArgs {
    /// A recording written with --record.
    pub file: PathBuf,
    /// The scenario it was recorded on, when it is not where the recording says.
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Write it as a rerun recording (.rrd): the tree, every tick on the `tick` timeline,
    /// the cell re-simulated after each tick, and the session's log.
    #[arg(long, value_name = "OUT")]
    pub to_rrd: Option<PathBuf>,
}

pub fn replay(args: &ReplayArgs) -> Result<ExitCode> {
    let replay = Replay::load(&args.file, args.scenario.as_deref())?;
    if let Some(line) = replay.cut_at {
        eprintln!(
            "note: {}: the recording ends in a partial entry at line {line} (the session did not end cleanly); replayed up to it",
            args.file.display()
        );
    }
    match &args.to_rrd {
        Some(out) => to_rrd(&replay, out),
        None => {
            print_steps(&replay);
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn to_rrd(replay: &Replay, out: &Path) -> Result<ExitCode> {
    let mut viz = Viz::open(&Sinks {
        viewer: None,
        rrd: Some(out.to_path_buf()),
    })?
    .context("--to-rrd: no recording was opened")?;
    let mut cell = Resimulation::new(replay);
    for (_, step) in &replay.steps {
        match step {
            Step::Command(text) => {
                if let Some(instruction) = text.strip_prefix("submit ") {
                    viz.instruction(instruction);
                }
            }
            Step::Event(event) => {
                viz.on_event(event);
                if let Some(scene) = cell.follow(event) {
                    viz.on_event(&scene);
                }
            }
        }
    }
    viz.flush();
    if let Some(tick) = cell.diverged {
        eprintln!(
            "note: re-simulating the cell gave other statuses from tick {tick} on (has the scenario changed since it was recorded?); the tree's statuses are the recorded ones"
        );
    }
    eprintln!("Wrote {}", out.display());
    Ok(ExitCode::SUCCESS)
}

/// One line per step; consecutive ticks of one run on one line.
fn print_steps(replay: &Replay) {
    println!(
        "Recording: {} ({} steps)",
        replay.path.display(),
        replay.steps.len()
    );
    println!(
        "Scenario:  {} ({}), recorded {} with betr {}",
        replay.header.name,
        replay.header.scenario.display(),
        replay.header.started,
        replay.header.betr
    );
    let mut ticks: Option<(u64, u64, u64)> = None; // (ms of the first, first, last)
    let flush = |ticks: &mut Option<(u64, u64, u64)>| {
        if let Some((ms, first, last)) = ticks.take() {
            if first == last {
                println!("{}  tick {first}", time(ms));
            } else {
                println!("{}  ticks {first}–{last}", time(ms));
            }
        }
    };
    for (ms, step) in &replay.steps {
        if let Step::Event(Event::Ticked { record }) = step {
            ticks = match ticks {
                Some((start, first, last)) if record.tick == last + 1 => {
                    Some((start, first, record.tick))
                }
                other => {
                    let mut other = other;
                    flush(&mut other);
                    Some((*ms, record.tick, record.tick))
                }
            };
            continue;
        }
        if let Some(line) = describe(step) {
            flush(&mut ticks);
            println!("{}  {line}", time(*ms));
        }
    }
    flush(&mut ticks);
}

fn time(ms: u64) -> String {
    format!(
        "{:>3}:{:02}.{:03}",
        ms / 60_000,
        (ms / 1000) % 60,
        ms % 1000
    )
}

/// A step in one line (none for what only a live screen shows).
fn describe(step: &Step) -> Option<String> {
    let event = match step {
        Step::Command(text) => return Some(format!("> {text}")),
        Step::Event(event) => event,
    };
    Some(match event {
        Event::TreeChanged { tree, why, .. } => format!("tree ({} nodes): {why}", tree.len()),
        Event::Goal { goal, .. } => format!("goal: {goal}"),
        Event::Asking { what } => format!("asking the model for {what}"),
        Event::Replied {
            attribution, text, ..
        } => format!(
            "reply from {attribution}: {}",
            betr::excerpt::excerpt(text.trim(), None)
        ),
        Event::InvalidReply { error } => format!("unusable reply: {error}"),
        Event::CandidateRejected {
            candidate, reason, ..
        } => format!("set aside {candidate}: {reason}"),
        Event::ActionFailed {
            action,
            node_path,
            error,
            ..
        } => format!("✗ {action}! (node {node_path}) failed: {error}"),
        Event::Proposal {
            proposal, author, ..
        } => format!("proposal by {author}: {proposal}"),
        Event::Approved => "approved".into(),
        Event::Rejected => "rejected".into(),
        Event::Repaired {
            added_nodes,
            valued_nodes,
        } => format!("repaired: {added_nodes} node(s) added, a value set on {valued_nodes}"),
        Event::DidNotHelp { reason } => format!("did not help: {reason}"),
        Event::Success { ticks } => format!("✓ success after {ticks} tick(s)"),
        Event::GaveUp { reason } => format!("gave up: {reason}"),
        Event::BreakpointHit {
            node_path, tick, ..
        } => format!("stopped at the breakpoint on node {node_path} (tick {tick})"),
        Event::PolicySaved { path, fixes } => {
            format!("policy saved to {} ({fixes} fix(es))", path.display())
        }
        Event::PolicyLoaded { path, fixes } => {
            format!("policy loaded from {} ({fixes} fix(es))", path.display())
        }
        Event::Error { message } => format!("error: {message}"),
        Event::Notice { message } => message.clone(),
        _ => return None,
    })
}
