//! Record and replay. A cassette is a JSONL file; each line holds one request and its
//! reply, keyed by (model, prompt hash), and names the model that produced the reply (or
//! says the reply was hand-written). Recording wraps a live backend and appends each entry
//! as one whole line (`store::append_line`), or, reusing, first answers from the file what
//! it already holds for that model (an evaluation re-run with one rule changed asks the
//! model only the questions that changed); replay answers from the file and fails
//! loudly on a miss, never calling a model. A cut last line (a recording killed midway)
//! is left out and reported.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::{ChatFuture, ChatReply, ChatRequest, LanguageModel, LlmError, ReplySource, TokenUsage};

/// One line of a cassette.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// The model the request was made for.
    pub model: String,
    /// The model the reply says produced it.
    #[serde(default)]
    pub reply_model: String,
    pub prompt_hash: String,
    pub request: ChatRequest,
    pub reply: String,
    pub usage: TokenUsage,
    pub latency_ms: u64,
    pub source: ReplySource,
    pub recorded_unix: u64,
    /// The answers a beam search ranked, best first, when it was asked for.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ranked: Vec<(String, f64)>,
}

/// The key of a request: the SHA-256 of its canonical JSON (messages, temperature, token
/// limit, stop sequences and output constraint), in hex.
pub fn prompt_hash(request: &ChatRequest) -> String {
    let canonical = serde_json::to_string(request).unwrap_or_default();
    let digest = Sha256::digest(canonical.as_bytes());
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// A line of a cassette that is not an entry.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {detail}")]
pub struct EntryError {
    /// 1-based.
    pub line: usize,
    pub detail: String,
}

/// A cassette's entries read back.
#[derive(Debug, Clone, PartialEq)]
pub struct Entries {
    /// In order.
    pub entries: Vec<Entry>,
    /// The number of a cut last line that was left out.
    pub cut_at: Option<usize>,
}

/// The entries of a cassette's text, in order; blank lines are skipped, and a last line
/// without its newline that does not read (a recording killed midway) is left out and
/// reported in `cut_at`. Any other line that is not an entry is an error naming it.
pub fn read_entries(text: &str) -> Result<Entries, EntryError> {
    let read = crate::store::read_lines(text, 1, |line| {
        let entry: Entry = serde_json::from_str(line).map_err(|e| e.to_string())?;
        // A number beyond f32 reads as an infinite temperature, which JSON cannot hold:
        // the entry could not be written again, nor its request hashed as recorded.
        if !entry.request.temperature.is_finite() {
            return Err("the request's temperature is not a finite number".to_string());
        }
        Ok(entry)
    })
    .map_err(|(line, detail)| EntryError { line, detail })?;
    Ok(Entries {
        entries: read.items.into_iter().map(|(_, e)| e).collect(),
        cut_at: read.cut_at,
    })
}

/// Wraps a backend and appends every successful exchange to a cassette.
pub struct Recorder<M> {
    inner: M,
    path: PathBuf,
    lock: std::sync::Mutex<()>,
    /// The exchanges already in the cassette for this model, by prompt hash, answered
    /// without asking it; when reusing, each exchange recorded since joins them, so a
    /// prompt asked twice in one run is asked once (empty unless reusing).
    known: std::sync::Mutex<HashMap<String, Entry>>,
    reusing: bool,
}

impl<M: LanguageModel> Recorder<M> {
    /// A recorder appending to `path`, which is opened for appending (made, empty, when
    /// missing) before any model is asked: a cassette that cannot be written is an error
    /// now, not after a call that was paid for.
    pub fn new(inner: M, path: impl Into<PathBuf>) -> Result<Self, LlmError> {
        let path = path.into();
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| LlmError::Cassette {
                path: path.display().to_string(),
                detail: e.to_string(),
            })?;
        }
        std::fs::File::options()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| LlmError::Cassette {
                path: path.display().to_string(),
                detail: format!("cannot be written: {e}"),
            })?;
        Ok(Recorder {
            inner,
            path,
            lock: std::sync::Mutex::new(()),
            known: std::sync::Mutex::new(HashMap::new()),
            reusing: false,
        })
    }

    /// A recorder that answers what the cassette already holds for `inner`'s model from
    /// it (as recorded replies) and asks `inner` the rest, appending those. A cassette
    /// that does not exist yet is empty; one that does not read is an error naming the
    /// line.
    pub fn reusing(inner: M, path: impl Into<PathBuf>) -> Result<Self, LlmError> {
        let path = path.into();
        let err = |detail: String| LlmError::Cassette {
            path: path.display().to_string(),
            detail,
        };
        let text = match crate::store::read_text(&path, crate::store::LOG_FILE_BYTES) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) => return Err(err(e.to_string())),
        };
        let read = read_entries(&text).map_err(|e| err(e.to_string()))?;
        let model = inner.model().to_string();
        // A prompt recorded twice (by runs that did not reuse) is answered by its first
        // recording, as the run that recorded it first was answered.
        let mut known: HashMap<String, Entry> = HashMap::new();
        for e in read.entries.into_iter().filter(|e| e.model == model) {
            known.entry(e.prompt_hash.clone()).or_insert(e);
        }
        let mut recorder = Recorder::new(inner, path)?;
        recorder.known = std::sync::Mutex::new(known);
        recorder.reusing = true;
        Ok(recorder)
    }

    async fn call(&self, request: &ChatRequest) -> Result<ChatReply, LlmError> {
        let hash = prompt_hash(request);
        if let Some(reply) = self.known_reply(&hash) {
            return Ok(reply);
        }
        let reply = self.inner.chat(request).await?;
        let entry = Entry {
            model: self.inner.model().to_string(),
            reply_model: reply.model.clone(),
            prompt_hash: hash.clone(),
            request: request.clone(),
            reply: reply.text.clone(),
            usage: reply.usage,
            latency_ms: u64::try_from(reply.latency.as_millis()).unwrap_or(u64::MAX),
            source: reply.source.clone(),
            recorded_unix: super::usage::unix_now(),
            ranked: reply.ranked.clone(),
        };
        // The call is paid for and its reply is used: a cassette that cannot take it (a
        // full disk) fails the command at its end, naming the file, not the work now.
        if let Err(e) = self.append(&entry) {
            tracing::error!(path = %self.path.display(), error = %e, "cannot append to the cassette");
            let why = match e {
                LlmError::Cassette { detail, .. } => detail,
                other => other.to_string(),
            };
            crate::store::note_unwritten(&self.path, &why);
        }
        if self.reusing
            && let Ok(mut known) = self.known.lock()
        {
            known.insert(hash, entry);
        }
        Ok(reply)
    }

    /// The reply recorded for the prompt hashed `hash`, when reusing one.
    fn known_reply(&self, hash: &str) -> Option<ChatReply> {
        let known = self.known.lock().ok()?;
        Some(recorded_reply(known.get(hash)?, Instant::now()))
    }

    fn append(&self, entry: &Entry) -> Result<(), LlmError> {
        let err = |e: String| LlmError::Cassette {
            path: self.path.display().to_string(),
            detail: e,
        };
        let line = serde_json::to_string(entry).map_err(|e| err(e.to_string()))?;
        let _guard = self.lock.lock().map_err(|_| err("lock poisoned".into()))?;
        crate::store::append_line(&self.path, &line).map_err(|e| err(e.to_string()))
    }
}

