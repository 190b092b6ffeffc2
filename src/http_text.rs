//! Text from HTTP servers made safe to show: the error message an OpenAI-style server
//! sends, shortened, with a secret removed; and the secret itself, an API key that never
//! prints. Shared by the chat and the transcription clients (which otherwise know nothing
//! of each other). Every secret made is also kept out of what betr writes — files, logs,
//! the command line's output — by [`without_secrets`], while what betr reads (a model's
//! reply) is left as it came.

use std::borrow::Cow;
use std::sync::RwLock;

use serde_json::Value as Json;

/// Secrets shorter than this are placeholders (`x`, `test`, for a server that checks
/// nothing), and taking them out of what betr writes would take letters out of its
/// words and JSON: they are kept out of messages only ([`redact`]).
pub const SHORTEST_SECRET: usize = 8;

/// The secrets of this process, kept out of everything it writes.
static SECRETS: RwLock<Vec<String>> = RwLock::new(Vec::new());

/// An API key: shown as `<redacted>` by `Debug`, read only where it is sent.
#[derive(Clone)]
pub struct Secret(String);

impl Secret {
    pub fn new(key: impl Into<String>) -> Self {
        let key = key.into();
        if key.chars().count() >= SHORTEST_SECRET
            && let Ok(mut secrets) = SECRETS.write()
            && !secrets.contains(&key)
        {
            secrets.push(key.clone());
        }
        Secret(key)
    }

    /// The key itself, for the authorization header and for removing it from texts.
    pub fn expose(&self) -> &str {
        &self.0
    }
}

impl PartialEq for Secret {
    fn eq(&self, other: &Secret) -> bool {
        self.0 == other.0
    }
}

/// The key a client sends and where it came from, for its messages: the key in the
/// variable `env_name` names (read through `var`), else the one the base URL carried.
/// The source is `None` when no variable is named and the URL has no key.
pub fn chosen_key(
    env_name: Option<&str>,
    var: &dyn Fn(&str) -> Option<String>,
    url_key: Option<&Secret>,
) -> (Option<Secret>, Option<String>) {
    let from_env = env_name
        .and_then(var)
        .filter(|k| !k.is_empty())
        .map(Secret::new);
    let source = match (&from_env, url_key) {
        (None, Some(_)) => Some("the base URL".to_string()),
        _ => env_name.map(|n| match from_env {
            Some(_) => n.to_string(),
            None => format!("{n}, which is not set"),
        }),
    };
    (from_env.or_else(|| url_key.cloned()), source)
}

/// A URL with the credentials it carries (`http://user:KEY@host/v1`) taken out: the URL
/// without them, and the password (else the user name) as a secret, to be sent and
/// redacted as a key is. A URL without credentials, or one that does not parse, is
/// given back as it is.
pub fn split_credentials(url: &str) -> (String, Option<Secret>) {
    let Ok(mut parsed) = reqwest::Url::parse(url) else {
        return (url.to_string(), None);
    };
    let secret = match (parsed.username(), parsed.password()) {
        (_, Some(password)) if !password.is_empty() => password.to_string(),
        (user, _) if !user.is_empty() => user.to_string(),
        _ => return (url.to_string(), None),
    };
    let secret = percent_decoded(&secret);
    if parsed.set_username("").is_err() || parsed.set_password(None).is_err() {
        return (url.to_string(), None);
    }
    let mut clean = parsed.to_string();
    // `Url` writes a root path as `/`; a base URL given without one keeps its form.
    if !url.trim_end().ends_with('/') && clean.ends_with('/') {
        clean.pop();
    }
    (clean, Some(Secret::new(secret)))
}

/// `%XX` escapes of a URL's user information turned back into bytes.
fn percent_decoded(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(b)) => {
                out.push(b);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

impl std::fmt::Debug for Secret {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Secret(<redacted>)")
    }
}

/// `text` with every occurrence of `secret` replaced (an empty secret changes nothing),
/// for what betr writes: messages and logs, never a reply it reads.
pub fn redact(text: &str, secret: Option<&str>) -> String {
    match secret {
        Some(key) if !key.is_empty() => text.replace(key, "<redacted>"),
        _ => text.to_string(),
    }
}

