//! The benchmark's chart, drawn with `plotters` (SVG backend): the compared
//! error against wall time on log-log axes, uniform runs as blue circles,
//! adaptive runs as orange squares, the Pareto front as a dashed staircase
//! through ringed points; points are numbered, with the key of numbers to
//! labels on the right. The largest floor run's error, when within two
//! decades of the smallest error, is a dotted grey line labelled "largest
//! floor": errors closer together than it are not told apart by the
//! comparison.

use plotters::coord::Shift;
use plotters::coord::combinators::WithKeyPoints;
use plotters::prelude::*;

use super::collect::Row;
use super::{BenchError, Compare};

const W: u32 = 900;
const H: u32 = 520;
/// Width of the key of point numbers on the right.
const KEY_W: u32 = 250;
const UNIFORM: RGBColor = RGBColor(0x2e, 0x86, 0xde);
const ADAPTIVE: RGBColor = RGBColor(0xe6, 0x7e, 0x22);

/// Whole decades around the positive finite `values` (`1..10` when there are none).
fn decades(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v.log10());
        hi = hi.max(v.log10());
    }
    if !lo.is_finite() {
        return (1.0, 10.0);
    }
    let (lo, hi) = (lo.floor(), hi.ceil());
    let hi = if hi > lo { hi } else { lo + 1.0 };
    (10f64.powf(lo), 10f64.powf(hi))
}

/// Tick values in `lo..=hi` (whole decades): labelled ones at 1, 2 and 5
/// times each power of ten, light grid lines at 1 to 9 times.
fn ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut bold, mut light) = (Vec::new(), Vec::new());
    let (d0, d1) = (lo.log10().round() as i32, hi.log10().round() as i32);
    for d in d0..=d1 {
        for m in 1..=9 {
            let v = f64::from(m) * 10f64.powi(d);
            if v > hi * (1.0 + 1e-9) {
                break;
            }
            if matches!(m, 1 | 2 | 5) {
                bold.push(v);
            } else {
                light.push(v);
            }
        }
    }
    (bold, light)
}

/// A tick label: plain for ordinary magnitudes, exponent form otherwise.
fn tick(v: f64) -> String {
    if (1e-3..1e4).contains(&v) {
        format!("{}", (v * 1e6).round() / 1e6)
    } else {
        format!("{v:.0e}")
    }
}

/// True when the row is a candidate that can be drawn on log axes.
fn drawable(r: &Row) -> bool {
    !r.run.floor && r.wall_s.is_finite() && r.wall_s > 0.0 && r.error.is_finite() && r.error > 0.0
}

/// The chart of `rows` (wall time against the error compared as `compare`,
/// in percent) as SVG text, titled `title`.
pub fn svg(title: &str, rows: &[Row], compare: Compare) -> Result<String, BenchError> {
    let floor = rows
        .iter()
        .filter(|r| r.run.floor && r.error.is_finite())
        .map(|r| r.error)
        .reduce(f64::max);
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (W, H)).into_drawing_area();
        draw(&root, (title, compare), rows, floor).map_err(|e| BenchError::Chart(e.to_string()))?;
        root.present()
            .map_err(|e| BenchError::Chart(e.to_string()))?;
    }
    Ok(out)
}

/// A log axis over whole decades with [`ticks`] as its key points.
fn log_axis(lo: f64, hi: f64) -> WithKeyPoints<LogCoord<f64>> {
    let (bold, light) = ticks(lo, hi);
    (lo..hi)
        .log_scale()
        .with_key_points(bold)
        .with_light_points(light)
}

type DrawResult = Result<(), DrawingAreaErrorKind<std::io::Error>>;

