//! Beam search under a grammar: the few whole answers the grammar allows that the model
//! finds most likely, each scored by the sum of its tokens' log-probabilities under the
//! model's own, unconstrained distribution.
//!
//! Greedy decoding under a grammar commits at every token: a model that would write
//! `At_CompostBin` for "drive to the compost heap" (a place where the vocabulary has
//! `RobotAt_CompostBin`) takes `At` first, and the grammar then forces an item and a place
//! the model never meant. Scored whole, the answer the grammar forced is unlikely and the
//! one the model meant, written as the grammar allows, wins; the runners-up are the
//! model's other readings, best first.
//!
//! Each beam is a sequence of the key-value cache: the prompt's (sequence 0) is copied,
//! not evaluated again, and each step decodes one token per beam in one batch.

use llama_cpp_2::context::LlamaContext;
use llama_cpp_2::llama_batch::LlamaBatch;
use llama_cpp_2::model::LlamaModel;
use llama_cpp_2::sampling::LlamaSampler;
use llama_cpp_2::token::LlamaToken;
use llama_cpp_2::token::data::LlamaTokenData;
use llama_cpp_2::token::data_array::LlamaTokenDataArray;
use llama_cpp_2::vocab::LlamaVocab;

use super::engine::{EngineError, runtime};

/// The widest beam the context is made for.
pub(super) const MAX_BEAMS: u32 = 6;

/// Cache sequences a context needs for beams: the prompt's, and two banks of beams
/// (parents and children) used in turn.
pub(super) const SEQUENCES: u32 = 1 + 2 * MAX_BEAMS;

/// How many of a beam's most likely tokens are checked against its grammar one by one
/// before the grammar is applied to the whole vocabulary (which costs more).
const CHECKED_ONE_BY_ONE: usize = 48;

/// A whole answer the search found.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Found {
    pub text: String,
    /// The sum of its tokens' log-probabilities.
    pub logprob: f64,
}

/// What a search found, best first, and the tokens it decoded in all.
pub(super) struct Searched {
    pub found: Vec<Found>,
    pub decoded: u32,
}

struct Beam {
    tokens: Vec<LlamaToken>,
    logprob: f64,
    grammar: LlamaSampler,
    seq: i32,
    logits: Vec<f32>,
}

/// Search `width` beams from the prompt in sequence 0 (`prompt_len` tokens, whose last
/// token's logits are `first_logits`), each following `grammar`, for at most
/// `max_tokens` tokens; an answer ends at the end of generation or before a `stop`
/// string. Leaves only the prompt in the cache.
pub(super) fn search(
    model: &LlamaModel,
    ctx: &mut LlamaContext<'_>,
    (prompt_len, first_logits): (usize, Vec<f32>),
    grammar: LlamaSampler,
    width: usize,
    (max_tokens, stop): (u32, &[String]),
) -> Result<Searched, EngineError> {
    let search = Search {
        vocab: model.vocab(),
        stop,
        width: width.clamp(1, MAX_BEAMS as usize),
        prompt_len,
    };
    let width = search.width;
    let mut live = vec![Beam {
        tokens: Vec::new(),
        logprob: 0.0,
        grammar,
        seq: 0,
        logits: first_logits,
    }];
    let mut found: Vec<Found> = Vec::new();
    let mut decoded = 0u32;
    let mut batch = LlamaBatch::new(width, 1);
    let bank = |step: u32| {
        if step.is_multiple_of(2) {
            1
        } else {
            1 + MAX_BEAMS as i32
        }
    };
    for step in 0..max_tokens {
        let children = scored_children(&mut live, width);
        let next = search.going_on(&live, children, &mut found);
        if next.is_empty() {
            live.clear();
            break;
        }
        let mut children_beams = search.branch(ctx, &mut batch, &live, next, bank(step))?;
        ctx.decode(&mut batch).map_err(|e| runtime(&e))?;
        decoded += u32::try_from(children_beams.len()).unwrap_or(u32::MAX);
        for (k, beam) in children_beams.iter_mut().enumerate() {
            let at = i32::try_from(k).map_err(|e| runtime(&e))?;
            beam.logits = ctx.get_logits_ith(at).to_vec();
        }
        clear(ctx, &live)?;
        live = children_beams;
        // An answer only loses probability as it grows: a beam already below the
        // width-th answer found cannot enter the list.
        if found.len() >= width {
            let worst = found
                .iter()
                .map(|f| f.logprob)
                .fold(f64::INFINITY, f64::min);
            live.retain(|b| b.logprob > worst);
        }
        if live.is_empty() {
            break;
        }
    }
    // Beams cut by the token limit end where they are, as a greedy answer would.
    for beam in &live {
        found.push(Found {
            text: search.text_of(&beam.tokens),
            logprob: beam.logprob,
        });
    }
    clear(ctx, &live)?;
    found.sort_by(|a, b| b.logprob.total_cmp(&a.logprob));
    found.truncate(width);
    Ok(Searched { found, decoded })
}

