//! `betr replay FILE`: a recorded session opened in the workbench, read-only, to step
//! through forward and back without an engine or a model; `--print` tells it as text, one
//! line per step; `--to-rrd OUT` converts it into a rerun recording with its tick
//! timeline. A recording of a watched BehaviorTree.CPP process (`betr monitor --record`)
//! opens on the monitor screen instead, `--print` tells it as the monitor's `--print`
//! did, and `--to-rrd` puts its status changes on a `watch` timeline.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context as _, Result, bail};

use betr::record::{Replay, Resimulation, Source, Step, WatchedRun};
use betr::session::Event;
use betr::tui::Theme;
use betr::tui::replay::{Player, ReplayScreen};
use betr::viz::{Sinks, Viz};

/// What `betr replay` is asked.
#[derive(clap::Args)]
pub struct ReplayArgs {
    /// A recording written with --record (by a session, or by `betr monitor`).
    pub file: PathBuf,
    /// The scenario it was recorded on, when it is not where the recording says.
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Write it as a rerun recording (.rrd): the tree, every tick on the `tick` timeline,
    /// the cell re-simulated after each tick, and the session's log (a watched process:
    /// its tree and every status change on the `watch` timeline).
    #[arg(long, value_name = "OUT", conflicts_with = "print")]
    pub to_rrd: Option<PathBuf>,
    /// Print the steps as text (one line per step, a run of ticks on one line) instead of
    /// opening the workbench.
    #[arg(long)]
    pub print: bool,
    /// Key bindings to override (default: $XDG_CONFIG_HOME/betr/keys.toml, as `betr tui`).
    #[arg(long, value_name = "FILE")]
    pub keys: Option<PathBuf>,
}

pub fn replay(args: &ReplayArgs, ascii: bool) -> Result<ExitCode> {
    let recording = betr::record::read(&args.file)?;
    if let Source::Watched { .. } = recording.header.source {
        if args.scenario.is_some() {
            bail!(
                "{}: a watched BehaviorTree.CPP process, recorded with no scenario; --scenario is for the recording of a session",
                args.file.display()
            );
        }
        return watched(WatchedRun::of(recording)?, args, ascii);
    }
    let replay = Replay::of(recording, args.scenario.as_deref())?;
    if let Some(out) = &args.to_rrd {
        cut_note(&args.file, &replay);
        return to_rrd(&replay, out);
    }
    if args.print {
        cut_note(&args.file, &replay);
        print_steps(&replay);
        return Ok(ExitCode::SUCCESS);
    }
    workbench(replay, args, ascii)
}

/// Said when the recording's last entry was cut (the session did not end cleanly).
fn cut_note(file: &Path, replay: &Replay) {
    if let Some(line) = replay.cut_at {
        errln!(
            "note: {}: {}",
            file.display(),
            betr::tui::strings::replay_cut(line)
        );
    }
}

/// A watched BehaviorTree.CPP process's recording: told as `betr monitor --print` told it,
/// written as a rerun recording, or replayed on the monitor screen.
fn watched(run: WatchedRun, args: &ReplayArgs, ascii: bool) -> Result<ExitCode> {
    if let Some(line) = run.cut_at {
        errln!(
            "note: {}: {}",
            args.file.display(),
            betr::tui::strings::replay_cut(line)
        );
    }
    if let Some(out) = &args.to_rrd {
        return watched_to_rrd(&run, out);
    }
    if args.print {
        outln!(
            "# replay of {}: {} watched from {} with betr {}",
            run.path.display(),
            run.address,
            run.header.started,
            run.header.betr
        );
        let mut printer = super::monitor_cmd::Printer::new(ascii);
        for event in run.events() {
            printer.on(event.clone());
        }
        return Ok(ExitCode::SUCCESS);
    }
    use std::io::IsTerminal as _;
    if !std::io::stdout().is_terminal() {
        bail!(
            "{}: standard output is not a terminal, and the replay opens the monitor screen; --print prints the status changes as text",
            args.file.display()
        );
    }
    let player = betr::tui::monitor::WatchPlayer::at_first_tree(run, ascii);
    betr::tui::monitor::look(player, super::tui_cmd::log_path().as_deref())?;
    Ok(ExitCode::SUCCESS)
}

fn watched_to_rrd(run: &WatchedRun, out: &Path) -> Result<ExitCode> {
    let changes = betr::viz::watched::write(out, run.events())?;
    errln!(
        "Wrote {} ({changes} status changes on the `{}` timeline)",
        out.display(),
        betr::viz::watched::WATCH
    );
    Ok(ExitCode::SUCCESS)
}

/// The workbench on the recording, read-only, at its end.
fn workbench(replay: Replay, args: &ReplayArgs, ascii: bool) -> Result<ExitCode> {
    use std::io::IsTerminal as _;
    if !std::io::stdout().is_terminal() {
        anyhow::bail!(
            "{}: standard output is not a terminal, and the replay opens the workbench; --print prints the steps as text",
            args.file.display()
        );
    }
    let (keys, keys_error) = super::tui_cmd::key_bindings(args.keys.as_deref());
    let theme = Theme::of(ascii);
    let cut = replay.cut_at;
    let player = Player::of(replay, keys, theme);
    let mut screen = ReplayScreen::open(player, usize::MAX);
    // Said on the screen, where the person looks (standard error is under it).
    if let Some(e) = keys_error {
        screen.say(betr::tui::strings::keys_file_error(&e), true);
    } else if let Some(line) = cut {
        screen.say(betr::tui::strings::replay_cut(line), true);
    }
    betr::tui::replay::run(screen, super::tui_cmd::log_path().as_deref())?;
    Ok(ExitCode::SUCCESS)
}

fn to_rrd(replay: &Replay, out: &Path) -> Result<ExitCode> {
    let mut viz = Viz::open(&Sinks {
        rrd: Some(out.to_path_buf()),
        no_scene: replay.scenario.world_kind != "cell",
        ..Sinks::default()
    })?
    .context("--to-rrd: no recording was opened")?;
    let mut cell = Resimulation::new(replay.scenario.clone(), replay.variant.clone());
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
        errln!(
            "note: re-simulating the cell gave other statuses from tick {tick} on (has the scenario changed since it was recorded?); the tree's statuses are the recorded ones"
        );
    }
    errln!("Wrote {}", out.display());
    Ok(ExitCode::SUCCESS)
}

/// One line per step; consecutive ticks of one run on one line.
fn print_steps(replay: &Replay) {
    outln!(
        "Recording: {} ({} steps)",
        replay.path.display(),
        replay.steps.len()
    );
    outln!(
        "Scenario:  {} ({}), recorded {} with betr {}",
        replay.scenario.name,
        replay.scenario_file.display(),
        replay.header.started,
        replay.header.betr
    );
    let mut ticks: Option<(u64, u64, u64)> = None; // (ms of the first, first, last)
    let flush = |ticks: &mut Option<(u64, u64, u64)>| {
        if let Some((ms, first, last)) = ticks.take() {
            if first == last {
                outln!("{}  tick {first}", time(ms));
            } else {
                outln!("{}  ticks {first}–{last}", time(ms));
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
        let lines = betr::record::describe_step(step);
        if !lines.is_empty() {
            flush(&mut ticks);
        }
        for line in lines {
            outln!("{}  {line}", time(*ms));
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
