//! Every user-facing text of the workbench, in one place.

use crate::bt::Status;
use crate::session::PhaseKind;

pub const TREE_TITLE: &str = " Behavior tree ";
pub const FOLLOWING: &str = " following the running node ";
pub const SEARCH_TITLE: &str = " Search the tree (Enter finds, Esc cancels) ";

/// On the tree's border when its rows are cut sideways: `«16` when 16 columns are
/// scrolled past on the left, `»` when rows go on past the right edge.
pub fn sideways(scrolled: usize, more_right: bool) -> Option<String> {
    match (scrolled, more_right) {
        (0, false) => None,
        (0, true) => Some(" » ".to_string()),
        (n, false) => Some(format!(" «{n} ")),
        (n, true) => Some(format!(" «{n} » ")),
    }
}

/// Under the tree while a search is on.
pub fn searching(query: &str) -> String {
    format!(" /{query} ")
}

/// Where a search stands, in the status bar.
pub fn found(query: &str, at: usize, of: usize) -> String {
    format!("/{query}: match {at} of {of}")
}

pub fn not_found(query: &str) -> String {
    format!("/{query}: no node's label holds it")
}

pub fn follow(on: bool) -> &'static str {
    if on {
        "following the running node after every tick"
    } else {
        "not following the running node"
    }
}

pub const NOTHING_RUNNING: &str = "no node is running or has failed yet";
pub const TREE_EMPTY: &str = "No tree yet. Press i to type an instruction (or a goal formula), or p to plan the scenario's goal.";
pub const LLM_TITLE: &str = " LLM ";
pub const WORLD_TITLE: &str = " World ";
pub const INPUT_TITLE_IDLE: &str = " Input ";
pub const INPUT_TITLE_INSTRUCTION: &str = " Instruction or goal (Enter submits, Esc cancels) ";
pub const INPUT_TITLE_EDIT: &str = " Edit the proposal (Enter applies, Esc cancels) ";
/// Under the edit line while nothing else is said there.
pub const TAB_COMPLETES: &str = " Tab completes a condition of this scene ";
pub const NO_COMPLETION: &str = "no condition of this scene begins so";

/// The completions left under the edit line: a few, and how many.
pub fn completions(listed: &[&str], count: usize) -> String {
    let more = if count > listed.len() { ", …" } else { "" };
    format!("{count} match: {}{more}", listed.join(", "))
}

/// Under the line while Tab goes through the matches one by one.
pub fn cycling(shown: usize, count: usize) -> String {
    format!("match {shown} of {count} \u{b7} Tab next \u{b7} Shift-Tab back")
}

pub const REJECTED: &str = "rejected: the tree is unchanged; the model is asked again without it (e: type the fix yourself)";
pub const CONFIRM_QUIT_TITLE: &str = " Quit? ";

pub const PLAN_AGAIN_TITLE: &str = " Plan again? ";
pub const KEEP_REFUSED_KEY: char = 'k';
pub const FORGET_REFUSED_KEY: char = 'f';

/// The question before planning again with `count` fixes refused.
pub fn plan_again(count: usize) -> Vec<String> {
    vec![
        format!(
            "Planning again starts the tree afresh; {count} fix(es) were refused for its failures."
        ),
        format!(
            "{KEEP_REFUSED_KEY}  keep them: the model is told them and they are not offered again"
        ),
        format!("{FORGET_REFUSED_KEY}  forget them: ask as if for the first time"),
        "any other key: do not plan".to_string(),
    ]
}

/// What the person can do when nothing more is asked about a failure: the head, then
/// each key with what it does.
pub fn person_decides(action: &str, why: &str) -> String {
    format!("Nothing more is asked about {action}!: {why}. What now:")
}
pub const TYPE_THE_FIX: &str = "type the missing condition(s) or value yourself (Tab completes)";
pub const UNDO_THE_CHANGE: &str = "undo the last change to the tree";
pub const STEP_ASKS_AGAIN: &str = "step: the model is asked again";

/// Planning again, in the guidance: with the refused fixes or without any.
pub fn plan_from_the_goal(refused: usize) -> String {
    if refused == 0 {
        "plan the goal again".to_string()
    } else {
        format!("plan the goal again, keeping the {refused} refused fix(es) or forgetting them")
    }
}

/// Approved fixes no saved policy holds, in the quit question.
pub fn unsaved_fixes(count: usize, save_key: &str) -> String {
    format!(
        "{count} approved fix(es) in the tree are not saved as a policy ({save_key} saves them)."
    )
}

