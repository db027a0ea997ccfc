//! The frames the mesh decides: how long a frame-by-frame comparison stays
//! deterministic before the runs part.
//!
//! A falling sheet that slides and folds is chaotic: the reference run again
//! with its cloth started 1 micrometre higher (the lift floor, `floor.rs`)
//! stays within rounding of the reference while the cloth falls and first
//! touches, then parts from it by as much as any mesh does. Measured on
//! `tablecloth` at uniform 128's edges (twelfth sitting,
//! `docs/speed-vs-error-history.md`): the lifted reference is within 1e-4 % of the
//! diagonal until 0.367 s and 0.150 % away at 0.400 s, a third of uniform
//! 128's error at that frame; from there on every run is a few tenths of a
//! per cent away. The mean over all the frames mixes the two, so the target
//! check over a whole chaotic run cannot be decided, while the frames before
//! the parting can.
//!
//! A change of triangulation may move a buckling sheet's folds where a lift
//! does not: the reference with every diagonal turned (the pattern floor,
//! `--pattern-floor`, `floor.rs`). Where it is measured, the window ends at
//! the larger of the two at each frame (`report::parting_text`).
//!
//! The rule (with "the lift floor" the larger of the lift and pattern floors
//! at each frame where both are measured): a frame is decided while the lift
//! floor is below a tenth of the
//! smallest error of the uniform runs at that frame, so that a 10 %
//! difference of errors there is more than the floor. A frame where even that smallest error is below a thousandth
//! of its largest over the run (the free fall, where every run agrees to
//! rounding) has nothing to decide and does not end the window.

use crate::math::Scalar;

/// The lift floor over a tenth of the smallest uniform error ends the window
/// (module docs).
pub const DECIDED_FRACTION: Scalar = 0.1;

/// Frames whose smallest uniform error is below this fraction of its largest
/// over the run have nothing to decide (module docs).
pub const NOTHING_TO_DECIDE: Scalar = 1e-3;

/// Where the runs part (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parting {
    /// Recorded frames before the parting (the first `frames` of the floor's
    /// given to [`parting`]).
    pub frames: usize,
    /// Of those, the frames with something to decide (the others are the
    /// free fall's, where every run agrees to rounding).
    pub decided: usize,
    /// Time of the last of those frames, s.
    pub until: Scalar,
    /// The first frame past the window: its time, the floor's error there
    /// and the smallest uniform error there; `None` when the runs never part.
    pub parted: Option<(Scalar, Scalar, Scalar)>,
}

/// The error at time `t` in `errors` (`(time, error)` pairs), matched to a
/// billionth of the time.
fn error_at(errors: &[(Scalar, Scalar)], t: Scalar) -> Option<Scalar> {
    let tol = 1e-9 * t.abs().max(1.0);
    errors
        .iter()
        .find(|(s, _)| (s - t).abs() <= tol)
        .map(|e| e.1)
}

/// The larger of several floors' per-frame errors at each of the first's
/// frames (`(time, error)` pairs), the series [`parting`] is given when more
/// than one floor ends the window. A frame another floor lacks, or where one
/// is NaN, is NaN, which ends the window (`f64::max` would drop a NaN).
pub fn larger_at_each_frame(
    first: &[(Scalar, Scalar)],
    others: &[&[(Scalar, Scalar)]],
) -> Vec<(Scalar, Scalar)> {
    let larger = |m: Scalar, o: Scalar| match m.is_nan() || o.is_nan() {
        true => Scalar::NAN,
        false => m.max(o),
    };
    first
        .iter()
        .map(|&(t, e)| {
            let at_t = others.iter().map(|o| error_at(o, t).unwrap_or(Scalar::NAN));
            (t, at_t.fold(e, larger))
        })
        .collect()
}

