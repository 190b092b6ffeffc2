//! Charts of the resolution and parameter experiments: success rate per scenario
//! (horizontal bars), and the values proposed per parameter scenario with the range the
//! world accepts shaded.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{ChartError, ensure_font};

/// What one panel of the parameter chart shows.
#[derive(Debug, Clone, PartialEq)]
pub enum Panel {
    /// Proposed numbers in order (accepted or not), the accepted range, the paper's value.
    Numeric {
        title: String,
        unit: String,
        values: Vec<(f64, bool)>,
        min: Option<f64>,
        max: Option<f64>,
        paper: Option<f64>,
    },
    /// How often each category was proposed, and whether the world accepts it.
    Categorical {
        title: String,
        counts: Vec<(String, usize, bool)>,
    },
}

const ACCEPTED: RGBColor = RGBColor(46, 139, 87);
const REJECTED: RGBColor = RGBColor(200, 40, 40);

fn draw_err(path: &Path) -> impl Fn(&dyn std::fmt::Display) -> ChartError + '_ {
    move |e| ChartError::Draw {
        path: path.to_path_buf(),
        detail: e.to_string(),
    }
}

/// Horizontal bars: success rate (%) per scenario, top to bottom in the given order.
pub fn success_chart(path: &Path, title: &str, bars: &[(String, f64)]) -> Result<(), ChartError> {
    ensure_font()?;
    let err = draw_err(path);
    let n = bars.len().max(1);
    let root = BitMapBackend::new(path, (960, 120 + 44 * n as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(36)
        .y_label_area_size(300)
        .build_cartesian_2d(0f64..100f64, 0f64..n as f64)
        .map_err(|e| err(&e))?;
    let names: Vec<String> = bars.iter().map(|(l, _)| l.clone()).collect();
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(2 * n + 1)
        .y_label_formatter(&|y| {
            let slot = n as f64 - y;
            if (slot.fract() - 0.5).abs() < 1e-6 {
                names
                    .get(slot.floor() as usize)
                    .cloned()
                    .unwrap_or_default()
            } else {
                String::new()
            }
        })
        .x_desc("success rate (%)")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|e| err(&e))?;
    chart
        .draw_series(bars.iter().enumerate().map(|(i, (_, v))| {
            let top = n as f64 - i as f64 - 0.15;
            Rectangle::new([(0.0, top - 0.7), (*v, top)], ACCEPTED.filled())
        }))
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// One panel per parameter scenario, four to a row.
pub fn params_chart(path: &Path, title: &str, panels: &[Panel]) -> Result<(), ChartError> {
    ensure_font()?;
    let err = draw_err(path);
    let cols = 4;
    let rows = panels.len().div_ceil(cols).max(1);
    let root = BitMapBackend::new(path, (1200, 60 + 340 * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(title, ("sans-serif", 24))
        .map_err(|e| err(&e))?;
    let areas = root.split_evenly((rows, cols));
    for (panel, area) in panels.iter().zip(areas.iter()) {
        match panel {
            Panel::Numeric {
                title,
                unit,
                values,
                min,
                max,
                paper,
            } => numeric(area, title, unit, values, *min, *max, *paper).map_err(|e| err(&e))?,
            Panel::Categorical { title, counts } => {
                categorical(area, title, counts).map_err(|e| err(&e))?;
            }
        }
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult<'a> =
    Result<(), DrawingAreaErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>>;

fn numeric<'a>(
    area: &Area<'a>,
    title: &str,
    unit: &str,
    values: &[(f64, bool)],
    min: Option<f64>,
    max: Option<f64>,
    paper: Option<f64>,
) -> DrawResult<'a> {
    let mut top = values.iter().map(|v| v.0).fold(0.0f64, f64::max);
    for b in [min, max, paper].into_iter().flatten() {
        top = top.max(b);
    }
    let top = if top > 0.0 { top * 1.2 } else { 1.0 };
    let n = values.len().max(1) as f64;
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(28)
        .y_label_area_size(48)
        .build_cartesian_2d(0f64..n + 1.0, 0f64..top)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_desc("proposal")
        .y_desc(unit)
        .x_labels(values.len().clamp(1, 10) + 1)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .label_style(("sans-serif", 12))
        .draw()?;
    let band = (min.unwrap_or(0.0), max.unwrap_or(top));
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, band.0), (n + 1.0, band.1)],
        ACCEPTED.mix(0.15).filled(),
    )))?;
    if let Some(p) = paper {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(0.0, p), (n + 1.0, p)],
            BLUE.stroke_width(2),
        )))?;
    }
    chart.draw_series(values.iter().enumerate().map(|(i, (v, ok))| {
        let color = if *ok { ACCEPTED } else { REJECTED };
        Circle::new((i as f64 + 1.0, *v), 5, color.filled())
    }))?;
    Ok(())
}

fn categorical<'a>(
    area: &Area<'a>,
    title: &str,
    counts: &[(String, usize, bool)],
) -> DrawResult<'a> {
    let n = counts.len().max(1);
    let top = counts.iter().map(|c| c.1).max().unwrap_or(1).max(1) as f64 * 1.2;
    let names: Vec<String> = counts.iter().map(|c| c.0.clone()).collect();
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(28)
        .y_label_area_size(48)
        .build_cartesian_2d(0f64..n as f64, 0f64..top)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .y_desc("times proposed")
        .x_labels(2 * n + 1)
        .x_label_formatter(&|x| {
            if (x.fract() - 0.5).abs() < 1e-6 {
                names.get(x.floor() as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .label_style(("sans-serif", 12))
        .draw()?;
    chart.draw_series(counts.iter().enumerate().map(|(i, (_, k, ok))| {
        let color = if *ok { ACCEPTED } else { REJECTED };
        let x = i as f64;
        Rectangle::new([(x + 0.2, 0.0), (x + 0.8, *k as f64)], color.filled())
    }))?;
    Ok(())
}

/// The panels of `params.png`: every proposed value in run order (numeric), or how often
/// each category was proposed (categorical).
pub fn params_panels(results: &super::params::ParamsResults) -> Vec<Panel> {
    results
        .scenarios
        .iter()
        .map(|s| {
            let values: Vec<&super::params::ValueRecord> = results
                .cases
                .iter()
                .filter(|c| c.scenario == s.scenario)
                .flat_map(|c| &c.values)
                .collect();
            let title = format!("{} ({})", s.name, s.limits.parameter);
            if s.limits.unit.is_some() {
                Panel::Numeric {
                    title,
                    unit: s.limits.unit.clone().unwrap_or_default(),
                    values: values
                        .iter()
                        .filter_map(|v| v.number.map(|n| (n, v.accepted)))
                        .collect(),
                    min: s.limits.min,
                    max: s.limits.max,
                    paper: s
                        .paper
                        .split_whitespace()
                        .next()
                        .and_then(|t| t.parse().ok()),
                }
            } else {
                let mut names = s.limits.categories.clone();
                for v in &values {
                    if !names.contains(&v.value) {
                        names.push(v.value.clone());
                    }
                }
                let counts = names
                    .into_iter()
                    .map(|c| {
                        let k = values.iter().filter(|v| v.value == c).count();
                        let ok = s.limits.allowed.as_ref().is_none_or(|a| a.contains(&c));
                        (c, k, ok)
                    })
                    .collect();
                Panel::Categorical { title, counts }
            }
        })
        .collect()
}
