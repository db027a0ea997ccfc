//! What each lower block of a [`BlockPattern`] sums, built with the pattern:
//! per kind, the indices of the kind's values that it adds or subtracts
//! ([`crate::physics::kinds::ForceKind::listed_blocks`]), each list in
//! element order.

use super::{BlockPattern, Elements, Lists, NEGATE};
use crate::physics::kinds::{KIND_COUNT, listed_blocks};

impl BlockPattern {
    /// Every kind's listed blocks of every lower block, each kind's list in
    /// the order the kind gives them (element order). Needs the blocks and the
    /// diagonal.
    pub(super) fn build_sources(&mut self, elements: &Elements) {
        let mut tagged: [Vec<(u32, u32)>; KIND_COUNT] = Default::default();
        listed_blocks(elements, |kind, i, j, value, negate| {
            debug_assert!(value < NEGATE, "too many values");
            let entry = if negate { value | NEGATE } else { value };
            tagged[kind].push((self.lower_slot(i, j), entry));
        });
        // The grouping is stable: each block's list keeps the kind's order.
        self.listed = tagged.map(|t| Lists::grouped(self.blocks(), &t));
    }
}
