//! Where the error is, drawn (`SCENE-map.svg`): one panel per run and per
//! floor, the cloth in material coordinates (u across, v up), each sample
//! point a cell shaded by its error ([`super::sampling::sample_errors`]: at
//! rest the last frame's, otherwise the RMS over the frames) on one shared
//! scale from white (0) to dark red (the largest error of any panel), so that
//! panels compare at a glance. Each panel's title gives its label and the
//! RMS of its cells (at rest the run's final error; frame by frame the RMS
//! over points and frames together, not the bench's mean of each frame's
//! RMS). The same numbers are in `SCENE-samples.csv`.
//!
//! Written for the eleventh sitting's question on `hanging_sheet_rest`
//! (docs/speed-vs-error-history.md): uniform 128's error was the same everywhere (a
//! shift of the whole sheet), the adaptive runs' lay along the folds of the
//! sheet's lower half.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{BenchError, Compare, Floor, Row};
use crate::math::Scalar;

/// Panels per row of the figure.
const COLUMNS: usize = 3;
/// Size of one panel, px (square plot plus its title).
const PANEL: u32 = 300;
/// Height of the colour key at the bottom, px.
const KEY_H: u32 = 60;

/// One panel: its title and its error at every sample point (`NaN`: none).
struct Panel<'a> {
    label: String,
    errors: &'a [Scalar],
}

/// The shade of `e` on the scale `0..=top`: white to dark red.
fn shade(e: Scalar, top: Scalar) -> RGBColor {
    let t = if top > 0.0 {
        (e / top).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let lerp = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
    RGBColor(lerp(255.0, 150.0), lerp(255.0, 0.0), lerp(255.0, 0.0))
}

/// RMS of the finite values (`NaN` when there are none).
fn rms(values: &[Scalar]) -> Scalar {
    let (sum, n) = values
        .iter()
        .filter(|e| e.is_finite())
        .fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
    if n == 0 {
        Scalar::NAN
    } else {
        (sum / n as Scalar).sqrt()
    }
}

/// The half width of a sample's cell: half the smallest positive gap between
/// distinct coordinates along either axis (the sample grid's spacing); for
/// samples on one point, with no gap to take, 0.5 m (a cell of 1 m around it:
/// only the drawing's scale depends on it).
fn half_cell(points: &[[Scalar; 2]]) -> Scalar {
    let gap = |k: usize| {
        let mut c: Vec<Scalar> = points.iter().map(|p| p[k]).collect();
        c.sort_by(|a, b| a.total_cmp(b));
        c.windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| *d > 1e-12)
            .fold(Scalar::INFINITY, Scalar::min)
    };
    let g = gap(0).min(gap(1));
    if g.is_finite() { g / 2.0 } else { 0.5 }
}

/// The map of `rows` and `floors` at the sample `points` (material
/// coordinates) as SVG text titled `title`; `None` when no run has per-point
/// errors (every run failed, or there are no points).
pub fn svg<'a>(
    title: &str,
    points: &[[Scalar; 2]],
    rows: &[Row],
    floors: impl IntoIterator<Item = &'a Floor>,
) -> Result<Option<String>, BenchError> {
    let panels: Vec<Panel> = rows
        .iter()
        .map(|r| Panel {
            label: r.label.clone(),
            errors: &r.sample_errors,
        })
        .chain(floors.into_iter().map(|f| Panel {
            label: f.change.label(),
            errors: &f.sample_errors,
        }))
        .filter(|p| p.errors.len() == points.len() && p.errors.iter().any(|e| e.is_finite()))
        .collect();
    if points.is_empty() || panels.is_empty() {
        return Ok(None);
    }
    let cols = panels.len().min(COLUMNS);
    let lines = panels.len().div_ceil(COLUMNS);
    let (w, h) = (PANEL * cols as u32, PANEL * lines as u32 + KEY_H + 30);
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (w, h)).into_drawing_area();
        let at_rest = rows.first().is_some_and(|r| r.compare == Compare::Rest);
        draw(&root, title, points, &panels, (lines, cols), at_rest)
            .map_err(|e| BenchError::Chart(e.to_string()))?;
        root.present()
            .map_err(|e| BenchError::Chart(e.to_string()))?;
    }
    Ok(Some(out))
}

type DrawResult = Result<(), DrawingAreaErrorKind<std::io::Error>>;

fn draw(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    points: &[[Scalar; 2]],
    panels: &[Panel],
    (lines, cols): (usize, usize),
    at_rest: bool,
) -> DrawResult {
    root.fill(&WHITE)?;
    let root = root.titled(
        &format!("{title}: error at each sample point"),
        ("sans-serif", 17),
    )?;
    let (grid, key) = root.split_vertically(PANEL * lines as u32);
    let top = panels
        .iter()
        .flat_map(|p| p.errors.iter().copied())
        .filter(|e| e.is_finite())
        .fold(0.0, Scalar::max);
    let half = half_cell(points);
    let bounds = |k: usize| {
        let lo = points
            .iter()
            .map(|p| p[k])
            .fold(Scalar::INFINITY, Scalar::min);
        let hi = points
            .iter()
            .map(|p| p[k])
            .fold(Scalar::NEG_INFINITY, Scalar::max);
        (lo - half)..(hi + half)
    };
    // At rest the RMS over the points is the run's final error; frame by
    // frame it is over points and frames together, which is not the bench's
    // mean over the frames of each frame's RMS.
    let what = if at_rest {
        "RMS"
    } else {
        "RMS, points and frames"
    };
    let areas = grid.split_evenly((lines, cols));
    for (panel, area) in panels.iter().zip(&areas) {
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("{}: {:.3} % {what}", panel.label, 100.0 * rms(panel.errors)),
                ("sans-serif", 12),
            )
            .margin(6)
            .build_cartesian_2d(bounds(0), bounds(1))?;
        chart.draw_series(points.iter().zip(panel.errors).map(|(p, &e)| {
            let color = if e.is_finite() {
                shade(e, top)
            } else {
                RGBColor(0xcc, 0xcc, 0xcc)
            };
            Rectangle::new(
                [(p[0] - half, p[1] - half), (p[0] + half, p[1] + half)],
                color.filled(),
            )
        }))?;
    }
    // The colour key: the scale from 0 to the largest error.
    let steps = 20;
    let (kw, _) = key.dim_in_pixel();
    let x0 = 20i32;
    let bar = (kw as i32 - 2 * x0).max(steps);
    for s in 0..steps {
        let a = x0 + bar * s / steps;
        let b = x0 + bar * (s + 1) / steps;
        let e = top * (f64::from(s) + 0.5) / f64::from(steps);
        key.draw(&Rectangle::new([(a, 8), (b, 24)], shade(e, top).filled()))?;
    }
    let style = ("sans-serif", 12).into_font().color(&BLACK);
    key.draw(&Text::new("0 %", (x0, 30), style.clone()))?;
    let right = format!("{:.3} % of the diagonal", 100.0 * top);
    key.draw(&Text::new(right, (x0 + bar - 150, 30), style))?;
    Ok(())
}