/// A proposal waiting, in the quit question.
pub fn pending_lost(target: &str) -> String {
    format!("The proposal for {target} waits for approval.")
}

pub fn confirm_quit(quit_key: &str) -> String {
    format!("Press {quit_key} again to quit; any other key stays.")
}

/// Where a goal loaded with a policy came from.
pub fn from_policy(path: &str) -> String {
    format!("policy {path}")
}

pub const INPUT_HINT: &str = "press i to type an instruction, d to dictate one, ? for help";
pub const HELP_TITLE: &str = " Keys ";
pub const HELP_FOOTER: &str = "Press any key to close.";

/// The footer of a key list that does not fit: which rows show and how to see the rest.
pub fn help_rows(from: usize, to: usize, of: usize) -> String {
    format!(
        "rows {from}\u{2013}{to} of {of} \u{b7} \u{2191}\u{2193} PgUp PgDn scroll \u{b7} any other key closes"
    )
}
pub const VERIFY_TITLE: &str = " Verification (any key closes) ";
pub const VIOLATION_TITLE: &str = " The change fails verification (any key closes) ";
pub const RULES_TITLE: &str = " Rules learned from approved fixes (any key closes) ";
pub const PROPOSAL_DETAILS_TITLE: &str = " The proposal, whole (any key closes) ";
pub const NODE_DETAILS_TITLE: &str = " The selected node, whole (any key closes) ";
pub const NOTHING_TO_DETAIL: &str =
    "nothing to show whole: no proposal is pending and no node is selected (↑ ↓)";
pub const READINGS_TITLE: &str = " Readings of the instruction (press a number; Esc: none) ";
pub const READINGS_INTRO: &str =
    "The instruction can be read in ways that make the robot do different things:";
pub const READING_DOUBTED: &str =
    "The goal read from the instruction is doubtful; press 1 to work on it anyway:";
pub const NO_READING_CHOSEN: &str =
    "no reading chosen: type the instruction again (i), said otherwise";

pub const NOW_TRUE: &str = "True now:";
/// Before a fact the last tick made true, and one it made false.
pub const MADE_TRUE: &str = "+ ";
pub const MADE_FALSE: &str = "- ";
pub const VALUE_SET: &str = "value set:";
pub const LAST_MOTION: &str = "last motion:";

/// The world pane's row naming what performs the actions.
pub fn performed_by(executor: &str) -> String {
    format!("Performed by the {executor} executor; this world is its twin.")
}

/// The world pane's row of what reality did that the twin did not predict.
pub fn reality_differs(what: &str) -> String {
    format!("Reality differs: {what}")
}

/// The last motion of a real arm in one line: the arm, the joint path's length or what
/// blocked it, how long finding it took and in how many attempts.
pub fn last_motion(m: &crate::world::cell::snapshot::MotionView) -> String {
    let attempts = match m.attempts {
        1 => "1 attempt".to_string(),
        n => format!("{n} attempts"),
    };
    let ms = m.seconds * 1000.0;
    match (m.length, &m.blocker) {
        (Some(length), _) => format!(
            "{LAST_MOTION} {} moved, joint path {length:.2} rad, planned in {ms:.1} ms, {attempts}",
            m.arm
        ),
        (None, Some(blocker)) => format!(
            "{LAST_MOTION} {} found no path, blocked by {blocker}, {ms:.1} ms, {attempts}",
            m.arm
        ),
        (None, None) => format!(
            "{LAST_MOTION} {} found no path (out of reach), {ms:.1} ms, {attempts}",
            m.arm
        ),
    }
}
pub const FILTER_TITLE: &str = " Show the facts holding (Enter filters, empty: all) ";

/// The objects when their names do not fit on a line.
pub fn objects_counted(count: usize) -> String {
    format!("{OBJECTS} {count} (too many to name here)")
}

/// Above the fact table: how many are listed, of how many, and the filter.
pub fn facts_heading(shown: usize, total: usize, filter: Option<&str>) -> String {
    match filter {
        Some(q) => format!("True now: {shown} of {total} holding \"{q}\""),
        None => format!("True now: {total} (+ made true, - made false by the last tick)"),
    }
}

/// Over the fact table scrolled down.
/// The first line of the log when a web viewer shows the session; the address follows
/// on a line of its own, to copy whole.
pub const VIEWER_PAGE: &str = "3D view: open this address in a browser:";

