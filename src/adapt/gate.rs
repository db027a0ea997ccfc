//! The remesh gate (`adapt.min_change`, `adapt.urgent_ratio`): whether an
//! adaptation pass is applied or deferred.
//!
//! Applying a pass costs the operations and the transfer, and then a rebuild
//! of everything that derives from the mesh (force elements, fold splits,
//! the solver's block pattern, its ordering and first factorization), much
//! of it in proportion to the whole mesh however few triangles the pass
//! changes. The gate applies a pass only when it changes enough to matter:
//! when its operations would replace at least `min_change` of the mesh's
//! triangles, or when one of its splits reads `urgent_ratio` or more (a
//! triangle that coarse is refined at once, so a fold that forms fast is
//! not left on a coarse mesh). A deferred pass changes nothing: the next
//! pass measures the criterion again on the state as it is then.
//!
//! What that does to the error: between applied passes at most a fraction
//! `min_change` of the triangles is coarser than its target, none of them
//! by more than `urgent_ratio` (at the passes' times), and merges wait
//! (a mesh finer than asked costs time, not accuracy). The decision counts
//! marks and compares ratios: it uses no clock and is the same at any
//! thread count.

use crate::math::Scalar;

/// When an adaptation pass is applied (the scene's `adapt.min_change` and
/// `adapt.urgent_ratio`; module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RemeshGate {
    /// A pass is applied when its operations would replace at least this
    /// fraction of the mesh's triangles (in (0, 1]).
    pub min_change: Scalar,
    /// ... or when one of its splits reads at least this ratio of the
    /// criterion (1: at the threshold; >= 1).
    pub urgent_ratio: Scalar,
}

/// What a pass would do, as the gate weighs it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PassSize {
    /// Triangles of the mesh that the pass's operations would replace
    /// (closure left out: it follows from the operations).
    pub replaced: usize,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// The largest reading among the pass's splits (0 without splits).
    pub worst_ratio: Scalar,
}

impl RemeshGate {
    /// True when a pass of `size` is applied: it replaces nothing (there is
    /// nothing to defer), enough triangles, or a split of it is urgent.
    pub fn applies(&self, size: &PassSize) -> bool {
        size.replaced == 0
            || size.worst_ratio >= self.urgent_ratio
            || size.replaced as Scalar >= self.min_change * size.triangles as Scalar
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GATE: RemeshGate = RemeshGate {
        min_change: 0.05,
        urgent_ratio: 2.0,
    };

    fn size(replaced: usize, worst_ratio: Scalar) -> PassSize {
        PassSize {
            replaced,
            triangles: 1000,
            worst_ratio,
        }
    }

    #[test]
    fn a_small_pass_of_mild_splits_is_deferred() {
        assert!(!GATE.applies(&size(49, 1.9)));
        assert!(!GATE.applies(&size(10, 0.0)));
    }

    #[test]
    fn a_pass_that_replaces_enough_triangles_is_applied() {
        assert!(GATE.applies(&size(50, 1.1)));
    }

    #[test]
    fn an_urgent_split_applies_the_smallest_pass() {
        assert!(GATE.applies(&size(1, 2.0)));
    }

    #[test]
    fn a_pass_that_replaces_nothing_is_not_deferred() {
        assert!(GATE.applies(&size(0, 0.0)));
    }
}
