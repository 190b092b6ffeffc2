//! `betr` and `betr tui [SCENARIO]`: the workbench on a scenario (scenario 1 by default)
//! with the configured model. A model that cannot be set up (no model name for a server,
//! an embedded model file that cannot be fetched or loaded) is shown in the LLM pane; the
//! rest of the workbench works. What is not in the cache yet is fetched while the
//! workbench is open (`background_fetch`): the robot description a cell's arms need (the
//! cell moves the arms once it is there) and the embedded model (it answers once it is
//! loaded); the progress is in the status bar, and quitting cancels the fetch.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{Context, Result};
use clap::Args;

use betr::llm::LanguageModel;
use betr::llm::arriving::ArrivingModel;
use betr::llm::usage::Ledger;
use betr::session::{NoModel, PolicyStore, Setup};
use betr::tui::dictation::{DefaultMicrophone, Microphone, WavMicrophone};
use betr::tui::{Info, KeyBindings, Theme, Workbench};

use super::llm_cmds::{self, LlmFlags};

#[derive(Args, Debug, Clone, Default)]
pub struct TuiArgs {
    /// Scenario file or name (default: cell/red_on_blue, the red cube on the blue cube),
    /// looked for as given, under ./scenarios, then under $XDG_DATA_HOME/betr/scenarios.
    pub scenario: Option<PathBuf>,
    /// Apply every proposal of the model without asking (shown in the status bar).
    #[arg(long)]
    pub auto_approve: bool,
    /// Where policies are saved and looked up (default: $XDG_DATA_HOME/betr/policies).
    #[arg(long, value_name = "DIR")]
    pub policy_dir: Option<PathBuf>,
    /// Plan without the rules learned from approved fixes (knowledge.toml in the policy
    /// directory).
    #[arg(long)]
    pub no_knowledge: bool,
    /// Open this tree file instead of planning one (betr text, a saved policy, or
    /// BehaviorTree.CPP v4 XML).
    #[arg(long, value_name = "FILE")]
    pub tree: Option<PathBuf>,
    /// Run in the scenario's `[world.variants.NAME]` world.
    #[arg(long)]
    pub variant: Option<String>,
    /// Perform the actions in `mujoco` (the cell in MuJoCo physics, installed on first
    /// use) or in this program (a simulator or a robot bridge speaking betr's executor
    /// protocol: docs/EXECUTORS.md) instead of betr's world, which becomes its twin; split
    /// as a shell would: `--executor "python3 sim.py --seed 3"`.
    #[arg(long, value_name = "COMMAND")]
    pub executor: Option<String>,
    /// Key bindings to override (default: $XDG_CONFIG_HOME/betr/keys.toml).
    #[arg(long, value_name = "FILE")]
    pub keys: Option<PathBuf>,
    /// Fetch nothing (the command line's global `--offline` or `BETR_OFFLINE`).
    #[arg(skip)]
    pub offline: bool,
    /// Milliseconds between ticks when running.
    #[arg(value_parser = clap::value_parser!(u64).range(1..=60_000), long, default_value_t = 150, value_name = "MS")]
    pub tick_ms: u64,
    #[command(flatten)]
    pub llm: LlmFlags,
    #[command(flatten)]
    pub viz: super::viz_flags::VizFlags,
}

pub fn tui(args: &TuiArgs, ascii: bool) -> Result<ExitCode> {
    let var = |k: &str| std::env::var(k).ok();
    let arg = args
        .scenario
        .clone()
        .unwrap_or_else(|| PathBuf::from(betr::scenario::catalog::DEFAULT_SCENARIO));
    let path = super::find_scenario(&arg)?;
    let microphone = microphone()?;
    let (scenario, knowledge) = scenario_of(args, &path)?;
    if let Some(file) = &args.tree
        && let Err(refusal) = super::export_cmd::load_tree(&scenario, file)
    {
        return show_not_run(file, refusal, ascii);
    }
    let (settings, mut options) = llm_cmds::settings(&args.llm)?;
    options.max_rounds = 5;
    let ledger = Ledger::new(settings.usage_log.clone());
    let (model, wanted_model) = workbench_model(&settings, &ledger, args.offline, &var);
    let (background, arrivals) = fetch_missing(&scenario, wanted_model, args.offline)?.unzip();
    let model_name = model_name(&settings);
    let no_model = model.as_ref().err().map(ToString::to_string);
    let policy_dir = args
        .policy_dir
        .clone()
        .or_else(|| PolicyStore::default_dir(&var));
    let (keys, keys_error) = key_bindings(args.keys.as_deref());
    let info = Info {
        scenario: path
            .file_stem()
            .map_or_else(|| scenario.name.clone(), |s| s.to_string_lossy().into()),
        backend: settings.backend,
        model: model_name,
        auto_approve: args.auto_approve,
        objects: scenario.domain.vocabulary.object_names(),
        no_model,
        keys_error,
    };
    let record = args
        .viz
        .recorder(&scenario, &path, args.variant.as_deref())?;
    let viz = args
        .viz
        .open(true, betr::viz::ViewerLife::StopsWithSession, &scenario)?;
    // A person is there to choose among readings that make the robot do different things.
    let options = betr::session::Options {
        choose_reading: true,
        ..options
    };
    let setup = Setup {
        variant: args.variant.clone(),
        ledger: Some(ledger),
        options,
        auto_approve: args.auto_approve,
        policies: policy_dir.map(PolicyStore::new),
        tick_interval: Duration::from_millis(args.tick_ms),
        scenes: args.viz.viewer.is_some() || args.viz.rrd.is_some(),
        knowledge,
        executor: super::executor_of(args.executor.as_deref())?,
        ..Setup::new(scenario, path, model)
    };
    // The status bar says it when a viewer is not there or the recording stopped.
    let mut tap = super::viz_flags::SessionTap { viz, record };
    let theme = Theme::of(ascii);
    // The screen's thread; the session engine gets threads of its own (`EngineThreads`).
    let runtime = super::runtime()?;
    let workbench = Workbench {
        info,
        keys,
        theme,
        microphone,
        stt: speech_to_text(args),
        stderr_to: log_path(),
        tree: args.tree.clone(),
        model_arrival: arrivals,
    };
    let ran = runtime.block_on(betr::tui::run(
        setup,
        workbench,
        (!tap.is_empty()).then_some(&mut tap as &mut dyn betr::tui::Tap),
    ));
    // Quitting while the model is fetched stops the fetch and removes what it wrote.
    if let Some(fetch) = background {
        fetch.cancel();
    }
    report_session(&ran?, args, &mut tap);
    Ok(ExitCode::SUCCESS)
}

