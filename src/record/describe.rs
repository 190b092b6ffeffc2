//! A replayed step in one line: what `betr replay --print` lists and what the replay
//! workbench's status bar says about the step it stands on.

use crate::session::Event;

use super::Step;

/// A step in one line; none for what only a live screen shows (ticks, world facts, run
/// state, usage), which [`brief`] names.
pub fn describe(step: &Step) -> Option<String> {
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
            crate::excerpt::excerpt(text.trim(), None)
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

/// Any step in one line: [`describe`]'s words, else a short name of what happened.
pub fn brief(step: &Step) -> String {
    if let Some(text) = describe(step) {
        return text;
    }
    let Step::Event(event) = step else {
        return String::new();
    };
    match event {
        Event::Ticked { record } => format!("tick {}: root {}", record.tick, record.root),
        Event::WorldChanged { reset: true, .. } => "the world was reset".into(),
        Event::WorldChanged { reset: false, .. } => "the world changed".into(),
        Event::RunState { running: true } => "running".into(),
        Event::RunState { running: false } => "paused".into(),
        Event::Usage { totals } => format!("model calls so far: {}", totals.calls),
        Event::Forced { forced } => format!("{} node(s) forced", forced.len()),
        Event::Breakpoints { nodes, .. } => format!("{} breakpoint(s)", nodes.len()),
        Event::Planned { .. } => "planned".into(),
        Event::Verifying { .. } => "verifying".into(),
        Event::Verified { report, .. } if report.holds() => "verified".into(),
        Event::Verified { .. } => "NOT verified".into(),
        Event::ChangeViolates { .. } => "the change fails verification".into(),
        Event::Exported { .. } => "exported".into(),
        Event::RuleOffered { rule, .. } => format!("rule offered: {rule}"),
        Event::RuleKept { rule, .. } => format!("rule kept: {rule}"),
        Event::RuleRefused { rule, .. } => format!("rule refused: {rule}"),
        Event::Knowledge { rules, .. } => format!("{} rule(s) kept", rules.len()),
        Event::Failed { error } => format!("error: {error}"),
        Event::Scene { .. } => "the scene".into(),
        Event::ArmMotion { motion } => format!("arm motion of {}", motion.arm),
        // Every other event has words in `describe`.
        _ => String::new(),
    }
}
