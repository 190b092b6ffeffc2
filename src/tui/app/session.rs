//! What the session's events do to the app's state, one function per group of events:
//! `on_session` routes each event to its group.

use crate::session::{Event, PhaseKind};

use super::super::components::help::report_lines;
use super::super::components::llm_pane::{Guidance, ProposalView};
use super::super::components::status_bar::Ending;
use super::super::keys::Action;
use super::super::strings;
use super::{App, Overlay, Stuck};

impl App {
    pub fn on_session(&mut self, event: Event) {
        match event {
            e @ (Event::Asking { .. }
            | Event::CallCancelled
            | Event::Replied { .. }
            | Event::InvalidReply { .. }
            | Event::CandidateRejected { .. }
            | Event::Goal { .. }
            | Event::Readings { .. }
            | Event::Usage { .. }) => self.on_model_talk(e),
            e @ (Event::TreeChanged { .. } | Event::Repaired { .. }) => self.on_tree_change(e),
            e @ (Event::ActionFailed { .. }
            | Event::Proposal { .. }
            | Event::Approved
            | Event::Rejected
            | Event::DidNotHelp { .. }
            | Event::GaveUp { .. }
            | Event::PersonDecides { .. }
            | Event::Screened { .. }
            | Event::FixCounts(_)) => self.on_failure_or_proposal(e),
            e @ (Event::Ticked { .. }
            | Event::WorldChanged { .. }
            | Event::RunState { .. }
            | Event::Phase(_)
            | Event::Success { .. }
            | Event::Scene { .. }
            | Event::ArmMotion { .. }
            | Event::Executor { .. }
            | Event::Diverged { .. }) => self.on_world(e),
            e @ (Event::Verified { .. }
            | Event::ChangeViolates { .. }
            | Event::PolicySaved { .. }
            | Event::PolicyLoaded { .. }
            | Event::Exported { .. }) => self.on_policy_or_verification(e),
            e @ (Event::RuleOffered { .. }
            | Event::RuleKept { .. }
            | Event::RuleRefused { .. }
            | Event::Knowledge { .. }) => self.on_knowledge(e),
            e
            @ (Event::Forced { .. } | Event::Breakpoints { .. } | Event::BreakpointHit { .. }) => {
                self.on_debugger(e)
            }
            e @ (Event::Error { .. } | Event::Failed { .. } | Event::Notice { .. }) => {
                self.on_report(e);
            }
            // The engine's notices say these in the log; the report shows what was checked.
            Event::Planned { .. } | Event::Verifying { .. } => {}
        }
    }

    /// The ways on from a failure nothing more is asked about, with the keys as bound.
    fn show_guidance(&mut self) {
        let Some(stuck) = &self.stuck else {
            self.llm.guidance = None;
            return;
        };
        let key = |a: Action| self.keys.key(a).map(|k| k.to_string()).unwrap_or_default();
        let mut ways = vec![(key(Action::Edit), strings::TYPE_THE_FIX.to_string())];
        if stuck.undoable {
            ways.push((key(Action::Undo), strings::UNDO_THE_CHANGE.to_string()));
        }
        ways.push((
            key(Action::Plan),
            strings::plan_from_the_goal(self.refused_fixes),
        ));
        if stuck.rounds_left {
            ways.push((key(Action::Step), strings::STEP_ASKS_AGAIN.to_string()));
        }
        self.llm.guidance = Some(Guidance {
            head: strings::person_decides(&stuck.action, &stuck.why),
            ways,
        });
    }

    /// A way on was taken (a proposal, a question, a changed tree): the guidance goes.
    fn clear_guidance(&mut self) {
        self.stuck = None;
        self.llm.guidance = None;
    }

