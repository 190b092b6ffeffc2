//! A model that arrives after the session has started: the embedded model fetched (or
//! loaded) while the workbench is already open. Until it is there, every question is
//! refused at once with what it waits for, so nothing in the session blocks on it and
//! everything that needs no model works meanwhile.

use std::sync::{Arc, Mutex, OnceLock};

use super::{ChatFuture, ChatRequest, LanguageModel, LlmError};

pub struct ArrivingModel {
    name: String,
    /// What the model will honour once it is there (the embedded model: a grammar).
    grammar: bool,
    constraint: bool,
    model: OnceLock<Arc<dyn LanguageModel>>,
    /// What it waits for, or why it will not come; said to whoever asks meanwhile.
    waiting: Mutex<String>,
}

impl ArrivingModel {
    /// A model named `name` that is not there yet, for `waiting` (said when asked).
    pub fn new(name: &str, grammar: bool, constraint: bool, waiting: &str) -> ArrivingModel {
        ArrivingModel {
            name: name.to_string(),
            grammar,
            constraint,
            model: OnceLock::new(),
            waiting: Mutex::new(waiting.to_string()),
        }
    }

    /// What a question asked now is told (a fetch's progress, or why it failed).
    pub fn set_waiting(&self, waiting: &str) {
        if let Ok(mut w) = self.waiting.lock() {
            *w = waiting.to_string();
        }
    }

    /// The model is there: every later question goes to it. A second arrival is ignored.
    pub fn arrive(&self, model: Arc<dyn LanguageModel>) {
        if self.model.set(model).is_err() {
            tracing::warn!(model = %self.name, "the model arrived twice; the first stays");
        }
    }

    pub fn has_arrived(&self) -> bool {
        self.model.get().is_some()
    }

    fn not_yet(&self) -> LlmError {
        let waiting = self
            .waiting
            .lock()
            .map(|w| w.clone())
            .unwrap_or_else(|_| "the model is not there yet".into());
        LlmError::NotReady(waiting)
    }
}

impl LanguageModel for ArrivingModel {
    fn model(&self) -> &str {
        self.model.get().map_or(&self.name, |m| m.model())
    }
    fn supports_constraint(&self) -> bool {
        self.model
            .get()
            .map_or(self.constraint, |m| m.supports_constraint())
    }
    fn supports_grammar(&self) -> bool {
        self.model
            .get()
            .map_or(self.grammar, |m| m.supports_grammar())
    }
    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        match self.model.get() {
            Some(model) => model.chat(request),
            None => {
                let error = self.not_yet();
                Box::pin(async move { Err(error) })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::llm::{ChatReply, Message, ReplySource, TokenUsage};

    struct Fixed;
    impl LanguageModel for Fixed {
        fn model(&self) -> &str {
            "fixed-1"
        }
        fn supports_grammar(&self) -> bool {
            true
        }
        fn chat<'a>(&'a self, _: &'a ChatRequest) -> ChatFuture<'a> {
            Box::pin(async move {
                Ok(ChatReply {
                    text: "On_A_B".into(),
                    model: "fixed-1".into(),
                    usage: TokenUsage::default(),
                    latency: Duration::ZERO,
                    source: ReplySource::Model,
                    ranked: Vec::new(),
                })
            })
        }
    }

    fn ask(model: &ArrivingModel) -> Result<ChatReply, LlmError> {
        let request = ChatRequest::new(vec![Message::user("goal?")]);
        tokio::runtime::Builder::new_current_thread()
            .build()
            .unwrap()
            .block_on(model.chat(&request))
    }

    #[test]
    fn questions_are_refused_with_what_it_waits_for_until_the_model_arrives() {
        let model = ArrivingModel::new("fixed-1", true, false, "fetching fixed-1: 0 of 9 MB");
        assert!(model.supports_grammar() && !model.supports_constraint());
        assert_eq!(
            ask(&model).unwrap_err(),
            LlmError::NotReady("fetching fixed-1: 0 of 9 MB".into())
        );
        model.set_waiting("fetching fixed-1: 3 of 9 MB");
        assert!(ask(&model).unwrap_err().to_string().contains("3 of 9 MB"));
        assert!(!model.has_arrived());

        model.arrive(Arc::new(Fixed));
        assert!(model.has_arrived());
        assert_eq!(ask(&model).unwrap().text, "On_A_B");
        assert_eq!(model.model(), "fixed-1");
    }
}
