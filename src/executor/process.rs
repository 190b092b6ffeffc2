//! An executor in a process of its own, spoken to in JSON lines: one request per line on
//! its standard input, one reply per line on its standard output. A simulator or a robot
//! bridge in any language plugs in this way (docs/EXECUTORS.md has the protocol).
//!
//! ```text
//! → {"request":"perform","order":{…},"started":true}
//! ← {"reply":"running"} | {"reply":"success"} | {"reply":"failure","error":"…"}
//! → {"request":"halt","action":"grasp \"blue cube\""}        ← {"reply":"done"}
//! → {"request":"observe"}    ← {"reply":"observation","objects":[…],"held":null}
//! → {"request":"reset"}      ← {"reply":"done"} | {"reply":"refused","error":"…"}
//! → {"request":"load","scene":{…}}   ← {"reply":"done"} | {"reply":"refused","error":"…"}
//! ```
//!
//! A process that exits, closes its output, answers with something that is not a reply,
//! or does not answer within [`REPLY_WITHIN`] has stopped: the run stops with what it
//! said on its standard error, never with an action taken as done.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStderr, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use serde::{Deserialize, Serialize};

use super::{ActionOrder, Executor, ExecutorError};
use crate::domain::ActionCall;
use crate::world::observation::ObservedObject;
use crate::world::{Observation, SceneDescription, Step};

/// How long a reply may take: one tick of a simulator or of a robot's controller is far
/// shorter; a process silent this long has hung.
pub const REPLY_WITHIN: Duration = Duration::from_secs(10);

/// A process whose output closed is given up to a second to exit.
const EXIT_POLL: Duration = Duration::from_millis(50);
const EXIT_POLLS: u32 = 20;

#[derive(Serialize)]
#[serde(tag = "request", rename_all = "snake_case")]
enum Request<'a> {
    Perform {
        order: &'a ActionOrder,
        started: bool,
    },
    Halt {
        action: &'a ActionCall,
    },
    Observe,
    Reset,
    Load {
        scene: &'a SceneDescription,
    },
}

impl Request<'_> {
    fn name(&self) -> &'static str {
        match self {
            Request::Perform { .. } => "perform",
            Request::Halt { .. } => "halt",
            Request::Observe => "observe",
            Request::Reset => "reset",
            Request::Load { .. } => "load",
        }
    }
}

#[derive(Deserialize)]
#[serde(tag = "reply", rename_all = "snake_case", deny_unknown_fields)]
enum Reply {
    Running,
    Success,
    Failure {
        error: String,
    },
    Done,
    Refused {
        error: String,
    },
    Observation {
        objects: Vec<ObservedObject>,
        held: Option<String>,
    },
}

/// An executor process and the ends of its pipes.
pub struct ProcessExecutor {
    name: String,
    child: Child,
    /// Requests go to the process's standard input through a thread of their own, so a
    /// process that stops reading (its pipe full) cannot block the engine past the
    /// reply's time limit.
    requests: Sender<String>,
    /// Why writing a request failed, once it has.
    write_failed: Receiver<std::io::Error>,
    lines: Receiver<std::io::Result<String>>,
    /// The last line the process wrote on its standard error (its last words).
    last_words: Arc<Mutex<Option<String>>>,
    /// Says when the process's standard error has closed (it was read to the end).
    stderr_closed: Receiver<()>,
    reply_within: Duration,
}

impl ProcessExecutor {
    /// Start `program` with `args`; it is named after the program's file name and, when
    /// the first argument is not an option, that argument's (`python3 sim.py`: an
    /// interpreter's name alone says nothing).
    pub fn spawn(program: &str, args: &[String]) -> Result<ProcessExecutor, ExecutorError> {
        ProcessExecutor::spawn_named(None, program, args)
    }

