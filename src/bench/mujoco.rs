//! The MuJoCo cell: how fast it simulates (the scene of scenario 1 with both arms moving,
//! against real time), and scenario 1 end to end with every action performed in it
//! (planned and predicted in the twin, the failure found there, the expected fix
//! approved, the repaired tree run to success in MuJoCo; the model's part left out: the
//! fix comes from a stand-in that answers with the scenario's expected fix at once).

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::{BenchError, Better, Row, Target};
use crate::executor::mujoco;
use crate::llm::{ChatFuture, ChatReply, ChatRequest, LanguageModel, ReplySource, TokenUsage};
use crate::scenario::Scenario;
use crate::session::{self, Ending, Execution, Options};
use crate::world::{self, CellWorld};

fn setup(e: impl std::fmt::Display) -> BenchError {
    BenchError::Setup(e.to_string())
}

/// Simulated seconds per wall-clock second of the cell of `path` in MuJoCo, over `seconds`.
pub fn step_rate(path: &Path, seconds: f64) -> Result<Row, BenchError> {
    let scenario = Scenario::load(path)?;
    let exec = world::load_execution(&scenario, None)?;
    let cell = CellWorld::of(exec.world.as_ref()).ok_or_else(|| setup("not a cell"))?;
    let scene = cell.describe().map_err(setup)?;
    let file = std::env::temp_dir().join(format!("betr-mujoco-scene-{}.json", std::process::id()));
    let json = serde_json::to_vec(&scene).map_err(setup)?;
    std::fs::write(&file, json).map_err(setup)?;
    let (python, script) =
        mujoco::installed(false, &|line| tracing::info!("{line}")).map_err(setup)?;
    let out = std::process::Command::new(python)
        .arg(script)
        .arg("--step-rate")
        .arg(&file)
        .arg(seconds.to_string())
        .output()
        .map_err(setup)?;
    let _ = std::fs::remove_file(&file);
    if !out.status.success() {
        return Err(setup(format!(
            "the step-rate run failed: {}",
            String::from_utf8_lossy(&out.stderr)
        )));
    }
    let rate: serde_json::Value = serde_json::from_slice(&out.stdout).map_err(setup)?;
    let number = |k: &str| {
        rate[k]
            .as_f64()
            .ok_or_else(|| setup(format!("no {k} in {rate}")))
    };
    let (steps, wall, simulated) = (number("steps")?, number("wall")?, number("simulated")?);
    Ok(Row {
        part: "mujoco".into(),
        measure: "the cell of scenario 1 simulated, both arms moving".into(),
        unit: "× real time".into(),
        better: Better::Higher,
        betr: simulated / wall,
        anchor: None,
        target: Some(Target::AtLeast(20.0)),
        note: format!(
            "{:.0} steps/s of {} ms ({steps:.0} steps in {wall:.1} s); the YuMi's meshes, 3 cubes and the table in contact",
            steps / wall,
            simulated / steps * 1e3
        ),
    })
}

/// Answers every failure question with the scenario's expected fix, at once.
struct ExpectedFix(String);

impl LanguageModel for ExpectedFix {
    fn model(&self) -> &str {
        "expected-fix"
    }
    fn chat<'a>(&'a self, _: &'a ChatRequest) -> ChatFuture<'a> {
        Box::pin(async move {
            Ok(ChatReply {
                text: format!(
                    "Reasoning: the scenario's expected fix.\nConditions:\n{}\n",
                    self.0
                ),
                model: "expected-fix".into(),
                usage: TokenUsage::default(),
                latency: Duration::ZERO,
                source: ReplySource::HandWritten {
                    note: "the scenario's expected fix".into(),
                },
                ranked: Vec::new(),
            })
        })
    }
}

/// Scenario 1 end to end in MuJoCo, `runs` times; the mean wall time per run, and the
/// same loop with betr's world performing the actions (what MuJoCo adds is the
/// difference).
pub fn scenario_one(path: &Path, runs: u32) -> Result<Vec<Row>, BenchError> {
    let in_mujoco = scenario_one_in(path, runs, true)?;
    let in_betr = scenario_one_in(path, runs, false)?;
    Ok(vec![
        Row {
            part: "mujoco".into(),
            measure: "scenario 1 in MuJoCo: plan, fail, ask, repair, run to success".into(),
            unit: "s".into(),
            better: Better::Lower,
            betr: in_mujoco,
            anchor: None,
            target: Some(Target::AtMost(5.0)),
            note: format!(
                "mean of {runs} run(s); the executor process started and the scene built each run; the fix from a stand-in answering with the expected fix (no model time)"
            ),
        },
        Row {
            part: "mujoco".into(),
            measure: "the same loop in betr's world (no executor)".into(),
            unit: "s".into(),
            better: Better::Lower,
            betr: in_betr,
            anchor: None,
            target: None,
            note: format!("mean of {runs} run(s), for comparison"),
        },
    ])
}

/// Seconds per run of scenario 1's loop, its actions performed in MuJoCo or in betr's world.
fn scenario_one_in(path: &Path, runs: u32, mujoco_performs: bool) -> Result<f64, BenchError> {
    let scenario = Scenario::load(path)?;
    let fix = scenario.expected_fix.join("\n");
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(setup)?;
    let options = Options {
        use_scenario_goal: true,
        ..Options::default()
    };
    let began = Instant::now();
    for _ in 0..runs.max(1) {
        let executor: Option<Box<dyn crate::executor::Executor>> = if mujoco_performs {
            let started = mujoco::spawn(&[], false, &|line| tracing::info!("{line}"));
            Some(Box::new(started.map_err(setup)?))
        } else {
            None
        };
        let model: Arc<dyn LanguageModel> = Arc::new(ExpectedFix(fix.clone()));
        let mut approve = |_: &session::Proposal| true;
        let mut best = |_: &[session::Reading], _: Option<&str>| Some(0);
        let resolved = runtime
            .block_on(session::resolve_with_scenes(
                &scenario,
                None,
                model,
                &options,
                Execution {
                    scenes: false,
                    executor,
                },
                (&mut approve, &mut best),
                &mut |_| {},
            ))
            .map_err(setup)?;
        if !matches!(resolved.ending, Ending::Success { .. }) {
            return Err(setup(format!(
                "scenario 1 in MuJoCo ended {:?}",
                resolved.ending
            )));
        }
    }
    Ok(began.elapsed().as_secs_f64() / f64::from(runs.max(1)))
}
