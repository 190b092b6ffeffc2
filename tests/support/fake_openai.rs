//! A small HTTP/1.1 server on 127.0.0.1 that speaks the OpenAI chat-completions and
//! audio-transcriptions wire formats, for tests (a `Reply` text is a completion's content
//! or a transcript's text, by path). Each request takes the next scripted behaviour (then the default):
//! a normal reply, a slow one, 429 with Retry-After, 500, 401, 404, malformed JSON, no
//! choices, or a hand-written fixture reply chosen by matching the prompt. Replies from
//! fixtures carry the header `x-betr-fixture`, so they are never shown as a model's.

use std::collections::VecDeque;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use serde_json::{Value as Json, json};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

use super::fixtures::FixtureReply;
use super::multipart::{self, FormPart};

#[derive(Debug, Clone)]
pub enum Behavior {
    /// 200 with this text.
    Reply(String),
    /// 200 with this text after a delay.
    Slow(Duration, String),
    /// 429 with `Retry-After: secs`.
    TooMany { retry_after: String },
    /// 429 without `Retry-After`.
    TooManyBare,
    /// 500.
    ServerError,
    /// 503 without `Retry-After`.
    Unavailable,
    /// 200 whose body stops halfway (the connection closes before `content-length` bytes).
    CutBody,
    /// 401 (the body echoes the key it got, as some servers do, to test redaction).
    Unauthorized,
    /// 404 model not found.
    ModelNotFound,
    /// 200 with a body that is not JSON.
    Malformed,
    /// 200 with `choices: []`.
    EmptyChoices,
    /// 200 with the first fixture whose `when` strings all occur in the prompt.
    Fixtures(Vec<FixtureReply>),
    /// 200 with a chunked body that never ends (64 KiB chunks until the client goes).
    Endless,
}

/// What the server received.
#[derive(Debug, Clone)]
pub struct Received {
    pub path: String,
    pub headers: Vec<(String, String)>,
    /// The JSON body (`Null` for other bodies).
    pub body: Json,
    /// The fields of a `multipart/form-data` body.
    pub form: Vec<FormPart>,
}

impl Received {
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }

    /// The form field `name`.
    pub fn field(&self, name: &str) -> Option<&FormPart> {
        self.form.iter().find(|p| p.name == name)
    }

    /// All message contents, joined.
    pub fn prompt(&self) -> String {
        prompt_of(&self.body)
    }
}

struct State {
    script: VecDeque<Behavior>,
    default: Behavior,
    received: Vec<Received>,
}

pub struct FakeServer {
    pub addr: SocketAddr,
    state: Arc<Mutex<State>>,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl FakeServer {
    /// Start on a free port; requests take `script` in order, then `default`.
    pub fn start(script: Vec<Behavior>, default: Behavior) -> FakeServer {
        let state = Arc::new(Mutex::new(State {
            script: script.into(),
            default,
            received: Vec::new(),
        }));
        let (addr_tx, addr_rx) = std::sync::mpsc::channel();
        let (stop_tx, mut stop_rx) = tokio::sync::oneshot::channel::<()>();
        let shared = state.clone();
        let thread = std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .expect("runtime");
            rt.block_on(async move {
                let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
                addr_tx
                    .send(listener.local_addr().expect("addr"))
                    .expect("send addr");
                loop {
                    tokio::select! {
                        _ = &mut stop_rx => break,
                        accepted = listener.accept() => {
                            if let Ok((stream, _)) = accepted {
                                tokio::spawn(serve(stream, shared.clone()));
                            }
                        }
                    }
                }
            });
        });
        let addr = addr_rx.recv().expect("server address");
        FakeServer {
            addr,
            state,
            stop: Some(stop_tx),
            thread: Some(thread),
        }
    }

    /// `http://127.0.0.1:PORT/v1`
    pub fn base_url(&self) -> String {
        format!("http://{}/v1", self.addr)
    }

    pub fn received(&self) -> Vec<Received> {
        self.state.lock().expect("state").received.clone()
    }
}