    /// [`ProcessExecutor::spawn`], known by `name` when one is given.
    pub fn spawn_named(
        name: Option<&str>,
        program: &str,
        args: &[String],
    ) -> Result<ProcessExecutor, ExecutorError> {
        let file_name = |path: &str| {
            std::path::Path::new(path)
                .file_name()
                .map_or_else(|| path.to_string(), |n| n.to_string_lossy().into_owned())
        };
        let name = match (name, args.first()) {
            (Some(name), _) => name.to_string(),
            (None, Some(first)) if !first.starts_with('-') => {
                format!("{} {}", file_name(program), file_name(first))
            }
            (None, _) => file_name(program),
        };
        let stopped = |detail: String| ExecutorError::Stopped {
            executor: name.clone(),
            detail,
        };
        let mut child = Command::new(program)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| stopped(format!("cannot start {program}: {e}")))?;
        let (Some(stdin), Some(stdout), Some(stderr)) =
            (child.stdin.take(), child.stdout.take(), child.stderr.take())
        else {
            return Err(stopped("its pipes were not opened".into()));
        };
        let (requests, write_failed) = write_requests(stdin);
        let lines = read_replies(stdout);
        let (last_words, stderr_closed) = log_stderr(stderr, name.clone());
        Ok(ProcessExecutor {
            name,
            child,
            requests,
            write_failed,
            lines,
            last_words,
            stderr_closed,
            reply_within: REPLY_WITHIN,
        })
    }

    /// Wait at most `limit` for each reply.
    pub fn with_reply_limit(mut self, limit: Duration) -> ProcessExecutor {
        self.reply_within = limit;
        self
    }

    /// The executor's error, with how the process ended and its last words when its
    /// output closed (it is given a moment to exit and to finish its standard error).
    fn stopped(&mut self, detail: String) -> ExecutorError {
        self.stopped_with(detail, false)
    }

    fn stopped_with(&mut self, detail: String, output_closed: bool) -> ExecutorError {
        let mut status = self.child.try_wait().ok().flatten();
        if output_closed {
            for _ in 0..EXIT_POLLS {
                if status.is_some() {
                    break;
                }
                std::thread::sleep(EXIT_POLL);
                status = self.child.try_wait().ok().flatten();
            }
            if status.is_some() {
                let _ = self.stderr_closed.recv_timeout(EXIT_POLL * EXIT_POLLS);
            }
        }
        let exited = match status {
            Some(status) => format!(" (it exited: {status})"),
            None => String::new(),
        };
        let said = self.last_words.lock().ok().and_then(|line| line.clone());
        let last_words = match said {
            Some(line) => format!(
                "; its standard error ends: {}",
                crate::http_text::excerpt(&line)
            ),
            None => String::new(),
        };
        ExecutorError::Stopped {
            executor: self.name.clone(),
            detail: format!("{detail}{exited}{last_words}"),
        }
    }

    /// Send one request and read its reply.
    fn ask(&mut self, request: &Request) -> Result<Reply, ExecutorError> {
        let what = request.name();
        let mut line = serde_json::to_string(request)
            .map_err(|e| self.stopped(format!("the {what} request could not be written: {e}")))?;
        line.push('\n');
        let refused = |e: String| format!("the {what} request could not be sent: {e}");
        if let Ok(e) = self.write_failed.try_recv() {
            return Err(self.stopped(refused(e.to_string())));
        }
        if self.requests.send(line).is_err() {
            return Err(self.stopped(refused("its input is closed".into())));
        }
        let text = match self.lines.recv_timeout(self.reply_within) {
            Ok(Ok(text)) => text,
            Ok(Err(e)) => return Err(self.stopped(format!("its output could not be read: {e}"))),
            Err(RecvTimeoutError::Timeout) => {
                let secs = self.reply_within.as_secs_f64();
                return Err(self.stopped(format!("no reply to {what} within {secs} s")));
            }
            Err(RecvTimeoutError::Disconnected) => {
                let detail = format!("its output closed before it replied to {what}");
                return Err(self.stopped_with(detail, true));
            }
        };
        serde_json::from_str(&text).map_err(|e| {
            let shown = crate::http_text::excerpt(&text);
            self.stopped(format!(
                "it replied to {what} with `{shown}`, which is not a reply: {e}"
            ))
        })
    }

    fn unexpected(&mut self, what: &str, expected: &str) -> ExecutorError {
        self.stopped(format!(
            "it replied to {what} with something other than {expected}"
        ))
    }
}

