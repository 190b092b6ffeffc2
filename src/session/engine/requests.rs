//! Model calls as tokio tasks: reading an instruction as a goal, and asking for what a
//! failed action misses. Each call carries an id; its answer comes back as an
//! [`Internal`] message and is ignored when a newer call (or a re-plan) superseded it.

use std::sync::Arc;

use crate::llm::LanguageModel;
use crate::llm::prompt::Context;
use crate::llm::usage::UsageTotals;
use crate::verify::Report;

use super::super::ask::{Asked, FailedAction, Tried, ask_conditions, ask_value, missing_value};
use super::super::evidence::{Evidence, Found};
use super::super::interpret::{Interpretation, interpret};
use super::super::policy::Approval;
use super::super::screen::Screen;
use super::super::types::{Event, SessionError};
use super::{Engine, Failure, Pending, Request};

/// What background work sends back to the engine.
pub(crate) enum Internal {
    Goal {
        id: u64,
        instruction: String,
        result: Result<Interpretation, SessionError>,
        replies: Vec<Reply>,
    },
    Proposal {
        id: u64,
        failure: Failure,
        result: Result<Asked, SessionError>,
        /// What betr found, for the chosen proposal.
        evidence: Option<Box<Evidence>>,
        replies: Vec<Reply>,
    },
    Verified {
        report: Arc<Report>,
        origin: String,
        /// The check of an applied change this answers, if it is one.
        gate: Option<u64>,
    },
}

/// Who answered one call, and its tokens.
#[derive(Debug, Clone)]
pub(crate) struct Reply {
    attribution: String,
    prompt_tokens: u64,
    completion_tokens: u64,
    latency_ms: u64,
}

/// An emitter for a task: forwards events to front ends and notes each reply.
fn forward(
    events: tokio::sync::mpsc::UnboundedSender<Event>,
    replies: &mut Vec<Reply>,
) -> impl FnMut(&Event) + Send + '_ {
    move |e: &Event| {
        if let Event::Replied {
            attribution,
            prompt_tokens,
            completion_tokens,
            latency_ms,
            ..
        } = e
        {
            replies.push(Reply {
                attribution: attribution.clone(),
                prompt_tokens: *prompt_tokens,
                completion_tokens: *completion_tokens,
                latency_ms: *latency_ms,
            });
        }
        let _ = events.send(e.clone());
    }
}

impl Engine {
    fn next_request_id(&mut self) -> u64 {
        self.cancel_request();
        self.next_id += 1;
        self.next_id
    }

    /// Abort the call under way, if any; its answer will be ignored.
    pub(super) fn cancel_request(&mut self) {
        if let Some(r) = self.request.take() {
            r.handle.abort();
            self.notice("the model call under way was cancelled");
        }
    }

    pub(super) fn ask_goal(&mut self, model: Arc<dyn LanguageModel>, instruction: &str) {
        let id = self.next_request_id();
        let scenario = self.scenario.clone();
        // The candidates are checked by planning in a copy of the planning world.
        let world = self.planning.fork();
        let options = self.options.clone();
        let events = self.events.clone();
        let tx = self.internal_tx.clone();
        let instruction = instruction.to_string();
        let handle = tokio::spawn(async move {
            let mut replies = Vec::new();
            let result = {
                let mut emit = forward(events, &mut replies);
                interpret(
                    &scenario,
                    world,
                    &instruction,
                    model.as_ref(),
                    &options,
                    &mut emit,
                )
                .await
            };
            let _ = tx.send(Internal::Goal {
                id,
                instruction,
                result,
                replies,
            });
        });
        self.request = Some(Request { id, handle });
    }

