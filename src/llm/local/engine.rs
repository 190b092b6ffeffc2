//! The embedded llama.cpp runtime (through `llama-cpp-2`).
//!
//! One worker thread owns the backend, the model and one context; calls reach it over a
//! channel. (A context borrows its model and is not `Send`, so a thread that owns both is
//! simpler and safer than a self-referential struct.) The worker keeps the tokens already
//! in the key-value cache: a call whose prompt starts like the previous one (same role
//! text, vocabulary, objects and examples) only evaluates the tokens that differ.

use std::num::NonZeroU32;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use llama_cpp_2::context::params::LlamaContextParams;
use llama_cpp_2::llama_backend::LlamaBackend;
use llama_cpp_2::llama_batch::LlamaBatch;
use llama_cpp_2::model::params::LlamaModelParams;
use llama_cpp_2::model::{LlamaChatMessage, LlamaChatTemplate, LlamaModel};
use llama_cpp_2::sampling::LlamaSampler;
use llama_cpp_2::token::LlamaToken;
use llama_cpp_2::token::data::LlamaTokenData;
use llama_cpp_2::token::data_array::LlamaTokenDataArray;

use super::prompt_state::{self, PromptStates};

/// How the engine runs.
#[derive(Debug, Clone, PartialEq)]
pub struct EngineOptions {
    pub model_path: PathBuf,
    /// CPU threads for generation and prompt evaluation.
    pub threads: u32,
    /// Context length in tokens.
    pub context: u32,
    /// Where the state after a prompt is kept between processes (`None`: not kept).
    pub prompt_states: Option<PathBuf>,
}

/// One generation request, already in chat form.
#[derive(Debug, Clone, PartialEq)]
pub struct Generation {
    /// (role, content) pairs: `system`, `user`, `assistant`.
    pub messages: Vec<(String, String)>,
    pub max_tokens: u32,
    /// 0 = greedy.
    pub temperature: f32,
    pub seed: u32,
    /// Generation stops before any of these.
    pub stop: Vec<String>,
    /// A GBNF grammar the reply must follow (root rule `root`).
    pub grammar: Option<String>,
    /// With a grammar and temperature 0: search this many beams for the answers the model
    /// finds most likely as a whole ([`super::beam`]); 0 or 1: one greedy answer.
    pub beams: u32,
    /// The reply's first words, written after the assistant's header for the model to
    /// continue; the reply's text (and every ranked answer) begins with them.
    pub prefill: String,
}

/// What a generation produced, with its timings.
#[derive(Debug, Clone, PartialEq)]
pub struct Generated {
    pub text: String,
    pub prompt_tokens: u32,
    /// Prompt tokens that were already in the cache and not evaluated again.
    pub cached_tokens: u32,
    pub completion_tokens: u32,
    pub prompt_time: Duration,
    pub generation_time: Duration,
    /// With beams: every answer found with its log-probability, best first (`text` is
    /// the first).
    pub ranked: Vec<(String, f64)>,
}

