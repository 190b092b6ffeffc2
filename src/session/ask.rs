//! Questions to the model: the goal of an instruction, the missing preconditions of a
//! failed action, a missing parameter value. Each emits what was asked and who answered;
//! an unusable reply is reported as an event, not an error.

use crate::bt::NodeId;
use crate::domain::{ActionCall, Condition, Scenario, ValueParam};
use crate::goal;
use crate::llm::prompt::{self, Context};
use crate::llm::reply::{self, ReplyError, Substitution};
use crate::llm::{ChatReply, LanguageModel, Message, OutputConstraint, grammar, schema};

use super::types::{Event, Options, Proposal, SessionError};

/// Ask the model for the goal `instruction` means in `scenario`, given the facts true now.
pub async fn interpret(
    scenario: &Scenario,
    facts: &[Condition],
    instruction: &str,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<reply::GoalAnswer, SessionError> {
    let ctx = Context {
        scenario,
        facts,
        instruction,
        variant: &options.variant,
    };
    let messages = ctx.goal(&options.templates)?;
    let vocabulary = &scenario.domain.vocabulary;
    let constraint = schema::goal(vocabulary);
    let cot = options.variant.chain_of_thought;
    let goal_grammar = || grammar::goal_grammar(vocabulary, true, cot);
    let mut last = None;
    for _ in 0..options.interpret_attempts.max(1) {
        emit(&Event::Asking {
            what: "the goal of the instruction".into(),
        });
        let r = ask(
            model,
            messages.clone(),
            (constraint.clone(), &goal_grammar),
            options,
            emit,
        )
        .await?;
        match reply::goal(&r.text, &scenario.domain.vocabulary, options.min_similarity) {
            Ok(answer) => {
                let matches_expected = scenario
                    .goal
                    .as_ref()
                    .and_then(|expected| goal::equivalent(expected, &answer.goal).ok());
                emit(&Event::Goal {
                    goal: answer.goal.clone(),
                    reasoning: answer.reasoning.clone(),
                    substitutions: answer.substitutions.clone(),
                    matches_expected,
                });
                return Ok(answer);
            }
            Err(e) => {
                emit(&Event::InvalidReply {
                    error: e.to_string(),
                });
                last = Some(e);
            }
        }
    }
    Err(SessionError::NoGoal {
        attempts: options.interpret_attempts.max(1),
        last: last.unwrap_or(ReplyError::NoConditions),
    })
}

/// Ask, constraining the reply the way the backend can: a grammar for the local model
/// (built only when used), a JSON schema for servers that take one, else plain text.
async fn ask(
    model: &dyn LanguageModel,
    messages: Vec<Message>,
    (schema, grammar): (OutputConstraint, &(dyn Fn() -> String + Sync)),
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<ChatReply, SessionError> {
    let mut request = prompt::request(messages, options.temperature, options.max_tokens);
    if options.grammar && model.supports_grammar() {
        request.constraint = Some(OutputConstraint::Grammar {
            name: "answer".into(),
            gbnf: grammar(),
        });
    } else if options.structured && model.supports_constraint() {
        request.constraint = Some(schema);
    }
    let r = model.chat(&request).await?;
    emit(&Event::Replied {
        attribution: r.attribution(),
        prompt_tokens: r.usage.prompt_tokens,
        completion_tokens: r.usage.completion_tokens,
        latency_ms: u64::try_from(r.latency.as_millis()).unwrap_or(u64::MAX),
        text: r.text.clone(),
    });
    Ok(r)
}

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

pub(crate) type Asked = Option<(Proposal, Option<String>, Vec<Substitution>)>;

/// A failed action as the question about it needs it.
pub(crate) struct FailedAction<'a> {
    pub node: NodeId,
    pub action: &'a ActionCall,
    pub error: &'a str,
    /// Changes already tried for this failure that did not fix it.
    pub tried: &'a [String],
}

pub(crate) async fn ask_conditions(
    ctx: &Context<'_>,
    model: &dyn LanguageModel,
    options: &Options,
    failed: &FailedAction<'_>,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Asked, SessionError> {
    let FailedAction {
        node,
        action,
        error,
        tried,
    } = *failed;
    emit(&Event::Asking {
        what: format!("missing preconditions of {action}!"),
    });
    let messages = ctx.resolve(&options.templates, action, error, tried)?;
    let vocabulary = &ctx.scenario.domain.vocabulary;
    let conditions_grammar = || grammar::conditions_grammar(vocabulary, true);
    let r = ask(
        model,
        messages,
        (schema::conditions(vocabulary), &conditions_grammar),
        options,
        emit,
    )
    .await?;
    Ok(
        match reply::conditions(&r.text, vocabulary, options.min_similarity) {
            Ok(a) => Some((
                Proposal::Conditions {
                    action: action.clone(),
                    node,
                    conditions: a.conditions,
                },
                a.reasoning,
                a.substitutions,
            )),
            Err(e) => {
                emit(&Event::InvalidReply {
                    error: e.to_string(),
                });
                None
            }
        },
    )
}

pub(crate) async fn ask_value(
    ctx: &Context<'_>,
    model: &dyn LanguageModel,
    options: &Options,
    action: &ActionCall,
    param: &ValueParam,
    error: &str,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Asked, SessionError> {
    emit(&Event::Asking {
        what: format!("a value for {} of {action}!", param.name),
    });
    let messages = ctx.value(&options.templates, action, param, error)?;
    let value_grammar = || grammar::value_grammar(param.unit.as_deref(), &param.categories);
    let r = ask(
        model,
        messages,
        (schema::value(param), &value_grammar),
        options,
        emit,
    )
    .await?;
    Ok(match reply::value(&r.text, param, options.min_similarity) {
        Ok(a) => Some((
            Proposal::Value {
                skill: action.skill.clone(),
                object: action.args.first().cloned().unwrap_or_default(),
                param: param.name.clone(),
                value: a.value,
            },
            a.reasoning,
            a.substitutions,
        )),
        Err(e) => {
            emit(&Event::InvalidReply {
                error: e.to_string(),
            });
            None
        }
    })
}
