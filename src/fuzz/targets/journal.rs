//! Evaluation journals (`eval::run::records`, what `Journal::read` does with a
//! `cases.jsonl`), read as the records of each experiment: goal cases, resolve cases,
//! parameter cases, sequence steps.
//!
//! Properties: reading never fails (a line that does not read is left out, as the tail of
//! a cut write is); every record read is written back (as `Journal::append` writes it) to
//! a line that reads as the same record; a journal of the lines written reads the same
//! records again.

use crate::fuzz::Material;
use serde::Serialize;
use serde::de::DeserializeOwned;

use super::{Rng, Target, Violation, ensure, strings, text_of};
use crate::eval::goals::CaseResult;
use crate::eval::params::ParamsCase;
use crate::eval::resolve::ResolveCase;
use crate::eval::run::records;
use crate::eval::sequence::SequenceStep;
use crate::fuzz::Corpus;

pub struct JournalTarget {
    material: Material,
    lines: Vec<String>,
}

impl JournalTarget {
    pub fn new(corpus: &Corpus) -> JournalTarget {
        JournalTarget {
            material: Material {
                seeds: corpus
                    .journal_lines
                    .iter()
                    .map(|l| format!("{l}\n").into_bytes())
                    .collect(),
                tokens: strings(&[
                    "\"run\":",
                    "\"difficulty\":",
                    "\"index\":",
                    "\"scenario\":",
                    "\"success\":",
                    "\"calls\":[",
                    "\"latency_ms\":",
                    "\"price_usd\":",
                    "\"proposals\":[",
                    "\"values\":[",
                    "null",
                    "true",
                    "false",
                    "0.1",
                    "15042.769424",
                    "23017.729336999997",
                    "1.7976931348623157e308",
                    "2.2250738585072014e-308",
                    "4.9e-324",
                    "0.30000000000000004",
                    "123456789012345678901234567890",
                    "\\u0000",
                    "\\ud800\\udc00",
                    "\n",
                ]),
                brackets: super::pairs(&[("[", "]"), ("{\"a\":", "}")]),
            },
            lines: corpus.journal_lines.clone(),
        }
    }
}

/// Every `T` in `text` written as a journal line reads back the same, and the lines
/// written read back as the same records.
fn round_trip<T>(text: &str, kind: &str) -> Result<(), Violation>
where
    T: Serialize + DeserializeOwned + PartialEq + std::fmt::Debug,
{
    let read: Vec<T> = records(text);
    let mut written = String::new();
    for r in &read {
        let line = serde_json::to_string(r);
        let back = line.as_ref().ok().map(|l| serde_json::from_str::<T>(l));
        ensure(
            matches!(&back, Some(Ok(b)) if b == r),
            "a journal record written again reads back the same",
            || format!("{kind} {r:?} wrote {line:?}, read back as {back:?}"),
        )?;
        if let Ok(line) = line {
            written.push_str(&line);
            written.push('\n');
        }
    }
    let again: Vec<T> = records(&written);
    ensure(
        again == read,
        "a journal of the records written reads the same",
        || format!("{kind}: {} records, then {}", read.len(), again.len()),
    )
}

impl Target for JournalTarget {
    fn name(&self) -> &'static str {
        "journal"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        // Several journal lines, the last sometimes cut short as by a crash mid-write.
        let mut text = String::new();
        for _ in 0..1 + rng.small(5) {
            if let Some(line) = rng.pick(&self.lines) {
                text.push_str(line);
                text.push('\n');
            }
        }
        if rng.chance(30) {
            let cut = rng.below(text.len() + 1);
            let cut = (cut..=text.len())
                .find(|&i| text.is_char_boundary(i))
                .unwrap_or(0);
            text.truncate(cut);
        }
        text.into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        round_trip::<CaseResult>(&text, "goal case")?;
        round_trip::<ResolveCase>(&text, "resolve case")?;
        round_trip::<ParamsCase>(&text, "parameter case")?;
        round_trip::<SequenceStep>(&text, "sequence step")?;
        round_trip::<serde_json::Value>(&text, "JSON value")
    }
}
