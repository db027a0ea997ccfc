//! The broad phase of a self-collision pass: each triangle's swept box, the
//! patch trees fitted to them, the box-overlapping pairs of triangles that
//! share no vertex, and their primitive pairs whose own boxes overlap.

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use rayon::prelude::*;

use super::super::self_prims::{Prim, RestBounds, edge, sort_and_dedup};
use super::{Scratch, SelfCollider, SelfStats};
use crate::math::{Scalar, Vector};
use crate::mesh::Mesh;

impl SelfCollider {
    /// Primitive pairs of the box-overlapping, non-adjacent triangle pairs, into
    /// `s.prims`.
    pub(super) fn candidates(
        &mut self,
        mesh: &Mesh,
        x0: &[Vector],
        x: &[Vector],
        s: &mut Scratch,
    ) -> SelfStats {
        let tris = &mesh.triangles;
        self.swept_boxes(tris, x0, x, s);
        let pt = &self.patches;
        s.boundary.resize_with(pt.len(), Vec::new);
        s.boundary
            .par_iter_mut()
            .enumerate()
            .map(|(p, boundary)| self.culling && pt.cannot_self_intersect(p, tris, x0, x, boundary))
            .collect_into_vec(&mut s.culled);
        self.fit_trees(s);
        self.collect_pairs(tris, s);
        let limit = 1.5 * self.thickness;
        let mut stats = primitive_pairs(tris, s, &self.rest_bounds, limit);
        stats.triangles_culled = (s.culled.iter().zip(&self.patches.triangles))
            .filter(|(culled, _)| **culled)
            .map(|(_, ts)| ts.len() as u64)
            .sum();
        // Sorted and deduplicated, the list does not depend on the order the trees
        // report their pairs in (so neither on the trees' shapes). Of a pair's
        // copies the first is kept: one from a triangle pair far apart in rest
        // space, if any (`self_prims.rs`).
        let id_bound = x.len().max(tris.len());
        sort_and_dedup(&mut s.prims, &mut s.sort, id_bound);
        // Parts that are close in the rest state cannot be held a thickness apart.
        let rest_points = &self.rest;
        let rest = |i: u32| rest_points[i as usize];
        s.prims.retain(|p| {
            if !p.near() {
                return true;
            }
            let (ids, w) = p.weights(tris, &rest);
            let r: Vector = (0..4).map(|k| rest(ids[k]) * w[k]).sum();
            r.length() >= limit
        });
        stats
    }

    /// The swept box of every triangle, into `s.boxes`: its corners at the start and at
    /// the end of the step, inflated by the thickness; and of every vertex, into
    /// `s.vertex_boxes`.
    fn swept_boxes(&self, tris: &[[u32; 3]], x0: &[Vector], x: &[Vector], s: &mut Scratch) {
        let pad = Vector::splat(self.thickness);
        x0.par_iter()
            .zip(x.par_iter())
            .with_min_len(1024)
            .map(|(a, b)| Aabb::new(a.min(*b) - pad, a.max(*b) + pad))
            .collect_into_vec(&mut s.vertex_boxes);
        tris.par_iter()
            .map(|t| {
                let mut lo = Vector::splat(Scalar::INFINITY);
                let mut hi = -lo;
                for &i in t {
                    for p in [x0[i as usize], x[i as usize]] {
                        lo = lo.min(p);
                        hi = hi.max(p);
                    }
                }
                Aabb::new(lo - pad, hi + pad)
            })
            .collect_into_vec(&mut s.boxes);
    }

    /// Brings the patch trees to this step's boxes: built after the patches changed,
    /// else refitted in place (same tree shape, boxes recomputed bottom-up, no
    /// allocation). A refitted tree answers box queries exactly like a rebuilt one;
    /// only its traversal cost may differ.
    fn fit_trees(&mut self, s: &mut Scratch) {
        let pt = &self.patches;
        let boxes = &s.boxes;
        if self.trees_built {
            s.trees
                .par_iter_mut()
                .zip(pt.triangles.par_iter())
                .for_each(|(tree, ts)| {
                    for (k, &t) in ts.iter().enumerate() {
                        tree.update_partially_if_present(boxes[t as usize], k as u32, 0.0);
                    }
                    tree.refit_without_opt();
                });
        } else {
            // Leaves are numbered within their patch (0, 1, ...) and mapped back to
            // triangles on query: parry 0.31's `Bvh::from_iter` indexes its leaf table
            // by position for one or two leaves, so a small patch with global triangle
            // ids panicked.
            pt.triangles
                .par_iter()
                .map(|ts| {
                    Bvh::from_iter(
                        BvhBuildStrategy::Binned,
                        ts.iter().enumerate().map(|(k, &t)| (k, boxes[t as usize])),
                    )
                })
                .collect_into_vec(&mut s.trees);
            self.trees_built = true;
        }
        s.patch_box.clear();
        s.patch_box.extend(s.trees.iter().map(|b| b.root_aabb()));
    }