fn draw(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    (title, compare): (&str, Compare),
    rows: &[Row],
    floor: Option<f64>,
) -> DrawResult {
    root.fill(&WHITE)?;
    let (plot, key) = root.split_horizontally(W - KEY_W);
    let ok: Vec<&Row> = rows.iter().filter(|r| drawable(r)).collect();
    let (x0, x1) = decades(ok.iter().map(|r| r.wall_s));
    // The floor widens the error axis when it is within two decades of the
    // smallest error (a rounding-level floor, at rest, is left out).
    let smallest = ok
        .iter()
        .map(|r| 100.0 * r.error)
        .fold(f64::INFINITY, f64::min);
    let floor = floor
        .map(|f| 100.0 * f)
        .filter(|f| f.is_finite() && *f > 0.0 && *f >= 1e-2 * smallest);
    let (y0, y1) = decades(ok.iter().map(|r| 100.0 * r.error).chain(floor));
    let mut chart = ChartBuilder::on(&plot)
        .caption(title, ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(65)
        .build_cartesian_2d(log_axis(x0, x1), log_axis(y0, y1))?;
    let y_desc = match compare {
        Compare::Rest => "error at rest, % of the diagonal (log)",
        _ => "mean error, % of the diagonal (log)",
    };
    chart
        .configure_mesh()
        .x_desc("wall time, s (median; log)")
        .y_desc(y_desc)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .bold_line_style(RGBColor(0xcc, 0xcc, 0xcc))
        .draw()?;
    // The largest floor, where the axes show it.
    if let Some(f) = floor {
        let grey = RGBColor(0x88, 0x88, 0x88);
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, f), (x1, f)],
                2,
                4,
                grey.stroke_width(2),
            ))?
            .label("largest floor")
            .legend(move |(x, y)| {
                plotters::element::DashedPathElement::new(
                    [(x - 8, y), (x + 8, y)],
                    2,
                    4,
                    grey.stroke_width(2),
                )
            });
    }
    draw_points(&mut chart, rows, &ok)?;
    chart
        .configure_series_labels()
        // Lower left: a front runs from the upper left to the lower right, so
        // that corner (fast and accurate at once) is the one that stays empty.
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    draw_key(&key, rows)
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>,
>;

/// The Pareto front (a staircase through its points in order of cost), the
/// uniform and adaptive runs, and each point's number.
fn draw_points(chart: &mut Chart<'_, '_>, rows: &[Row], ok: &[&Row]) -> DrawResult {
    let point = |r: &Row| (r.wall_s, 100.0 * r.error);
    let mut front: Vec<&Row> = ok.iter().copied().filter(|r| r.pareto).collect();
    front.sort_by(|a, b| a.wall_s.total_cmp(&b.wall_s));
    let mut stair = Vec::new();
    for (i, r) in front.iter().enumerate() {
        if i > 0 {
            stair.push((r.wall_s, 100.0 * front[i - 1].error));
        }
        stair.push(point(r));
    }
    chart
        .draw_series(DashedLineSeries::new(stair, 6, 4, BLACK.into()))?
        .label("Pareto front")
        .legend(|(x, y)| Circle::new((x, y), 8, BLACK.stroke_width(2)));
    chart.draw_series(
        front
            .iter()
            .map(|r| Circle::new(point(r), 9, BLACK.stroke_width(2))),
    )?;
    chart
        .draw_series(
            ok.iter()
                .filter(|r| !r.run.adaptive())
                .map(|r| Circle::new(point(r), 5, UNIFORM.filled())),
        )?
        .label("uniform mesh")
        .legend(|(x, y)| Circle::new((x, y), 5, UNIFORM.filled()));
    chart
        .draw_series(ok.iter().filter(|r| r.run.adaptive()).map(|r| {
            EmptyElement::at(point(r)) + Rectangle::new([(-4, -4), (5, 5)], ADAPTIVE.filled())
        }))?
        .label("adaptive")
        .legend(|(x, y)| Rectangle::new([(x - 4, y - 4), (x + 5, y + 5)], ADAPTIVE.filled()));
    chart.draw_series(
        rows.iter()
            .enumerate()
            .filter(|(_, r)| drawable(r))
            .map(|(n, r)| {
                EmptyElement::at(point(r))
                    + Text::new(format!("{}", n + 1), (7, -15), ("sans-serif", 11))
            }),
    )?;
    Ok(())
}

/// The key of point numbers to run labels.
fn draw_key(key: &DrawingArea<SVGBackend<'_>, Shift>, rows: &[Row]) -> DrawResult {
    key.draw(&Text::new("runs", (10, 50), ("sans-serif", 13)))?;
    for (n, r) in rows.iter().enumerate() {
        let note = match (r.run.floor, drawable(r)) {
            (true, _) => " (floor)",
            (false, true) => "",
            (false, false) => " (not drawn)",
        };
        key.draw(&Text::new(
            format!("{} {}{note}", n + 1, r.run.label),
            (10, 72 + 15 * n as i32),
            ("sans-serif", 11),
        ))?;
    }
    Ok(())
}