/// Under a proposal cut to fit: which of its rows are shown.
pub fn rows_of(first: usize, last: usize, total: usize) -> String {
    format!("↕ rows {first}–{last} of {total} · D whole")
}

pub fn rows_above(rows: usize) -> String {
    format!("↑ {rows} row(s) above")
}
pub const NOTHING_TRUE: &str = "  (nothing)";
pub const OBJECTS: &str = "Objects:";
pub const LAST_ERROR: &str = "Last error:";
pub const LAST_ERROR_RESOLVED: &str = "Last error (resolved: the tree has succeeded since):";
/// What a failure waits for, in the status bar: in full, and for narrow terminals.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Awaiting {
    pub long: &'static str,
    pub short: &'static str,
}
/// What the status bar says the engine waits for in `phase`; none when it waits for
/// nothing (running, or paused with a tree or none).
pub fn waiting_for(phase: PhaseKind) -> Option<Awaiting> {
    let (long, short) = match phase {
        PhaseKind::Idle | PhaseKind::Ready | PhaseKind::Running => return None,
        PhaseKind::Reading => ("reading the instruction", "reading"),
        PhaseKind::Choosing => ("choose a reading", "choose"),
        PhaseKind::Failed => ("waits for you", "yours"),
        PhaseKind::Asking => ("asking the model", "asking"),
        PhaseKind::Proposed => ("awaiting approval", "approve?"),
        PhaseKind::Checking => ("verifying the change", "verifying"),
        PhaseKind::Violated => (
            "fails verification: approve again, reject or undo",
            "violates",
        ),
    };
    Some(Awaiting { long, short })
}
pub const CHANGE_VIOLATES: &str = "The changed tree fails verification in the model: it does not run until you approve the change again (a) with this counterexample in view, reject it (x: undone, and the model is asked again knowing why), or undo it (u).";
pub const PROPOSAL_FOR: &str = "Proposal for";
pub const NO_PROPOSAL: &str = "No proposal pending.";
pub const ASKING: &str = "asking the model for";
/// Above what betr itself established about a failure.
pub const FOUND_BY_BETR: &str = "Found by betr:";
/// Under the shortlist when no model chooses from it (the question was cancelled or is
/// over).
pub const SHORTLIST_IS_YOURS: &str = "  choose one yourself: the fix line opens with the first";

/// Under the shortlist while the model is asked.
pub fn model_chooses_among(n: usize) -> String {
    if n == 1 {
        "  the model is asked to confirm it".to_string()
    } else {
        format!("  the model is choosing among these {n}")
    }
}
pub const GOAL: &str = "Goal";

/// The LLM pane's border while a proposal waits.
pub fn proposed_title(proposal: &str) -> String {
    format!(" proposed: {proposal} ")
}

/// Who a proposal is by.
pub fn proposal_by(target: &str, author: &str) -> String {
    format!("{PROPOSAL_FOR} {target} (by {author}):")
}

/// Above an author's own reasoning: labelled as theirs, and as doubtful when the
/// evidence does not bear it out.
pub fn reasoning_of(author: &str, doubt: Option<&str>) -> String {
    match doubt {
        Some(why) => format!(
            "Reasoning of {author}, DOUBTFUL ({why}); not the reason, betr's findings above are:"
        ),
        None => format!("Reasoning of {author} (its words; the findings above are betr's):"),
    }
}

/// Under the goal: who wrote it.
pub fn goal_by(author: &str) -> String {
    format!("  from {author}")
}

/// Who answered the last model call.
pub fn last_reply(who: &str) -> String {
    format!("last reply from {who}")
}
pub const LOG: &str = "Log";

/// The marker under a log scrolled up: how many rows are below.
pub fn log_below(rows: usize) -> String {
    format!("↓ {rows} more row(s) below ([ ] scroll, newest at the bottom)")
}

/// A log line said `count` times in a row.
pub fn repeated(line: &str, count: usize) -> String {
    format!("{line} (×{count})")
}