    /// Ask the model what `failure` misses, unless there is no model or the rounds are
    /// used up.
    pub(super) fn ask_about(&mut self, failure: Failure) {
        let model = match self.model.clone() {
            Ok(m) => m,
            Err(why) => {
                return self.notice(format!(
                    "no language model ({why}): press e to type the missing condition(s) yourself"
                ));
            }
        };
        if self.rounds >= self.options.max_rounds {
            return self.emit(Event::GaveUp {
                reason: format!(
                    "{} round(s) asked and {}! still fails: {}",
                    self.rounds, failure.action, failure.error
                ),
            });
        }
        let Some(tree) = self.tree.clone() else {
            return self.error("no tree to change");
        };
        self.rounds += 1;
        let id = self.next_request_id();
        let scenario = self.scenario.clone();
        let facts = self.exec.facts();
        let options = self.options.clone();
        let events = self.events.clone();
        let tx = self.internal_tx.clone();
        let instruction = self
            .task
            .as_ref()
            .and_then(|t| t.instruction.clone())
            .or_else(|| self.task.as_ref().map(|t| t.goal.to_string()))
            .unwrap_or_default();
        let tried: Vec<Tried> = self
            .tried
            .iter()
            .filter(|(f, _)| *f == failure)
            .map(|(_, t)| t.clone())
            .collect();
        // Candidates are tried in a copy of the tree and of the planning world.
        let mut screen = Screen {
            scenario: scenario.clone(),
            tree,
            world: self.planning.fork(),
            failure: failure.clone(),
        };
        let handle = tokio::spawn(async move {
            let mut replies = Vec::new();
            let result = {
                let mut emit = forward(events, &mut replies);
                let ctx = Context {
                    scenario: &scenario,
                    facts: &facts,
                    instruction: &instruction,
                    variant: &options.steps.prompt,
                };
                let failed = FailedAction {
                    node: failure.node,
                    action: &failure.action,
                    error: &failure.error,
                    tried: &tried,
                };
                match missing_value(&scenario, &failure.action, &failure.error) {
                    Some(param) => {
                        ask_value(
                            &ctx,
                            model.as_ref(),
                            &options,
                            &failed,
                            param,
                            &mut screen,
                            &mut emit,
                        )
                        .await
                    }
                    None => {
                        ask_conditions(
                            &ctx,
                            model.as_ref(),
                            &options,
                            &failed,
                            &mut screen,
                            &mut emit,
                        )
                        .await
                    }
                }
            };
            let evidence = result.as_ref().ok().and_then(|asked| {
                let (proposal, reasoning) = asked.chosen.as_ref()?;
                let found = Found {
                    failure: &failure,
                    facts: &facts,
                    shortlist: asked.shortlist.as_ref(),
                    tried: &tried,
                    proposal,
                    verdict: asked.verdict,
                };
                Some(Box::new(Evidence::of(
                    &found,
                    reasoning.as_deref(),
                    &scenario.domain.vocabulary.objects,
                )))
            });
            let _ = tx.send(Internal::Proposal {
                id,
                failure,
                result,
                evidence,
                replies,
            });
        });
        self.request = Some(Request { id, handle });
    }

    pub(super) fn on_internal(&mut self, message: Internal) {
        match message {
            Internal::Verified {
                report,
                origin,
                gate,
            } => self.on_verified(report, origin, gate),
            Internal::Goal {
                id,
                instruction,
                result,
                replies,
            } => {
                self.count(&replies);
                if !self.is_current(id) {
                    return;
                }
                self.request = None;
                match result {
                    Ok(read) => self.on_interpretation(read, instruction),
                    Err(error) => self.emit(Event::Failed { error }),
                }
            }
            Internal::Proposal {
                id,
                failure,
                result,
                evidence,
                replies,
            } => {
                self.count(&replies);
                if !self.is_current(id) {
                    return;
                }
                self.request = None;
                match result {
                    Ok(asked) => {
                        // What did not help in simulation is told to the model next time.
                        for (proposal, why) in asked.rejected {
                            self.tried.push((failure.clone(), Tried { proposal, why }));
                        }
                        let Some((proposal, reasoning)) = asked.chosen else {
                            // No candidate fixed the failure: ask again while rounds remain.
                            return self.ask_about(failure);
                        };
                        let author = asked.author.unwrap_or_else(|| {
                            replies
                                .last()
                                .map_or_else(|| "unknown".into(), |r| r.attribution.clone())
                        });
                        self.emit(Event::Proposal {
                            proposal: proposal.clone(),
                            reasoning,
                            author: author.clone(),
                            evidence,
                        });
                        self.pending = Some(Pending {
                            proposal,
                            author,
                            failure: Some(failure),
                        });
                        if self.auto_approve {
                            self.apply_pending(Approval::Auto);
                        }
                    }
                    Err(error) => self.emit(Event::Failed { error }),
                }
            }
        }
    }

    fn is_current(&self, id: u64) -> bool {
        self.request.as_ref().is_some_and(|r| r.id == id)
    }

    /// Account the replies of a call and report the totals.
    fn count(&mut self, replies: &[Reply]) {
        for r in replies {
            self.usage.calls += 1;
            self.usage.prompt_tokens += r.prompt_tokens;
            self.usage.completion_tokens += r.completion_tokens;
            self.usage.latency_ms += r.latency_ms;
            self.usage.unpriced += 1;
        }
        let totals: UsageTotals = match &self.ledger {
            Some(ledger) => ledger.totals(),
            None => self.usage,
        };
        self.emit(Event::Usage { totals });
    }
}
