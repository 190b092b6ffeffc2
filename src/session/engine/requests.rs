//! Model calls as tokio tasks: reading an instruction as a goal, and asking for what a
//! failed action misses. Each call carries an id; its answer comes back as an
//! [`Internal`] message and is taken only by the phase that started it (a newer call, a
//! re-plan or an undo left that phase, and the answer is ignored).

use std::sync::Arc;

use crate::llm::LanguageModel;
use crate::llm::usage::UsageTotals;
use crate::verify::Report;

use super::super::interpret::{Interpretation, interpret};
use super::super::policy::Approval;
use super::super::repair::ask::{Asked, Tried};
use super::super::repair::question::{Answer, Question};
use super::super::types::{Event, Evidence, SessionError};
use super::Engine;
use super::phase::{Call, Failure, Pending, Phase};

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
        answer: Answer,
        replies: Vec<Reply>,
    },
    Verified {
        report: Arc<Report>,
        origin: String,
        /// The check of an applied change this answers, if it is one.
        gate: Option<u64>,
        /// The same checks of the tree before that change, when there was one.
        before: Option<Arc<Report>>,
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
    pub(super) fn ask_goal(&mut self, model: Arc<dyn LanguageModel>, instruction: &str) {
        let id = self.calls.next_id();
        let scenario = self.settings.scenario.clone();
        // The candidates are checked by planning in a copy of the planning world.
        let world = self.run.planning.fork();
        let options = self.settings.options.clone();
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
        self.enter(Phase::Reading {
            call: Call { id, handle },
        });
    }

    /// Nothing more is asked about `failure` (`why`): it waits for a person, who is told
    /// the ways on.
    pub(super) fn wait_for_person(&mut self, failure: Failure, why: String) {
        self.emit(Event::PersonDecides {
            action: failure.action.to_string(),
            why,
            rounds_left: self.settings.model.is_ok()
                && self.task.rounds < self.settings.options.max_rounds,
            undoable: !self.task.undo.is_empty(),
        });
        self.enter(Phase::Failed { failure });
    }

    /// Ask the model what `failure` misses, unless there is no model or the rounds are
    /// used up: then the failure waits for a person.
    pub(super) fn ask_about(&mut self, failure: Failure) {
        let model = match self.settings.model.clone() {
            Ok(m) => m,
            Err(why) => return self.wait_for_person(failure, format!("no language model ({why})")),
        };
        if self.task.rounds >= self.settings.options.max_rounds {
            let reason = format!(
                "{} round(s) asked and {}! still fails: {}",
                self.task.rounds, failure.action, failure.error
            );
            self.emit(Event::GaveUp { reason });
            let why = format!("{} round(s) asked", self.task.rounds);
            return self.wait_for_person(failure, why);
        }
        let Some(tree) = self.task.tree.clone() else {
            self.error("no tree to change");
            return self.enter(Phase::Failed { failure });
        };
        self.task.rounds += 1;
        let id = self.calls.next_id();
        let question = Question {
            scenario: self.settings.scenario.clone(),
            failure: failure.clone(),
            facts: self.run.exec.facts(),
            instruction: self.task.request_text(),
            tried: self.task.tried_for(&failure),
            tree,
            world: self.run.planning.fork(),
        };
        let options = self.settings.options.clone();
        let events = self.events.clone();
        let tx = self.internal_tx.clone();
        let asked_about = failure.clone();
        let handle = tokio::spawn(async move {
            let mut replies = Vec::new();
            let answer = {
                let mut emit = forward(events, &mut replies);
                question.answer(model.as_ref(), &options, &mut emit).await
            };
            let _ = tx.send(Internal::Proposal {
                id,
                failure: asked_about,
                answer,
                replies,
            });
        });
        self.enter(Phase::Asking {
            failure,
            call: Call { id, handle },
        });
    }

    pub(super) fn on_internal(&mut self, message: Internal) {
        match message {
            Internal::Verified {
                report,
                origin,
                gate,
                before,
            } => self.on_verified(report, origin, gate, before),
            Internal::Goal {
                id,
                instruction,
                result,
                replies,
            } => {
                self.count(&replies);
                if self.phase.call_id() != Some(id) {
                    return;
                }
                self.call_answered(self.settled());
                match result {
                    Ok(read) => self.on_interpretation(read, instruction),
                    Err(error) => self.emit(Event::Failed { error }),
                }
            }
            Internal::Proposal {
                id,
                failure,
                answer,
                replies,
            } => {
                self.count(&replies);
                if self.phase.call_id() != Some(id) {
                    return;
                }
                self.call_answered(Phase::Failed {
                    failure: failure.clone(),
                });
                match answer.result {
                    Ok(asked) => self.on_asked(failure, asked, answer.evidence, &replies),
                    Err(error) => {
                        let why = format!("the model's answer could not be used: {error}");
                        self.emit(Event::Failed { error });
                        self.wait_for_person(failure, why);
                    }
                }
            }
        }
    }

    /// The model answered the question about `failure`: offer the proposal that fixed it
    /// in simulation, or ask again.
    fn on_asked(
        &mut self,
        failure: Failure,
        asked: Asked,
        evidence: Option<Box<Evidence>>,
        replies: &[Reply],
    ) {
        // What did not help in simulation is told to the model next time.
        for (proposal, why) in asked.rejected {
            self.task
                .tried
                .push((failure.clone(), Tried { proposal, why }));
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
        self.enter(Phase::Proposed(Pending {
            proposal,
            author,
            failure: Some(failure),
        }));
        if self.settings.auto_approve {
            self.apply_pending(Approval::Auto);
        }
    }

    /// Account the replies of a call and report the totals.
    fn count(&mut self, replies: &[Reply]) {
        let usage = &mut self.calls.usage;
        for r in replies {
            usage.calls += 1;
            usage.prompt_tokens += r.prompt_tokens;
            usage.completion_tokens += r.completion_tokens;
            usage.latency_ms += r.latency_ms;
            usage.unpriced += 1;
        }
        let totals: UsageTotals = match &self.settings.ledger {
            Some(ledger) => ledger.totals(),
            None => self.calls.usage,
        };
        self.emit(Event::Usage { totals });
    }
}
