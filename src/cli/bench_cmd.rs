//! `betr bench`: betr against its anchors, one table (and JSON); `betr bench llm` times
//! each call of the goal prompt in detail.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context as _, Result};
use clap::{Args, ValueEnum};

use betr::bench::{self, Report, cold, model, motion, replay, scale, ticks};
use betr::llm::local::{Engine, EngineOptions, Generated, Generation};

/// A part of `betr bench`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Part {
    /// The tick loop against py_trees 2.6.0 on the same ~1000-node tree.
    Ticks,
    /// Scenario 1 end to end, and repair in cells of 10 to 10,000 cubes.
    Scale,
    /// Prompt and generation tokens/s against llama-bench (same libraries, file, threads).
    Model,
    /// The first answer of a one-shot command against a warm one, for both embedded models.
    Cold,
    /// Seeking to random steps of a 10,000-tick recording on a 500-node tree, as the replay
    /// workbench seeks.
    Replay,
    /// The YuMi's forward kinematics against Pinocchio; collision-free paths to 200 random
    /// reachable targets in a cluttered cell and on the cell scenarios' own arm motions
    /// against OMPL's RRTConnect with PyBullet's collision checks (same URDF, same
    /// solids); scenario 1 end to end with the real arms. Not part of the default set.
    Motion,
    /// `betr monitor` following a ~500-node BehaviorTree.CPP tree ticked at 100 Hz under
    /// Groot2's publisher (behaviortreepy); not part of the default set.
    Monitor,
    /// The MuJoCo cell: its simulation speed against real time, and scenario 1 end to end
    /// with every action performed in MuJoCo (no model time); not part of the default set.
    Mujoco,
    /// Every call of the goal prompt in detail (cold, warm, with and without the grammar);
    /// not part of the default set.
    Llm,
}

#[derive(Args)]
pub struct BenchArgs {
    /// The parts to run (default: ticks, scale, model, cold, replay).
    #[arg(value_enum)]
    parts: Vec<Part>,
    /// Tiny sizes and short runs: checks that every part runs, measures little.
    #[arg(long)]
    quick: bool,
    /// Where the report is written as JSON.
    #[arg(long, default_value = "eval-results/bench.json")]
    json: PathBuf,
    #[arg(long, default_value = "scenarios/cell/red_on_blue.toml")]
    scenario: PathBuf,
    /// The py_trees anchor script.
    #[arg(long, default_value = "../shared/anchors/bench_pytrees.py")]
    pytrees: PathBuf,
    /// Seconds each tick loop runs.
    #[arg(long, default_value_t = 3.0)]
    seconds: f64,
    /// A GGUF file instead of the default model (the model and llm parts).
    #[arg(long)]
    model_path: Option<PathBuf>,
    /// A known model by name (`betr model list`), fetched when missing.
    #[arg(long, conflicts_with = "model_path")]
    model: Option<String>,
    /// CPU threads for the model (default: the model part tries 1 to the number of cores,
    /// the cold part uses every core, the llm part the cores idle when the model loads).
    #[arg(long)]
    threads: Option<u32>,
    /// Runs per model measure (llama-bench's -r), warm calls in the cold and llm parts.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// The seed of the motion part's random targets and the boxes among them (both
    /// planners get the same cell and queries).
    #[arg(long, default_value_t = 39)]
    motion_seed: u64,
}

/// Run the chosen parts, print the table and write the JSON.
pub fn run(args: &BenchArgs) -> Result<ExitCode> {
    if args.parts == [Part::Llm] {
        return llm(
            &args.scenario,
            (args.model_path.as_deref(), args.model.as_deref()),
            args.threads,
            args.repeats,
        );
    }
    let parts: Vec<Part> = if args.parts.is_empty() {
        vec![
            Part::Ticks,
            Part::Scale,
            Part::Model,
            Part::Cold,
            Part::Replay,
        ]
    } else {
        args.parts.clone()
    };
    let mut report = Report::new();
    for part in &parts {
        errln!("bench: {}", format!("{part:?}").to_lowercase());
        let rows = match part {
            Part::Ticks => ticks_part(args)?,
            Part::Scale => scale_part(args)?,
            Part::Model => model_part(args)?,
            Part::Cold => cold_part(args)?,
            Part::Replay => replay::rows(&replay::seek_times(
                &args.scenario,
                if args.quick {
                    replay::Sizes::QUICK
                } else {
                    replay::Sizes::FULL
                },
            )?),
            Part::Motion => motion_part(args)?,
            Part::Monitor => bench::monitor::rows(&bench::monitor::run(
                &bench::monitor::btcpp_python()?,
                500,
                if args.quick { 1.0 } else { 10.0 },
            )?),
            Part::Mujoco => {
                let seconds = if args.quick { 1.0 } else { args.seconds };
                let runs = if args.quick { 1 } else { 3 };
                let mut rows = vec![bench::mujoco::step_rate(&args.scenario, seconds)?];
                rows.extend(bench::mujoco::scenario_one(&args.scenario, runs)?);
                rows
            }
            Part::Llm => anyhow::bail!("`llm` runs alone: betr bench llm"),
        };
        for row in &rows {
            errln!(
                "  {} {}: {}",
                row.part,
                row.measure,
                bench::number(row.betr)
            );
        }
        report.rows.extend(rows);
    }
    report.machine.load_after = bench::load_average();
    outln!("{}", report.markdown());
    report
        .write_json(&args.json)
        .with_context(|| format!("cannot write {}", args.json.display()))?;
    errln!("bench: written to {}", args.json.display());
    Ok(ExitCode::SUCCESS)
}

