//! Questions to the model about a failed action: its missing preconditions, or a missing
//! parameter value. Several candidates are drawn (the first greedy, the rest sampled) and
//! each is tried in simulation before it is offered; what did not help is reported, and
//! told to the model the next time it is asked. Each call emits what was asked and who
//! answered; an unusable reply is reported as an event, not an error.

use crate::bt::NodeId;
use crate::domain::{ActionCall, Condition, ValueParam};
use crate::llm::prompt::Context;
use crate::llm::reply::{self, ReplyError};
use crate::llm::{LanguageModel, Message, OutputConstraint, grammar, schema};
use crate::scenario::Scenario;

use super::super::call::ask;
use super::super::types::{Event, Options, Proposal, Question, SessionError, Shortlist};
use super::screen::{NotHelped, Screen, Verdict};
use super::shortlist::{shortlist, without_implied};
use super::value_bounds::Bounds;
use super::value_levels::{as_levels, level_value};

/// The value parameter a failed action needs, if the failure is about one: a parameter the
/// error names, else one the action has not set.
pub fn missing_value<'a>(
    scenario: &'a Scenario,
    action: &ActionCall,
    error: &str,
) -> Option<&'a ValueParam> {
    let skill = scenario.domain.skill_for(action)?;
    let error = error.to_lowercase();
    skill
        .values
        .iter()
        .find(|v| {
            let name = v.name.to_lowercase();
            error.contains(&name) || error.contains(&name.replace('_', " "))
        })
        .or_else(|| {
            skill
                .values
                .iter()
                .find(|v| action.value(&v.name).is_none())
        })
}

/// What a question about a failure produced.
pub(crate) struct Asked {
    /// The first candidate that fixed the failure in simulation, with the model's
    /// reasoning; `None` when no candidate did.
    pub chosen: Option<(Proposal, Option<String>)>,
    /// Candidates that did not fix it, each with what happened in simulation.
    pub rejected: Vec<(Proposal, String)>,
    /// Replies that could not be read at all.
    pub unusable: usize,
    /// Who wrote the chosen proposal when it was not the model's reply.
    pub author: Option<String>,
    /// The conditions tried in simulation before the model was asked, when they were.
    pub shortlist: Option<Shortlist>,
    /// What the chosen proposal did in simulation.
    pub verdict: Option<Verdict>,
}

/// Who proposes a value midway between values the world refused on either side.
pub const MIDWAY: &str = "betr, midway between values the world refused";

/// How the reason of a value turned away untried begins.
pub const NOT_TRIED: &str = "not tried: ";

/// A change tried for a failure that did not fix it, and what happened.
#[derive(Debug, Clone, PartialEq)]
pub struct Tried {
    pub proposal: Proposal,
    pub why: String,
}

impl std::fmt::Display for Tried {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({})", self.proposal, self.why)
    }
}

/// A failed action as the question about it needs it.
pub(crate) struct FailedAction<'a> {
    pub node: NodeId,
    pub action: &'a ActionCall,
    pub error: &'a str,
    /// Changes already tried for this failure that did not fix it, with what happened.
    pub tried: &'a [Tried],
}

/// Sampling temperature of the extra candidates for a failure: proposals must differ to
/// be worth trying.
const SAMPLE_TEMPERATURE: f32 = 0.8;

/// Reads one reply into a proposal and the reasoning shown with it.
type ReadProposal<'a> = dyn Fn(&str) -> Result<(Proposal, Option<String>), ReplyError> + Sync + 'a;

