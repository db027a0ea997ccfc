//! The Pareto front of (cost, error) points: the runs that no other run beats
//! on both wall time and error.

/// For each point `(cost, error)`, whether it is on the Pareto front: no other
/// point has a cost and an error both at most its own with one of them smaller.
/// Points with a non-finite coordinate (failed runs) are never on the front and
/// never dominate. Equal points are all on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    points
        .iter()
        .map(|p| {
            finite(p)
                && !points
                    .iter()
                    .any(|q| finite(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect()
}
