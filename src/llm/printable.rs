//! Replies made safe to show: a model's text reaches terminals (the workbench's panes,
//! the command line's log), so escape sequences and other control characters in it are
//! written out (`\u{1b}`) before anything else sees the reply. Newlines and tabs stay.

use super::{ChatReply, ChatRequest, LlmError};

/// A model whose replies are printable.
pub struct Printable<M> {
    inner: M,
}

impl<M> Printable<M> {
    pub fn new(inner: M) -> Printable<M> {
        Printable { inner }
    }
}

impl<M: super::LanguageModel> Printable<M> {
    async fn call(&self, request: &ChatRequest) -> Result<ChatReply, LlmError> {
        let mut reply = self.inner.chat(request).await?;
        if let std::borrow::Cow::Owned(text) = crate::http_text::printable(&reply.text) {
            reply.text = text;
        }
        Ok(reply)
    }
}

super::forwarding_model!(impl<M> for Printable<M>);
