//! What the workbench still needs from the package index, fetched while it is open: the
//! robot description the cell's arms need, then the embedded model. The fetch runs on a
//! thread of its own, its progress goes to the status bar, each thing is handed over when
//! it is there (the arms to the session's world, the loaded model to the session), and
//! quitting cancels it (pip stopped, its temporary files removed, nothing half-written).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use tokio::sync::mpsc::UnboundedSender;

use betr::llm::LanguageModel;
use betr::llm::arriving::ArrivingModel;
use betr::llm::config::Settings;
use betr::llm::usage::Ledger;
use betr::model::{DescriptionSpec, FetchError, ModelSpec, Pip, Progress};
use betr::tui::ModelArrival;

/// A fetch under way; [`BackgroundFetch::cancel`] stops it.
pub struct BackgroundFetch {
    cancel: Arc<AtomicBool>,
    thread: JoinHandle<()>,
}

/// The embedded model to fetch, and what builds it and hands it over once it is there.
pub struct WantedModel {
    pub spec: &'static ModelSpec,
    pub settings: Settings,
    pub ledger: Ledger,
    pub arriving: Arc<ArrivingModel>,
}

/// What the model says to a question asked while it is fetched.
fn waiting_for(name: &str, status: &str) -> String {
    format!(
        "the model {name} is not there yet ({status}); meanwhile a goal formula can be typed, planned, stepped and verified"
    )
}

/// Fetch `robot` (when given) and then `model` (when given) into the cache; each step is
/// reported on `report`.
pub fn start(
    robot: Option<&'static DescriptionSpec>,
    model: Option<WantedModel>,
    report: UnboundedSender<ModelArrival>,
) -> Result<BackgroundFetch> {
    let cancel = Arc::new(AtomicBool::new(false));
    let cancelled = cancel.clone();
    let thread = std::thread::Builder::new()
        .name("fetch".into())
        .spawn(move || {
            if let Some(robot) = robot {
                let waiting = model.as_ref().map(|m| (m.spec.name, m.arriving.clone()));
                if !fetch_robot(robot, waiting, &report, &cancelled) {
                    return;
                }
            }
            if let Some(model) = model {
                fetch_model(model, &report, &cancelled);
            }
        })
        .context("starting the fetch")?;
    Ok(BackgroundFetch { cancel, thread })
}

/// Fetch the robot description and say how it went; false when the person quit. A model
/// waiting behind it tells questions asked meanwhile that it comes next.
fn fetch_robot(
    robot: &'static DescriptionSpec,
    waiting: Option<(&'static str, Arc<ArrivingModel>)>,
    report: &UnboundedSender<ModelArrival>,
    cancelled: &Arc<AtomicBool>,
) -> bool {
    let mut progress = StatusProgress {
        label: format!("robot {}: ", robot.name),
        stage: "starting".into(),
        last: String::new(),
        report: report.clone(),
        waiting: waiting.map(|(name, arriving)| (name, arriving, "after the robot description")),
        cancel: cancelled.clone(),
    };
    let fetched = betr::model::ensure_description(
        robot,
        &betr::model::cache_dir(),
        Pip::DEFAULT,
        &mut progress,
    );
    let arrival = match fetched {
        Ok(path) => {
            tracing::info!(path = %path.display(), "robot description fetched");
            ModelArrival::RobotReady
        }
        Err(FetchError::Cancelled) => return false,
        Err(e) => {
            tracing::warn!(robot = robot.name, error = %e, "no robot description");
            ModelArrival::RobotFailed(e.to_string())
        }
    };
    let _ = report.send(arrival);
    !cancelled.load(Ordering::Relaxed)
}

/// Fetch the model, build it and let its stand-in answer with it.
fn fetch_model(
    wanted: WantedModel,
    report: &UnboundedSender<ModelArrival>,
    cancelled: &Arc<AtomicBool>,
) {
    let WantedModel {
        spec,
        settings,
        ledger,
        arriving,
    } = wanted;
    let mut progress = StatusProgress {
        label: String::new(),
        stage: "starting".into(),
        last: String::new(),
        report: report.clone(),
        waiting: Some((spec.name, arriving.clone(), "")),
        cancel: cancelled.clone(),
    };
    let fetched = betr::model::fetch(spec, &betr::model::cache_dir(), "python3", &mut progress);
    let fail = |why: String| {
        tracing::warn!(model = spec.name, error = %why, "no model");
        arriving.set_waiting(&format!("no model: {why}"));
        let _ = report.send(ModelArrival::Failed(why));
    };
    match fetched {
        Ok(path) => tracing::info!(path = %path.display(), "model fetched"),
        Err(FetchError::Cancelled) => return,
        Err(e) => return fail(e.to_string()),
    }
    if cancelled.load(Ordering::Relaxed) {
        return;
    }
    progress.say(&format!("loading {}", spec.name));
    let var = |k: &str| std::env::var(k).ok();
    match settings.build(ledger, &var) {
        Ok(model) => {
            model.set_purpose("workbench");
            arriving.arrive(Arc::new(model) as Arc<dyn LanguageModel>);
            let _ = report.send(ModelArrival::Ready);
        }
        Err(e) => fail(e.to_string()),
    }
}

impl BackgroundFetch {
    /// Stop the fetch and wait until pip is stopped and its files are removed (what was
    /// already fetched is kept, and a model being loaded finishes loading first).
    pub fn cancel(self) {
        tracing::info!("cancelling the fetch");
        self.cancel.store(true, Ordering::Relaxed);
        if self.thread.join().is_err() {
            tracing::warn!("the fetch ended in a panic");
        }
    }
}

/// The fetch's progress as a few words for the status bar, also told to questions asked
/// meanwhile.
struct StatusProgress {
    /// What is fetched, before the status (empty for the model, which the status bar
    /// already names).
    label: String,
    stage: String,
    /// The last text sent (sent again only when it changes).
    last: String,
    report: UnboundedSender<ModelArrival>,
    /// The model that answers questions meanwhile with where its fetch stands, and how
    /// that relates to this fetch ("after the robot description").
    waiting: Option<(&'static str, Arc<ArrivingModel>, &'static str)>,
    cancel: Arc<AtomicBool>,
}

impl StatusProgress {
    fn say(&mut self, status: &str) {
        let status = format!("{}{status}", self.label);
        if status == self.last {
            return;
        }
        if let Some((name, arriving, relation)) = &self.waiting {
            let where_it_stands = if relation.is_empty() {
                status.clone()
            } else {
                format!("{relation}: {status}")
            };
            arriving.set_waiting(&waiting_for(name, &where_it_stands));
        }
        self.last.clone_from(&status);
        let _ = self.report.send(ModelArrival::Progress(status));
    }
}

impl Progress for StatusProgress {
    /// The status bar has room for a word: the wheels downloading, the model file
    /// assembled and checked, or the step's own words otherwise (waiting for another
    /// fetch).
    fn stage(&mut self, message: &str) {
        self.stage = if message.starts_with("downloading") {
            "fetching".into()
        } else if message.starts_with("assembling") {
            "verifying".into()
        } else {
            message.to_string()
        };
        let stage = self.stage.clone();
        self.say(&stage);
    }

    fn bytes(&mut self, done: u64, total: u64) {
        let status = format!(
            "{} {}/{} MB",
            self.stage,
            done / 1_000_000,
            total.div_ceil(1_000_000)
        );
        self.say(&status);
    }

    fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}