/// What is not in the cache yet, fetched while the workbench is open: the robot
/// description the cell's arms need, then the embedded model (nothing when `offline`),
/// with where the fetch reports. A failed fetch or load leaves the workbench usable
/// without it and says why.
fn fetch_missing(
    scenario: &betr::scenario::Scenario,
    model: Option<super::background_fetch::WantedModel>,
    offline: bool,
) -> Result<
    Option<(
        super::background_fetch::BackgroundFetch,
        tokio::sync::mpsc::UnboundedReceiver<betr::tui::ModelArrival>,
    )>,
> {
    let robot = betr::session::missing_description(scenario).filter(|_| !offline);
    if robot.is_none() && model.is_none() {
        return Ok(None);
    }
    let (report, arrivals) = tokio::sync::mpsc::unbounded_channel();
    let fetch = super::background_fetch::start(robot, model, report)?;
    Ok(Some((fetch, arrivals)))
}

/// A `--tree` betr's engine does not run is the command's error (exit 2), said when
/// the screen closes. A BehaviorTree.CPP tree the monitor can read (any node kind) is first
/// shown whole on the monitor's file screen beside why, when a person is at the terminal.
fn show_not_run(file: &Path, refusal: anyhow::Error, ascii: bool) -> Result<ExitCode> {
    use std::io::IsTerminal as _;
    if !std::io::stdout().is_terminal() {
        return Err(refusal);
    }
    let Ok(tree) = super::monitor_cmd::read_tree_file(file) else {
        return Err(refusal);
    };
    let label = file.display().to_string();
    let view = betr::tui::monitor::FileView::new(tree, &label, Some(format!("{refusal:#}")), ascii);
    betr::tui::monitor::look(view, log_path().as_deref())?;
    Err(refusal.context(format!("{} was shown, not run", file.display())))
}

/// The variable naming a WAV file push-to-talk plays instead of the microphone: a stand-in
/// for demonstrations and tests on machines without one, not a setting of the workbench
/// (people without a microphone dictate a file with `betr interpret --audio`).
const STAND_IN_MICROPHONE: &str = "BETR_PUSH_TO_TALK_WAV";

/// The microphone push-to-talk listens to: the stand-in file, checked now rather than at
/// the first key press, or the default input device.
fn microphone() -> Result<Arc<dyn Microphone>> {
    Ok(match std::env::var_os(STAND_IN_MICROPHONE) {
        Some(file) => {
            let file = PathBuf::from(file);
            betr::voice::Audio16k::from_wav(&file).context(STAND_IN_MICROPHONE)?;
            Arc::new(WavMicrophone::new(file))
        }
        None => Arc::new(DefaultMicrophone),
    })
}

/// The scenario at `path` with the rules learned for it (fixes approved in the workbench
/// may be kept as rules in the same file).
fn scenario_of(
    args: &TuiArgs,
    path: &std::path::Path,
) -> Result<(
    Arc<betr::scenario::Scenario>,
    Option<betr::session::knowledge::Knowledge>,
)> {
    let mut scenario = betr::scenario::Scenario::load(path)?;
    let knowledge_flags = super::knowledge_cmd::KnowledgeFlags {
        dir: super::knowledge_cmd::PolicyDir {
            policy_dir: args.policy_dir.clone(),
        },
        no_knowledge: args.no_knowledge,
    };
    let knowledge = knowledge_flags.apply(&mut scenario)?;
    super::with_made_examples(&mut scenario);
    Ok((Arc::new(scenario), knowledge))
}

