//! PNG charts of evaluation results (plotters, bitmap backend). Text is drawn with a
//! TrueType font from the system (DejaVu Sans from Debian's `fonts-dejavu-core`, or the
//! file in `$BETR_FONT`), so the chart carries its labels without a font in the repository.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;

/// Accuracy per difficulty of one system, in percent.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub label: String,
    pub values: [f64; 3],
}

#[derive(Debug, Clone, thiserror::Error)]
pub enum ChartError {
    #[error(
        "no TrueType font found for chart labels (looked for {}); install fonts-dejavu-core or set BETR_FONT",
        .tried.join(", ")
    )]
    NoFont { tried: Vec<String> },
    #[error("drawing {path}: {detail}")]
    Draw { path: PathBuf, detail: String },
}

const FONT_CANDIDATES: [&str; 3] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
];

/// The outcome of registering the font, kept for every later chart.
static FONT: OnceLock<Result<(), ChartError>> = OnceLock::new();

/// Register the label font once per process.
pub(crate) fn ensure_font() -> Result<(), ChartError> {
    FONT.get_or_init(|| {
        let mut tried: Vec<String> = Vec::new();
        let env = std::env::var("BETR_FONT").ok().filter(|f| !f.is_empty());
        for path in env.iter().map(String::as_str).chain(FONT_CANDIDATES) {
            tried.push(path.to_string());
            if let Ok(bytes) = std::fs::read(path) {
                // plotters keeps the font for the life of the process.
                let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                    return Ok(());
                }
            }
        }
        Err(ChartError::NoFont { tried })
    })
    .clone()
}

/// Grouped bars: accuracy (%) per difficulty for each series.
pub fn accuracy_chart(path: &Path, title: &str, series: &[Series]) -> Result<(), ChartError> {
    ensure_font()?;
    let err = |e: &dyn std::fmt::Display| ChartError::Draw {
        path: path.to_path_buf(),
        detail: e.to_string(),
    };
    let root = BitMapBackend::new(path, (960, 540)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let groups = ["easy", "medium", "hard"];
    let n = series.len().max(1) as f64;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 26))
        .margin(16)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(0f64..3f64, 0f64..145f64)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        // Ticks every half group; only the group centres carry a name.
        .x_labels(7)
        .x_label_formatter(&|x| {
            if (x.fract() - 0.5).abs() < 1e-6 {
                groups
                    .get(x.floor() as usize)
                    .copied()
                    .unwrap_or("")
                    .to_string()
            } else {
                String::new()
            }
        })
        .y_labels(8)
        .y_label_formatter(&|y| {
            if *y <= 100.0 {
                format!("{y:.0}")
            } else {
                String::new()
            }
        })
        .y_desc("accuracy (%)")
        .label_style(("sans-serif", 16))
        .draw()
        .map_err(|e| err(&e))?;
    for (k, s) in series.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let width = 0.8 / n;
        let bars = s.values.iter().enumerate().map(|(g, v)| {
            let x0 = g as f64 + 0.1 + k as f64 * width;
            Rectangle::new([(x0, 0.0), (x0 + width * 0.92, *v)], color.filled())
        });
        chart
            .draw_series(bars)
            .map_err(|e| err(&e))?
            .label(s.label.clone())
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