/// Refuse a file that does not start as a GGUF model does, before llama.cpp reads it.
fn check_gguf(path: &std::path::Path) -> Result<(), EngineError> {
    use std::io::Read;
    let mut magic = [0u8; 4];
    let read = std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut magic));
    match read {
        Ok(()) if &magic == b"GGUF" => Ok(()),
        Ok(()) => Err(EngineError::NotGguf {
            path: path.to_path_buf(),
            found: format!(
                "it starts with the bytes {}",
                magic.map(|b| format!("{b:02x}")).join(" ")
            ),
        }),
        Err(e) => Err(EngineError::NotGguf {
            path: path.to_path_buf(),
            found: e.to_string(),
        }),
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EngineError {
    #[error("model file {0} does not exist (run `betr model fetch`, or pass --model-path)")]
    Missing(PathBuf),
    #[error("cannot load model {path}: {detail}")]
    Load { path: PathBuf, detail: String },
    #[error("{path} is not a GGUF model file ({found})")]
    NotGguf { path: PathBuf, found: String },
    #[error("the model has no usable chat template: {0}")]
    Template(String),
    #[error("the prompt has {tokens} tokens but the context holds {context}")]
    PromptTooLong { tokens: usize, context: u32 },
    #[error("invalid grammar: {0}")]
    Grammar(String),
    #[error("llama.cpp failed: {0}")]
    Runtime(String),
    #[error("the model worker stopped")]
    WorkerGone,
}

type Reply = tokio::sync::oneshot::Sender<Result<Generated, EngineError>>;

/// A loaded model, ready for generations.
pub struct Engine {
    /// `None` only while dropping.
    jobs: Option<mpsc::Sender<(Generation, Reply)>>,
    worker: Option<std::thread::JoinHandle<()>>,
    load_time: Duration,
}

impl Drop for Engine {
    /// Close the queue and wait for the worker, which may still be saving the prompt state
    /// of its last call (a one-shot command that exits right after its answer would leave
    /// it unsaved).
    fn drop(&mut self) {
        self.jobs.take();
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

/// llama.cpp's backend may be initialised once per process; a failure is kept and
/// returned to every later caller.
static BACKEND: OnceLock<Result<LlamaBackend, EngineError>> = OnceLock::new();

fn backend() -> Result<&'static LlamaBackend, EngineError> {
    let b = BACKEND.get_or_init(|| {
        LlamaBackend::init()
            .map(|mut b| {
                b.void_logs();
                b
            })
            .map_err(|e| EngineError::Runtime(e.to_string()))
    });
    b.as_ref().map_err(Clone::clone)
}

impl Engine {
    /// Load the model in a new worker thread; returns when it is ready (or failed).
    pub fn load(options: EngineOptions) -> Result<Engine, EngineError> {
        if !Path::new(&options.model_path).is_file() {
            return Err(EngineError::Missing(options.model_path));
        }
        let (jobs, queue) = mpsc::channel::<(Generation, Reply)>();
        let (ready_tx, ready) = mpsc::channel::<Result<Duration, EngineError>>();
        let handle = std::thread::Builder::new()
            .name("betr-llm".into())
            .spawn(move || worker(options, ready_tx, queue))
            .map_err(|e| EngineError::Runtime(format!("cannot start the model thread: {e}")))?;
        let load_time = ready.recv().map_err(|_| EngineError::WorkerGone)??;
        Ok(Engine {
            jobs: Some(jobs),
            worker: Some(handle),
            load_time,
        })
    }

    pub fn load_time(&self) -> Duration {
        self.load_time
    }

    /// Run one generation; the model thread does the work, so awaiting this never blocks
    /// an async runtime. Calls queue up and run one at a time.
    pub async fn generate(&self, generation: Generation) -> Result<Generated, EngineError> {
        let (tx, rx) = tokio::sync::oneshot::channel();
        self.jobs
            .as_ref()
            .ok_or(EngineError::WorkerGone)?
            .send((generation, tx))
            .map_err(|_| EngineError::WorkerGone)?;
        rx.await.map_err(|_| EngineError::WorkerGone)?
    }

    /// The same, for callers outside an async runtime (benchmarks).
    pub fn generate_blocking(&self, generation: Generation) -> Result<Generated, EngineError> {
        let (tx, rx) = tokio::sync::oneshot::channel();
        self.jobs
            .as_ref()
            .ok_or(EngineError::WorkerGone)?
            .send((generation, tx))
            .map_err(|_| EngineError::WorkerGone)?;
        rx.blocking_recv().map_err(|_| EngineError::WorkerGone)?
    }
}

/// The model thread: load the model and make its context, say on `ready` when it is
/// ready (or why not), then answer the queued calls one at a time until the queue closes.
fn worker(
    options: EngineOptions,
    ready: mpsc::Sender<Result<Duration, EngineError>>,
    queue: mpsc::Receiver<(Generation, Reply)>,
) {
    let started = Instant::now();
    let (backend, model) = match load_model(&options.model_path) {
        Ok(x) => x,
        Err(e) => {
            let _ = ready.send(Err(e));
            return;
        }
    };
    let mut ctx = match model.new_context(backend, context_params(&options)) {
        Ok(c) => c,
        Err(e) => {
            let _ = ready.send(Err(EngineError::Load {
                path: options.model_path.clone(),
                detail: e.to_string(),
            }));
            return;
        }
    };
    let template = match model.chat_template(None) {
        Ok(t) => t,
        Err(e) => {
            let _ = ready.send(Err(EngineError::Template(e.to_string())));
            return;
        }
    };
    if ready.send(Ok(started.elapsed())).is_err() {
        return;
    }
    let mut worker = Worker {
        model: &model,
        template,
        states: options
            .prompt_states
            .as_deref()
            .map(|dir| PromptStates::new(dir, &options.model_path)),
        cached: Vec::new(),
    };
    while let Ok((job, reply)) = queue.recv() {
        let (result, save) = worker.answer(&mut ctx, &job);
        // A caller that went away (a cancelled request) does not stop the worker.
        let _ = reply.send(result);
        // Saved after answering, so the caller does not wait for the write.
        if save
            && let Some(states) = &worker.states
            && let Err(e) = states.save(&ctx, &worker.cached)
        {
            tracing::warn!("{e}");
        }
    }
}

/// The backend, and the model read from `path` after checking it is a GGUF file.
fn load_model(path: &Path) -> Result<(&'static LlamaBackend, LlamaModel), EngineError> {
    check_gguf(path)?;
    let backend = backend()?;
    let model =
        LlamaModel::load_from_file(backend, path, &LlamaModelParams::default()).map_err(|e| {
            EngineError::Load {
                path: path.to_path_buf(),
                detail: format!(
                    "llama.cpp could not read it (a truncated or corrupt GGUF file?): {e}"
                ),
            }
        })?;
    Ok((backend, model))
}

/// The context's size and threads as `options` ask.
fn context_params(options: &EngineOptions) -> LlamaContextParams {
    let threads = i32::try_from(options.threads.max(1)).unwrap_or(1);
    LlamaContextParams::default()
        .with_n_ctx(NonZeroU32::new(options.context.max(512)))
        .with_n_batch(512)
        .with_n_threads(threads)
        .with_n_threads_batch(threads)
        // Beams are cache sequences beside the prompt's; one unified cache keeps the whole
        // context for each.
        .with_n_seq_max(super::beam::SEQUENCES)
        .with_kv_unified(true)
}

/// What the worker keeps from one call to the next besides its context.
struct Worker<'m> {
    model: &'m LlamaModel,
    template: LlamaChatTemplate,
    states: Option<PromptStates>,
    /// Tokens whose keys and values are in the cache, in order.
    cached: Vec<LlamaToken>,
}

impl Worker<'_> {
    /// One call's reply, and whether the prompt's state is to be saved after it.
    fn answer(
        &mut self,
        ctx: &mut llama_cpp_2::context::LlamaContext<'_>,
        job: &Generation,
    ) -> (Result<Generated, EngineError>, bool) {
        // From an empty cache (the first call, or after a failure) a saved state of the
        // prompt's fixed part spares evaluating it again; a state is saved after the call.
        let cold = self.cached.is_empty();
        let mut loaded = false;
        let result = self.prompt(job).and_then(|tokens| {
            if cold
                && let Some(saved) = self.states.as_ref().and_then(|s| s.load(ctx, &tokens))
            {
                tracing::debug!(file = %saved.file.display(), tokens = saved.tokens.len(), "prompt state loaded");
                self.cached = saved.tokens;
                loaded = true;
            }
            generate(self.model, ctx, &mut self.cached, &tokens, job)
                .map(|g| with_prefill(g, &job.prefill))
        });
        let save = match &result {
            Ok(g) => {
                cold && (!loaded
                    || !prompt_state::still_fits(
                        g.cached_tokens as usize,
                        g.prompt_tokens as usize,
                    ))
            }
            Err(_) => {
                // After a failure the cache contents are unknown: start clean next time.
                self.cached.clear();
                let _ = ctx.clear_kv_cache_seq(None, None, None);
                false
            }
        };
        (result, save)
    }

    /// The call's messages through the model's chat template, with the prefill, as tokens.
    fn prompt(&self, job: &Generation) -> Result<Vec<LlamaToken>, EngineError> {
        let chat = job
            .messages
            .iter()
            .map(|(role, content)| LlamaChatMessage::new(role.clone(), content.clone()))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| EngineError::Template(e.to_string()))?;
        let mut prompt = self
            .model
            .apply_chat_template(&self.template, &chat, true)
            .map_err(|e| EngineError::Template(e.to_string()))?;
        prompt.push_str(&job.prefill);
        // The template already wrote the special tokens; parse them as such.
        Ok(self.model.vocab().tokenize(prompt.as_bytes(), false, true))
    }
}