/// A beam's next token: the index of the beam in the live ones, the token, and the
/// whole answer's log-probability with it.
type Child = (usize, LlamaToken, f64);

/// What a search keeps from start to end besides its beams.
struct Search<'a> {
    vocab: LlamaVocab<'a>,
    stop: &'a [String],
    width: usize,
    prompt_len: usize,
}

impl Search<'_> {
    /// The text of `tokens` (pieces are bytes; a character may span two tokens).
    fn text_of(&self, tokens: &[LlamaToken]) -> String {
        let bytes: Vec<u8> = tokens
            .iter()
            .flat_map(|t| self.vocab.token_to_piece(*t, false, None))
            .collect();
        String::from_utf8_lossy(&bytes).into_owned()
    }

    /// The best `children` (best first) until the answers found and the beams going on
    /// fill the width: a child that ends the answer (the end of generation or a stop
    /// string) goes into `found`, the others are the beams going on.
    fn going_on(&self, live: &[Beam], children: Vec<Child>, found: &mut Vec<Found>) -> Vec<Child> {
        let mut next: Vec<Child> = Vec::new();
        for (parent, token, score) in children {
            if found.len() + next.len() >= self.width {
                break;
            }
            let mut tokens = live[parent].tokens.clone();
            if self.vocab.is_eog(token) {
                found.push(Found {
                    text: self.text_of(&tokens),
                    logprob: score,
                });
                continue;
            }
            tokens.push(token);
            let text = self.text_of(&tokens);
            if let Some(cut) = self.stop.iter().filter_map(|s| text.find(s.as_str())).min() {
                found.push(Found {
                    text: text[..cut].to_string(),
                    logprob: score,
                });
                continue;
            }
            next.push((parent, token, score));
        }
        next
    }

    /// The beams going on, each in its own cache sequence from `first_seq` on (a copy of
    /// its parent's) with its token added to `batch` for decoding; their logits are not
    /// known yet.
    fn branch(
        &self,
        ctx: &mut LlamaContext<'_>,
        batch: &mut LlamaBatch<'_>,
        live: &[Beam],
        next: Vec<Child>,
        first_seq: i32,
    ) -> Result<Vec<Beam>, EngineError> {
        batch.clear();
        let mut children_beams: Vec<Beam> = Vec::with_capacity(next.len());
        for (k, (parent, token, score)) in next.into_iter().enumerate() {
            let seq = first_seq + i32::try_from(k).map_err(|e| runtime(&e))?;
            let parent = &live[parent];
            let seq_u = u32::try_from(seq).map_err(|e| runtime(&e))?;
            ctx.clear_kv_cache_seq(Some(seq_u), None, None)
                .map_err(|e| runtime(&e))?;
            ctx.copy_kv_cache_seq(parent.seq, seq, None, None)
                .map_err(|e| runtime(&e))?;
            let pos =
                i32::try_from(self.prompt_len + parent.tokens.len()).map_err(|e| runtime(&e))?;
            batch
                .add(token, pos, &[seq], true)
                .map_err(|e| runtime(&e))?;
            let mut grammar = parent.grammar.clone();
            grammar.accept(token);
            let mut tokens = parent.tokens.clone();
            tokens.push(token);
            children_beams.push(Beam {
                tokens,
                logprob: score,
                grammar,
                seq,
                logits: Vec::new(),
            });
        }
        Ok(children_beams)
    }
}