pub const RUNNING: &str = "running";
pub const PAUSED: &str = "paused";
pub const AUTO_APPROVE: &str = "AUTO-APPROVE";
pub const SUCCESS: &str = "SUCCESS";
pub const FAILED: &str = "FAILED";
pub const HELP_WORD: &str = "help";
pub const NEW_MARK: &str = "+";
pub const ADDED_BY_LAST_CHANGE: &str = "+ added by the last change";
pub const FAILED_MARK: &str = "◀ failed";
/// After a node with a breakpoint.
pub const BREAKPOINT_MARK: &str = "● break";
/// After the node a run stopped at.
pub const STOPPED_MARK: &str = "◀ stopped here";
/// In the status bar while a run is stopped at a breakpoint, and while break-on-failure
/// is on.
pub const STOPPED: &str = "STOPPED";
pub const BREAK_ON_FAILURE: &str = "break on failure";
pub const SELECT_A_NODE: &str = "select a node in the tree first (↑ ↓)";

/// One line per navigation key (fixed, not rebindable).
pub const NAVIGATION: &[(&str, &str)] = &[
    ("↑ ↓ / k j", "move in the focused pane (the tree: select)"),
    ("← →", "collapse / expand a node"),
    ("Enter", "toggle a node"),
    ("PgUp PgDn Home End", "scroll the focused pane"),
    ("mouse", "click: focus a pane, select a node; wheel: scroll"),
    ("shift-wheel", "scroll the tree sideways"),
    ("typing: ↑ ↓", "what was submitted before in that line"),
    (
        "typing: Tab",
        "complete a condition; again: the next match (Shift-Tab back)",
    ),
    ("Ctrl-C", "quit"),
];

/// The navigation keys of a replay: the arrows move in the recording, so a node is
/// collapsed and expanded with Enter.
pub const REPLAY_NAVIGATION: &[(&str, &str)] = &[
    ("↑ ↓ / k j", "move in the focused pane (the tree: select)"),
    ("Enter", "collapse / expand a node"),
    ("PgUp PgDn Home End", "scroll the focused pane"),
    ("mouse", "click: focus a pane, select a node; wheel: scroll"),
    ("shift-wheel", "scroll the tree sideways"),
    ("Ctrl-C", "quit"),
];

/// What a key-bound action does, for the help overlay.
pub fn action_help(action: super::keys::Action) -> &'static str {
    use super::keys::Action::*;
    match action {
        Step => "step one tick",
        Run => "run / pause",
        Plan => "plan (the typed goal, else the scenario's)",
        Instruction => "type an instruction or a goal formula",
        Dictate => "dictate an instruction (again: stop; Esc: discard)",
        Approve => "approve the proposal",
        Reject => "reject the proposal",
        Cancel => "cancel the model call under way",
        Edit => "edit the proposal (or type conditions yourself)",
        Undo => "undo the last expansion",
        Verify => "verify the tree",
        Save => "save the policy",
        Load => "load the saved policy",
        Export => "write the tree out as BT.CPP XML and Graphviz DOT",
        KeepRule => "keep the approved fix as a rule for later tasks",
        KeepRuleOnly => "keep the approved fix as a rule for its objects only",
        DeclineRule => "do not keep the approved fix as a rule",
        Knowledge => "show the rules learned from approved fixes",
        Reset => "reset the world",
        Breakpoint => "set / clear a breakpoint on the selected node",
        Force => "force the selected node: failure, success, running, off",
        BreakOnFailure => "break on failure: stop running when a node fails",
        Details => "show whole what a pane cuts: the proposal, else the selected node",
        Follow => "follow the running node after every tick (on / off)",
        WorldUp => "scroll the world's facts up",
        WorldDown => "scroll the world's facts down",
        WorldFilter => "show only the world's facts holding a text",
        Search => "search the tree's labels",
        SearchNext => "the next match of the search",
        SearchPrevious => "the previous match of the search",
        CollapseAll => "collapse every node",
        ExpandAll => "expand every node",
        ExpandToRunning => "collapse all but the way to the running node",
        ScrollLeft => "scroll the tree left (long labels)",
        ScrollRight => "scroll the tree right (long labels)",
        FocusNext => "focus the next pane: tree, proposal, log, world",
        LogUp => "scroll the log to older lines",
        LogDown => "scroll the log to newer lines",
        Help => "show / hide this help",
        Quit => "quit",
        EventForward => "one step forward (an event or a command)",
        EventBack => "one step back",
        TickForward => "forward to the next tick",
        TickBack => "back to the previous tick",
        NextFailure => "forward to the next failed action",
        PreviousFailure => "back to the previous failed action",
        NextModelCall => "forward to the next model call (question or reply)",
        PreviousModelCall => "back to the previous model call",
        Start => "the start of the recording",
        End => "the end of the recording",
    }
}

