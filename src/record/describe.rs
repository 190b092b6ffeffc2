//! An event in words: the one description that the command line's event lines, the log
//! (`tracing`), `betr replay --print`, the replay workbench's status bar and the 3D view's
//! log all show. Front ends choose which events they print and how they lay a line out;
//! the words are these.

use crate::bt::path_text;
use crate::session::{BreakReason, Event};

use super::Step;

/// Where an action was performed: the executor named, else betr's simulation.
fn performed_in(executor: &Option<String>) -> String {
    match executor {
        Some(name) => format!("in the {name} executor"),
        None => "in simulation".to_string(),
    }
}

/// `event` in words, one line each, the line that says what happened last (what precedes
/// it is what led there: a reasoning, betr's findings); none for what only a live screen
/// shows (ticks, world facts, run state, usage, forced statuses, breakpoints), which
/// [`brief`] names.
pub fn describe(event: &Event) -> Vec<String> {
    match event {
        Event::Goal {
            goal,
            reasoning,
            matches_expected,
            first_answer,
            doubt,
            ..
        } => {
            let check = match matches_expected {
                Some(true) => "  (equivalent to the scenario's goal)",
                Some(false) => "  (differs from the scenario's goal)",
                None => "",
            };
            let mut lines: Vec<String> = reasoning
                .iter()
                .map(|r| format!("Reasoning: {r}"))
                .collect();
            lines.push(format!("Goal: {goal}{check}"));
            if let Some(first) = first_answer {
                lines.push(format!(
                    "  (the model answered {first} first; this goal is the one the \
                     request's words and the checks kept)"
                ));
            }
            if let Some(doubt) = doubt {
                lines.push(format!("  ({doubt})"));
            }
            lines
        }
        Event::Proposal {
            proposal,
            reasoning,
            author,
            evidence,
        } => {
            // What betr found comes first; the author's reasoning is labelled as theirs.
            let doubt = evidence.as_ref().and_then(|e| e.doubt.as_deref());
            let mut lines: Vec<String> = evidence
                .iter()
                .flat_map(|e| &e.findings)
                .map(|f| format!("Found: {f}"))
                .collect();
            if let Some(r) = reasoning {
                lines.push(match doubt {
                    Some(why) => format!("Reasoning of {author}, doubtful ({why}): {r}"),
                    None => format!("Reasoning of {author}: {r}"),
                });
            }
            lines.push(format!("Proposal: {proposal} (by {author})"));
            lines
        }
        other => headline(other).into_iter().collect(),
    }
}

/// The one line of an event that says only what happened.
fn headline(event: &Event) -> Option<String> {
    Some(match event {
        Event::TreeChanged { tree, why, .. } => format!("tree ({} nodes): {why}", tree.len()),
        Event::Asking { what } => format!("asking the model for {what}"),
        Event::Replied {
            attribution,
            prompt_tokens,
            completion_tokens,
            latency_ms,
            ..
        } => format!(
            "reply from {attribution}: {prompt_tokens} prompt + {completion_tokens} completion tokens, {:.2} s",
            *latency_ms as f64 / 1000.0
        ),
        Event::InvalidReply { error } => format!("unusable reply: {error}"),
        Event::CandidateRejected {
            candidate, reason, ..
        } => format!("set aside {candidate}: {reason}"),
        Event::ActionFailed {
            action,
            node_path,
            error,
            executor,
            ..
        } => format!(
            "✗ {action}! (node {}) failed {}: {error}",
            path_text(node_path),
            performed_in(executor)
        ),
        Event::Approved => "approved".into(),
        Event::Rejected => "Not approved".into(),
        Event::Repaired {
            added_nodes,
            valued_nodes: 0,
        } => format!("Repaired: {added_nodes} node(s) added"),
        Event::Repaired {
            added_nodes,
            valued_nodes,
        } => {
            format!("Repaired: value set on {valued_nodes} action(s), {added_nodes} node(s) added")
        }
        Event::DidNotHelp { reason } => {
            format!("The change did not help and was undone: {reason}")
        }
        Event::Success { ticks, executor } => {
            format!("✓ SUCCESS {} after {ticks} tick(s)", performed_in(executor))
        }
        Event::GaveUp { reason } => format!("Gave up: {reason}"),
        Event::PersonDecides { action, why, .. } => {
            format!("nothing more is asked about {action}!: {why}; a person decides")
        }
        Event::BreakpointHit {
            node_path,
            tick,
            reason,
            ..
        } => {
            let when = match reason {
                BreakReason::Breakpoint => "at a breakpoint before",
                BreakReason::Failure => "after a failure in",
            };
            format!("stopped {when} tick {tick} (node {})", path_text(node_path))
        }
        other => return about_the_tree(other),
    })
}