super::forwarding_model!(impl<M> for Recorder<M>);

/// Answers from a cassette.
#[derive(Debug)]
pub struct Replay {
    path: PathBuf,
    model: String,
    structured: bool,
    grammar: bool,
    entries: HashMap<(String, String), Entry>,
}

impl Replay {
    /// Read a cassette. `model` selects the recordings of that model; without it, the
    /// cassette must hold exactly one model.
    pub fn open(path: &Path, model: Option<&str>, structured: bool) -> Result<Replay, LlmError> {
        let text = crate::store::read_text(path, crate::store::LOG_FILE_BYTES).map_err(|e| {
            LlmError::Cassette {
                path: path.display().to_string(),
                detail: e.to_string(),
            }
        })?;
        Self::from_text(path, &text, model, structured)
    }

    /// A cassette from its text, as if read from `path` (which names it in errors).
    pub fn from_text(
        path: &Path,
        text: &str,
        model: Option<&str>,
        structured: bool,
    ) -> Result<Replay, LlmError> {
        let err = |detail: String| LlmError::Cassette {
            path: path.display().to_string(),
            detail,
        };
        let read = read_entries(text).map_err(|e| err(e.to_string()))?;
        if let Some(line) = read.cut_at {
            tracing::warn!(
                path = %path.display(),
                line,
                "the cassette's last line was cut (a recording stopped midway); it is left out"
            );
        }
        // Of a prompt recorded twice, the first recording answers (as a reusing recorder).
        let mut entries = HashMap::new();
        for entry in read.entries {
            entries
                .entry((entry.model.clone(), entry.prompt_hash.clone()))
                .or_insert(entry);
        }
        let mut models: Vec<&str> = entries.keys().map(|(m, _)| m.as_str()).collect();
        models.sort_unstable();
        models.dedup();
        let model = match (model, models.as_slice()) {
            (Some(m), _) => m.to_string(),
            (None, [only]) => (*only).to_string(),
            (None, []) => return Err(err("the cassette is empty".into())),
            (None, many) => {
                return Err(err(format!(
                    "the cassette holds several models ({}); choose one with --model",
                    many.join(", ")
                )));
            }
        };
        // A cassette recorded from a grammar-constrained model replays only requests that
        // carry the same grammar, so replay asks for grammars exactly when it holds some.
        let grammar = entries.iter().any(|((m, _), e)| {
            *m == model
                && matches!(
                    e.request.constraint,
                    Some(super::OutputConstraint::Grammar { .. })
                )
        });
        Ok(Replay {
            path: path.to_path_buf(),
            model,
            structured,
            grammar,
            entries,
        })
    }

