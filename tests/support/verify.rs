//! Shared by the verification tests: repairing a scenario's planned tree with its
//! `expected_fix`, verifying it from the world's facts, reading verdicts, running SPIN on
//! the exported Promela model, and ticking a tree over a fact set with the real ticker.
//!
//! SPIN is installed by `scripts/test.sh` when missing. Without it the SPIN comparison is
//! skipped with a loud message, unless CI is set, where a missing SPIN fails the test.

use std::path::{Path, PathBuf};
use std::process::Command;

use betr::bt::{self, ActionStep, Leaves, NodeId, Outcome, Ticker, Tree};
use betr::domain::{ActionCall, Atom, Condition};
use betr::planner::{Outcome as PlanOutcome, Planner};
use betr::scenario::Scenario;
use betr::verify::abstraction::instance_of;
use betr::verify::{self, Counterexample, Limits, PropertyKind, Report, Verdict, VerifyConfig};
use betr::world;

pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

pub fn load(rel: &str) -> Scenario {
    Scenario::load(&root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The scenario files under `dir`, sorted, without example pools and the cell's base file
/// (which scenarios extend).
pub fn scenario_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    collect_scenario_files(dir, &mut out);
    out
}

fn collect_scenario_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            collect_scenario_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "toml")
            // Example pools, and the cell's base file, which scenarios extend.
            && !path
                .file_name()
                .is_some_and(|n| n == "examples.toml" || n == "cell.toml")
        {
            out.push(path);
        }
    }
}

/// The scenario's goal planned in its first state, `None` when it states no goal.
pub fn planned(s: &Scenario) -> Option<Tree> {
    let goal = s.goal.as_ref()?.to_dnf();
    let world = world::load(s).unwrap();
    Some(
        Planner::new(&s.domain)
            .plan(&goal, world.as_ref())
            .unwrap()
            .tree,
    )
}

/// The scenario's goal planned, then repaired with its `expected_fix`, one fix per
/// failure in order (scenario 2 needs two), each at the action that fails. A scenario
/// whose failure only the real arms produce is planned in the execution world, as the
/// engine does once planning and execution disagree.
pub fn repaired(s: &Scenario) -> Tree {
    let goal = s.goal.clone().unwrap().to_dnf();
    let planner = Planner::new(&s.domain);
    let mut world = world::load(s).unwrap();
    let mut plan = planner.plan(&goal, world.as_ref()).unwrap();
    if plan.outcome == PlanOutcome::Success && !s.expected_fix.is_empty() {
        fetch_yumi();
        let execution = world::load_execution(s, None).unwrap();
        assert_eq!(
            execution.notice, None,
            "{}: its failure needs the robot's description in the cache",
            s.name
        );
        world = execution.world;
        plan = planner.plan(&goal, world.as_ref()).unwrap();
    }
    for fix in &s.expected_fix {
        let PlanOutcome::ActionFailed { node, .. } = plan.outcome else {
            panic!(
                "{}: expected a failure to repair with {fix}, got {:?}",
                s.name, plan.outcome
            );
        };
        let fix: Vec<Condition> = s.parse_goal(fix).unwrap().to_dnf().0.remove(0);
        plan = planner
            .repair(plan.tree, node, &fix, world.as_ref())
            .unwrap();
    }
    assert_eq!(plan.outcome, PlanOutcome::Success, "{}", s.name);
    plan.tree
}

/// The YuMi's description in the cache, fetched on first use like the robot's own tests.
pub fn fetch_yumi() {
    struct Quiet;
    impl betr::model::Progress for Quiet {
        fn stage(&mut self, _: &str) {}
        fn bytes(&mut self, _: u64, _: u64) {}
    }
    let spec = &betr::model::YUMI_DESCRIPTION;
    betr::model::ensure_description(
        spec,
        &betr::model::cache_dir(),
        betr::model::Pip::DEFAULT,
        &mut Quiet,
    )
    .unwrap_or_else(|e| panic!("fetching the YuMi's description: {e}"));
}

/// Verify `tree` from the facts of the scenario's world, under its `[verify]` table.
pub fn check(s: &Scenario, tree: &Tree, failures: bool) -> (Report, verify::promela::PromelaModel) {
    let config = VerifyConfig::from_scenario(s).unwrap();
    let initial = world::load(s).unwrap().facts();
    let input = verify::VerifyInput {
        domain: &s.domain,
        tree,
        initial: &initial,
        disturbances: &config.disturbances,
        properties: &config.properties,
        limits: Limits {
            action_failures: failures,
            ..Limits::default()
        },
    };
    (
        verify::verify(&input),
        verify::export_promela(&input).unwrap(),
    )
}

pub fn holds(report: &Report, kind: PropertyKind) -> bool {
    match &report.property(kind).unwrap().verdict {
        Verdict::Holds => true,
        Verdict::Violated(_) => false,
        Verdict::Unknown { states } => panic!("{kind:?} undecided after {states} states"),
    }
}

