//! Text from HTTP servers made safe to show: the error message an OpenAI-style server
//! sends, shortened, with a secret removed; and the secret itself, an API key that never
//! prints. Shared by the chat and the transcription clients (which otherwise know nothing
//! of each other).

use serde_json::Value as Json;

/// An API key: shown as `<redacted>` by `Debug`, read only where it is sent.
#[derive(Clone)]
pub struct Secret(String);

impl Secret {
    pub fn new(key: impl Into<String>) -> Self {
        Secret(key.into())
    }

    /// The key itself, for the authorization header and for removing it from texts.
    pub fn expose(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Debug for Secret {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Secret(<redacted>)")
    }
}

/// `text` with every occurrence of `secret` replaced (an empty secret changes nothing).
pub fn redact(text: &str, secret: Option<&str>) -> String {
    match secret {
        Some(key) if !key.is_empty() => text.replace(key, "<redacted>"),
        _ => text.to_string(),
    }
}

/// The server's error message (`{"error": {"message": ...}}`, `{"error": "..."}` or
/// `{"message": ...}`), else the whole body; without `secret`, shortened.
pub fn server_message(body: &str, secret: Option<&str>) -> String {
    let message = serde_json::from_str::<Json>(body).ok().and_then(|j| {
        j.pointer("/error/message")
            .or_else(|| j.get("error"))
            .or_else(|| j.get("message"))
            .and_then(Json::as_str)
            .map(str::to_string)
    });
    excerpt(&redact(
        &message.unwrap_or_else(|| body.to_string()),
        secret,
    ))
}

/// Why a response's body was not read.
#[derive(Debug)]
pub enum BodyError {
    /// It passed `limit` bytes (what came was dropped).
    TooLarge {
        limit: usize,
    },
    Transport(reqwest::Error),
}

/// A response's body as text, read a chunk at a time and given up as soon as it passes
/// `limit` bytes, so a server that sends without end costs at most `limit` bytes of
/// memory. Bytes that are not UTF-8 are replaced.
pub async fn read_body(mut response: reqwest::Response, limit: usize) -> Result<String, BodyError> {
    let declared = response.content_length().unwrap_or(0);
    if usize::try_from(declared).map_or(true, |n| n > limit) {
        return Err(BodyError::TooLarge { limit });
    }
    let mut body = Vec::new();
    while let Some(chunk) = response.chunk().await.map_err(BodyError::Transport)? {
        if body.len().saturating_add(chunk.len()) > limit {
            return Err(BodyError::TooLarge { limit });
        }
        body.extend_from_slice(&chunk);
    }
    Ok(String::from_utf8_lossy(&body).into_owned())
}

/// `text` safe to show on a terminal: control characters other than newline and tab
/// (escape sequences, carriage returns, bells) written out as `\u{1b}` instead of
/// reaching the terminal raw.
pub fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(hidden) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        if hidden(c) {
            out.push_str(&format!("\\u{{{:x}}}", u32::from(c)));
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// A character a terminal would act on rather than show.
fn hidden(c: char) -> bool {
    c.is_control() && c != '\n' && c != '\t'
}

/// At most 300 characters of `text`, trimmed and printable; `(empty body)` for nothing.
pub fn excerpt(text: &str) -> String {
    let text = printable(text);
    let t = text.trim();
    match t.char_indices().nth(300) {
        Some((i, _)) => format!("{}…", &t[..i]),
        None if t.is_empty() => "(empty body)".into(),
        None => t.to_string(),
    }
}

#[cfg(test)]
mod printable_tests {
    use super::*;

    #[test]
    fn escape_sequences_and_carriage_returns_are_written_out() {
        assert_eq!(printable("plain\ttext\n"), "plain\ttext\n");
        assert_eq!(
            printable("\u{1b}[2Jgone\rback\u{7}"),
            "\\u{1b}[2Jgone\\u{d}back\\u{7}"
        );
        assert!(!excerpt("\u{1b}]0;title\u{7}").contains('\u{1b}'));
    }
}