/// `g` with the reply's prefilled first words put back before its text and every ranked
/// answer.
fn with_prefill(mut g: Generated, prefill: &str) -> Generated {
    if !prefill.is_empty() {
        g.text.insert_str(0, prefill);
        for (text, _) in &mut g.ranked {
            text.insert_str(0, prefill);
        }
    }
    g
}

/// A llama.cpp failure as the engine's error.
pub(super) fn runtime(e: &dyn std::fmt::Display) -> EngineError {
    EngineError::Runtime(e.to_string())
}

fn generate(
    model: &LlamaModel,
    ctx: &mut llama_cpp_2::context::LlamaContext<'_>,
    cached: &mut Vec<LlamaToken>,
    tokens: &[LlamaToken],
    job: &Generation,
) -> Result<Generated, EngineError> {
    let n_ctx = ctx.n_ctx();
    if tokens.len() + job.max_tokens as usize > n_ctx as usize {
        return Err(EngineError::PromptTooLong {
            tokens: tokens.len() + job.max_tokens as usize,
            context: n_ctx,
        });
    }
    let keep = reuse_cache(ctx, cached, tokens)?;
    let prompt_started = Instant::now();
    let mut batch = evaluate_prompt(ctx, cached, tokens, keep)?;
    let prompt_time = prompt_started.elapsed();

    let mut grammar = match &job.grammar {
        Some(g) => Some(
            LlamaSampler::grammar(model, g, "root")
                .map_err(|e| EngineError::Grammar(e.to_string()))?,
        ),
        None => None,
    };
    let prompted = Prompted {
        tokens,
        keep,
        prompt_time,
    };
    if job.beams > 1
        && job.temperature <= 0.0
        && let Some(grammar) = grammar.take()
    {
        let first = batch.n_tokens() - 1;
        return beam_reply(model, ctx, &prompted, first, grammar, job);
    }
    let generation_started = Instant::now();
    let (text, produced) = sample_reply(model, ctx, cached, &mut batch, grammar, job)?;
    Ok(Generated {
        text,
        prompt_tokens: tokens.len() as u32,
        cached_tokens: keep as u32,
        completion_tokens: produced,
        prompt_time,
        generation_time: generation_started.elapsed(),
        ranked: Vec::new(),
    })
}

