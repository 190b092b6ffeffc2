//! `betr interpret` and `betr resolve`: the commands that ask a language model.

use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Context as _, Result};

use betr::bt::{self, Glyphs, TickRecord};
use betr::llm::LanguageModel;
use betr::llm::usage::Metered;
use betr::record::SessionRecorder;
use betr::scenario::Scenario;
use betr::session::interpret::submitted::{self, Submitted};
use betr::session::{self, Ending, Event};

use super::llm_cmds::{CallFlags, LlmFlags, setup};

/// What `betr resolve` is asked.
#[derive(clap::Args)]
pub struct ResolveFlags {
    pub scenario: PathBuf,
    /// An instruction instead of the scenario's.
    #[arg(long, conflicts_with = "audio")]
    pub instruction: Option<String>,
    /// Dictate the instruction from a WAV file (printed; confirmed on the terminal or
    /// by --yes).
    #[arg(long, value_name = "FILE.wav")]
    pub audio: Option<PathBuf>,
    /// Approve every proposal (and a dictated transcript) without asking.
    #[arg(long, short = 'y')]
    pub yes: bool,
    /// Questions about failures before giving up.
    #[arg(value_parser = super::ranged(0, 100), long, default_value_t = 5)]
    pub max_rounds: usize,
    /// Where to save the final tree (default: on success, as a policy in the policy
    /// directory, where the workbench finds it).
    #[arg(long)]
    pub save: Option<PathBuf>,
    /// Work on the scenario's stated goal instead of reading its instruction (no model
    /// call for the goal).
    #[arg(long)]
    pub stated_goal: bool,
    /// When the instruction has several readings that make the robot do different things,
    /// work on reading N (from 1) of those listed; without it they are asked on the
    /// terminal, and --yes stops (exit 3) rather than choose one.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub reading: Option<u16>,
    /// After success, offer each approved fix as a rule of its skill for later tasks
    /// (asked on the terminal; with --yes kept without asking), checked before it is
    /// kept in the knowledge file beside the policies.
    #[arg(long)]
    pub learn: bool,
    /// Perform the actions in `mujoco` (the cell in MuJoCo physics, installed on first
    /// use) or in this program (a simulator or a robot bridge speaking betr's executor
    /// protocol: docs/EXECUTORS.md) instead of betr's world, which becomes its twin.
    #[arg(long, value_name = "COMMAND")]
    pub executor: Option<String>,
    #[command(flatten)]
    pub knowledge: super::knowledge_cmd::KnowledgeFlags,
    #[command(flatten)]
    pub llm: LlmFlags,
    #[command(flatten)]
    pub call: CallFlags,
    #[command(flatten)]
    pub stt: super::voice_cmd::SttFlags,
    #[command(flatten)]
    pub viz: super::viz_flags::VizFlags,
}

/// What `betr interpret` is asked.
#[derive(clap::Args)]
pub struct InterpretArgs {
    pub scenario: PathBuf,
    /// The instruction (default: the scenario's).
    #[arg(conflicts_with = "audio")]
    pub instruction: Option<String>,
    /// Dictate the instruction: transcribe this WAV file, print the transcript and use
    /// it once confirmed (or corrected) on the terminal, or with --yes.
    #[arg(long, value_name = "FILE.wav")]
    pub audio: Option<PathBuf>,
    /// Use a dictated transcript without asking (it is still printed).
    #[arg(long, short = 'y')]
    pub yes: bool,
    /// Print reading N (from 1) of those listed as the goal, when the instruction has
    /// several that make the robot do different things.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub reading: Option<u16>,
    #[command(flatten)]
    pub knowledge: super::knowledge_cmd::KnowledgeFlags,
    #[command(flatten)]
    pub llm: LlmFlags,
    #[command(flatten)]
    pub call: CallFlags,
    #[command(flatten)]
    pub stt: super::voice_cmd::SttFlags,
}

/// `betr interpret`: the instruction typed or dictated, then read.
pub fn interpret_command(args: &InterpretArgs) -> Result<ExitCode> {
    let scenario_path = super::find_scenario(&args.scenario)?;
    let scenario = super::load_with(&args.scenario, &args.knowledge)?;
    let instruction = super::voice_cmd::instruction(
        args.instruction.clone(),
        args.audio.as_deref(),
        args.llm.config.as_deref(),
        &args.stt,
        args.yes,
    )?;
    interpret(
        (&scenario, &scenario_path),
        instruction.as_deref(),
        (args.reading, &args.knowledge.dir),
        (&args.llm, &args.call),
    )
}