/// Where a floor's per-frame errors (`floor`: the lift floor's, or the
/// larger of it and the pattern floor's) part from the uniform runs'
/// (`uniform`, each `(time, error)` per frame); `None` without a uniform run
/// or a frame, or when a uniform run misses one of the floor's frames or has
/// a non-finite error there (nothing can be said from then).
pub fn parting(floor: &[(Scalar, Scalar)], uniform: &[&[(Scalar, Scalar)]]) -> Option<Parting> {
    if uniform.is_empty() || floor.is_empty() {
        return None;
    }
    let smallest: Vec<Option<Scalar>> = floor
        .iter()
        .map(|&(t, _)| {
            uniform
                .iter()
                .map(|u| error_at(u, t).filter(|e| e.is_finite()))
                .try_fold(Scalar::INFINITY, |m, e| e.map(|e| m.min(e)))
        })
        .collect();
    let scale = smallest
        .iter()
        .flatten()
        .fold(0.0, |m: Scalar, &e| m.max(e));
    let (mut until, mut decided) = (None, 0);
    for (i, (&(t, l), m)) in floor.iter().zip(&smallest).enumerate() {
        let m = (*m)?;
        // A NaN floor error ends the window too: nothing is decided past it.
        let below = l < DECIDED_FRACTION * m;
        let something = m >= NOTHING_TO_DECIDE * scale;
        if something && !below {
            return Some(Parting {
                frames: i,
                decided,
                until: until.unwrap_or(Scalar::NAN),
                parted: Some((t, l, m)),
            });
        }
        decided += usize::from(something);
        until = Some(t);
    }
    Some(Parting {
        frames: floor.len(),
        decided,
        until: until.unwrap_or(Scalar::NAN),
        parted: None,
    })
}

/// The mean of `errors` over the frames up to `until` (inclusive, to a
/// billionth of the time); NaN without such a frame.
pub fn mean_until(errors: &[(Scalar, Scalar)], until: Scalar) -> Scalar {
    let tol = 1e-9 * until.abs().max(1.0);
    let kept: Vec<Scalar> = errors
        .iter()
        .filter(|(t, _)| *t <= until + tol)
        .map(|e| e.1)
        .collect();
    if kept.is_empty() {
        Scalar::NAN
    } else {
        kept.iter().sum::<Scalar>() / kept.len() as Scalar
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(values: &[Scalar]) -> Vec<(Scalar, Scalar)> {
        values
            .iter()
            .enumerate()
            .map(|(i, &e)| (i as Scalar * 0.1, e))
            .collect()
    }

    /// The landing's shape: all agree while the cloth falls (rounding), the
    /// mesh decides the first contact, the lift floor jumps at frame 5.
    #[test]
    fn the_window_ends_where_the_lift_floor_reaches_a_tenth_of_the_uniform_error() {
        let lift = series(&[1e-17, 2e-17, 1e-9, 2e-9, 1e-8, 1.5e-3, 2e-3]);
        let coarse = series(&[2e-17, 3e-17, 1e-3, 3e-3, 4e-3, 5e-3, 8e-3]);
        let fine = series(&[1e-17, 1e-17, 5e-4, 2e-3, 3e-3, 4e-3, 9e-3]);
        let p = parting(&lift, &[&coarse, &fine]).expect("parting");
        assert_eq!(
            (p.frames, p.decided),
            (5, 3),
            "frames 0 and 1 are the free fall"
        );
        assert!((p.until - 0.4).abs() < 1e-12);
        let (t, l, m) = p.parted.expect("parted");
        assert!((t - 0.5).abs() < 1e-12 && l == 1.5e-3 && m == 4e-3);
        // The fine run's mean over frames 0 to 4 only.
        let mean = mean_until(&fine, p.until);
        assert!((mean - (2e-17 + 5e-4 + 2e-3 + 3e-3) / 5.0).abs() < 1e-15);
    }

    /// A run that never parts keeps every frame; one that parts at the first
    /// frame with anything to decide keeps only the frames before it, none
    /// of them decided; a uniform run missing a frame gives no answer.
    #[test]
    fn a_window_of_every_frame_of_none_and_of_a_missing_frame() {
        let fine = series(&[0.0, 1e-3, 2e-3]);
        let whole = parting(&series(&[0.0, 1e-6, 2e-6]), &[&fine]).expect("parting");
        assert_eq!((whole.frames, whole.parted), (3, None));
        assert!((whole.until - 0.2).abs() < 1e-12);
        let none = parting(&series(&[0.0, 5e-4, 2e-6]), &[&fine]).expect("parting");
        assert_eq!(
            (none.frames, none.decided),
            (1, 0),
            "the first frame has nothing to decide"
        );
        let at_once = parting(&series(&[1e-3, 1e-3]), &[&series(&[1e-3, 1e-3])]);
        assert_eq!(
            at_once.map(|p| (p.frames, p.until.is_nan())),
            Some((0, true))
        );
        let short = series(&[0.0, 1e-3]);
        assert_eq!(parting(&series(&[0.0, 1e-6, 2e-6]), &[&short]), None);
        assert_eq!(parting(&[], &[&fine]), None);
        assert_eq!(parting(&fine, &[]), None);
    }
}