/// Every allowed next token of every beam (up to `width` each), scored by the whole
/// answer so far, best first.
fn scored_children(live: &mut [Beam], width: usize) -> Vec<Child> {
    let mut children: Vec<Child> = Vec::new();
    for (i, beam) in live.iter_mut().enumerate() {
        let log_z = log_sum_exp(&beam.logits);
        for (token, logit) in allowed_best(&beam.logits, &mut beam.grammar, width) {
            children.push((i, token, beam.logprob + f64::from(logit - log_z)));
        }
    }
    children.sort_by(|a, b| b.2.total_cmp(&a.2));
    children
}

/// Drop the cache sequences of `beams` (never the prompt's).
fn clear(ctx: &mut LlamaContext<'_>, beams: &[Beam]) -> Result<(), EngineError> {
    for b in beams.iter().filter(|b| b.seq != 0) {
        let seq = u32::try_from(b.seq).map_err(|e| EngineError::Runtime(e.to_string()))?;
        ctx.clear_kv_cache_seq(Some(seq), None, None)
            .map_err(|e| EngineError::Runtime(e.to_string()))?;
    }
    Ok(())
}

/// `ln(Σ exp(x))`, computed without overflow.
fn log_sum_exp(logits: &[f32]) -> f32 {
    let max = logits.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    if !max.is_finite() {
        return max;
    }
    let sum: f32 = logits.iter().map(|l| (l - max).exp()).sum();
    max + sum.ln()
}

/// Up to `n` tokens `grammar` allows next, most likely first, with their logits: the
/// most likely tokens are checked one by one, and only when none of them is allowed is
/// the grammar applied to the whole vocabulary.
fn allowed_best(logits: &[f32], grammar: &mut LlamaSampler, n: usize) -> Vec<(LlamaToken, f32)> {
    let mut order: Vec<(f32, i32)> = (0_i32..)
        .zip(logits.iter().copied())
        .map(|(i, l)| (l, i))
        .collect();
    let top = CHECKED_ONE_BY_ONE.min(order.len());
    if top == 0 {
        return Vec::new();
    }
    order.select_nth_unstable_by(top - 1, |a, b| b.0.total_cmp(&a.0));
    order.truncate(top);
    order.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut out = Vec::new();
    for (logit, id) in order {
        let token = LlamaToken::new(id);
        let mut one = LlamaTokenDataArray::new(vec![LlamaTokenData::new(token, logit, 0.0)], false);
        grammar.apply(&mut one);
        if one
            .data
            .first()
            .is_some_and(|d| d.logit() > f32::NEG_INFINITY)
        {
            out.push((token, logit));
            if out.len() == n {
                return out;
            }
        }
    }
    if !out.is_empty() {
        return out;
    }
    let mut all = LlamaTokenDataArray::from_iter(
        (0_i32..)
            .zip(logits)
            .map(|(id, logit)| LlamaTokenData::new(LlamaToken::new(id), *logit, 0.0)),
        false,
    );
    grammar.apply(&mut all);
    let mut allowed: Vec<(LlamaToken, f32)> = all
        .data
        .iter()
        .filter(|d| d.logit() > f32::NEG_INFINITY)
        .map(|d| {
            let id = usize::try_from(d.id().0).ok();
            let own = id.and_then(|i| logits.get(i)).copied().unwrap_or(d.logit());
            (d.id(), own)
        })
        .collect();
    allowed.sort_by(|a, b| b.1.total_cmp(&a.1));
    allowed.truncate(n);
    allowed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_sum_exp_is_stable_and_exact() {
        let l = [1000.0_f32, 1000.0];
        assert!((log_sum_exp(&l) - (1000.0 + 2.0_f32.ln())).abs() < 1e-3);
        let l = [0.0_f32, (3.0_f32).ln()];
        assert!((log_sum_exp(&l) - 4.0_f32.ln()).abs() < 1e-6);
        assert_eq!(log_sum_exp(&[f32::NEG_INFINITY]), f32::NEG_INFINITY);
    }
}