/// Draw up to `options.candidates` replies to `messages` (the first greedy, the rest
/// sampled), read each with `read`, and try each new proposal in `screen`; stop at the
/// first that fixes the failure. A value that `bounds` rules out is turned away without
/// a try, and what the world says of each value tried tightens `bounds`. A proposal tried
/// before for this failure (`before`: refused by the simulation, verification or a
/// person) is not offered again.
#[allow(clippy::too_many_arguments)]
async fn draw_and_screen(
    model: &dyn LanguageModel,
    messages: Vec<Message>,
    constraint: (OutputConstraint, &(dyn Fn() -> String + Sync)),
    options: &Options,
    (screen, before): (&mut Screen, &[Tried]),
    bounds: &mut Bounds,
    read: &ReadProposal<'_>,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Asked, SessionError> {
    let mut asked = Asked {
        chosen: None,
        rejected: Vec::new(),
        unusable: 0,
        author: None,
        shortlist: None,
        verdict: None,
    };
    let draws = options.candidates.max(1);
    for draw in 0..draws {
        let mut opts = options.clone();
        // Questions about failures choose among conditions tried in simulation: one
        // greedy answer each.
        opts.beams = 1;
        let seed = if draw > 0 {
            opts.temperature = opts.temperature.max(SAMPLE_TEMPERATURE);
            Some(draw as u64)
        } else {
            None
        };
        let r = ask(
            model,
            messages.clone(),
            (constraint.0.clone(), constraint.1),
            &opts,
            seed,
            emit,
        )
        .await?;
        let (proposal, reasoning) = match read(&r.text) {
            Ok(x) => x,
            Err(e) => {
                emit(&Event::InvalidReply {
                    error: e.to_string(),
                });
                asked.unusable += 1;
                continue;
            }
        };
        if asked
            .rejected
            .iter()
            .any(|(p, _)| same_proposal(p, &proposal))
        {
            continue;
        }
        if let Some(t) = before
            .iter()
            .find(|t| same_proposal(&t.proposal, &proposal))
        {
            emit(&Event::CandidateRejected {
                candidate: proposal.to_string(),
                proposal: Some(proposal.clone()),
                reason: format!("tried before: {}", t.why),
                author: None,
            });
            continue;
        }
        if let Some(Err(why)) = value_of(&proposal).map(|v| bounds.admits(v)) {
            let why = format!("{NOT_TRIED}{why}");
            emit(&Event::CandidateRejected {
                candidate: proposal.to_string(),
                proposal: Some(proposal.clone()),
                reason: why.clone(),
                author: None,
            });
            // Told to the model next time like a value tried; its bound is learned already.
            asked.rejected.push((proposal, why));
            continue;
        }
        if !options.steps.screen_proposals {
            asked.chosen = Some((proposal, reasoning));
            return Ok(asked);
        }
        match screen_one(screen, bounds, (&proposal, None), emit) {
            Ok(verdict) => {
                asked.verdict = Some(verdict);
                asked.chosen = Some((proposal, reasoning));
                return Ok(asked);
            }
            Err(why) => asked.rejected.push((proposal, why.to_string())),
        }
    }
    Ok(asked)
}