/// The prompt as evaluated: its tokens, how many of them were in the cache, and the time
/// evaluating the rest took.
struct Prompted<'t> {
    tokens: &'t [LlamaToken],
    keep: usize,
    prompt_time: Duration,
}

/// Keep the cached prefix the prompt shares and drop the rest of the cache; always
/// evaluate at least the last prompt token, whose logits start the reply. How many
/// tokens were kept.
fn reuse_cache(
    ctx: &mut llama_cpp_2::context::LlamaContext<'_>,
    cached: &mut Vec<LlamaToken>,
    tokens: &[LlamaToken],
) -> Result<usize, EngineError> {
    let common = cached
        .iter()
        .zip(tokens)
        .take_while(|(a, b)| a == b)
        .count();
    let keep = common.min(tokens.len().saturating_sub(1));
    ctx.clear_kv_cache_seq(Some(0), Some(keep as u32), None)
        .map_err(|e| runtime(&e))?;
    cached.truncate(keep);
    Ok(keep)
}

/// Evaluate the prompt's tokens after the first `keep` in batches, adding them to
/// `cached`; the last batch, whose last token has the logits that start the reply.
fn evaluate_prompt<'b>(
    ctx: &mut llama_cpp_2::context::LlamaContext<'_>,
    cached: &mut Vec<LlamaToken>,
    tokens: &[LlamaToken],
    keep: usize,
) -> Result<LlamaBatch<'b>, EngineError> {
    let batch_size = ctx.n_batch() as usize;
    let mut batch = LlamaBatch::new(batch_size.max(1), 1);
    let rest = &tokens[keep..];
    for (chunk_index, chunk) in rest.chunks(batch_size.max(1)).enumerate() {
        batch.clear();
        let base = keep + chunk_index * batch_size;
        for (i, t) in chunk.iter().enumerate() {
            let pos = (base + i) as i32;
            let last = base + i == tokens.len() - 1;
            batch.add(*t, pos, &[0], last).map_err(|e| runtime(&e))?;
        }
        ctx.decode(&mut batch).map_err(|e| runtime(&e))?;
        cached.extend_from_slice(chunk);
    }
    Ok(batch)
}