/// The lines of what was done with the tree (plans, checks, policies, rules) and what the
/// engine says in words.
fn about_the_tree(event: &Event) -> Option<String> {
    Some(match event {
        Event::Planned { summary } => summary.log_line(),
        Event::Readings {
            readings, doubt, ..
        } => crate::session::interpret::readings::summary(readings, doubt.as_deref()),
        Event::Verified { report, origin } if report.holds() => format!("verified ({origin})"),
        Event::Verified { origin, .. } => format!("NOT verified ({origin})"),
        Event::ChangeViolates { inherited, .. } if inherited.is_empty() => {
            "✕ the approved change fails verification in the model".into()
        }
        Event::ChangeViolates { inherited, .. } => format!(
            "✕ the approved change fails verification in the model; {}",
            not_the_change(inherited)
        ),
        Event::PolicySaved { path, fixes } => {
            format!("policy saved to {} ({fixes} fix(es))", path.display())
        }
        Event::PolicyLoaded { path, fixes } => {
            format!("policy loaded from {} ({fixes} fix(es))", path.display())
        }
        Event::Exported { paths } => format!(
            "exported to {}",
            paths
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        Event::RuleOffered { rule, .. } => format!("offered as a rule: {rule}"),
        Event::RuleKept { id, rule, .. } => format!("kept as rule {id}: {rule}"),
        Event::RuleRefused { rule, reason } => format!("not kept as a rule: {rule}: {reason}"),
        Event::ArmMotion { motion } => {
            let ms = motion.seconds * 1000.0;
            match (motion.length, &motion.blocker) {
                (Some(length), _) => format!(
                    "{} moved: joint path {length:.2} rad, planned in {ms:.1} ms, {} attempt(s)",
                    motion.arm, motion.attempts
                ),
                (None, blocker) => format!(
                    "{} found no path{}: {ms:.1} ms, {} attempt(s)",
                    motion.arm,
                    blocker
                        .as_ref()
                        .map_or(String::new(), |b| format!(", blocked by {b}")),
                    motion.attempts
                ),
            }
        }
        Event::WorldChanged { reset: true, .. } => "the world was reset".into(),
        Event::Error { message } => format!("error: {message}"),
        Event::Failed { error } => format!("error: {error}"),
        Event::Notice { message } => message.clone(),
        Event::Executor { name } => {
            format!("the {name} executor performs the actions; betr's world is its twin")
        }
        Event::Diverged {
            executor,
            action,
            reality,
            ..
        } => crate::executor::describe_divergence(action, executor, reality),
        Event::Screened { action, shortlist } => format!("for {action}!: {shortlist}"),
        _ => return None,
    })
}

/// A replayed step in words: a command as `> command`, an event as [`describe`] says it.
/// Beside a changed tree's failures: those the tree before the change has too.
pub fn not_the_change(inherited: &[String]) -> String {
    format!(
        "not the change's doing (the tree before it fails these too): {}",
        inherited.join("; ")
    )
}

pub fn describe_step(step: &Step) -> Vec<String> {
    match step {
        Step::Command(text) => vec![format!("> {text}")],
        Step::Event(event) => describe(event),
    }
}

/// Any step in one line: the last line of its words, else a short name of what happened.
pub fn brief(step: &Step) -> String {
    if let Some(line) = describe_step(step).pop() {
        return line;
    }
    let Step::Event(event) = step else {
        return String::new();
    };
    match event {
        Event::Ticked { record } => format!("tick {}: root {}", record.tick, record.root),
        Event::WorldChanged { .. } => "the world changed".into(),
        Event::RunState { running: true } => "running".into(),
        Event::RunState { running: false } => "paused".into(),
        Event::Phase(phase) => format!("phase: {phase:?}").to_lowercase(),
        Event::Usage { totals } => format!("model calls so far: {}", totals.calls),
        Event::Forced { forced } => format!("{} node(s) forced", forced.len()),
        Event::Breakpoints { nodes, .. } => format!("{} breakpoint(s)", nodes.len()),
        Event::Verifying { .. } => "verifying".into(),
        Event::Knowledge { rules, .. } => format!("{} rule(s) kept", rules.len()),
        Event::Scene { .. } => "the scene".into(),
        // Every other event has words in `describe`.
        _ => String::new(),
    }
}

/// Write `event`'s words to the log (`tracing`, at debug level), one record a line.
pub fn trace(event: &Event) {
    for line in describe(event) {
        tracing::debug!(target: "betr::event", "{line}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::Question;

    #[test]
    fn a_goal_with_its_reasoning_is_two_lines_the_goal_last() {
        let event = Event::Goal {
            goal: crate::goal::Formula::parse("A & B").unwrap(),
            reasoning: Some("because".into()),
            matches_expected: Some(true),
            author: "model".into(),
            first_answer: None,
            doubt: None,
        };
        assert_eq!(
            describe(&event),
            [
                "Reasoning: because",
                "Goal: A & B  (equivalent to the scenario's goal)"
            ]
        );
        assert_eq!(
            brief(&Step::Event(event)),
            "Goal: A & B  (equivalent to the scenario's goal)"
        );
    }

    #[test]
    fn a_question_names_what_it_asks() {
        let action = crate::domain::ActionCall::parse("grasp \"egg\"").unwrap();
        let event = Event::Asking {
            what: Question::Value {
                param: "force".into(),
                action,
            },
        };
        assert_eq!(
            describe(&event),
            ["asking the model for a value for force of grasp \"egg\"!"]
        );
    }

    #[test]
    fn what_only_a_screen_shows_has_a_brief_name() {
        let step = Step::Event(Event::RunState { running: true });
        assert!(describe_step(&step).is_empty());
        assert_eq!(brief(&step), "running");
        assert_eq!(brief(&Step::Command("run".into())), "> run");
    }
}
