//! The model's state after a prompt, kept on disk so a new process does not evaluate the
//! fixed part of a prompt again.
//!
//! Every one-shot command (`betr interpret`, `resolve`, a new workbench) starts with an
//! empty key-value cache and would pay for the prompt's role text, vocabulary, objects and
//! examples before the first answer. After a call from an empty cache the worker saves the
//! sequence's state (keys and values of every token in the cache, with the tokens) here;
//! the next process whose prompt starts with the same tokens loads it, and the usual
//! common-prefix rule evaluates only what differs.
//!
//! A file is keyed by the model file, the betr build and the prompt's first tokens, and has
//! a metadata file beside it that is checked before the state is loaded; a state whose
//! prompt has changed since (the shared prefix is short) is saved again. Files are written
//! to a temporary name and renamed, so a reader never sees half of one.

use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

use llama_cpp_2::context::LlamaContext;
use llama_cpp_2::token::LlamaToken;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// The prompt tokens that name a state file: enough to tell prompts of different kinds and
/// scenarios apart, few enough to lie in the fixed part of every prompt.
const KEY_TOKENS: usize = 256;
/// State files kept per directory; the least recently used go first.
const MAX_FILES: usize = 24;
const FORMAT: u32 = 1;

/// Why a prompt state could not be saved (the call it follows has answered already).
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error("cannot write the prompt state to {path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("llama.cpp could not save the prompt state to {0}")]
    Llama(PathBuf),
}

/// What a state file was made from, checked before the state is loaded.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Meta {
    format: u32,
    model: String,
    build: String,
    tokens: usize,
    bytes: u64,
}

/// Prompt states of one model and one build, in one directory.
#[derive(Debug, Clone)]
pub struct PromptStates {
    dir: PathBuf,
    model: String,
    build: String,
}

/// A state loaded for a prompt: its tokens are in the key-value cache.
pub struct Loaded {
    pub tokens: Vec<LlamaToken>,
    pub file: PathBuf,
}

impl PromptStates {
    /// States for `model_path` in `dir`. The model is identified by its file's name, size
    /// and modification time, the build by the running executable's (any rebuild of betr,
    /// which may change llama.cpp's state format, starts afresh).
    pub fn new(dir: &Path, model_path: &Path) -> PromptStates {
        PromptStates {
            dir: dir.to_path_buf(),
            model: file_identity(model_path),
            build: std::env::current_exe()
                .map(|exe| file_identity(&exe))
                .unwrap_or_default(),
        }
    }

    /// The state file for a prompt, when it is long enough to be worth one.
    fn paths(&self, prompt: &[LlamaToken]) -> Option<(PathBuf, PathBuf)> {
        if prompt.len() < KEY_TOKENS {
            return None;
        }
        let mut hash = Sha256::new();
        hash.update(self.model.as_bytes());
        hash.update([0]);
        hash.update(self.build.as_bytes());
        hash.update([0]);
        for t in &prompt[..KEY_TOKENS] {
            hash.update(t.0.to_le_bytes());
        }
        let digest = hash.finalize();
        let name: String = digest[..12].iter().map(|b| format!("{b:02x}")).collect();
        Some((
            self.dir.join(format!("{name}.state")),
            self.dir.join(format!("{name}.json")),
        ))
    }

    /// Load the state saved for a prompt starting like `prompt` into sequence 0 of `ctx`,
    /// when there is one and its metadata matches. A file that cannot be used is removed.
    pub fn load(&self, ctx: &mut LlamaContext<'_>, prompt: &[LlamaToken]) -> Option<Loaded> {
        let (state, meta_path) = self.paths(prompt)?;
        let meta: Meta = match std::fs::read(&meta_path) {
            Ok(bytes) => match serde_json::from_slice(&bytes) {
                Ok(m) => m,
                Err(e) => {
                    self.discard(&state, &meta_path, &format!("unreadable metadata: {e}"));
                    return None;
                }
            },
            Err(_) => return None,
        };
        let size = std::fs::metadata(&state).map(|m| m.len()).unwrap_or(0);
        let fits = meta.format == FORMAT
            && meta.model == self.model
            && meta.build == self.build
            && meta.bytes == size
            && meta.tokens <= ctx.n_ctx() as usize;
        if !fits {
            self.discard(&state, &meta_path, "made for another model, build or size");
            return None;
        }
        match ctx.state_seq_load_file(&state, 0, meta.tokens) {
            Ok((tokens, _)) if tokens.len() == meta.tokens => {
                touch(&meta_path);
                Some(Loaded {
                    tokens,
                    file: state,
                })
            }
            Ok(_) | Err(_) => {
                let _ = ctx.clear_kv_cache_seq(Some(0), None, None);
                self.discard(&state, &meta_path, "llama.cpp could not load it");
                None
            }
        }
    }

