//! What each lower block of a [`BlockPattern`] sums, built with the pattern:
//! its springs, the indices of its other element terms in [`super::ElementTerms`]
//! (and where each element's terms lie there, [`TermLayout`]), and per vertex the
//! dropped shape blocks whose norms compensate its diagonal.

use super::buckets::group_by_key;
use super::terms::{lower_pairs, shape_active};
use super::{BlockPattern, Elements};
use crate::physics::shape::SHAPE_SLOTS;

/// Where each element's terms lie in [`super::ElementTerms`]: per kind, the
/// length of one element's stretch (the most terms that an element of the kind
/// has) and the start of the kind's section.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct TermLayout {
    /// Terms per hinge (10 for four distinct vertices).
    pub hinge: usize,
    /// Terms per membrane triangle (6).
    pub membrane: usize,
    /// Terms per shape triangle (21 with six distinct slots in use).
    pub shape: usize,
    /// Start of the membrane triangles' section (the hinges' starts at 0).
    pub membrane_start: usize,
    /// Start of the shape triangles' section.
    pub shape_start: usize,
    /// Length of the whole array.
    pub len: usize,
    /// Dropped-block norms per shape triangle.
    pub shape_norms: usize,
}

impl BlockPattern {
    /// The springs and element terms of every lower block, each list in element
    /// order, their layout, and the shape triangles' dropped blocks. Needs the
    /// blocks, the diagonal and `factored`.
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
        // Hinges, membrane triangles, shape triangles: indices ascend with the
        // pushes, so the grouping (stable) leaves each block's list ascending.
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
        l.shape_start = l.membrane_start + l.membrane * elements.membrane_triangles.len();
        let shapes = elements
            .shape_triangles
            .iter()
            .map(|t| (&t.v[..], shape_active(t)));
        l.shape = self.tag_lower_blocks(l.shape_start, shapes, &mut tagged);
        l.len = l.shape_start + l.shape * elements.shape_triangles.len();
        (self.term_start, self.terms) = group_by_key(self.blocks(), &tagged);
        l.shape_norms = self.build_shape_dropped(elements);
        self.layout = l;
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

    /// The shape triangles' blocks that the factorization drops (pairs of used
    /// slots on distinct vertices whose block is not factored; `factored` is
    /// symmetric, so the lower block tells): per triangle their bits
    /// `6 k + l`, and per vertex `v[k]` the indices of their norms, triangle
    /// `t`'s `n`-th (by bit) at `t * stride + n`. Returns the stride, the most
    /// of one triangle.
    fn build_shape_dropped(&mut self, elements: &Elements) -> usize {
        let shapes = &elements.shape_triangles;
        self.shape_dropped_mask = shapes
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
        let stride = self
            .shape_dropped_mask
            .iter()
            .map(|m| m.count_ones() as usize)
            .max()
            .unwrap_or(0)
            .max(1);
        let mut dropped: Vec<(u32, u32)> = Vec::new();
        for (ti, (t, &mask)) in shapes.iter().zip(&self.shape_dropped_mask).enumerate() {
            let mut bits = mask;
            let mut index = ti * stride;
            while bits != 0 {
                let bit = bits.trailing_zeros() as usize;
                dropped.push((t.v[bit / SHAPE_SLOTS], index as u32));
                index += 1;
                bits &= bits - 1;
            }
        }
        (self.shape_dropped_start, self.shape_dropped) = group_by_key(self.vertices(), &dropped);
        stride
    }
}