fn motion_part(args: &BenchArgs) -> Result<Vec<bench::Row>> {
    let spec = &betr::model::YUMI_DESCRIPTION;
    let dir = spec.path();
    if !spec.urdf_in(&dir).is_file() {
        anyhow::bail!(
            "the YuMi's description is not in the cache ({}): the motion part needs it",
            dir.display()
        );
    }
    let robot = betr::robot::Robot::read(spec, &dir)?;
    let shapes = betr::robot::RobotShapes::new(&robot.model, &robot.arms)?;
    let python = motion::anchor_python(Path::new("target/motion-bench-venv"))?;
    let script = Path::new("scripts/bench_motion.py");
    let seconds = if args.quick { 0.3 } else { args.seconds };
    let betr_fk = motion::betr_fk_rate(&robot, seconds);
    let pin_fk = motion::pin_fk_rate(&python, script, &spec.urdf_in(&dir), &dir, &robot, seconds)?;
    let mut rows = vec![bench::Row {
        part: "motion".into(),
        measure: "forward kinematics of both arms' flanges".into(),
        unit: "configurations/s".into(),
        better: bench::Better::Higher,
        betr: betr_fk,
        anchor: Some(("Pinocchio 4.1.0".into(), pin_fk)),
        target: Some(bench::Target::RatioAtLeast(1.0)),
        note: format!(
            "{seconds} s each on 1000 random configurations; Pinocchio computes every joint and the two flange frames"
        ),
    }];
    let rest = motion::cell_rest();
    let count = if args.quick { 10 } else { 200 };
    let seed = args.motion_seed;
    let boxes = motion::clutter(&robot, &shapes, &rest, 12, seed)?;
    let cell = motion::ClutteredCell {
        robot: &robot,
        shapes: &shapes,
        rest: &rest,
        boxes: &boxes,
    };
    let anchor = motion::AnchorRun {
        python: &python,
        script,
        spec,
        dir: &dir,
        budget_s: 2.0,
        scratch: Path::new("target"),
    };
    let queries = motion::random_queries(&cell, count, seed)?;
    let betr_times = motion::betr_plan(&cell, &queries, &betr::motion::PlanOptions::default())?;
    let ompl_times = motion::ompl_plan(&anchor, &cell, &queries)?;
    rows.extend(motion::plan_rows(
        &format!("{count} random reachable targets among 12 boxes (seed {seed})"),
        &betr_times,
        &ompl_times,
        "from each arm's rest values; betr: 4000 samples at most, steps up to a fifth of \
         the joint space across, 0.03 rad segment checks, shortcutting; OMPL: 2 s at most, \
         its default range (the same fifth), the same resolution, simplified",
    ));
    rows.extend(cell_motion_rows(args, &anchor)?);
    let scenario_one = if args.quick {
        Duration::from_millis(100)
    } else {
        Duration::from_secs(3)
    };
    rows.push(bench::scale::scenario_one_arms(
        &args.scenario,
        scenario_one,
    )?);
    // The towers extend the cell's base file, beside scenario 1's.
    let base = args
        .scenario
        .parent()
        .unwrap_or(Path::new("."))
        .join("cell.toml");
    rows.push(bench::scale::towers_arms(
        if args.quick { 100 } else { 1000 },
        &base,
    )?);
    Ok(rows)
}