    /// Save sequence 0 of `ctx`, holding `tokens`, as the state for prompts that start like
    /// `tokens`; then drop the least recently used files beyond the limit.
    pub fn save(&self, ctx: &LlamaContext<'_>, tokens: &[LlamaToken]) -> Result<(), SaveError> {
        let Some((state, meta_path)) = self.paths(tokens) else {
            return Ok(());
        };
        std::fs::create_dir_all(&self.dir).map_err(|error| SaveError::Io {
            path: self.dir.clone(),
            error,
        })?;
        let partial = state.with_extension(format!("state.{}.partial", std::process::id()));
        let saved = self.save_as(ctx, tokens, &partial, (&state, &meta_path));
        if saved.is_err() {
            let _ = std::fs::remove_file(&partial);
        }
        saved
    }

    /// Save to `partial`, then the metadata, then rename `partial` to `state`.
    fn save_as(
        &self,
        ctx: &LlamaContext<'_>,
        tokens: &[LlamaToken],
        partial: &Path,
        (state, meta_path): (&Path, &Path),
    ) -> Result<(), SaveError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |error| SaveError::Io { path, error }
        };
        ctx.state_seq_save_file(partial, 0, tokens)
            .map_err(|_| SaveError::Llama(partial.to_path_buf()))?;
        let bytes = std::fs::metadata(partial).map_err(io(partial))?.len();
        let meta = Meta {
            format: FORMAT,
            model: self.model.clone(),
            build: self.build.clone(),
            tokens: tokens.len(),
            bytes,
        };
        let json = serde_json::to_vec(&meta).map_err(|e| SaveError::Io {
            path: meta_path.to_path_buf(),
            error: e.into(),
        })?;
        // The metadata goes first and the state is renamed last, so a metadata file never
        // vouches for a state that is not whole (a reader checks the size too).
        crate::store::write_atomic(meta_path, &json).map_err(io(meta_path))?;
        std::fs::rename(partial, state).map_err(io(state))?;
        self.prune();
        Ok(())
    }

    fn discard(&self, state: &Path, meta: &Path, why: &str) {
        tracing::info!(file = %state.display(), why, "prompt state not used");
        let _ = std::fs::remove_file(state);
        let _ = std::fs::remove_file(meta);
    }

    /// Keep the `MAX_FILES` most recently used states.
    fn prune(&self) {
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return;
        };
        let mut metas: Vec<(std::time::SystemTime, PathBuf)> = entries
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "json"))
            .filter_map(|p| Some((std::fs::metadata(&p).ok()?.modified().ok()?, p)))
            .collect();
        metas.sort_by_key(|m| std::cmp::Reverse(m.0));
        for (_, meta) in metas.into_iter().skip(MAX_FILES) {
            let _ = std::fs::remove_file(meta.with_extension("state"));
            let _ = std::fs::remove_file(&meta);
        }
    }
}

/// Whether a state loaded for `prompt` served it well enough to keep: the prompt shares at
/// least half its tokens with it. Otherwise the prompt's text changed since the state was
/// saved (edited templates, another scene) and a new state is saved after the call.
pub fn still_fits(shared: usize, prompt: usize) -> bool {
    shared * 2 >= prompt
}

fn file_identity(path: &Path) -> String {
    let meta = std::fs::metadata(path).ok();
    let size = meta.as_ref().map_or(0, std::fs::Metadata::len);
    let modified = meta
        .and_then(|m| m.modified().ok())
        .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_nanos());
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    format!("{name}:{size}:{modified}")
}

/// Mark a state as used now (the pruning keeps the recently used ones).
fn touch(path: &Path) {
    if let Ok(file) = std::fs::File::options().append(true).open(path) {
        let _ = file.set_modified(std::time::SystemTime::now());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_state_is_kept_while_it_covers_half_the_prompt() {
        assert!(still_fits(688, 912));
        assert!(still_fits(500, 1000));
        assert!(!still_fits(256, 912));
    }

    #[test]
    fn prompts_shorter_than_the_key_get_no_file_and_the_key_follows_model_and_build() {
        let dir = std::env::temp_dir().join(format!("betr-prompt-state-{}", std::process::id()));
        let a = PromptStates::new(&dir, Path::new("/nonexistent/a.gguf"));
        let b = PromptStates::new(&dir, Path::new("/nonexistent/b.gguf"));
        let short: Vec<LlamaToken> = (0..10).map(LlamaToken).collect();
        assert!(a.paths(&short).is_none());
        let long: Vec<LlamaToken> = (0..300).map(LlamaToken).collect();
        let mut other = long.clone();
        other[299] = LlamaToken(7); // beyond the key: same file
        assert_eq!(a.paths(&long), a.paths(&other));
        other[10] = LlamaToken(7); // within the key: another file
        assert_ne!(a.paths(&long), a.paths(&other));
        assert_ne!(a.paths(&long), b.paths(&long));
    }
}