impl Drop for FakeServer {
    fn drop(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn prompt_of(body: &Json) -> String {
    body["messages"]
        .as_array()
        .map(|m| {
            m.iter()
                .filter_map(|x| x["content"].as_str())
                .collect::<Vec<_>>()
                .join("\n")
        })
        .unwrap_or_default()
}

async fn serve(mut stream: TcpStream, state: Arc<Mutex<State>>) {
    let Some((path, headers, body)) = read_request(&mut stream).await else {
        return;
    };
    let form = headers
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case("content-type"))
        .and_then(|(_, v)| multipart::boundary(v))
        .map(|b| multipart::parse(&body, &b))
        .unwrap_or_default();
    let body: Json = serde_json::from_slice(&body).unwrap_or(Json::Null);
    let behavior = {
        let mut s = state.lock().expect("state");
        s.received.push(Received {
            path: path.clone(),
            headers,
            body: body.clone(),
            form,
        });
        s.script.pop_front().unwrap_or_else(|| s.default.clone())
    };
    let model = body["model"].as_str().unwrap_or("unknown").to_string();
    let prompt_words = prompt_of(&body).split_whitespace().count();
    let transcription = path == "/v1/audio/transcriptions";
    let ok = |text: &str| {
        if transcription {
            json!({ "text": text }).to_string()
        } else {
            completion(&model, prompt_words, text)
        }
    };
    let (status, extra, payload): (u16, Vec<(&str, String)>, String) = if path
        != "/v1/chat/completions"
        && !transcription
    {
        (
            404,
            vec![],
            json!({"error": {"message": format!("no route {path}")}}).to_string(),
        )
    } else {
        match behavior {
            Behavior::Reply(text) => (200, vec![], ok(&text)),
            Behavior::Slow(delay, text) => {
                tokio::time::sleep(delay).await;
                (200, vec![], ok(&text))
            }
            Behavior::TooMany { retry_after } => (
                429,
                vec![("Retry-After", retry_after)],
                json!({"error": {"message": "Rate limit reached", "type": "requests"}}).to_string(),
            ),
            Behavior::TooManyBare => (
                429,
                vec![],
                json!({"error": {"message": "Rate limit reached", "type": "requests"}}).to_string(),
            ),
            Behavior::ServerError => (500, vec![], json!({"error": {"message": "internal error"}}).to_string()),
            Behavior::Unavailable => (503, vec![], json!({"error": {"message": "overloaded"}}).to_string()),
            Behavior::Endless => {
                let head = "HTTP/1.1 200 OK\r\ncontent-type: application/json\r\ntransfer-encoding: chunked\r\nconnection: close\r\n\r\n";
                if stream.write_all(head.as_bytes()).await.is_err() {
                    return;
                }
                let piece = format!("{:x}\r\n{}\r\n", 65_536, "x".repeat(65_536));
                while stream.write_all(piece.as_bytes()).await.is_ok() {}
                return;
            }
            Behavior::CutBody => {
                let whole = ok("Goal: On_Coffee_Table1");
                let head = format!(
                    "HTTP/1.1 200 OK\r\ncontent-type: application/json\r\ncontent-length: {}\r\nconnection: close\r\n\r\n",
                    whole.len()
                );
                let _ = stream.write_all(head.as_bytes()).await;
                let _ = stream.write_all(&whole.as_bytes()[..whole.len() / 2]).await;
                let _ = stream.shutdown().await;
                return;
            }
            Behavior::Unauthorized => {
                let got = body_header_echo(&state);
                (401, vec![], json!({"error": {"message": format!("Incorrect API key provided: {got}")}}).to_string())
            }
            Behavior::ModelNotFound => (
                404,
                vec![],
                json!({"error": {"message": format!("The model `{model}` does not exist"), "code": "model_not_found"}}).to_string(),
            ),
            Behavior::Malformed => (200, vec![], "{\"id\": \"x\", \"choices\": [".to_string()),
            Behavior::EmptyChoices => (
                200,
                vec![],
                json!({"id": "x", "object": "chat.completion", "model": model, "choices": []}).to_string(),
            ),
            Behavior::Fixtures(fixtures) => {
                let prompt = prompt_of(&body);
                let seed = body["seed"].as_u64();
                match fixtures.iter().find(|f| f.answers(&prompt, seed)) {
                    Some(f) => (200, vec![("x-betr-fixture", f.note.clone())], ok(&f.text)),
                    None => (
                        400,
                        vec![],
                        json!({"error": {"message": "the fake server has no fixture reply for this prompt"}}).to_string(),
                    ),
                }
            }
        }
    };
    let mut head = format!(
        "HTTP/1.1 {status} {}\r\ncontent-type: application/json\r\ncontent-length: {}\r\nconnection: close\r\n",
        reason(status),
        payload.len()
    );
    for (k, v) in extra {
        head.push_str(&format!("{k}: {v}\r\n"));
    }
    head.push_str("\r\n");
    let _ = stream.write_all(head.as_bytes()).await;
    let _ = stream.write_all(payload.as_bytes()).await;
    let _ = stream.shutdown().await;
}

/// The bearer token of the last request (what a careless server would echo).
fn body_header_echo(state: &Arc<Mutex<State>>) -> String {
    let s = state.lock().expect("state");
    s.received
        .last()
        .and_then(|r| r.header("authorization"))
        .map(|a| a.trim_start_matches("Bearer ").to_string())
        .unwrap_or_default()
}

/// A completion; token counts are word counts, a stand-in for a tokenizer.
fn completion(model: &str, prompt_words: usize, text: &str) -> String {
    let completion_words = text.split_whitespace().count();
    json!({
        "id": "chatcmpl-fake",
        "object": "chat.completion",
        "created": 0,
        "model": model,
        "choices": [{
            "index": 0,
            "message": {"role": "assistant", "content": text},
            "finish_reason": "stop"
        }],
        "usage": {
            "prompt_tokens": prompt_words,
            "completion_tokens": completion_words,
            "total_tokens": prompt_words + completion_words
        }
    })
    .to_string()
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        401 => "Unauthorized",
        404 => "Not Found",
        429 => "Too Many Requests",
        503 => "Service Unavailable",
        _ => "Internal Server Error",
    }
}

async fn read_request(stream: &mut TcpStream) -> Option<(String, Vec<(String, String)>, Vec<u8>)> {
    let mut buf = Vec::new();
    let mut chunk = [0u8; 8192];
    let head_end = loop {
        let n = stream.read(&mut chunk).await.ok()?;
        if n == 0 {
            return None;
        }
        buf.extend_from_slice(&chunk[..n]);
        if let Some(i) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            break i;
        }
    };
    let head = String::from_utf8_lossy(&buf[..head_end]).to_string();
    let mut lines = head.split("\r\n");
    let path = lines.next()?.split(' ').nth(1)?.to_string();
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect();
    let length: usize = headers
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case("content-length"))
        .and_then(|(_, v)| v.parse().ok())
        .unwrap_or(0);
    let mut body = buf[head_end + 4..].to_vec();
    while body.len() < length {
        let n = stream.read(&mut chunk).await.ok()?;
        if n == 0 {
            break;
        }
        body.extend_from_slice(&chunk[..n]);
    }
    Some((path, headers, body))
}
