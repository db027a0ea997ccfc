//! One axis of the tensor grid: its lines in a one-dimensional binary
//! hierarchy, the operations a pass chooses on it, and their application
//! (`super`'s module docs give the rules).

use crate::math::Scalar;

/// A grid line: its material coordinate and how many halvings made it (0 for
/// the base grid's lines).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Line {
    pub(super) at: Scalar,
    pub(super) level: u8,
}

/// Where a line of the grid after a pass comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Source {
    /// Line `i` of the grid before the pass.
    Old(usize),
    /// Inserted between the old lines `i` and `i + 1`.
    Between(usize),
}

/// The lines of one axis, in increasing order.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Axis {
    pub(super) lines: Vec<Line>,
}

/// What a pass does on one axis.
#[derive(Debug, Clone, Default, PartialEq)]
pub(in crate::adapt) struct AxisOps {
    /// Columns (between line `c` and `c + 1`) to halve, with the measure that
    /// asked for it (radians for the angle criterion, `kappa h` for the
    /// sizing one) or `None` for a split forced by the one-halving rule.
    pub(in crate::adapt) splits: Vec<(usize, Option<Scalar>)>,
    /// Lines to remove.
    pub(in crate::adapt) merges: Vec<usize>,
}

/// The thresholds of a pass, in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::adapt) struct Thresholds {
    /// Sizing (`kappa h` against `refine`) or angle (`phi` against both).
    pub(in crate::adapt) sizing: bool,
    /// Upper threshold.
    pub(in crate::adapt) refine: Scalar,
    /// Lower threshold (angle criterion) or `refine / hysteresis` (sizing).
    pub(in crate::adapt) coarsen: Scalar,
    /// Halvings allowed.
    pub(in crate::adapt) max_halvings: u8,
    /// Shortest cell side a split may make, m (0: no limit).
    pub(in crate::adapt) min_edge: Scalar,
}

impl Axis {
    pub(super) fn n(&self) -> usize {
        self.lines.len()
    }

    /// Level of the column between lines `c` and `c + 1`.
    pub(super) fn column_level(&self, c: usize) -> u8 {
        self.lines[c].level.max(self.lines[c + 1].level)
    }

    /// Each column's index among the columns of its level: a column of level
    /// `L` that is the `k`-th of its base column `b` (the `b`-th between base
    /// lines) has index `b 2^L + k`. On a uniform base grid this is its
    /// offset from the first line over its width; base lines need not be
    /// uniform (a grid fitted to pin boxes).
    pub(super) fn cell_indices(&self) -> Vec<i64> {
        let mut out = Vec::with_capacity(self.n().saturating_sub(1));
        let (mut base, mut base_at) = (-1i64, self.lines[0].at);
        for c in 0..self.n().saturating_sub(1) {
            if self.lines[c].level == 0 {
                base += 1;
                base_at = self.lines[c].at;
            }
            let level = u32::from(self.column_level(c)).min(62);
            let k = ((self.lines[c].at - base_at) / self.width(c)).round() as i64;
            out.push((base << level) + k);
        }
        out
    }

    pub(super) fn width(&self, c: usize) -> Scalar {
        self.lines[c + 1].at - self.lines[c].at
    }

    /// Whether line `m` halved its parent column (both neighbours coarser).
    pub(super) fn removable(&self, m: usize) -> bool {
        m > 0
            && m + 1 < self.n()
            && self.lines[m].level > self.lines[m - 1].level
            && self.lines[m].level > self.lines[m + 1].level
    }

    /// The operations of a pass given the largest measure at each line (`phi`
    /// or `kappa`; zero at the two boundary lines, which have none).
    pub(super) fn marks(&self, at_line: &[Scalar], th: &Thresholds) -> AxisOps {
        let cols = self.n() - 1;
        let mut level: Vec<u8> = (0..cols).map(|c| self.column_level(c)).collect();
        let mut split: Vec<Option<Option<Scalar>>> = vec![None; cols];
        for c in 0..cols {
            let demand = at_line[c].max(at_line[c + 1]);
            let measure = if th.sizing {
                demand * self.width(c)
            } else {
                demand
            };
            if measure > th.refine && self.can_split(c, th) {
                split[c] = Some(Some(measure));
                level[c] += 1;
            }
        }
        // One halving between neighbours: split the coarser one.
        loop {
            let mut changed = false;
            for c in 0..cols {
                for n in [c.wrapping_sub(1), c + 1] {
                    if n < cols && level[c] > level[n] + 1 && split[n].is_none() {
                        split[n] = Some(None);
                        level[n] += 1;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        let mut ops = AxisOps {
            splits: (0..cols).filter_map(|c| split[c].map(|m| (c, m))).collect(),
            merges: Vec::new(),
        };
        for m in (1..self.n() - 1).filter(|&m| self.removable(m)) {
            if split[m - 1].is_some() || split[m].is_some() {
                continue;
            }
            let demand = at_line[m - 1].max(at_line[m]).max(at_line[m + 1]);
            let parent = self.lines[m - 1].level.max(self.lines[m + 1].level);
            let measure = if th.sizing {
                demand * (self.lines[m + 1].at - self.lines[m - 1].at)
            } else {
                demand
            };
            let flat = if th.sizing {
                measure <= th.coarsen
            } else {
                measure < th.coarsen && measure < 0.5 * th.refine
            };
            // The columns beyond the parent (after this pass's splits) may be
            // at most one halving finer than it.
            let balanced = (m < 2 || level[m - 2] <= parent + 1)
                && (m + 1 >= cols || level[m + 1] <= parent + 1);
            if flat && balanced {
                ops.merges.push(m);
            }
        }
        // No two removals are neighbours (a removable line's neighbours are
        // coarser than it, so not removable), so each parent is judged against
        // columns no removal of this pass changes, except to coarsen them.
        ops
    }

    fn can_split(&self, c: usize, th: &Thresholds) -> bool {
        self.column_level(c) < th.max_halvings
            && (th.min_edge <= 0.0 || 0.5 * self.width(c) >= th.min_edge)
    }

    /// Applies `ops`: the new lines and where each comes from.
    pub(super) fn apply(&mut self, ops: &AxisOps) -> Vec<Source> {
        let mut split = vec![false; self.n()];
        for &(c, _) in &ops.splits {
            split[c] = true;
        }
        let mut merged = vec![false; self.n()];
        for &m in &ops.merges {
            merged[m] = true;
        }
        let mut lines = Vec::with_capacity(self.n() + ops.splits.len());
        let mut source = Vec::with_capacity(lines.capacity());
        for i in 0..self.n() {
            if !merged[i] {
                lines.push(self.lines[i]);
                source.push(Source::Old(i));
            }
            if i + 1 < self.n() && split[i] {
                lines.push(Line {
                    at: 0.5 * (self.lines[i].at + self.lines[i + 1].at),
                    level: self.column_level(i) + 1,
                });
                source.push(Source::Between(i));
            }
        }
        self.lines = lines;
        source
    }
}
