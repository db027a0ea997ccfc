//! What each lower block of a [`BlockPattern`] sums, built with the pattern:
//! its springs and the indices of its hinge and membrane terms in
//! [`super::ElementTerms`] (where each element's terms lie there:
//! [`TermLayout`]); per shape triangle the slots of its lower blocks and the
//! blocks that the factorization drops; per band the shape triangles that add
//! to it.

use super::buckets::group_by_key;
use super::terms::{lower_pairs, shape_active};
use super::{BAND_ROWS, BlockPattern, Elements};
use crate::physics::shape::SHAPE_SLOTS;

/// Where each hinge's and membrane triangle's terms lie in
/// [`super::ElementTerms`]: per kind, the length of one element's stretch (the
/// most terms that an element of the kind has) and the start of the kind's
/// section; and the same stretch for the shape triangles' slots.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct TermLayout {
    /// Terms per hinge (10 for four distinct vertices).
    pub hinge: usize,
    /// Terms per membrane triangle (6).
    pub membrane: usize,
    /// Lower blocks per shape triangle (21 with six distinct slots in use).
    pub shape: usize,
    /// Start of the membrane triangles' section (the hinges' starts at 0).
    pub membrane_start: usize,
    /// Length of the whole array.
    pub len: usize,
}

impl BlockPattern {
    /// The springs and hinge and membrane terms of every lower block, each
    /// list in element order, their layout, and the shape triangles' slots,
    /// dropped blocks and bands. Needs the blocks, the diagonal and `factored`.
    pub(super) fn build_sources(&mut self, elements: &Elements) {
        let mut springs: Vec<(u32, u32)> = Vec::with_capacity(3 * elements.springs.len());
        for (e, sp) in elements.springs.iter().enumerate() {
            let [a, b] = sp.v;
            let e = e as u32;
            springs.push((self.diagonal[a as usize], e));
            springs.push((self.diagonal[b as usize], e));
            springs.push((self.lower_slot(a, b), e));
        }
        (self.spring_start, self.springs) = group_by_key(self.blocks(), &springs);
        // Hinges, then membrane triangles: indices ascend with the pushes, so
        // the grouping (stable) leaves each block's list ascending.
        let mut tagged: Vec<(u32, u32)> = Vec::new();
        let mut l = TermLayout::default();
        let hinges = elements.hinges.iter().map(|h| (&h.v[..], 0b1111));
        l.hinge = self.tag_lower_blocks(0, hinges, &mut tagged);
        l.membrane_start = l.hinge * elements.hinges.len();
        let membrane = elements
            .membrane_triangles
            .iter()
            .map(|t| (&t.v[..], 0b111));
        l.membrane = self.tag_lower_blocks(l.membrane_start, membrane, &mut tagged);
        l.len = l.membrane_start + l.membrane * elements.membrane_triangles.len();
        (self.term_start, self.terms) = group_by_key(self.blocks(), &tagged);
        // The shape triangles' slots, tagged by triangle instead of by block.
        let mut slots: Vec<(u32, u32)> = Vec::new();
        let shapes = elements
            .shape_triangles
            .iter()
            .map(|t| (&t.v[..], shape_active(t)));
        l.shape = self.tag_lower_blocks(0, shapes, &mut slots);
        self.shape_slots = vec![0; l.shape * elements.shape_triangles.len()];
        for (slot, index) in slots {
            self.shape_slots[index as usize] = slot;
        }
        self.layout = l;
        self.build_shape_dropped(elements);
        self.build_bands(elements);
    }

    /// Tags each lower block of the `elements` (vertices and active local
    /// vertices, [`lower_pairs`]) with the index of its term: element `e`'s
    /// `w`-th at `start + e * stride + w`. Returns the stride, the most terms of
    /// one element.
    fn tag_lower_blocks<'e>(
        &self,
        start: usize,
        elements: impl Iterator<Item = (&'e [u32], u32)> + Clone,
        tagged: &mut Vec<(u32, u32)>,
    ) -> usize {
        let count = |(v, active): (&[u32], u32)| {
            let mut c = 0;
            lower_pairs(v, active, |_, _| c += 1);
            c
        };
        let stride = elements.clone().map(count).max().unwrap_or(0);
        for (e, (v, active)) in elements.enumerate() {
            let mut index = start + e * stride;
            lower_pairs(v, active, |k, l| {
                tagged.push((self.lower_slot(v[k], v[l]), index as u32));
                index += 1;
            });
        }
        stride
    }

    /// Per shape triangle, the blocks that the factorization drops (pairs of
    /// used slots on distinct vertices whose block is not factored; `factored`
    /// is symmetric, so the lower block tells) as bits `6 k + l`.
    fn build_shape_dropped(&mut self, elements: &Elements) {
        self.shape_dropped_mask = elements
            .shape_triangles
            .iter()
            .map(|t| {
                let active = shape_active(t);
                let mut mask = 0u64;
                for k in (0..SHAPE_SLOTS).filter(|&k| active >> k & 1 != 0) {
                    for l in (0..SHAPE_SLOTS).filter(|&l| active >> l & 1 != 0) {
                        let (i, j) = (t.v[k], t.v[l]);
                        if i != j && !self.factored[self.lower_slot(i, j) as usize] {
                            mask |= 1 << (SHAPE_SLOTS * k + l);
                        }
                    }
                }
                mask
            })
            .collect();
    }

    /// Per band, the shape triangles with a used slot in it, ascending.
    fn build_bands(&mut self, elements: &Elements) {
        let mut tagged: Vec<(u32, u32)> = Vec::new();
        for (ti, t) in elements.shape_triangles.iter().enumerate() {
            let active = shape_active(t);
            let mut bands = [u32::MAX; SHAPE_SLOTS];
            for (k, band) in bands.iter_mut().enumerate() {
                if active >> k & 1 != 0 {
                    *band = (t.v[k] as usize / BAND_ROWS) as u32;
                }
            }
            bands.sort_unstable();
            let mut last = u32::MAX;
            for band in bands.into_iter().filter(|&b| b != u32::MAX) {
                if band != last {
                    tagged.push((band, ti as u32));
                    last = band;
                }
            }
        }
        (self.band_shape_start, self.band_shapes) = group_by_key(self.bands(), &tagged);
    }
}
