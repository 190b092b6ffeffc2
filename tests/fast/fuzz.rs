//! Every fuzz target for a short fixed run (the same inputs on every run: seed 1), every
//! input saved under `fuzz/regressions/TARGET/` replayed, and `betr fuzz` itself. Longer
//! runs are `scripts/fuzz.sh` (docs/FUZZ.md).

use crate::support;

use std::sync::OnceLock;

use betr::fuzz::{self, Corpus, RunOptions, TARGETS};

fn corpus() -> &'static Corpus {
    static CORPUS: OnceLock<Corpus> = OnceLock::new();
    CORPUS.get_or_init(|| Corpus::load(support::repo::root()).expect("the seed corpus"))
}

/// Run `inputs` inputs of `name`; none may fail.
fn fuzz(name: &str, inputs: u64) {
    let target = fuzz::target(name, corpus()).expect("a target");
    assert!(!target.material().seeds.is_empty(), "{name} has no seeds");
    let options = RunOptions {
        seed: 1,
        inputs,
        ..RunOptions::default()
    };
    let report = fuzz::run(target.as_ref(), &options, &mut |_| {}).expect("a run");
    assert_eq!(report.inputs, inputs);
    assert!(
        report.failures.is_empty(),
        "{name}: {} failing inputs (replay with `betr fuzz {name} 1 --start INDEX`):\n{:#?}",
        report.failed,
        report.failures
    );
}

#[test]
fn goal() {
    fuzz("goal", 3_000);
}

#[test]
fn reply() {
    fuzz("reply", 2_000);
}

#[test]
fn tree() {
    fuzz("tree", 3_000);
}

#[test]
fn btcpp() {
    fuzz("btcpp", 3_000);
}

#[test]
fn scenario() {
    fuzz("scenario", 3_000);
}

#[test]
fn policy() {
    fuzz("policy", 3_000);
}

#[test]
fn cassette() {
    fuzz("cassette", 3_000);
}

#[test]
fn journal() {
    fuzz("journal", 3_000);
}

#[test]
fn wav() {
    fuzz("wav", 3_000);
}

#[test]
fn recording() {
    fuzz("recording", 3_000);
}

#[test]
fn groot2() {
    fuzz("groot2", 3_000);
}

#[test]
fn every_saved_regression_input_passes() {
    let dir = support::repo::path("fuzz/regressions");
    let mut replayed = 0;
    for entry in std::fs::read_dir(&dir).expect("fuzz/regressions") {
        let target_dir = entry.expect("an entry").path();
        let name = target_dir
            .file_name()
            .and_then(|n| n.to_str())
            .expect("a directory name")
            .to_string();
        assert!(
            TARGETS.contains(&name.as_str()),
            "{}: not a fuzz target",
            target_dir.display()
        );
        let target = fuzz::target(&name, corpus()).expect("a target");
        for file in std::fs::read_dir(&target_dir).expect("a target's directory") {
            let path = file.expect("an entry").path();
            let input = std::fs::read(&path).expect("a saved input");
            let checked = fuzz::check_caught(target.as_ref(), &input);
            assert_eq!(checked, Ok(()), "{}", path.display());
            replayed += 1;
        }
    }
    assert!(replayed > 0, "no regression inputs under {}", dir.display());
}

#[test]
fn the_command_runs_a_target_and_saves_what_fails() {
    let out = std::env::temp_dir().join(format!("betr-fuzz-{}", std::process::id()));
    let out_arg = out.to_string_lossy().into_owned();
    let run = support::repo::betr(&["fuzz", "tree", "300", "--seed", "7", "--out", &out_arg]);
    let (code, text) = support::repo::code_and_text(&run);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("tree: 300 inputs (seed 7, from 0)"), "{text}");
    let bad = out.join("bad.txt");
    std::fs::create_dir_all(&out).expect("a directory");
    std::fs::write(&bad, "sequence\n  Sweep!\n").expect("an input");
    let replay = support::repo::betr(&["fuzz", "tree", "--replay", &bad.to_string_lossy()]);
    let (code, text) = support::repo::code_and_text(&replay);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains(": ok"), "{text}");
    let unknown = support::repo::betr(&["fuzz", "nothing", "1"]);
    let (code, text) = support::repo::code_and_text(&unknown);
    assert_ne!(code, Some(0), "{text}");
    assert!(text.contains("unknown fuzz target \"nothing\""), "{text}");
    std::fs::remove_dir_all(&out).expect("cleanup");
}