    fn answer(&self, request: &ChatRequest) -> Result<ChatReply, LlmError> {
        let started = Instant::now();
        let hash = prompt_hash(request);
        let Some(entry) = self.entries.get(&(self.model.clone(), hash.clone())) else {
            return Err(LlmError::CassetteMiss {
                path: self.path.display().to_string(),
                model: self.model.clone(),
                hash,
            });
        };
        Ok(recorded_reply(entry, started))
    }
}

/// The reply a cassette's entry gives back: marked as recorded (or hand-written).
fn recorded_reply(entry: &Entry, started: Instant) -> ChatReply {
    let source = match &entry.source {
        ReplySource::Model | ReplySource::Recorded => ReplySource::Recorded,
        hand @ ReplySource::HandWritten { .. } => hand.clone(),
    };
    ChatReply {
        text: entry.reply.clone(),
        model: if entry.reply_model.is_empty() {
            entry.model.clone()
        } else {
            entry.reply_model.clone()
        },
        usage: entry.usage,
        latency: started.elapsed(),
        source,
        ranked: entry.ranked.clone(),
    }
}

impl LanguageModel for Replay {
    fn model(&self) -> &str {
        &self.model
    }
    fn supports_constraint(&self) -> bool {
        self.structured
    }
    fn supports_grammar(&self) -> bool {
        self.grammar
    }
    fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
        Box::pin(std::future::ready(self.answer(request)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llm::Message;
    use std::time::Duration;

    struct Echo;
    impl LanguageModel for Echo {
        fn model(&self) -> &str {
            "echo-1"
        }
        fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
            let text = request.messages[0].content.to_uppercase();
            Box::pin(async move {
                Ok(ChatReply {
                    ranked: Vec::new(),
                    text,
                    model: "echo-1".into(),
                    usage: TokenUsage {
                        prompt_tokens: 4,
                        completion_tokens: 2,
                    },
                    latency: Duration::from_millis(3),
                    source: ReplySource::Model,
                })
            })
        }
    }

    fn block<F: std::future::Future>(f: F) -> F::Output {
        tokio::runtime::Builder::new_current_thread()
            .build()
            .unwrap()
            .block_on(f)
    }

    #[test]
    fn records_then_replays_and_misses_loudly() {
        let dir = std::env::temp_dir().join(format!("betr-cassette-{}", std::process::id()));
        let path = dir.join("c.jsonl");
        let _ = std::fs::remove_file(&path);
        let a = ChatRequest::new(vec![Message::user("goal please")]);
        let b = ChatRequest::new(vec![Message::user("other")]);
        let rec = Recorder::new(Echo, &path).unwrap();
        assert_eq!(block(rec.chat(&a)).unwrap().text, "GOAL PLEASE");
        let replay = Replay::open(&path, None, false).unwrap();
        assert_eq!(replay.model(), "echo-1");
        let r = block(replay.chat(&a)).unwrap();
        assert_eq!(r.text, "GOAL PLEASE");
        assert_eq!(r.source, ReplySource::Recorded);
        assert!(r.attribution().contains("echo-1"));
        let miss = block(replay.chat(&b)).unwrap_err();
        assert!(matches!(miss, LlmError::CassetteMiss { .. }), "{miss}");
        let other = Replay::open(&path, Some("gpt-x"), false).unwrap();
        assert!(block(other.chat(&a)).is_err());
        // Of a prompt recorded twice, the first recording answers.
        let text = std::fs::read_to_string(&path).unwrap();
        let line = text.lines().next().unwrap();
        let later = line.replace("GOAL PLEASE", "LATER");
        assert_ne!(line, later);
        std::fs::write(&path, format!("{line}\n{later}\n")).unwrap();
        let twice = Replay::open(&path, None, false).unwrap();
        assert_eq!(block(twice.chat(&a)).unwrap().text, "GOAL PLEASE");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Counts the calls that reach it.
    struct Counting(std::sync::atomic::AtomicUsize);
    impl LanguageModel for Counting {
        fn model(&self) -> &str {
            "echo-1"
        }
        fn chat<'a>(&'a self, request: &'a ChatRequest) -> ChatFuture<'a> {
            self.0.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            Echo.chat(request)
        }
    }

    #[test]
    fn reusing_asks_only_what_the_cassette_lacks_and_records_it() {
        let dir = std::env::temp_dir().join(format!("betr-cassette-reuse-{}", std::process::id()));
        let path = dir.join("c.jsonl");
        let _ = std::fs::remove_file(&path);
        let a = ChatRequest::new(vec![Message::user("goal please")]);
        let b = ChatRequest::new(vec![Message::user("other")]);
        block(Recorder::new(Echo, &path).unwrap().chat(&a)).unwrap();
        let live = Recorder::reusing(Counting(Default::default()), &path).unwrap();
        let reused = block(live.chat(&a)).unwrap();
        assert_eq!(
            (reused.text.as_str(), &reused.source),
            ("GOAL PLEASE", &ReplySource::Recorded)
        );
        assert_eq!(live.inner.0.load(std::sync::atomic::Ordering::SeqCst), 0);
        assert_eq!(block(live.chat(&b)).unwrap().text, "OTHER");
        assert_eq!(live.inner.0.load(std::sync::atomic::Ordering::SeqCst), 1);
        // Asked again in the same run, the new exchange is answered as recorded.
        let again = block(live.chat(&b)).unwrap();
        assert_eq!(again.source, ReplySource::Recorded);
        assert_eq!(live.inner.0.load(std::sync::atomic::Ordering::SeqCst), 1);
        // The new exchange was appended; the reused one was not written twice.
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(read_entries(&text).unwrap().entries.len(), 2);
        // Of two recordings of one prompt, the first answers.
        let mut first = read_entries(&text).unwrap().entries.remove(0);
        let mut second = first.clone();
        first.reply = "first".into();
        second.reply = "second".into();
        let lines: Vec<String> = [first, second]
            .iter()
            .map(|e| serde_json::to_string(e).unwrap())
            .collect();
        let twice_path = dir.join("twice.jsonl");
        std::fs::write(&twice_path, lines.join("\n") + "\n").unwrap();
        let replayed = Recorder::reusing(Counting(Default::default()), &twice_path).unwrap();
        assert_eq!(block(replayed.chat(&a)).unwrap().text, "first");
        // Another model's entries are not reused.
        std::fs::write(
            &path,
            text.replace("\"model\":\"echo-1\"", "\"model\":\"other-2\""),
        )
        .unwrap();
        let fresh = Recorder::reusing(Counting(Default::default()), &path).unwrap();
        block(fresh.chat(&a)).unwrap();
        assert_eq!(fresh.inner.0.load(std::sync::atomic::Ordering::SeqCst), 1);
        std::fs::write(&path, "not json\n").unwrap();
        let bad = Recorder::reusing(Echo, &path).err().unwrap();
        assert!(bad.to_string().contains("line 1"), "{bad}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_temperature_beyond_f32_is_refused_with_its_line() {
        let request = ChatRequest::new(vec![Message::user("x")]);
        let entry = Entry {
            ranked: Vec::new(),
            model: "m".into(),
            reply_model: String::new(),
            prompt_hash: prompt_hash(&request),
            request,
            reply: "r".into(),
            usage: TokenUsage::default(),
            latency_ms: 1,
            source: ReplySource::Model,
            recorded_unix: 0,
        };
        let line = serde_json::to_string(&entry).unwrap();
        let read = read_entries(&format!("{line}\n")).unwrap();
        assert_eq!((read.entries, read.cut_at), (vec![entry.clone()], None));
        // The same line without its newline, cut short: left out and reported.
        let cut = read_entries(&format!("{line}\n{}", &line[..30])).unwrap();
        assert_eq!((cut.entries, cut.cut_at), (vec![entry], Some(2)));
        let hot = line.replace("\"temperature\":0.0", "\"temperature\":1e39");
        assert_ne!(hot, line);
        let e = read_entries(&format!("{line}\n\n{hot}\n")).unwrap_err();
        assert_eq!(e.line, 3);
        // Refused by the reader (out of f32's range) or by the check of finite numbers.
        assert!(
            e.detail.contains("temperature") || e.detail.contains("out of range"),
            "{e}"
        );
    }

    #[test]
    fn hash_depends_on_the_whole_request() {
        let a = ChatRequest::new(vec![Message::user("x")]);
        let mut b = a.clone();
        b.temperature = 0.5;
        assert_ne!(prompt_hash(&a), prompt_hash(&b));
        assert_eq!(prompt_hash(&a), prompt_hash(&a.clone()));
        assert_eq!(prompt_hash(&a).len(), 64);
    }
}
