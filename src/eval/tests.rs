use std::path::Path;

use super::run::{CallRecord, Journal, mean_sd, percentile, records};
use crate::scenario::Scenario;

fn cafe() -> Scenario {
    Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml"))
        .expect("cafe scenario")
}

#[test]
fn percentiles_and_spread() {
    let v: Vec<f64> = (1..=100).map(f64::from).collect();
    assert_eq!(percentile(&v, 50.0), 50.0);
    assert_eq!(percentile(&v, 95.0), 95.0);
    assert_eq!(percentile(&[], 95.0), 0.0);
    assert_eq!(percentile(&[3.0], 95.0), 3.0);
    let (m, sd) = mean_sd(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]).expect("values");
    assert!((m - 5.0).abs() < 1e-12 && (sd - 2.138_089_935).abs() < 1e-6);
    assert_eq!(mean_sd(&[]), None);
}

#[test]
fn a_line_cut_short_is_skipped_and_the_next_record_starts_a_new_line() {
    let dir = std::env::temp_dir().join(format!("betr-journal-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(dir.join("cases.jsonl"), "[1]\n[2]\n[3, 4").expect("write");
    let j = Journal::new(&dir);
    let read: Vec<Vec<u32>> = j.read().expect("read");
    assert_eq!(read, vec![vec![1], vec![2]]);
    j.append(&vec![5u32]).expect("append");
    let read: Vec<Vec<u32>> = j.read().expect("read");
    assert_eq!(read, vec![vec![1], vec![2], vec![5]]);
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn numbers_read_from_the_journal_are_the_numbers_written() {
    // Latencies are durations in milliseconds with up to 17 significant digits.
    for latency_ms in [10_635.123_456_789_013, 923_017.729_336_999_9, 0.1 + 0.2] {
        let record = CallRecord {
            prompt_tokens: 1,
            completion_tokens: 2,
            latency_ms,
            price_usd: Some(latency_ms / 7.0),
            source: "model".into(),
        };
        let line = serde_json::to_string(&record).expect("json");
        let read: Vec<CallRecord> = records(&format!("{line}\n"));
        assert_eq!(read, vec![record], "{line}");
    }
}

/// A model that answers `Goal: Active_AC` after a short wait and counts the calls in flight.
struct Slow {
    inflight: std::sync::atomic::AtomicUsize,
    most: std::sync::atomic::AtomicUsize,
}

impl crate::llm::LanguageModel for Slow {
    fn model(&self) -> &str {
        "slow"
    }
    fn chat<'a>(&'a self, request: &'a crate::llm::ChatRequest) -> crate::llm::ChatFuture<'a> {
        use std::sync::atomic::Ordering::SeqCst;
        Box::pin(async move {
            let now = self.inflight.fetch_add(1, SeqCst) + 1;
            self.most.fetch_max(now, SeqCst);
            tokio::time::sleep(std::time::Duration::from_millis(20)).await;
            self.inflight.fetch_sub(1, SeqCst);
            Ok(crate::llm::ChatReply {
                ranked: Vec::new(),
                text: format!("Goal: Active_AC\n(seed {:?})", request.seed),
                model: "slow".into(),
                usage: crate::llm::TokenUsage::default(),
                latency: std::time::Duration::from_millis(20),
                source: crate::llm::ReplySource::HandWritten {
                    note: "unit test".into(),
                },
            })
        })
    }
}

#[test]
fn requests_run_concurrently_up_to_the_limit_and_each_run_sends_its_seed() {
    use super::goals_run::run_goals;
    use super::run::{RunConfig, Silent};
    use crate::dataset::{Case, Difficulty};
    let s = cafe();
    let cases: Vec<Case> = (0..9)
        .map(|i| Case {
            difficulty: Difficulty::Easy,
            index: i,
            instruction: format!("Please switch the AC on ({i})."),
            gold: "Active_AC".into(),
        })
        .collect();
    let model = std::sync::Arc::new(Slow {
        inflight: Default::default(),
        most: Default::default(),
    });
    let dir = std::env::temp_dir().join(format!("betr-concurrency-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let options = crate::session::Options {
        max_tokens: 100,
        ..Default::default()
    };
    let cfg = RunConfig {
        runs: 2,
        concurrency: 3,
        limit: None,
        prices: Default::default(),
        progress: &Silent,
        executor: None,
    };
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("runtime");
    let results = rt
        .block_on(run_goals(
            &(model.clone() as std::sync::Arc<dyn crate::llm::LanguageModel>),
            &s,
            &cases,
            &options,
            &cfg,
            &dir,
        ))
        .expect("run");
    assert_eq!(model.most.load(std::sync::atomic::Ordering::SeqCst), 3);
    assert_eq!(results.easy.correct, 18);
    assert_eq!(results.runs.len(), 2);
    for c in &results.cases {
        let seed = format!("(seed Some({}))", c.run);
        assert!(c.reply.as_deref().is_some_and(|r| r.contains(&seed)));
    }
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn the_goals_table_gives_the_time_a_person_waits_per_instruction() {
    use super::goals::{CaseResult, GoalsResults, Tally};
    let call = |ms: f64| CallRecord {
        prompt_tokens: 100,
        completion_tokens: 5,
        latency_ms: ms,
        price_usd: None,
        source: "model".into(),
    };
    let case = |index: usize, calls: Vec<CallRecord>| CaseResult {
        run: 1,
        difficulty: "easy".into(),
        index,
        instruction: format!("request {index}"),
        gold: "Exists_Coffee".into(),
        answer: Some("Exists_Coffee".into()),
        correct: true,
        problem: None,
        reply: None,
        calls,
        first_answer: Some("Exists_Coffee".into()),
        first_correct: Some(true),
        feedback_rounds: 0,
        readings: Vec::new(),
        gold_in_readings: None,
        evidence: None,
    };
    // Three instructions: one call of 4 s, two calls of 1 + 2 s, three calls of 2 s each.
    let cases = vec![
        case(0, vec![call(4000.0)]),
        case(1, vec![call(1000.0), call(2000.0)]),
        case(2, vec![call(2000.0), call(2000.0), call(2000.0)]),
    ];
    let results = GoalsResults {
        easy: Tally {
            correct: 3,
            total: 3,
        },
        medium: Tally::default(),
        hard: Tally::default(),
        runs: Vec::new(),
        usage: Some(super::run::UsageSummary::of(
            cases.iter().flat_map(|c| &c.calls),
        )),
        second_pass: None,
        doubt: None,
        cases,
    };
    let table = super::goals_run::table(&results, "fake", 0.0, 3);
    // Per call the median is 2 s; per instruction (4, 3 and 6 s) it is 4 s, the p95 6 s.
    assert!(
        table.contains("Time per instruction, all its calls: median 4.00 s, p95 6.00 s."),
        "{table}"
    );
    assert!(table.contains("| 2.00 s |"), "{table}");
}

/// A model whose context a request naming the curtain does not fit.
struct Small;

impl crate::llm::LanguageModel for Small {
    fn model(&self) -> &str {
        "small"
    }
    fn chat<'a>(&'a self, request: &'a crate::llm::ChatRequest) -> crate::llm::ChatFuture<'a> {
        let too_long = request
            .messages
            .iter()
            .any(|m| m.content.contains("Please close the curtain"));
        Box::pin(async move {
            if too_long {
                return Err(crate::llm::LlmError::TooLong {
                    tokens: 5000,
                    context: 4096,
                });
            }
            Ok(crate::llm::ChatReply {
                ranked: Vec::new(),
                text: "Goal: Active_AC".into(),
                model: "small".into(),
                usage: crate::llm::TokenUsage::default(),
                latency: std::time::Duration::from_millis(1),
                source: crate::llm::ReplySource::HandWritten {
                    note: "unit test".into(),
                },
            })
        })
    }
}

#[test]
fn a_case_past_the_context_window_fails_alone() {
    use super::goals_run::run_goals;
    use super::run::{RunConfig, Silent};
    use crate::dataset::{Case, Difficulty};
    let s = cafe();
    let case = |index: usize, instruction: &str, gold: &str| Case {
        difficulty: Difficulty::Easy,
        index,
        instruction: instruction.into(),
        gold: gold.into(),
    };
    let cases = vec![
        case(0, "Please switch the AC on.", "Active_AC"),
        case(1, "Please close the curtain.", "Closed_Curtain"),
        case(2, "The AC, on please.", "Active_AC"),
    ];
    let dir = std::env::temp_dir().join(format!("betr-too-long-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let cfg = RunConfig {
        runs: 1,
        concurrency: 1,
        limit: None,
        prices: Default::default(),
        progress: &Silent,
        executor: None,
    };
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("runtime");
    let model: std::sync::Arc<dyn crate::llm::LanguageModel> = std::sync::Arc::new(Small);
    let results = rt
        .block_on(run_goals(
            &model,
            &s,
            &cases,
            &crate::session::Options::default(),
            &cfg,
            &dir,
        ))
        .expect("the run goes on past the case that does not fit");
    assert_eq!(results.cases.len(), 3);
    assert_eq!(results.easy.correct, 2);
    let failed = &results.cases[1];
    assert!(!failed.correct);
    assert!(
        failed
            .problem
            .as_deref()
            .is_some_and(|p| p.contains("past the model's context")),
        "{:?}",
        failed.problem
    );
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

/// The right goal of every request of every set of the suite, against the check that an
/// object was guessed for one the scene lacks: a right goal doubted would cost the person
/// a question for nothing, on domains the check was not written for as much as on the cell.
#[test]
fn no_right_goal_of_the_suite_is_taken_for_a_guessed_object() {
    use crate::reading::{Request, lexicon::Lexicon, names::guessed_for_unknown};
    // The suite's paths are read from the repository's top folder, where cargo runs the
    // unit tests.
    let sets = super::suite::load(Path::new("docs/eval-suite.toml")).expect("the suite");
    let (mut read, mut doubted) = (0, Vec::new());
    for set in &sets {
        for (scene, case) in &set.cases {
            let scene = &set.scenes[*scene];
            let lexicon = Lexicon::new(&scene.domain.vocabulary, &scene.examples);
            let request = Request::new(&case.instruction, scene, &lexicon);
            let gold = scene
                .parse_goal(&case.gold)
                .expect("a right goal in the scene");
            read += 1;
            if let Some(why) = guessed_for_unknown(&gold, &request) {
                doubted.push(format!("{}: {:?}: {why}", set.name, case.instruction));
            }
        }
    }
    assert!(read > 250, "{read} requests read");
    assert!(doubted.is_empty(), "{}", doubted.join("\n"));
}