pub fn status_word(status: Status) -> &'static str {
    match status {
        Status::Idle => "not ticked",
        Status::Running => "running",
        Status::Success => "success",
        Status::Failure => "failure",
        Status::Halted => "halted",
    }
}

pub fn calls(n: usize, tokens: u64, price: f64) -> String {
    format!("{n} call(s), {tokens} tok, ${price:.4}")
}

/// The calls where the status bar has no room for their tokens and price.
pub fn calls_short(n: usize) -> String {
    format!("{n} call(s)")
}

pub fn tick(n: u64) -> String {
    format!("tick {n}")
}

pub fn failed(action: &str, error: &str) -> String {
    format!("{action}! failed: {error}")
}

pub fn policy_loaded(path: &str, fixes: usize) -> String {
    format!("loaded policy {path}: {fixes} approved fix(es), no LLM call needed")
}

pub fn policy_saved(path: &str, fixes: usize) -> String {
    format!("saved policy {path} ({fixes} fix(es))")
}

pub fn verified_tree(origin: &str) -> String {
    format!("Tree: {origin}")
}

pub fn exported(paths: &[String]) -> String {
    format!("tree written to {}", paths.join(" and "))
}

/// An approved proposal in the log, with who proposed it.
pub fn approved(change: &str, target: &str, author: &str) -> String {
    format!("approved {change} for {target} (proposed by {author})")
}

pub fn repaired(added: usize, valued: usize) -> String {
    if valued == 0 {
        format!("repaired: {added} node(s) added")
    } else {
        format!("repaired: value set on {valued} action(s), {added} node(s) added")
    }
}

pub fn success(ticks: u64, executor: Option<&str>) -> String {
    match executor {
        Some(name) => format!("SUCCESS in the {name} executor after {ticks} tick(s)"),
        None => format!("SUCCESS after {ticks} tick(s)"),
    }
}

/// Said in the LLM pane's log when a model fetched while the workbench was open is there.
pub const MODEL_READY: &str = "The model is fetched and loaded: instructions are read from now on.";

pub fn no_robot(why: &str) -> String {
    format!(
        "No robot description: {why}. The cell checks its reach spheres and gripper sweep instead of moving the arms."
    )
}

pub fn no_model(why: &str) -> String {
    format!(
        "No language model: {why}. You can still type goal formulas, plan, tick, and type conditions with e."
    )
}

pub fn keys_file_error(error: &str) -> String {
    format!("key bindings file ignored (defaults kept): {error}")
}

pub const REC_MARK: &str = "● REC";
pub const OPENING_MICROPHONE: &str = "opening the microphone…";
pub const DICTATION_TITLE_STARTING: &str = " Dictation ";
pub const DICTATION_TITLE_TRANSCRIBING: &str = " Dictation: transcribing ";
pub const NO_SOUND_YET: &str = "no sound yet: is the microphone muted?";
pub const DICTATION_BUSY: &str =
    "still transcribing the last recording; wait for it before recording again";
pub const STOP_RECORDING_FIRST: &str =
    "recording: press the dictation key to stop it (Esc discards) before typing";
pub const RECORDING_DISCARDED: &str = "recording discarded";

pub fn dictation_title_recording(key: &str) -> String {
    format!(" Dictation: recording ({key} stops and transcribes, Esc discards) ")
}

pub fn transcribing(seconds: Option<f64>) -> String {
    match seconds {
        Some(s) => format!("transcribing {s:.1} s of audio…"),
        None => "stopping the recording…".to_string(),
    }
}

pub fn dictation_unavailable(why: &str) -> String {
    format!("dictation is not available: {why}")
}

pub fn dictation_failed(why: &str) -> String {
    format!("dictation: {why}")
}

pub fn dictated(audio_seconds: f64, elapsed_seconds: f64, source: &str) -> String {
    format!(
        "dictated {audio_seconds:.1} s in {elapsed_seconds:.1} s ({source}): correct it if needed, Enter submits, Esc discards"
    )
}

pub fn transcript_not_placed(text: &str) -> String {
    format!("dictated while the proposal editor was open, so not placed: {text}")
}