pub fn counterexample(report: &Report, kind: PropertyKind) -> &Counterexample {
    match &report.property(kind).unwrap().verdict {
        Verdict::Violated(cx) => cx,
        other => panic!("expected {kind:?} to be violated, got {other:?}"),
    }
}

/// The state the last step of a counterexample starts from.
pub fn before_last(cx: &Counterexample) -> &[Atom] {
    if cx.steps.len() > 1 {
        &cx.steps[cx.steps.len() - 2].state
    } else {
        &cx.initial
    }
}

/// Whether SPIN can be used; panics under CI when it cannot.
pub fn spin_available() -> bool {
    let ok = Command::new("spin").arg("-V").output().is_ok();
    if !ok {
        super::check::cannot_check(
            "the SPIN cross-check",
            "spin is not installed (scripts/setup.sh --test installs it, or apt-get install spin)",
        );
    }
    ok
}

/// Run SPIN on the model, one claim at a time; returns (claim, holds).
fn spin_verdicts(model: &verify::promela::PromelaModel, name: &str) -> Vec<(String, bool)> {
    // A directory of its own for every run, so checks running side by side never share
    // SPIN's generated files, whatever they are named.
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let nth = RUNS.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let dir: PathBuf =
        std::env::temp_dir().join(format!("betr-spin-{name}-{}-{nth}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("model.pml"), &model.text).unwrap();
    let run = |cmd: &mut Command| {
        let out = cmd.current_dir(&dir).output().unwrap();
        assert!(
            out.status.success(),
            "{cmd:?} failed:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    run(Command::new("spin").args(["-a", "model.pml"]));
    run(Command::new("cc").args(["-O2", "-DNOREDUCE", "-DVECTORSZ=4096", "-o", "pan", "pan.c"]));
    let verdicts = model
        .claims
        .iter()
        .map(|(claim, _)| {
            let out = run(Command::new("./pan").args(["-a", "-m1000000", "-N", claim]));
            let errors: usize = out
                .split("errors: ")
                .nth(1)
                .and_then(|rest| rest.split_whitespace().next())
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("no error count in pan's output:\n{out}"));
            assert!(!out.contains("max search depth too small"), "{out}");
            (claim.clone(), errors == 0)
        })
        .collect();
    let _ = std::fs::remove_dir_all(&dir);
    verdicts
}

/// SPIN must reach betr's verdict on every claim; returns one line per claim
/// (`claim betr/SPIN`), or None when SPIN is not installed.
pub fn spin_agrees(
    report: &Report,
    model: &verify::promela::PromelaModel,
    name: &str,
) -> Option<Vec<String>> {
    if !spin_available() {
        return None;
    }
    let word = |h: bool| if h { "holds" } else { "violated" };
    let spin = spin_verdicts(model, name);
    let mut lines = Vec::new();
    for ((claim, kind), (_, spin_holds)) in model.claims.iter().zip(&spin) {
        let betr_holds = holds(report, *kind);
        assert_eq!(
            betr_holds,
            *spin_holds,
            "{name}: claim {claim}: betr says {}, SPIN says {}",
            word(betr_holds),
            word(*spin_holds)
        );
        lines.push(format!(
            "{claim} {}/{}",
            word(betr_holds),
            word(*spin_holds)
        ));
    }
    Some(lines)
}

/// Whether a condition holds over a fact set, wildcards as the abstraction reads them.
pub fn holds_over(facts: &[Atom], c: &Condition) -> bool {
    facts.iter().any(|f| instance_of(&c.atom, f)) != c.negated
}

/// Ticks a tree once over a fact set, as the abstraction does, with the real `bt` ticker.
struct Facts {
    facts: Vec<Atom>,
    started: Vec<ActionCall>,
}

impl Leaves for Facts {
    fn check(&mut self, c: &Condition) -> bool {
        holds_over(&self.facts, c)
    }
    fn step(&mut self, _: NodeId, action: &ActionCall, _: bool) -> ActionStep {
        self.started.push(action.clone());
        ActionStep::Running
    }
    fn halt(&mut self, _: NodeId, _: &ActionCall) {}
}

pub fn tick_over(tree: &Tree, facts: &[Atom]) -> (Outcome, Vec<ActionCall>) {
    let mut leaves = Facts {
        facts: facts.to_vec(),
        started: Vec::new(),
    };
    let record = Ticker::new().tick(tree, &mut leaves);
    (record.root, leaves.started)
}

pub fn has(facts: &[Atom], atom: &str) -> bool {
    facts.iter().any(|a| a.to_string() == atom)
}

/// The tree as text, for messages.
pub fn text(tree: &Tree) -> String {
    bt::to_text(tree)
}
