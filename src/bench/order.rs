//! The observed order of convergence of the uniform runs: the least-squares
//! slope of log(error) against log(h), where h is the edge length (taken as
//! 1 / resolution: the slope does not depend on the scale) for runs at one
//! step, or the step for runs on one mesh. Error ~ h^order.
//!
//! Against a reference of finite resolution the error of a run at `h` is about
//! `C (h^p - h_ref^p)`, smaller than `C h^p` the closer `h` is to `h_ref`; the
//! local orders between neighbouring runs then grow towards the finest run,
//! and the fitted slope overstates `p`. The report gives the local orders so
//! that this shows.

use std::collections::BTreeMap;

use super::Row;
use crate::math::Scalar;

/// What varies along a convergence series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variable {
    /// The mesh: uniform runs at one step, h = 1 / resolution.
    EdgeLength,
    /// The step: uniform runs on one mesh, h = dt.
    Step,
}

/// The error of a series of uniform runs against h, and its observed order.
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    /// What varies.
    pub variable: Variable,
    /// What is held fixed, in words (`dt 8.33e-3 s`, `resolution 16`).
    pub fixed: String,
    /// `(label, h, error)` from the largest h to the smallest.
    pub points: Vec<(String, Scalar, Scalar)>,
    /// The least-squares slope of log(error) against log(h).
    pub order: Scalar,
    /// The slope between each pair of neighbouring distinct h (where several
    /// runs share an h, such as a ladder's square and stretched cells, the
    /// first of them in ladder order).
    pub local: Vec<Scalar>,
}

/// Least-squares slope of `ln y` against `ln x`; `None` with fewer than two
/// distinct `x` or any non-positive or non-finite value.
pub fn loglog_slope(points: &[(Scalar, Scalar)]) -> Option<Scalar> {
    let ok = |v: Scalar| v.is_finite() && v > 0.0;
    if points.len() < 2 || !points.iter().all(|&(x, y)| ok(x) && ok(y)) {
        return None;
    }
    let n = points.len() as Scalar;
    let lx: Vec<Scalar> = points.iter().map(|p| p.0.ln()).collect();
    let ly: Vec<Scalar> = points.iter().map(|p| p.1.ln()).collect();
    let mx = lx.iter().sum::<Scalar>() / n;
    let my = ly.iter().sum::<Scalar>() / n;
    let sxx: Scalar = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    let sxy: Scalar = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// A series from `(label, h, error)` points (at least two distinct h).
fn series(
    variable: Variable,
    fixed: String,
    mut points: Vec<(String, Scalar, Scalar)>,
) -> Option<Convergence> {
    points.sort_by(|a, b| b.1.total_cmp(&a.1));
    let xy: Vec<(Scalar, Scalar)> = points.iter().map(|p| (p.1, p.2)).collect();
    let order = loglog_slope(&xy)?;
    // The sort is stable: the first point at each h is the ladder's first.
    let mut distinct = xy.clone();
    distinct.dedup_by(|b, a| a.0 == b.0);
    let local = distinct
        .windows(2)
        .map(|w| loglog_slope(w).unwrap_or(Scalar::NAN))
        .collect();
    Some(Convergence {
        variable,
        fixed,
        points,
        order,
        local,
    })
}

fn usable(r: &&Row) -> bool {
    !r.adaptive && r.status == "ok" && r.error.is_finite() && r.error > 0.0
}

/// The largest group (by distinct h) of usable uniform rows under `key`.
fn largest<K: Ord>(rows: &[Row], key: impl Fn(&Row) -> Option<K>) -> Vec<&Row> {
    let mut groups: BTreeMap<K, Vec<&Row>> = BTreeMap::new();
    for r in rows.iter().filter(usable) {
        if let Some(k) = key(r) {
            groups.entry(k).or_default().push(r);
        }
    }
    groups
        .into_values()
        .max_by_key(Vec::len)
        .unwrap_or_default()
}

/// The uniform runs at one step (the step most of them share) against their
/// edge length; `None` without two such runs at different resolutions.
pub fn spatial(rows: &[Row]) -> Option<Convergence> {
    let group = largest(rows, |r| Some(r.dt.clone()));
    let dt = group.first()?.dt.clone();
    let points = group
        .iter()
        .map(|r| {
            (
                r.label.clone(),
                1.0 / Scalar::from(r.resolution.max(1)),
                r.error,
            )
        })
        .collect();
    let fixed = match dt.parse::<Scalar>() {
        Ok(v) => format!("dt {v:.4e} s"),
        Err(_) => format!("dt {dt}"),
    };
    series(Variable::EdgeLength, fixed, points)
}

/// The uniform runs on one mesh at different fixed steps against the step;
/// `None` without two such runs.
pub fn temporal(rows: &[Row]) -> Option<Convergence> {
    let group = largest(rows, |r| r.dt.parse::<Scalar>().ok().map(|_| r.resolution));
    let res = group.first()?.resolution;
    let points: Vec<_> = group
        .iter()
        .filter_map(|r| Some((r.label.clone(), r.dt.parse::<Scalar>().ok()?, r.error)))
        .collect();
    series(Variable::Step, format!("resolution {res}"), points)
}