/// The model's name as the status bar says it.
fn model_name(settings: &betr::llm::config::Settings) -> String {
    match settings.backend {
        betr::llm::config::Backend::Local => settings.local_model().map(|(name, _)| name).ok(),
        _ => settings.model.clone(),
    }
    .unwrap_or_else(|| "(no model)".into())
}

/// Speech-to-text for push-to-talk, from the settings file and the `BETR_STT*` variables.
/// Bad speech settings disable dictation (saying why when the key is pressed), not the
/// workbench.
fn speech_to_text(
    args: &TuiArgs,
) -> Result<betr::tui::dictation::SttLoader, betr::tui::dictation::DictationError> {
    let no_flags = super::voice_cmd::SttFlags::default();
    super::voice_cmd::settings(args.llm.config.as_deref(), &no_flags)
        .map(betr::tui::dictation::loader_of)
        .map_err(|e| betr::tui::dictation::DictationError::Settings {
            reason: format!("{e:#}"),
        })
}

/// The workbench's model: one being fetched (it answers once it has arrived, and the
/// fetch to start is returned), or the configured one ready now, or why there is none.
fn workbench_model(
    settings: &betr::llm::config::Settings,
    ledger: &Ledger,
    offline: bool,
    var: &dyn Fn(&str) -> Option<String>,
) -> (
    Result<Arc<dyn LanguageModel>, NoModel>,
    Option<super::background_fetch::WantedModel>,
) {
    match llm_cmds::local_model_to_fetch(settings) {
        Some(spec) if offline => (
            Err(NoModel::Unavailable(format!(
                "the model {} is not in the cache and --offline fetches nothing (`betr model fetch` fetches it)",
                spec.name
            ))),
            None,
        ),
        Some(spec) => {
            let arriving = Arc::new(ArrivingModel::new(
                spec.name,
                true,
                false,
                &format!("the model {} is not fetched yet", spec.name),
            ));
            let wanted = super::background_fetch::WantedModel {
                spec,
                settings: settings.clone(),
                ledger: ledger.clone(),
                arriving: arriving.clone(),
            };
            (Ok(arriving as Arc<dyn LanguageModel>), Some(wanted))
        }
        None => (ready_model(settings, ledger, var), None),
    }
}

/// Where what the session made went, now the terminal is the shell's again; the web
/// viewer started for the workbench goes with it.
fn report_session(
    summary: &betr::tui::Summary,
    args: &TuiArgs,
    tap: &mut super::viz_flags::SessionTap,
) {
    for path in &summary.policies {
        outln!("policy saved: {}", path.display());
    }
    if summary.unsaved_fixes > 0 {
        outln!(
            "not saved: {} approved fix(es) of the last tree",
            summary.unsaved_fixes
        );
    }
    for path in &summary.exported {
        outln!("tree exported: {}", path.display());
    }
    if let Some(path) = &args.viz.record {
        outln!("session recording: {}", path.display());
    }
    if let Some(path) = &args.viz.rrd {
        outln!("3D view (.rrd): {}", path.display());
    }
    if let Some(mut server) = tap.viz.as_mut().and_then(betr::viz::Viz::take_web_server) {
        server.stop();
        outln!("3D view: the web viewer was stopped");
    }
}

/// The configured model when nothing needs fetching: a server's client, or the embedded
/// model loaded from its file.
fn ready_model(
    settings: &betr::llm::config::Settings,
    ledger: &Ledger,
    var: &dyn Fn(&str) -> Option<String>,
) -> Result<Arc<dyn LanguageModel>, NoModel> {
    llm_cmds::ensure_local_model(settings)
        .map_err(|e| NoModel::Unavailable(format!("{e:#}")))
        .and_then(|()| {
            settings
                .build(ledger.clone(), var)
                .map_err(|e| NoModel::Unavailable(e.to_string()))
        })
        .map(|m| {
            m.set_purpose("workbench");
            Arc::new(m) as Arc<dyn LanguageModel>
        })
}

/// Where the key bindings file is looked for when none is given.
/// The key bindings: `keys` (a `--keys` file), else the default keys file, with the
/// defaults patched by it; why a file could not be used, to say on the screen.
pub fn key_bindings(keys: Option<&std::path::Path>) -> (KeyBindings, Option<String>) {
    let var = |k: &str| std::env::var(k).ok();
    let path = keys
        .map(std::path::Path::to_path_buf)
        .or_else(|| default_keys_path(&var));
    match &path {
        Some(p) => KeyBindings::load(p),
        None => (KeyBindings::default(), None),
    }
}

pub fn default_keys_path(var: &dyn Fn(&str) -> Option<String>) -> Option<PathBuf> {
    let config = var("XDG_CONFIG_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| var("HOME").map(|h| Path::new(&h).join(".config")))?;
    Some(config.join("betr").join("keys.toml"))
}

/// Where the workbench writes its log (the terminal belongs to the screen).
pub fn log_path() -> Option<PathBuf> {
    let state = std::env::var_os("XDG_STATE_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".local/state")))?;
    Some(state.join("betr").join("tui.log"))
}
