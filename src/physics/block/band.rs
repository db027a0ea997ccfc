//! One band's share of the assembly (block module docs, "Assembly"): its
//! rows' lower blocks summed from every kind's listed blocks, the blocks the
//! kinds add in place, and the mass on the diagonal.

use super::{BAND_ROWS, BlockPattern, ElementBlocks, NEGATE};
use crate::math::{Matrix3, Vector};

/// One band's share of the assembly: its rows' lower blocks (the band's first
/// block at `base`) and its vertices' diagonal compensation of dropped blocks.
#[derive(Debug)]
pub struct Band<'a> {
    /// The band's first row.
    pub first_row: usize,
    /// The slot of the band's first block.
    pub base: usize,
    /// The band's blocks (lower ones filled, upper ones unused).
    pub lower: &'a mut [Matrix3],
    /// Per row of the band, the compensation of the dropped in-place blocks
    /// on its diagonal block (added by the kinds' in-place blocks).
    pub lumps: &'a mut [Matrix3],
}

impl Band<'_> {
    /// The band's index (its rows are `index * BAND_ROWS..`).
    #[inline(always)]
    pub fn index(&self) -> usize {
        self.first_row / BAND_ROWS
    }

    /// The band's rows.
    #[inline(always)]
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.first_row..self.first_row + self.lumps.len()
    }
}

impl BlockPattern {
    /// Sums band `band`'s lower blocks (block module docs, "Assembly"): each
    /// lower block's listed blocks, kind by kind, from the kinds' `values`;
    /// then every kind's in-place blocks; then the mass.
    pub(super) fn gather_band(
        &self,
        terms: &ElementBlocks<'_>,
        values: &[&[Matrix3]],
        band: &mut Band<'_>,
    ) {
        let rows = band.rows();
        for i in rows.clone() {
            // The lower blocks lead each row (columns ascend to the diagonal).
            for slot in self.row_start[i] as usize..=self.diagonal[i] as usize {
                let mut m = Matrix3::ZERO;
                for (list, values) in self.listed.iter().zip(values) {
                    for &e in list.of(slot) {
                        if e & NEGATE == 0 {
                            m += values[e as usize];
                        } else {
                            m -= values[(e & !NEGATE) as usize];
                        }
                    }
                }
                band.lower[slot - band.base] = m;
            }
        }
        band.lumps.fill(Matrix3::ZERO);
        terms
            .kinds
            .add_in_place(terms.elements, &self.in_place, terms.h2, band);
        for i in rows {
            band.lower[self.diagonal[i] as usize - band.base] +=
                Matrix3::from_diagonal(Vector::splat(terms.diagonal_mass[i]));
        }
    }
}