/// The answers a beam search under `grammar` finds most likely, starting from the logits
/// of batch index `first`; the best is the reply.
fn beam_reply(
    model: &LlamaModel,
    ctx: &mut llama_cpp_2::context::LlamaContext<'_>,
    prompted: &Prompted<'_>,
    first: i32,
    grammar: LlamaSampler,
    job: &Generation,
) -> Result<Generated, EngineError> {
    let generation_started = Instant::now();
    let first = ctx.get_logits_ith(first).to_vec();
    let searched = super::beam::search(
        model,
        ctx,
        (prompted.tokens.len(), first),
        grammar,
        job.beams as usize,
        (job.max_tokens, &job.stop),
    )?;
    for f in &searched.found {
        tracing::debug!(logprob = f.logprob, text = %f.text, "beam answer");
    }
    let text = searched
        .found
        .first()
        .map(|f| f.text.clone())
        .unwrap_or_default();
    Ok(Generated {
        text,
        prompt_tokens: prompted.tokens.len() as u32,
        cached_tokens: prompted.keep as u32,
        completion_tokens: searched.decoded,
        prompt_time: prompted.prompt_time,
        generation_time: generation_started.elapsed(),
        ranked: searched
            .found
            .into_iter()
            .map(|f| (f.text, f.logprob))
            .collect(),
    })
}

/// One reply drawn token by token (greedy, or at the job's temperature), within the
/// grammar if any, until the end of generation, a stop string or `max_tokens`; its text
/// and how many tokens it took. `batch` holds the prompt's last batch on entry.
fn sample_reply(
    model: &LlamaModel,
    ctx: &mut llama_cpp_2::context::LlamaContext<'_>,
    cached: &mut Vec<LlamaToken>,
    batch: &mut LlamaBatch<'_>,
    mut grammar: Option<LlamaSampler>,
    job: &Generation,
) -> Result<(String, u32), EngineError> {
    let mut pick = if job.temperature > 0.0 {
        LlamaSampler::chain_simple([
            LlamaSampler::temp(job.temperature),
            LlamaSampler::dist(job.seed),
        ])
    } else {
        LlamaSampler::greedy()
    };
    let vocab = model.vocab();
    // Pieces are bytes; a character may span two tokens, so decode the whole reply.
    let mut bytes: Vec<u8> = Vec::new();
    let mut text = String::new();
    let mut produced = 0u32;
    let mut logits_at = batch.n_tokens() - 1;
    while produced < job.max_tokens {
        let token = next_token(ctx.get_logits_ith(logits_at), grammar.as_mut(), &mut pick)
            .ok_or_else(|| runtime(&"no token is allowed here"))?;
        if vocab.is_eog(token) {
            break;
        }
        produced += 1;
        bytes.extend(vocab.token_to_piece(token, false, None));
        text = String::from_utf8_lossy(&bytes).into_owned();
        if let Some(cut) = job.stop.iter().filter_map(|s| text.find(s.as_str())).min() {
            text.truncate(cut);
            break;
        }
        batch.clear();
        batch
            .add(token, cached.len() as i32, &[0], true)
            .map_err(|e| runtime(&e))?;
        ctx.decode(batch).map_err(|e| runtime(&e))?;
        cached.push(token);
        logits_at = 0;
    }
    Ok((text, produced))
}

