//! What each lower block of a [`BlockPattern`] sums, built with the pattern:
//! its springs and the indices of its hinge and membrane terms in
//! [`super::ElementTerms`] (where each element's terms lie there:
//! [`TermLayout`]); per shape triangle the blocks that it adds or whose norm the
//! factorization's compensation needs; per band the shape triangles that add
//! to it.

use super::buckets::group_by_key;
use super::terms::{lower_pairs, shape_active};
use super::{BAND_ROWS, BlockPattern, Elements, ShapeOp};
use crate::physics::shape::SHAPE_SLOTS;

/// Where each hinge's and membrane triangle's terms lie in
/// [`super::ElementTerms`]: per kind, the length of one element's stretch (the
/// most terms that an element of the kind has) and the start of the kind's
/// section.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct TermLayout {
    /// Terms per hinge (10 for four distinct vertices).
    pub hinge: usize,
    /// Terms per membrane triangle (6).
    pub membrane: usize,
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
        self.layout = l;
        self.build_shape_ops(elements);
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

    /// Per shape triangle, the blocks that the assembly computes ([`ShapeOp`]):
    /// each pair of used slots `(k, l)` (`k` outer, `l` inner, ascending) whose
    /// block is in the lower triangle (`v[l] <= v[k]`), marked when the
    /// factorization drops it.
    fn build_shape_ops(&mut self, elements: &Elements) {
        let shapes = &elements.shape_triangles;
        let (mut start, mut ops) = (Vec::with_capacity(shapes.len() + 1), Vec::new());
        start.push(0);
        for t in shapes {
            let active = shape_active(t);
            for k in (0..SHAPE_SLOTS).filter(|&k| active >> k & 1 != 0) {
                for l in (0..SHAPE_SLOTS).filter(|&l| active >> l & 1 != 0) {
                    let (i, j) = (t.v[k], t.v[l]);
                    if j <= i {
                        let slot = self.slot(i, j);
                        let dropped = i != j && !self.factored[slot as usize];
                        let (k, l) = (k as u8, l as u8);
                        ops.push(ShapeOp {
                            slot,
                            k,
                            l,
                            dropped,
                        });
                    }
                }
            }
            start.push(ops.len() as u32);
        }
        (self.shape_op_start, self.shape_ops) = (start, ops);
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