/// The offer to keep an approved fix as a rule, with the keys that answer it.
pub fn rule_offer(rule: &str, only: Option<&str>, keys: (&str, &str, &str)) -> String {
    let (keep, keep_only, decline) = keys;
    match only {
        Some(only) => format!(
            "Keep as a rule for later tasks: {rule}? {keep} keeps it · {keep_only} only: {only} · {decline} keeps nothing"
        ),
        None => format!(
            "Keep as a rule for later tasks: {rule}? {keep} keeps it · {decline} keeps nothing"
        ),
    }
}

pub fn rule_kept(id: &str, rule: &str, path: &str) -> String {
    format!("kept as rule {id}: {rule} (in {path}); later tasks plan with it")
}

pub fn rule_refused(rule: &str, reason: &str) -> String {
    format!("not kept as a rule: {rule}: {reason}")
}

pub fn knowledge_title(path: &str, count: usize) -> String {
    format!(
        "Rules learned from approved fixes ({count}, in {path}; betr knowledge revoke ID takes one out)"
    )
}

pub const NO_RULES: &str =
    "No rules kept yet for this domain: approve a fix, then keep it as a rule.";

/// The mark after a condition a learned rule put in the tree.
pub fn learned_mark(rules: &[String]) -> String {
    format!(" ◆ learned {}", rules.join(", "))
}

/// The mark after a node whose status is forced.
pub fn forced_mark(status: crate::bt::Forced) -> String {
    format!(" ⚑ forced {status}")
}

/// Why a run stopped at a node: `leaf` is the node as the tree shows it.
pub fn stopped_at(
    reason: crate::session::BreakReason,
    leaf: &str,
    node_path: &str,
    tick: u64,
) -> String {
    match reason {
        crate::session::BreakReason::Breakpoint => {
            format!("stopped at a breakpoint: {leaf} (node {node_path}) before tick {tick}")
        }
        crate::session::BreakReason::Failure => {
            format!("stopped on failure: {leaf} (node {node_path}) failed in tick {tick}")
        }
    }
}

pub fn break_on_failure(on: bool) -> &'static str {
    if on {
        "break on failure on: running stops after a tick in which a node fails"
    } else {
        "break on failure off"
    }
}

/// The forced statuses after a change, for the log: each node as the tree shows it.
pub fn forced_list(forced: &[(String, crate::bt::Forced)]) -> String {
    if forced.is_empty() {
        return "no status forced".to_string();
    }
    let each: Vec<String> = forced.iter().map(|(n, s)| format!("{n} {s}")).collect();
    format!("forced: {}", each.join(", "))
}

/// The breakpoints after a change, for the log.
pub fn breakpoint_list(nodes: &[String]) -> String {
    if nodes.is_empty() {
        "no breakpoint".to_string()
    } else {
        format!("breakpoints: {}", nodes.join(", "))
    }
}

pub const REPLAY: &str = "REPLAY";
pub const REPLAY_INPUT_TITLE: &str = " Replay (read-only) ";
pub const REPLAY_TREE_EMPTY: &str = "No tree yet at this point of the recording.";
pub const REPLAY_AT_START: &str = "the start of the recording";
/// Under a proposal in a replay: the answer is further on in the recording.
pub const REPLAY_PROPOSAL_HINT: &str = "recorded: step on to see how it was answered";

/// Where a replay stands: `REPLAY  step 123/4567  tick 42  0:12.345`.
pub fn replay_position(step: usize, steps: usize, tick: u64, ms: u64) -> String {
    format!(
        "{REPLAY}  step {step}/{steps}  tick {tick}  {}",
        replay_time(ms)
    )
}

/// Milliseconds since the session started as `m:ss.mmm`.
pub fn replay_time(ms: u64) -> String {
    format!("{}:{:02}.{:03}", ms / 60_000, (ms / 1000) % 60, ms % 1000)
}

/// The input line of a replay: its keys.
pub fn replay_hint(keys: &[(&str, String)]) -> String {
    let each: Vec<String> = keys.iter().map(|(what, k)| format!("{k} {what}")).collect();
    each.join(" · ")
}

/// A command of the recorded session in the log, as the person gave it.
pub fn replayed_command(text: &str) -> String {
    format!("> {text}")
}

/// A move in a replay that finds nothing to go to.
pub fn replay_nothing(what: &str) -> String {
    format!("no {what}")
}

/// A recording whose last entry was cut (the session did not end cleanly).
pub fn replay_cut(line: usize) -> String {
    format!(
        "the recording ends in a partial entry at line {line} (the session did not end cleanly); replayed up to it"
    )
}