/// The next token from `logits`, drawn by `pick` among those `grammar` allows, and
/// accepted into both. The draw is first made among all tokens and checked against the
/// grammar alone; only when the grammar refuses it is the grammar applied to the whole
/// vocabulary and the draw made again. Applying a grammar to every token of a large
/// vocabulary costs more than evaluating a token, and the first draw is nearly always
/// allowed. The result is the same: a greedy pick allowed by the grammar is the best
/// allowed token, and a random draw kept when allowed and otherwise redrawn among the
/// allowed ones follows the distribution restricted to them.
fn next_token(
    logits: &[f32],
    grammar: Option<&mut LlamaSampler>,
    pick: &mut LlamaSampler,
) -> Option<LlamaToken> {
    let candidates = || {
        LlamaTokenDataArray::from_iter(
            (0_i32..)
                .zip(logits)
                .map(|(id, logit)| LlamaTokenData::new(LlamaToken::new(id), *logit, 0.0)),
            false,
        )
    };
    let mut free = candidates();
    pick.apply(&mut free);
    let drawn = free.selected_token();
    let token = match grammar {
        None => drawn?,
        Some(grammar) => {
            let allowed = drawn.filter(|&t| {
                let logit = usize::try_from(t.0)
                    .ok()
                    .and_then(|i| logits.get(i))
                    .copied()
                    .unwrap_or(f32::NEG_INFINITY);
                let mut one =
                    LlamaTokenDataArray::new(vec![LlamaTokenData::new(t, logit, 0.0)], false);
                grammar.apply(&mut one);
                one.data
                    .first()
                    .is_some_and(|d| d.logit() > f32::NEG_INFINITY)
            });
            let token = match allowed {
                Some(t) => t,
                None => {
                    let mut all = candidates();
                    grammar.apply(&mut all);
                    if all.data.iter().all(|d| d.logit() == f32::NEG_INFINITY) {
                        return None;
                    }
                    pick.apply(&mut all);
                    all.selected_token()?
                }
            };
            grammar.accept(token);
            token
        }
    };
    pick.accept(token);
    Some(token)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_grammar_the_pick_decides() {
        let logits = [0.1, 2.5, -1.0, 2.0];
        let mut greedy = LlamaSampler::greedy();
        assert_eq!(
            next_token(&logits, None, &mut greedy),
            Some(LlamaToken::new(1))
        );
        // A draw at a low temperature lands on the best token; at any temperature it is
        // one of the vocabulary's.
        let mut cold =
            LlamaSampler::chain_simple([LlamaSampler::temp(0.01), LlamaSampler::dist(7)]);
        assert_eq!(
            next_token(&logits, None, &mut cold),
            Some(LlamaToken::new(1))
        );
        let mut hot = LlamaSampler::chain_simple([LlamaSampler::temp(5.0), LlamaSampler::dist(7)]);
        for _ in 0..20 {
            let t = next_token(&logits, None, &mut hot).unwrap();
            assert!((0..4).contains(&t.0), "{t:?}");
        }
    }
}