impl Executor for ProcessExecutor {
    fn name(&self) -> &str {
        &self.name
    }

    fn perform(&mut self, order: &ActionOrder, started: bool) -> Result<Step, ExecutorError> {
        match self.ask(&Request::Perform { order, started })? {
            Reply::Running => Ok(Step::Running),
            Reply::Success => Ok(Step::Success),
            Reply::Failure { error } => Ok(Step::Failure(error)),
            _ => Err(self.unexpected("perform", "running, success or failure")),
        }
    }

    fn halt(&mut self, action: &ActionCall) -> Result<(), ExecutorError> {
        match self.ask(&Request::Halt { action })? {
            Reply::Done => Ok(()),
            _ => Err(self.unexpected("halt", "done")),
        }
    }

    fn observe(&mut self) -> Result<Observation, ExecutorError> {
        match self.ask(&Request::Observe)? {
            Reply::Observation { objects, held } => Ok(Observation { objects, held }),
            _ => Err(self.unexpected("observe", "an observation")),
        }
    }

    fn reset(&mut self) -> Result<(), ExecutorError> {
        match self.ask(&Request::Reset)? {
            Reply::Done => Ok(()),
            Reply::Refused { error } => Err(ExecutorError::Stopped {
                executor: self.name.clone(),
                detail: format!("it cannot go back to the first state: {error}"),
            }),
            _ => Err(self.unexpected("reset", "done or refused")),
        }
    }

    fn load(&mut self, scene: &SceneDescription) -> Result<(), ExecutorError> {
        match self.ask(&Request::Load { scene })? {
            Reply::Done => Ok(()),
            Reply::Refused { error } => Err(ExecutorError::Load {
                executor: self.name.clone(),
                detail: error,
            }),
            _ => Err(self.unexpected("load", "done or refused")),
        }
    }
}

/// A thread reading the process's replies, a line at a time, into the channel returned.
fn read_replies(stdout: ChildStdout) -> Receiver<std::io::Result<String>> {
    let (tx, lines) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            if tx.send(line).is_err() {
                return;
            }
        }
    });
    lines
}

/// A thread passing the process's standard error to the log, keeping its last line; the
/// receiver hears when it has been read to the end.
fn log_stderr(stderr: ChildStderr, name: String) -> (Arc<Mutex<Option<String>>>, Receiver<()>) {
    let last_words = Arc::new(Mutex::new(None));
    let keep = last_words.clone();
    let (closed, stderr_closed) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            tracing::info!(executor = %name, "{line}");
            if let Ok(mut last) = keep.lock() {
                *last = Some(line);
            }
        }
        let _ = closed.send(());
    });
    (last_words, stderr_closed)
}

/// A thread writing each request sent to `stdin`, a line at a time; the first error it
/// meets is sent back and ends it.
fn write_requests(mut stdin: ChildStdin) -> (Sender<String>, Receiver<std::io::Error>) {
    let (requests, lines) = channel::<String>();
    let (failed, write_failed) = channel();
    std::thread::spawn(move || {
        for line in lines {
            if let Err(e) = stdin
                .write_all(line.as_bytes())
                .and_then(|()| stdin.flush())
            {
                let _ = failed.send(e);
                return;
            }
        }
    });
    (requests, write_failed)
}

impl Drop for ProcessExecutor {
    fn drop(&mut self) {
        // The process may be a simulator holding memory or a bridge holding a robot: it
        // does not outlive the session that started it.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