    /// The model: a question under way, its answer, a goal read, the tokens spent.
    fn on_model_talk(&mut self, event: Event) {
        match event {
            Event::Asking { what } => {
                self.clear_guidance();
                self.llm.error = None;
                self.llm.asking = Some(what.to_string());
                self.llm.asking_since = Some(std::time::Instant::now());
                self.llm.replies_to_question = 0;
            }
            Event::CallCancelled => self.llm.stop_asking(),
            // The question stays shown until the engine leaves it: a reply the checks
            // refuse is followed by another call.
            Event::Replied { attribution, .. } => {
                self.llm.replies_to_question += 1;
                self.llm.replied_by = Some(attribution);
            }
            Event::InvalidReply { error } => self.llm.log(format!("unusable reply: {error}")),
            Event::CandidateRejected {
                candidate, reason, ..
            } => {
                self.llm.log(format!("set aside {candidate}: {reason}"));
            }
            Event::Goal {
                goal,
                reasoning,
                author,
                first_answer,
                doubt,
                ..
            } => {
                self.llm.goal_doubt = doubt;
                if let Some(first) = first_answer {
                    self.llm.log(format!(
                        "the model answered {first} first; the goal kept is {goal}, which the \
                         request's words and the checks agree with"
                    ));
                }
                self.llm.goal = Some(goal.to_string());
                // A model's goal names the model that answered.
                let by = match (author.as_str(), &self.llm.replied_by) {
                    ("model", Some(who)) => who.clone(),
                    _ => author,
                };
                self.llm.goal_by = Some(by);
                self.llm.goal_reasoning = reasoning;
            }
            Event::Readings {
                readings, doubt, ..
            } => {
                self.llm.log(match &doubt {
                    Some(why) => format!("the goal read is doubtful ({why}): approve it or not"),
                    None => format!(
                        "the instruction reads {} ways that make the robot do different things: choose one",
                        readings.len()
                    ),
                });
                // No goal is worked on until the person chooses: the model's first answer
                // is not shown as the goal meanwhile.
                self.llm.goal = None;
                self.llm.goal_by = None;
                self.llm.goal_reasoning = None;
                self.overlay = Some(Overlay::Readings(readings, doubt));
            }
            Event::Usage { totals } => self.status.usage = totals,
            _ => {}
        }
    }

    /// A new tree (planned, repaired, undone, loaded) and what a repair added.
    fn on_tree_change(&mut self, event: Event) {
        self.clear_guidance();
        match event {
            Event::TreeChanged {
                tree,
                new_nodes,
                learned,
                why,
            } => {
                let added = new_nodes.len();
                self.world.values = values_set(&tree);
                self.tree.set_tree(tree, new_nodes, learned);
                self.status.ending = None;
                self.llm.log(if added > 0 {
                    format!("{why}: {added} new node(s)")
                } else {
                    why
                });
            }
            Event::Repaired {
                added_nodes,
                valued_nodes,
            } => {
                self.llm.log(strings::repaired(added_nodes, valued_nodes));
            }
            _ => {}
        }
    }

    /// A failed action and what becomes of the change proposed for it.
    fn on_failure_or_proposal(&mut self, event: Event) {
        match event {
            Event::ActionFailed {
                action,
                node,
                error,
                ..
            } => {
                let text = strings::failed(&action.to_string(), &error);
                self.tree.set_failing(node);
                self.world.last_error = Some(text.clone());
                self.world.error_resolved = false;
                self.status.ending = Some(Ending::Failed);
                self.llm.screened = None;
                self.llm.log(text);
            }
            Event::Screened { action, shortlist } => {
                self.llm.log(shortlist.to_string());
                self.llm.screened = Some((format!("{action}!"), shortlist));
            }
            Event::Proposal {
                proposal,
                reasoning,
                author,
                evidence,
            } => {
                self.clear_guidance();
                self.llm.stop_asking();
                self.llm.proposal = Some(ProposalView::of(&proposal, &author, reasoning, evidence));
            }
            Event::Approved => {
                // The log keeps who proposed what was approved.
                let line = match self.llm.proposal.take() {
                    Some(p) => strings::approved(&p.lines.join(" & "), &p.target, &p.author),
                    None => "approved".to_string(),
                };
                self.llm.log(line);
            }
            Event::Rejected => {
                self.llm.proposal = None;
                self.llm.log(strings::REJECTED);
            }
            Event::DidNotHelp { reason } => {
                self.llm
                    .log(format!("the change did not help and was undone: {reason}"));
            }
            Event::GaveUp { reason } => {
                // A tree that failed with no action failing (a forced status, a condition
                // nothing achieves) has failed as much as one whose action did.
                if self.tree.root_failed() {
                    self.status.ending = Some(Ending::Failed);
                }
                self.llm.log(reason);
            }
            Event::PersonDecides {
                action,
                why,
                rounds_left,
                undoable,
            } => {
                self.llm
                    .log(format!("nothing more is asked about {action}!: {why}"));
                self.stuck = Some(Stuck {
                    action,
                    why,
                    rounds_left,
                    undoable,
                });
                self.show_guidance();
            }
            Event::FixCounts(counts) => {
                self.refused_fixes = counts.refused;
                self.summary.unsaved_fixes = counts.unsaved;
                self.show_guidance();
            }
            _ => {}
        }
    }