/// `text` with every secret this process made (of at least [`SHORTEST_SECRET`]
/// characters) replaced: for what betr writes to files, logs and the terminal.
pub fn without_secrets(text: &str) -> Cow<'_, str> {
    let Ok(secrets) = SECRETS.read() else {
        return Cow::Borrowed(text);
    };
    if !secrets.iter().any(|k| text.contains(k.as_str())) {
        return Cow::Borrowed(text);
    }
    let mut out = text.to_string();
    for key in secrets.iter() {
        out = out.replace(key.as_str(), "<redacted>");
    }
    Cow::Owned(out)
}

/// A writer that keeps the process's secrets out of what it writes (the log's). Each
/// write is taken as text on its own: the log writes an event in one piece.
pub struct WithoutSecrets<W>(pub W);

impl<W: std::io::Write> std::io::Write for WithoutSecrets<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match std::str::from_utf8(buf).map(without_secrets) {
            Ok(Cow::Owned(text)) => self.0.write_all(text.as_bytes())?,
            _ => self.0.write_all(buf)?,
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
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
/// (escape sequences, carriage returns, bells) and the marks that reorder text (U+202E
/// and the other bidirectional controls) written out as `\u{1b}` instead of reaching the
/// terminal raw.
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

/// A character a terminal would act on rather than show, or one that makes the text
/// around it show in another order than it is read (embeddings, overrides, isolates).
fn hidden(c: char) -> bool {
    (c.is_control() && c != '\n' && c != '\t')
        || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
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
    fn the_environment_key_wins_over_the_url_and_the_source_is_named() {
        let url = Secret::new("sk-URL");
        let env = |k: &str| (k == "K").then(|| "sk-ENV".to_string());
        let (key, from) = chosen_key(Some("K"), &env, Some(&url));
        assert_eq!(
            (key.as_ref().map(Secret::expose), from.as_deref()),
            (Some("sk-ENV"), Some("K"))
        );
        let (key, from) = chosen_key(Some("UNSET"), &env, Some(&url));
        assert_eq!(
            (key.as_ref().map(Secret::expose), from.as_deref()),
            (Some("sk-URL"), Some("the base URL"))
        );
        let (key, from) = chosen_key(Some("UNSET"), &env, None);
        assert!(key.is_none());
        assert_eq!(from.as_deref(), Some("UNSET, which is not set"));
    }

    #[test]
    fn credentials_in_a_url_are_taken_out_as_a_secret() {
        let (url, key) = split_credentials("http://user:sk-KEY%21@127.0.0.1:8080/v1");
        assert_eq!(url, "http://127.0.0.1:8080/v1");
        assert_eq!(key.map(|k| k.expose().to_string()), Some("sk-KEY!".into()));
        let (url, key) = split_credentials("https://sk-only@api.example.com/v1");
        assert_eq!(url, "https://api.example.com/v1");
        assert_eq!(key.map(|k| k.expose().to_string()), Some("sk-only".into()));
        let (url, key) = split_credentials("http://127.0.0.1:8080/v1");
        assert_eq!((url.as_str(), key), ("http://127.0.0.1:8080/v1", None));
        let (url, key) = split_credentials("not a url");
        assert_eq!((url.as_str(), key), ("not a url", None));
    }

    #[test]
    fn escape_sequences_and_carriage_returns_are_written_out() {
        assert_eq!(printable("plain\ttext\n"), "plain\ttext\n");
        assert_eq!(
            printable("\u{1b}[2Jgone\rback\u{7}"),
            "\\u{1b}[2Jgone\\u{d}back\\u{7}"
        );
        assert!(!excerpt("\u{1b}]0;title\u{7}").contains('\u{1b}'));
        assert_eq!(printable("abc\u{202e}def"), "abc\\u{202e}def");

        // What betr writes never carries a secret it made; a placeholder key is no secret.
        let _key = Secret::new("sk-printable-test-key");
        let _placeholder = Secret::new("test");
        assert_eq!(
            without_secrets("key sk-printable-test-key, test tube"),
            "key <redacted>, test tube"
        );
        let mut log = WithoutSecrets(Vec::new());
        std::io::Write::write_all(&mut log, b"sent sk-printable-test-key").unwrap();
        assert_eq!(log.0, b"sent <redacted>");
        assert_eq!(printable("tree ├─ ✓ ü"), "tree ├─ ✓ ü");
    }
}