/// Try `proposal` (by `author`, `None`: the model) in `screen`: how it fixes the
/// failure, else what happened (reported, and learned into `bounds` for a value).
fn screen_one(
    screen: &Screen,
    bounds: &mut Bounds,
    (proposal, author): (&Proposal, Option<&str>),
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Verdict, NotHelped> {
    let why = match screen.try_change(proposal) {
        Ok(verdict) => return Ok(verdict),
        Err(why) => why,
    };
    let told = why.to_string();
    emit(&Event::CandidateRejected {
        candidate: proposal.to_string(),
        proposal: Some(proposal.clone()),
        reason: format!("tried in simulation: {told}"),
        author: author.map(str::to_string),
    });
    if let Some(v) = value_of(proposal) {
        bounds.learn(v, &told);
    }
    Err(why)
}

fn value_of(proposal: &Proposal) -> Option<&crate::domain::Value> {
    match proposal {
        Proposal::Value { value, .. } => Some(value),
        Proposal::Conditions { .. } => None,
    }
}

/// The same change, whatever the order of its conditions.
fn same_proposal(a: &Proposal, b: &Proposal) -> bool {
    match (a, b) {
        (
            Proposal::Conditions { conditions: x, .. },
            Proposal::Conditions { conditions: y, .. },
        ) => x.len() == y.len() && x.iter().all(|c| y.contains(c)),
        _ => a == b,
    }
}

/// Whether `condition` alone was proposed for this failure before and refused.
fn refused_alone(tried: &[Tried], condition: &Condition) -> bool {
    tried.iter().any(|t| {
        matches!(&t.proposal, Proposal::Conditions { conditions, .. }
            if conditions.as_slice() == std::slice::from_ref(condition))
    })
}

pub(crate) async fn ask_conditions(
    ctx: &Context<'_>,
    model: &dyn LanguageModel,
    options: &Options,
    failed: &FailedAction<'_>,
    screen: &mut Screen,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Asked, SessionError> {
    let FailedAction {
        node,
        action,
        error,
        tried,
    } = *failed;
    let screens = options.steps.shortlist && screen.reproduces();
    if options.steps.shortlist && !screens {
        emit(&Event::Notice {
            message: format!(
                "{action}! fails in execution but the tree succeeds in the planning world: no \
                 condition can be tried there, so the model names one from the whole vocabulary"
            ),
        });
    }
    let list = if screens {
        let mut list = shortlist(screen);
        // A fix already proposed for this failure and refused (by the simulation, by
        // verification or by a person) is not offered again: the model chooses under a
        // grammar that allows only the shortlist, so it would choose it again.
        let before = list.fixes.len();
        list.fixes.retain(|c| !refused_alone(tried, c));
        list.refused = before - list.fixes.len();
        // A fix that breaks a property the scenario declares would fail the changed
        // tree's check after approval: left out before anyone is asked, and said.
        list.leave_out_breaking(screen.breaking(&list.fixes));
        emit(&Event::Screened {
            action: action.clone(),
            shortlist: list.clone(),
        });
        Some(list)
    } else {
        None
    };
    let choices = list.as_ref().map(|l| l.fixes.clone()).unwrap_or_default();
    emit(&Event::Asking {
        what: Question::Preconditions {
            action: action.clone(),
        },
    });
    let tried_lines: Vec<String> = tried.iter().map(ToString::to_string).collect();
    let messages = ctx.resolve(&options.templates, action, error, &tried_lines, &choices)?;
    let vocabulary = &ctx.scenario.domain.vocabulary;
    let conditions_grammar = || {
        if choices.is_empty() {
            grammar::conditions_grammar(vocabulary, true)
        } else {
            grammar::chosen_conditions_grammar(&choices)
        }
    };
    let read = |text: &str| {
        reply::conditions(text, vocabulary, options.min_similarity).map(|a| {
            (
                Proposal::Conditions {
                    action: action.clone(),
                    node,
                    conditions: without_implied(a.conditions),
                },
                a.reasoning,
            )
        })
    };
    let mut asked = draw_and_screen(
        model,
        messages,
        (schema::conditions(vocabulary), &conditions_grammar),
        options,
        (screen, tried),
        &mut Bounds::default(),
        &read,
        emit,
    )
    .await?;
    asked.shortlist = list;
    Ok(asked)
}

/// What the world said of the values tried so far bounds the next ones, and so does what
/// it said of the value the action failed with (an executor's world may refuse a value
/// the twin accepted).
fn bounds_for(param: &ValueParam, tried: &[Tried], action: &ActionCall, error: &str) -> Bounds {
    let mut bounds = Bounds::declared(param);
    for t in tried {
        if let Some(v) = value_of(&t.proposal) {
            bounds.learn(v, &t.why);
        }
    }
    if let Some(v) = action.value(&param.name) {
        bounds.learn(v, error);
    }
    bounds
}

pub(crate) async fn ask_value(
    ctx: &Context<'_>,
    model: &dyn LanguageModel,
    options: &Options,
    failed: &FailedAction<'_>,
    param: &ValueParam,
    screen: &mut Screen,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Asked, SessionError> {
    let FailedAction {
        action,
        error,
        tried,
        ..
    } = *failed;
    emit(&Event::Asking {
        what: Question::Value {
            param: param.name.clone(),
            action: action.clone(),
        },
    });
    let mut bounds = bounds_for(param, tried, action, error);
    let unit = param.unit.as_deref().unwrap_or("");
    let summary = bounds.summary(unit);
    let tried_lines: Vec<String> = tried.iter().map(ToString::to_string).collect();
    // The first question about a number asks for a level of the robot's range; once the
    // world has answered, the next ones ask for numbers.
    let levels = if tried.is_empty() && options.steps.value_levels {
        as_levels(param)
    } else {
        None
    };
    let asked_as = levels.as_ref().unwrap_or(param);
    let messages = ctx.value(
        &options.templates,
        action,
        asked_as,
        error,
        (&tried_lines, summary.as_deref()),
    )?;
    let value_grammar = || grammar::value_grammar(asked_as.unit.as_deref(), &asked_as.categories);
    let proposal = |value| Proposal::Value {
        skill: action.skill.clone(),
        object: action.args.first().cloned().unwrap_or_default(),
        param: param.name.clone(),
        value,
    };
    let read = |text: &str| {
        let Some(levelled) = &levels else {
            let a = reply::value(text, param, options.min_similarity)?;
            return Ok((proposal(a.value), a.reasoning));
        };
        // A model that answers a level question with a number (a server without the
        // grammar) is taken at its number.
        let answer = match reply::value(text, levelled, options.min_similarity) {
            Ok(a) => a,
            Err(e) => {
                return reply::value(text, param, options.min_similarity)
                    .map(|a| (proposal(a.value), a.reasoning))
                    .map_err(|_| e);
            }
        };
        let number = level_value(param, &answer.value).ok_or_else(|| ReplyError::BadValue {
            text: answer.value.to_string(),
            reason: "not one of the levels offered".into(),
        })?;
        // The level the model chose is shown with the number it stands for.
        let said = format!("Level {} of what the robot can do: {number}.", answer.value);
        let reasoning = match answer.reasoning {
            Some(r) => format!("{said} {r}"),
            None => said,
        };
        Ok((proposal(number), Some(reasoning)))
    };
    let mut asked = draw_and_screen(
        model,
        messages,
        (schema::value(param), &value_grammar),
        options,
        (screen, tried),
        &mut bounds,
        &read,
        emit,
    )
    .await?;
    if asked.chosen.is_none() && options.steps.screen_proposals {
        try_midway(&mut asked, &mut bounds, screen, unit, &proposal, emit);
    }
    Ok(asked)
}

/// No value of the model's helped, and the world has refused values on both sides: one
/// midway between them is tried too (in simulation, like any other).
fn try_midway(
    asked: &mut Asked,
    bounds: &mut Bounds,
    screen: &mut Screen,
    unit: &str,
    proposal: &dyn Fn(crate::domain::Value) -> Proposal,
    emit: &mut (dyn FnMut(&Event) + Send),
) {
    let Some(midway) = bounds.midway() else {
        return;
    };
    let value = crate::domain::Value::Number {
        value: midway,
        unit: unit.to_string(),
    };
    let between = format!(
        "Midway between the values the world refused on either side: it leaves only values {}.",
        bounds.describe(unit).unwrap_or_default()
    );
    emit(&Event::Notice {
        message: format!("no value of the model's helped; trying {value}, {between}"),
    });
    let midway = proposal(value);
    match screen_one(screen, bounds, (&midway, Some(MIDWAY)), emit) {
        Ok(verdict) => {
            asked.verdict = Some(verdict);
            asked.chosen = Some((midway, Some(between)));
            asked.author = Some(MIDWAY.to_string());
        }
        Err(why) => asked.rejected.push((midway, why.to_string())),
    }
}