    /// The execution world: ticks, facts, a reset, running or not, success.
    fn on_world(&mut self, event: Event) {
        match event {
            Event::Ticked { record } => {
                self.status.ticks = record.tick;
                if self.status.ending == Some(Ending::Stopped) {
                    self.status.ending = None;
                }
                self.tree.set_record(record);
            }
            Event::WorldChanged { facts, reset } => {
                let mut facts: Vec<String> = facts.iter().map(ToString::to_string).collect();
                // Relations between objects first: they change; "near robot" rarely does.
                facts.sort_by_key(|f| std::cmp::Reverse(f.matches('"').count()));
                self.world.set_facts(facts, reset);
                if reset {
                    self.status.ticks = 0;
                    self.status.ending = None;
                    self.world.last_error = None;
                    self.world.motion = None;
                    self.world.diverged = None;
                    self.tree.clear_statuses();
                }
            }
            // Recordings made before the engine told its phase say only this.
            Event::RunState { running: true } => self.status.phase = PhaseKind::Running,
            Event::RunState { running: false } if self.status.phase == PhaseKind::Running => {
                self.status.phase = PhaseKind::Ready;
            }
            Event::Phase(phase) => {
                self.status.phase = phase;
                if !matches!(phase, PhaseKind::Reading | PhaseKind::Asking) {
                    self.llm.stop_asking();
                }
                // What screening found stays while its failure waits.
                if matches!(
                    phase,
                    PhaseKind::Idle | PhaseKind::Ready | PhaseKind::Running
                ) {
                    self.llm.screened = None;
                }
            }
            Event::Success {
                ticks,
                ref executor,
            } => {
                self.status.ending = Some(Ending::Success);
                self.world.error_resolved = true;
                self.llm.log(strings::success(ticks, executor.as_deref()));
            }
            Event::ArmMotion { motion } => self.world.motion = Some(motion),
            Event::Executor { ref name } => {
                self.world.executor = Some(name.clone());
                self.log_described(&event);
            }
            Event::Diverged { ref reality, .. } => {
                self.world.diverged = Some(reality.clone());
                self.log_described(&event);
            }
            // For the 3D view; the world pane shows facts.
            Event::Scene { .. } => {}
            _ => {}
        }
    }

    /// `event` in the log, in `record::describe`'s words.
    fn log_described(&mut self, event: &Event) {
        for line in crate::record::describe(event) {
            self.llm.log(line);
        }
    }

    /// Verification reports, and the policy saved, loaded or exported.
    fn on_policy_or_verification(&mut self, event: Event) {
        match event {
            Event::Verified { report, origin } => {
                let holds = report.holds();
                let mut lines = vec![strings::verified_tree(&origin)];
                lines.extend(report_lines(&report, &self.theme));
                self.overlay = Some(Overlay::Report {
                    title: strings::VERIFY_TITLE,
                    lines,
                });
                self.llm
                    .log(if holds { "verified" } else { "NOT verified" });
            }
            Event::ChangeViolates { report, inherited } => {
                let mut lines = vec![strings::CHANGE_VIOLATES.to_string()];
                if !inherited.is_empty() {
                    lines.push(crate::record::describe::not_the_change(&inherited));
                }
                lines.extend(report_lines(&report, &self.theme));
                self.overlay = Some(Overlay::Report {
                    title: strings::VIOLATION_TITLE,
                    lines,
                });
                self.llm.log(strings::CHANGE_VIOLATES);
            }
            Event::PolicySaved { path, fixes } => {
                self.llm
                    .log(strings::policy_saved(&path.display().to_string(), fixes));
                self.summary.policies.push(path);
            }
            Event::Exported { paths } => {
                let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
                self.llm.log(strings::exported(&names));
                self.summary.exported.extend(paths);
            }
            Event::PolicyLoaded { path, fixes } => {
                self.llm
                    .log(strings::policy_loaded(&path.display().to_string(), fixes));
                self.llm.goal_by = Some(strings::from_policy(&path.display().to_string()));
            }
            _ => {}
        }
    }