/// The cell scenarios' own arm motions (every scenario under the default scenario's
/// folder whose robot has arms), planned by betr and by OMPL + PyBullet.
fn cell_motion_rows(args: &BenchArgs, anchor: &motion::AnchorRun<'_>) -> Result<Vec<bench::Row>> {
    let folder = args.scenario.parent().unwrap_or(Path::new("."));
    let mut paths: Vec<PathBuf> = std::fs::read_dir(folder)
        .with_context(|| format!("cannot list {}", folder.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut scenarios = Vec::new();
    let mut queries = Vec::new();
    let mut arms = None;
    for path in &paths {
        // cell.toml and examples.toml are not scenarios of their own.
        let Ok(text) = std::fs::read_to_string(path) else {
            continue;
        };
        if !text.contains("[scenario]") {
            continue;
        }
        if let Some(found) = bench::cell_motion::scenario_queries(path)? {
            scenarios.push(format!("{} {}", found.scenario, found.queries.len()));
            queries.extend(found.queries);
            arms.get_or_insert(found.arms);
        }
    }
    let Some(arms) = arms else {
        anyhow::bail!("no scenario in {} moves the real arms", folder.display());
    };
    let betr_times = bench::cell_motion::betr_plan(&arms, &queries)?;
    let (ompl_times, skipped) = bench::cell_motion::ompl_plan(anchor, &arms, &queries)?;
    let mut note = format!(
        "each scenario's tree failing, repaired with its expected fix, run to success; queries per scenario: {}; the same start, goal, solids, other arm and carried object for both",
        scenarios.join(", ")
    );
    if !skipped.is_empty() {
        note.push_str(&format!(
            "; shapes PyBullet was not given: {}",
            skipped.join(", ")
        ));
    }
    Ok(motion::plan_rows(
        &format!("the cell scenarios' {} arm motions", queries.len()),
        &betr_times,
        &ompl_times,
        &note,
    ))
}

fn ticks_part(args: &BenchArgs) -> Result<Vec<bench::Row>> {
    let time = Duration::from_secs_f64(if args.quick {
        0.2
    } else {
        args.seconds.max(0.1)
    });
    let nodes = 1000;
    let python = ticks::pytrees_python(Path::new("target/bench-venv"))?;
    // Back to back: the anchor, then betr, on the same shape.
    let anchor = ticks::pytrees_ticks(&python, &args.pytrees, nodes, time)?;
    let tree = ticks::pytrees_shape(nodes)?;
    let betr = ticks::betr_ticks(&tree, time);
    if (betr.nodes, betr.visited_per_tick) != (anchor.nodes, anchor.visited_per_tick) {
        anyhow::bail!(
            "the trees differ: betr {} nodes, {} visited per tick; py_trees {} and {}",
            betr.nodes,
            betr.visited_per_tick,
            anchor.nodes,
            anchor.visited_per_tick
        );
    }
    Ok(vec![bench::Row {
        part: "ticks".into(),
        measure: format!("ticks of a {}-node planned-BT-shaped tree", betr.nodes),
        unit: "ticks/s".into(),
        better: bench::Better::Higher,
        betr: betr.ticks_per_s,
        anchor: Some((ticks::PY_TREES.replace("==", " "), anchor.ticks_per_s)),
        target: Some(bench::Target::RatioAtLeast(50.0)),
        note: format!(
            "{} nodes visited per tick; {:.1} s each; betr records every node's status per tick",
            betr.visited_per_tick,
            time.as_secs_f64()
        ),
    }])
}

fn scale_part(args: &BenchArgs) -> Result<Vec<bench::Row>> {
    let time = Duration::from_secs_f64(if args.quick { 0.05 } else { 1.0 });
    let mut rows = vec![scale::scenario_one(&args.scenario, time)?];
    let sizes: &[usize] = if args.quick {
        &[10, 100]
    } else {
        &[10, 100, 1000, 10_000]
    };
    // The towers extend the cell's base file, beside scenario 1's.
    let base = args
        .scenario
        .parent()
        .unwrap_or(Path::new("."))
        .join("cell.toml");
    rows.extend(scale::towers(sizes, &base)?);
    Ok(rows)
}

fn model_part(args: &BenchArgs) -> Result<Vec<bench::Row>> {
    let path = model_file(args, None)?;
    let name = model_name(&path);
    let sizes = if args.quick {
        model::ModelSizes {
            prompt: 64,
            generate: 8,
            repeats: 1,
        }
    } else {
        model::ModelSizes {
            prompt: 512,
            generate: 64,
            repeats: u32::try_from(args.repeats.max(1)).unwrap_or(3),
        }
    };
    // The llama.cpp this very binary was built with: the profile directory it lies in.
    let exe = std::env::current_exe().context("cannot tell where betr runs from")?;
    let profile = exe
        .ancestors()
        .skip(1)
        .find(|d| d.join("build").is_dir())
        .context("betr does not run from a cargo target directory, where llama-bench is built against its llama.cpp")?;
    let binary = model::llama_bench_binary(Path::new("scripts/llama-bench.sh"), profile)?;
    let cores = bench::cores();
    let threads: Vec<u32> = match args.threads {
        Some(t) => vec![t.max(1)],
        None if args.quick => vec![cores],
        None => (1..=cores).collect(),
    };
    let mut rows = Vec::new();
    for t in threads {
        // Back to back: llama-bench, then betr, with the same file and threads.
        let anchor = model::llama_bench(&binary, &path, t, sizes)?;
        let betr = model::betr_speeds(&path, t, sizes)?;
        rows.extend(model::rows(&name, t, betr, anchor, sizes));
    }
    Ok(rows)
}

fn cold_part(args: &BenchArgs) -> Result<Vec<bench::Row>> {
    // Every core, unless told: the idle-core count the product uses would depend on what
    // the part before left running.
    let threads = args.threads.map_or_else(bench::cores, |t| t.max(1));
    // Both embedded models, unless one was chosen.
    let models: Vec<PathBuf> = if args.model_path.is_some() || args.model.is_some() {
        vec![model_file(args, None)?]
    } else {
        betr::model::MODELS
            .iter()
            .map(|m| model_file(args, Some(m.name)))
            .collect::<Result<_>>()?
    };
    let states =
        std::env::temp_dir().join(format!("betr-bench-prompt-state-{}", std::process::id()));
    let warm = if args.quick { 1 } else { args.repeats.max(1) };
    let mut rows = Vec::new();
    for path in models {
        let l = cold::latencies(&path, &args.scenario, threads, &states, warm);
        let _ = std::fs::remove_dir_all(&states);
        rows.extend(cold::rows(&model_name(&path), threads, &l?));
    }
    Ok(rows)
}

/// The model file: `--model-path`, else the named (or `--model`, or default) model,
/// fetched when missing.
fn model_file(args: &BenchArgs, name: Option<&str>) -> Result<PathBuf> {
    match (&args.model_path, name) {
        (Some(p), _) => Ok(p.clone()),
        (None, Some(n)) => super::model_cmd::ensure(Some(n)),
        (None, None) => super::model_cmd::ensure(args.model.as_deref()),
    }
}

fn model_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Load the model, then time a cold call, warm calls that share the cached prompt prefix,
/// with and without the grammar, and print one table.
fn llm(
    scenario: &Path,
    (model_path, model): (Option<&Path>, Option<&str>),
    threads: Option<u32>,
    repeats: usize,
) -> Result<ExitCode> {
    let threads = threads.map_or_else(betr::llm::local::threads::idle_threads, |t| t.max(1));
    let path = match model_path {
        Some(p) => p.to_path_buf(),
        None => super::model_cmd::ensure(model)?,
    };
    outln!("model: {}", path.display());
    let prompt = cold::GoalPrompt::load(scenario)?;
    let instruction = prompt
        .scenario
        .instruction
        .clone()
        .context("the scenario has no instruction")?;

    let started = Instant::now();
    let engine = Engine::load(EngineOptions {
        model_path: path,
        threads,
        context: 4096,
        prompt_states: None,
    })?;
    let load = started.elapsed();
    outln!(
        "model load: {:.2} s ({threads} thread(s))",
        load.as_secs_f64()
    );
    outln!(
        "{:<34} {:>9} {:>8} {:>8} {:>11} {:>10}  answer",
        "call",
        "latency",
        "prompt",
        "cached",
        "prompt t/s",
        "gen t/s"
    );
    let cold = timed(&engine, prompt.generation(&instruction, true)?)?;
    report("cold (grammar)", &cold);
    // The same prompt prefix (role, vocabulary, objects, examples, scene) with other
    // instructions: only the request's own tokens are evaluated.
    let others = [
        "Put the red cube on the table",
        "Stack the green cube on the blue cube",
        "Hold the red cube",
    ];
    for (label, grammar) in [("warm (grammar)", true), ("warm (no grammar)", false)] {
        for i in 0..repeats.max(1) {
            let g = timed(
                &engine,
                prompt.generation(others[i % others.len()], grammar)?,
            )?;
            report(label, &g);
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn timed(engine: &Engine, generation: Generation) -> Result<(Generated, f64)> {
    let started = Instant::now();
    let g = engine.generate_blocking(generation)?;
    Ok((g, started.elapsed().as_secs_f64()))
}

fn report(label: &str, (g, seconds): &(Generated, f64)) {
    let evaluated = g.prompt_tokens.saturating_sub(g.cached_tokens);
    let rate = |n: u32, d: std::time::Duration| {
        if d.as_secs_f64() > 0.0 {
            n as f64 / d.as_secs_f64()
        } else {
            0.0
        }
    };
    outln!(
        "{:<34} {:>7.2} s {:>8} {:>8} {:>11.0} {:>10.1}  {}",
        label,
        seconds,
        g.prompt_tokens,
        g.cached_tokens,
        rate(evaluated, g.prompt_time),
        rate(g.completion_tokens, g.generation_time),
        g.text.trim()
    );
}