    /// Per patch, into `s.pairs`: its own box-overlapping pairs (none when culled:
    /// its tree is not even searched) and its pairs with later patches.
    fn collect_pairs(&self, tris: &[[u32; 3]], s: &mut Scratch) {
        let pt = &self.patches;
        let Scratch {
            boxes,
            culled,
            trees,
            patch_box,
            pairs,
            ..
        } = s;
        let disjoint = |a: u32, b: u32| {
            let (ta, tb) = (tris[a as usize], tris[b as usize]);
            !ta.iter().any(|v| tb.contains(v))
        };
        pairs.resize_with(pt.len(), Default::default);
        pairs.par_iter_mut().enumerate().for_each(|(p, pairs)| {
            pairs.clear();
            for &t in &pt.triangles[p] {
                if culled[p] {
                    break;
                }
                for k in trees[p].intersect_aabb(&boxes[t as usize]) {
                    let u = pt.triangles[p][k as usize];
                    if u > t && disjoint(t, u) {
                        pairs.push((t, u));
                    }
                }
            }
            for q in p + 1..pt.len() {
                if !patch_box[p].intersects(&patch_box[q]) {
                    continue;
                }
                for &t in &pt.triangles[p] {
                    if !patch_box[q].intersects(&boxes[t as usize]) {
                        continue;
                    }
                    for k in trees[q].intersect_aabb(&boxes[t as usize]) {
                        let u = pt.triangles[q][k as usize];
                        if disjoint(t, u) {
                            pairs.push((t, u));
                        }
                    }
                }
            }
        });
    }
}

/// Every triangle pair of `s.pairs` as its 6 vertex-triangle and 9 edge-edge primitive
/// pairs, into `s.prims` (unsorted, with repeats), each marked near unless its
/// triangles are farther than `limit` apart in rest space; counts the pairs
/// tested and the triangles.
///
/// A primitive pair whose swept boxes, each inflated by the thickness, do not
/// overlap is left out: its parts stay more than two thicknesses apart along
/// an axis at the start and at the end of the step, the margin the triangle
/// pairs were found with. Of the primitive pairs of box-overlapping triangle
/// pairs, most are such (two triangles side by side overlap in their boxes;
/// a vertex of one and the far edge of the other do not).
fn primitive_pairs(
    tris: &[[u32; 3]],
    s: &mut Scratch,
    rest: &RestBounds,
    limit: Scalar,
) -> SelfStats {
    let mut stats = SelfStats {
        triangles: tris.len() as u64,
        ..SelfStats::default()
    };
    for pairs in &s.pairs {
        stats.pairs_tested += pairs.len() as u64;
    }
    s.prims.clear();
    for pairs in &s.pairs {
        for &(t, u) in pairs {
            let near = !rest.far(t, u, limit);
            pair_prims(tris, &s.vertex_boxes, t, u, near, &mut s.prims);
        }
    }
    stats
}

/// The primitive pairs of triangles `t` and `u` whose inflated swept boxes
/// overlap, into `out` ([`primitive_pairs`]).
pub(super) fn pair_prims(
    tris: &[[u32; 3]],
    vb: &[Aabb],
    t: u32,
    u: u32,
    near: bool,
    out: &mut Vec<Prim>,
) {
    let edge_box = |e: [u32; 2]| vb[e[0] as usize].merged(&vb[e[1] as usize]);
    let (a, b) = (tris[t as usize], tris[u as usize]);
    let (box_a, box_b) = (
        vb[a[0] as usize]
            .merged(&vb[a[1] as usize])
            .merged(&vb[a[2] as usize]),
        vb[b[0] as usize]
            .merged(&vb[b[1] as usize])
            .merged(&vb[b[2] as usize]),
    );
    let edges_b = [0, 1, 2].map(|j| {
        let f = edge(b[j], b[(j + 1) % 3]);
        (f, edge_box(f))
    });
    for k in 0..3 {
        if vb[a[k] as usize].intersects(&box_b) {
            out.push(Prim::vertex_triangle(a[k], u, near));
        }
        if vb[b[k] as usize].intersects(&box_a) {
            out.push(Prim::vertex_triangle(b[k], t, near));
        }
        let e = edge(a[k], a[(k + 1) % 3]);
        let eb = edge_box(e);
        if !eb.intersects(&box_b) {
            continue;
        }
        for (f, fb) in &edges_b {
            if eb.intersects(fb) {
                out.push(Prim::edge_edge(e, *f, near));
            }
        }
    }
}