    /// Learned rules: an approved fix offered as one, kept, refused, and the kept ones.
    fn on_knowledge(&mut self, event: Event) {
        match event {
            Event::RuleOffered { rule, only, .. } => {
                let key = |a: Action| self.keys.key(a).map(|k| k.to_string()).unwrap_or_default();
                let text = strings::rule_offer(
                    &rule,
                    only.as_deref(),
                    (
                        &key(Action::KeepRule),
                        &key(Action::KeepRuleOnly),
                        &key(Action::DeclineRule),
                    ),
                );
                // Shown where a proposal would be, until it is answered: the log keeps the
                // steps of the repair in view.
                self.llm.offer = Some(text);
            }
            Event::RuleKept { id, rule, path } => {
                self.llm.offer = None;
                let text = strings::rule_kept(&id, &rule, &path.display().to_string());
                self.llm.log(text.clone());
                self.message(text, false);
            }
            Event::RuleRefused { rule, reason } => {
                self.llm.offer = None;
                let text = strings::rule_refused(&rule, &reason);
                self.llm.log(text.clone());
                self.message(text, true);
            }
            Event::Knowledge { path, rules } => {
                let mut lines = vec![strings::knowledge_title(
                    &path.display().to_string(),
                    rules.len(),
                )];
                if rules.is_empty() {
                    lines.push(strings::NO_RULES.to_string());
                }
                lines.extend(rules);
                self.overlay = Some(Overlay::Report {
                    title: strings::RULES_TITLE,
                    lines,
                });
            }
            _ => {}
        }
    }

    /// The debugger: forced statuses, breakpoints, and a run stopped at one.
    fn on_debugger(&mut self, event: Event) {
        match event {
            Event::Forced { forced } => {
                let named: Vec<_> = forced
                    .iter()
                    .map(|(n, s)| (self.tree.label(*n, &self.theme), *s))
                    .collect();
                self.llm.log(strings::forced_list(&named));
                self.tree.set_forced(forced);
            }
            Event::Breakpoints { nodes, on_failure } => {
                if on_failure != self.status.break_on_failure {
                    self.llm.log(strings::break_on_failure(on_failure));
                }
                if nodes != self.tree.breakpoints() {
                    let named: Vec<_> = nodes
                        .iter()
                        .map(|n| self.tree.label(*n, &self.theme))
                        .collect();
                    self.llm.log(strings::breakpoint_list(&named));
                }
                self.status.break_on_failure = on_failure;
                self.tree.set_breakpoints(nodes);
            }
            Event::BreakpointHit {
                node,
                node_path,
                tick,
                reason,
            } => {
                let leaf = self.tree.label(node, &self.theme);
                let text =
                    strings::stopped_at(reason, &leaf, &crate::bt::path_text(&node_path), tick);
                self.tree.set_stopped(node);
                self.status.ending = Some(Ending::Stopped);
                self.llm.log(text.clone());
                self.message(text, false);
            }
            _ => {}
        }
    }

    /// What the engine says in words: an error, a failure of the task, a notice.
    fn on_report(&mut self, event: Event) {
        match event {
            Event::Error { message } => self.show_error(message),
            Event::Failed { error } => {
                self.llm.stop_asking();
                self.llm.error = Some(error.to_string());
                self.llm.log(format!("error: {error}"));
            }
            Event::Notice { message } => self.llm.log(message),
            _ => {}
        }
    }
}

/// The values parameters set on `tree`'s actions, one line each, each action once.
fn values_set(tree: &crate::bt::Tree) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for node in tree.preorder() {
        if let Ok(crate::bt::NodeKind::Action(a)) = tree.kind(node) {
            for (name, value) in &a.values {
                let objects: Vec<String> = a.args.iter().map(|o| format!("\"{o}\"")).collect();
                let line = format!("{} {}: {name} = {value}", a.skill, objects.join(" "));
                if !lines.contains(&line) {
                    lines.push(line);
                }
            }
        }
    }
    lines
}