/// `betr resolve`: the instruction typed or dictated, then the whole loop.
pub fn resolve_command(args: &ResolveFlags, glyphs: &Glyphs) -> Result<ExitCode> {
    let scenario = super::load_with(&args.scenario, &args.knowledge)?;
    let instruction = super::voice_cmd::instruction(
        args.instruction.clone(),
        args.audio.as_deref(),
        args.llm.config.as_deref(),
        &args.stt,
        args.yes,
    )?;
    resolve(
        &scenario,
        &ResolveArgs {
            instruction: instruction.as_deref(),
            yes: args.yes,
            max_rounds: args.max_rounds,
            save: args.save.as_deref(),
            scenario_path: &args.scenario,
            viz: &args.viz,
            stated_goal: args.stated_goal,
            learn: args.learn.then_some(&args.knowledge.dir),
            reading: args.reading,
            policies: &args.knowledge.dir,
            executor: args.executor.as_deref(),
        },
        (&args.llm, &args.call),
        glyphs,
    )
}

fn interpret(
    (scenario, scenario_path): (&Scenario, &Path),
    instruction: Option<&str>,
    (chosen, policies): (Option<u16>, &super::knowledge_cmd::PolicyDir),
    (flags, call): (&LlmFlags, &CallFlags),
) -> Result<ExitCode> {
    let instruction = instruction
        .map(str::to_string)
        .or_else(|| scenario.instruction.clone())
        .with_context(|| format!("scenario {:?} has no instruction; give one", scenario.name))?;
    // Read before any model is asked: empty text and a formula the scene lacks are refused.
    let instruction = match submitted::read(scenario, &instruction)? {
        Submitted::Goal(goal) => {
            outln!("Scenario:    {}", scenario.name);
            outln!("Goal:        {goal} (a goal formula of the scene: no model asked)");
            return Ok(ExitCode::SUCCESS);
        }
        Submitted::Instruction(text) => text,
    };
    let llm = setup(flags, call)?;
    llm.model.set_purpose("interpret");
    outln!("Scenario:    {}", scenario.name);
    outln!("Instruction: {instruction}");
    let mut emit = |e: &Event| print_event(e, call.show_replies);
    let result = super::runtime()?.block_on(session::interpret::interpret_in_scenario(
        scenario,
        &instruction,
        llm.model.as_ref(),
        &llm.options,
        &mut emit,
    ));
    print_usage(&llm.model);
    let reading = result?;
    outln!("Doubt:       {}", reading.evidence.summary());
    outln!(
        "{} call(s), {} feedback round(s)",
        reading.calls,
        reading.feedback_rounds
    );
    let readings =
        session::interpret::readings::distinct_readings_in_scenario(scenario, &reading.readings)?;
    if readings.len() > 1 {
        outln!();
        for line in readings_text(&readings) {
            outln!("{line}");
        }
    }
    if let Some(n) = chosen {
        // One reading (or none the planner can achieve): the goal read is reading 1.
        let goals: Vec<&betr::goal::Formula> = if readings.is_empty() {
            vec![&reading.answer.goal]
        } else {
            readings.iter().map(|r| &r.goal).collect()
        };
        let Some(goal) = goals.get(usize::from(n) - 1) else {
            let count = goals.len();
            anyhow::bail!("no reading {n}: the instruction has {count} (1 to {count})");
        };
        outln!("Goal (reading {n}): {goal}");
        keep_choice(
            policies,
            (scenario, scenario_path),
            &instruction,
            &readings,
            usize::from(n) - 1,
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// The reading chosen on the terminal (or by `--reading`), kept as a correction of the
/// instruction when it was not the one offered first.
fn choose_and_keep(
    scenario: &Scenario,
    args: &ResolveArgs,
    (readings, doubt): (&[session::Reading], Option<&str>),
) -> Option<usize> {
    let chosen = choose_reading(readings, doubt, args.reading, args.yes);
    if let Some(index) = chosen {
        let said = args
            .instruction
            .or(scenario.instruction.as_deref())
            .unwrap_or_default();
        keep_choice(
            args.policies,
            (scenario, args.scenario_path),
            said,
            readings,
            index,
        );
    }
    chosen
}

/// Keep a reading chosen that was not offered first as a correction, when there is a
/// policy directory; a correction not kept never stops the command.
fn keep_choice(
    dir: &super::knowledge_cmd::PolicyDir,
    scenario: (&Scenario, &Path),
    instruction: &str,
    readings: &[session::Reading],
    index: usize,
) {
    if dir.dir().is_none() {
        return;
    }
    if let Err(e) = super::knowledge_cmd::keep_choice(dir, scenario, instruction, readings, index) {
        errln!("warning: the correction is not kept: {e:#}");
    }
}

/// The readings to choose among, numbered from 1, each with its words, goal and first
/// actions.
fn readings_text(readings: &[session::Reading]) -> Vec<String> {
    let mut lines = vec![format!(
        "The instruction has {} readings that make the robot do different things:",
        readings.len()
    )];
    for (i, r) in readings.iter().enumerate() {
        lines.push(format!("  {}  {}", i + 1, r.words));
        lines.push(format!("     goal: {}", r.goal));
        if !r.first_actions.is_empty() {
            lines.push(format!("     first: {}", r.first_actions.join(", ")));
        }
    }
    lines
}

/// The reading to work on: the one `--reading` names, else asked on the terminal; none
/// with `--yes` (a person must choose) or when the answer names none.
fn choose_reading(
    readings: &[session::Reading],
    doubt: Option<&str>,
    chosen: Option<u16>,
    yes: bool,
) -> Option<usize> {
    match doubt {
        // One reading, doubted: approved by a person, or by --reading 1, never by --yes.
        Some(why) => {
            outln!("The goal read is doubtful: {why}");
            if let Some(r) = readings.first() {
                outln!("  1  {}", r.words);
                outln!("     goal: {}", r.goal);
            }
        }
        None => {
            for line in readings_text(readings) {
                outln!("{line}");
            }
        }
    }
    if let Some(n) = chosen {
        let index = usize::from(n) - 1;
        if index < readings.len() {
            outln!("Reading {n} (--reading)");
            return Some(index);
        }
        outln!("no reading {n}: there are {}", readings.len());
        return None;
    }
    if yes {
        return None;
    }
    out!("Choose a reading [1-{}]: ", readings.len());
    super::out::flush();
    let mut line = String::new();
    match std::io::stdin().lock().read_line(&mut line) {
        Ok(0) | Err(_) => None,
        Ok(_) => line
            .trim()
            .parse::<usize>()
            .ok()
            .filter(|n| (1..=readings.len()).contains(n))
            .map(|n| n - 1),
    }
}

pub struct ResolveArgs<'a> {
    pub instruction: Option<&'a str>,
    pub yes: bool,
    pub max_rounds: usize,
    pub save: Option<&'a Path>,
    pub scenario_path: &'a Path,
    pub viz: &'a super::viz_flags::VizFlags,
    pub stated_goal: bool,
    /// Offer the kept fixes as rules, kept in this directory's knowledge file.
    pub learn: Option<&'a super::knowledge_cmd::PolicyDir>,
    /// The reading to work on when the instruction has several (from 1).
    pub reading: Option<u16>,
    /// Where the tree that succeeds is kept as a policy unless `save` says otherwise.
    pub policies: &'a super::knowledge_cmd::PolicyDir,
    /// What performs the actions (`--executor`), instead of betr's world.
    pub executor: Option<&'a str>,
}

fn resolve(
    scenario: &Scenario,
    args: &ResolveArgs,
    (flags, call): (&LlmFlags, &CallFlags),
    glyphs: &Glyphs,
) -> Result<ExitCode> {
    // The instruction read before any model is asked: empty text and a formula the scene
    // lacks are refused.
    if !args.stated_goal
        && let Some(text) = args.instruction.or(scenario.instruction.as_deref())
    {
        submitted::read(scenario, text)?;
    }
    let policy_dir = checked_destination(args)?;
    let mut llm = setup(flags, call)?;
    llm.options.max_rounds = args.max_rounds;
    llm.options.use_scenario_goal = args.stated_goal;
    llm.options.choose_reading = true;
    llm.options.policy_dir = policy_dir;
    llm.model.set_purpose("resolve");
    let mut viz = args
        .viz
        .open(false, betr::viz::ViewerLife::OutlivesCommand, scenario)?;
    let mut record = args.viz.recorder(scenario, args.scenario_path, None)?;
    outln!("Scenario:    {}", scenario.name);
    if let Some(i) = args.instruction.or(scenario.instruction.as_deref()) {
        outln!("Instruction: {i}");
        if let Some(v) = viz.as_mut() {
            v.instruction(i);
        }
    }
    // The statuses of the last run of the tree, shown with it at the end.
    let mut last: Option<Arc<TickRecord>> = None;
    let mut emit = |e: &Event| {
        if let Some(v) = viz.as_mut() {
            v.on_event(e);
        }
        if let Some(r) = record.as_mut() {
            r.event(e);
        }
        match e {
            Event::Ticked { record } => last = Some(record.clone()),
            Event::TreeChanged { .. } => last = None,
            _ => {}
        }
        print_event(e, call.show_replies);
    };
    let yes = args.yes;
    let mut approve = |p: &session::Proposal| approve_on_terminal(p, yes);
    let mut choose =
        |r: &[session::Reading], doubt: Option<&str>| choose_and_keep(scenario, args, (r, doubt));
    let result = super::runtime()?.block_on(session::resolve_with_scenes(
        scenario,
        args.instruction,
        llm.model.clone(),
        &llm.options,
        session::Execution {
            scenes: args.viz.viewer.is_some() || args.viz.rrd.is_some(),
            executor: super::executor_of(args.executor)?,
        },
        (&mut approve, &mut choose),
        &mut emit,
    ));
    let resolved = match result {
        Ok(r) => r,
        Err(e @ session::SessionError::ReadingNotChosen { .. }) => {
            print_usage(&llm.model);
            eprintln!("error: {e}");
            return Ok(ExitCode::from(3));
        }
        Err(e) => {
            print_usage(&llm.model);
            return Err(e.into());
        }
    };
    // A recording asked for and not made is a failed command, not a note.
    if let Some(why) = record.as_ref().and_then(SessionRecorder::stopped) {
        print_usage(&llm.model);
        anyhow::bail!("--record: {why}");
    }
    let success = matches!(resolved.ending, Ending::Success { .. });
    let saved = save(args, &resolved, success)?;
    report(&resolved, last.as_deref(), saved.as_deref(), glyphs);
    if let Some(dir) = args.learn.filter(|_| success) {
        outln!();
        super::knowledge_cmd::offer(scenario, args.scenario_path, &resolved.kept, dir, args.yes)?;
    }
    print_usage(&llm.model);
    Ok(if success {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// Where the work will be kept, checked before any of it is done: --save, else the
/// policy directory the workbench and --learn use (returned).
fn checked_destination(args: &ResolveArgs) -> Result<Option<PathBuf>> {
    let policy_dir = match args.save {
        Some(_) => None,
        None => Some(args.policies.dir().context(
            "no policy directory to keep the tree in: pass --policy-dir or --save (neither XDG_DATA_HOME nor HOME is set)",
        )?),
    };
    let save_to = match (args.save, &policy_dir) {
        (Some(path), _) => path.to_path_buf(),
        (None, Some(dir)) => dir.join(format!("{}.bt", stem(args.scenario_path))),
        (None, None) => PathBuf::new(),
    };
    betr::store::check_writable(&save_to)
        .with_context(|| format!("the tree is to be saved to {}", save_to.display()))?;
    if let Some(dir) = args.learn
        && let Some(path) = dir.knowledge_path()
    {
        betr::store::check_writable(&path).context("--learn")?;
    }
    Ok(policy_dir)
}

/// Where the tree was saved: to --save when it succeeded or was changed, before anything
/// is printed so the tree is kept whatever happens to the output; else where the loop
/// itself saved a policy on success.
fn save(
    args: &ResolveArgs,
    resolved: &session::Resolved,
    success: bool,
) -> Result<Option<PathBuf>> {
    Ok(match args.save {
        Some(path) if success || resolved.repairs > 0 => {
            betr::store::write_atomic(path, bt::to_text(&resolved.tree).as_bytes())
                .with_context(|| format!("saving the tree to {}", path.display()))?;
            Some(path.to_path_buf())
        }
        Some(_) => None,
        None => resolved.saved.clone(),
    })
}

/// The tree with the statuses of its last run, where it was saved, and what was asked
/// and kept.
fn report(
    resolved: &session::Resolved,
    last: Option<&TickRecord>,
    saved: Option<&Path>,
    glyphs: &Glyphs,
) {
    outln!();
    for line in bt::render(&resolved.tree, last, glyphs) {
        outln!("{line}");
    }
    match saved {
        Some(path) => {
            let success = matches!(resolved.ending, Ending::Success { .. });
            let note = if success { "" } else { " (it still fails)" };
            outln!("\nSaved the tree to {}{note}", path.display());
        }
        None => outln!("\nNothing saved: no change was kept."),
    }
    outln!(
        "{} question(s) about failures, {} change(s) kept",
        resolved.rounds,
        resolved.repairs
    );
}

/// A scenario file's stem, as policies are named by it.
fn stem(scenario: &Path) -> String {
    scenario
        .file_stem()
        .map_or_else(|| "tree".into(), |s| s.to_string_lossy().into_owned())
}

fn approve_on_terminal(proposal: &session::Proposal, yes: bool) -> bool {
    if yes {
        outln!("Approve? yes (--yes)");
        return true;
    }
    out!("Approve: {proposal}? [y/N] ");
    super::out::flush();
    let mut line = String::new();
    match std::io::stdin().lock().read_line(&mut line) {
        Ok(0) | Err(_) => {
            outln!("(no answer: not approved)");
            false
        }
        Ok(_) => matches!(line.trim().to_ascii_lowercase().as_str(), "y" | "yes"),
    }
}

fn print_event(event: &Event, show_replies: bool) {
    betr::record::trace(event);
    match event {
        Event::Replied { text, .. } if show_replies => {
            print_event_line(event);
            outln!("  ┌ reply text\n{}\n  └", indent(text));
        }
        _ => print_event_line(event),
    }
}

fn indent(text: &str) -> String {
    text.lines()
        .map(|l| format!("  │ {l}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// One event of the loop on the terminal, in `record::describe`'s words: this chooses
/// which events the printed log shows and lays their lines out (a new step of the loop
/// after a blank line, the model's replies indented under its question).
fn print_event_line(event: &Event) {
    let prefix = match event {
        Event::Asking { .. } => "\n→ ",
        Event::ActionFailed { .. } | Event::Success { .. } | Event::GaveUp { .. } => "\n",
        Event::Replied { .. } | Event::InvalidReply { .. } | Event::CandidateRejected { .. } => {
            "  "
        }
        Event::Goal { .. }
        | Event::Executor { .. }
        | Event::Diverged { .. }
        | Event::Proposal { .. }
        | Event::Repaired { .. }
        | Event::DidNotHelp { .. }
        | Event::Error { .. } => "",
        Event::Rejected => return outln!("Not approved; stopping."),
        Event::ChangeViolates { report, inherited } => {
            outln!(
                "\n✕ The approved change fails verification in the model; it is rejected and undone, not run (counterexample on stderr)"
            );
            if !inherited.is_empty() {
                outln!("  {}", betr::record::describe::not_the_change(inherited));
            }
            let mut err = std::io::stderr();
            if let Err(e) = super::verify_cmd::write_report(&mut err, report, false) {
                tracing::warn!("cannot write the report to stderr: {e}");
            }
            return;
        }
        // What a live front end shows; the printed log keeps to the loop's steps. The
        // readings are listed with the question that asks to choose among them, and a
        // failure is returned by the loop as its error and printed once by `main`.
        _ => return,
    };
    for (i, line) in betr::record::describe(event).iter().enumerate() {
        if i == 0 {
            outln!("{prefix}{line}");
        } else {
            outln!("{line}");
        }
    }
}

fn print_usage(model: &Arc<Metered<Box<dyn LanguageModel>>>) {
    let ledger = model.ledger();
    let log = match (ledger.log_path(), ledger.log_error()) {
        (Some(p), Some(e)) => format!("; NOT logged to {}: {e}", p.display()),
        (Some(p), None) => format!("; logged to {}", p.display()),
        (None, _) => String::new(),
    };
    outln!("LLM usage: {}{log}", ledger.totals());
}
