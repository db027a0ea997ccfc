//! Cloth self-collision: vertex-triangle and edge-edge proximity within the thickness,
//! resolved by repulsion (position correction plus an inelastic normal impulse).
//!
//! Each step: the swept box (start and end positions, inflated by the thickness) of every
//! triangle goes into one parry [`Bvh`] per Volino patch, built when the patches are
//! (for the current triangles) and refitted to the new boxes at every later step; patches that pass Volino's test ([`super::volino`]) skip their self-test;
//! every other box-overlapping pair of triangles that share no vertex yields its 6
//! vertex-triangle and 9 edge-edge primitive pairs (deduplicated). A primitive pair acts
//! when, with its closest features at the end positions, the two sides are closer than the
//! thickness, or when they crossed during the step (the end positions lie on the other
//! side of the start normal). Corrections are weighted by inverse lumped mass (0 for pinned
//! vertices), computed per pair in parallel and gathered per vertex in pair order, so the
//! result does not depend on the thread count.

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use rayon::prelude::*;

use super::self_prims::{PairSort, Prim, RestBounds, edge, sort_and_dedup};
use super::volino::{Patches, ProjectedEdge};
use crate::math::{Scalar, Vector};
use crate::mesh::Mesh;
use crate::spec::SelfCollision;

/// What one self-collision pass did.
#[derive(Debug, Clone, Copy, Default)]
pub struct SelfStats {
    /// Triangle pairs given to the exact tests.
    pub pairs_tested: u64,
    /// Triangles whose patch skipped its self-test (Volino culling).
    pub triangles_culled: u64,
    /// Triangles in all.
    pub triangles: u64,
    /// Primitive pairs that acted (summed over the iterations).
    pub resolved: u64,
}

/// Self-collision settings plus the per-mesh data (patches, lumped areas).
#[derive(Debug, Clone)]
pub struct SelfCollider {
    /// Distance kept between non-adjacent parts, m.
    pub thickness: Scalar,
    /// Repulsion passes per step.
    pub iterations: u32,
    /// Whether Volino culling runs.
    pub culling: bool,
    patch_size: Option<Scalar>,
    /// The triangles the patches were built for.
    built_for: Vec<[u32; 3]>,
    patches: Patches,
    area: Vec<Scalar>,
    /// Every vertex's rest point (`Mesh::rest_points`).
    rest: Vec<Vector>,
    /// Every triangle's extent in rest space, for telling far triangle pairs.
    rest_bounds: RestBounds,
    /// False after the patches were rebuilt: the next step builds the patch trees.
    trees_built: bool,
    scratch: Scratch,
}

/// The per-step buffers of [`SelfCollider::resolve`], kept between steps: once they
/// have grown to the mesh's size a step allocates nothing. Their contents
/// do not survive a step, except the patch trees, which keep their shape and are
/// refitted to the new boxes.
#[derive(Debug, Clone, Default)]
struct Scratch {
    inv_mass: Vec<Scalar>,
    /// Swept box of every triangle.
    boxes: Vec<Aabb>,
    /// Swept box of every vertex, inflated by the thickness.
    vertex_boxes: Vec<Aabb>,
    /// Per patch: Volino's test passed.
    culled: Vec<bool>,
    /// Per patch: its projected boundary (Volino's test).
    boundary: Vec<Vec<ProjectedEdge>>,
    /// One BVH per patch, leaves numbered within the patch.
    trees: Vec<Bvh>,
    /// Box of every patch tree.
    patch_box: Vec<Aabb>,
    /// Per patch: its box-overlapping triangle pairs.
    pairs: Vec<Vec<(u32, u32)>>,
    prims: Vec<Prim>,
    /// Scratch of `self_prims::sort_and_dedup`.
    sort: PairSort,
    fixes: Vec<Fix>,
    /// Per primitive pair: its closest points at the start of the step (the same
    /// for every repulsion pass), `None` when they coincide.
    start: Vec<Option<StartSide>>,
    /// Per vertex: corrected by the latest repulsion pass.
    moved: Vec<bool>,
    dx: Vec<Vector>,
    dv: Vec<Vector>,
    count: Vec<u32>,
}

impl Scratch {
    /// Sums the corrections of `fixes` per vertex into `dx`, `dv` and `count`
    /// (over `n` vertices); the number of pairs that acted.
    fn sum_fixes(&mut self, n: usize) -> u64 {
        for buf in [&mut self.dx, &mut self.dv] {
            buf.clear();
            buf.resize(n, Vector::ZERO);
        }
        self.count.clear();
        self.count.resize(n, 0);
        let mut acted = 0u64;
        for f in &self.fixes {
            acted += 1;
            for k in 0..4 {
                let i = f.vertex[k] as usize;
                if f.dx[k] != Vector::ZERO || f.dv[k] != Vector::ZERO {
                    self.dx[i] += f.dx[k];
                    self.dv[i] += f.dv[k];
                    self.count[i] += 1;
                }
            }
        }
        acted
    }

    /// Moves every corrected vertex by the mean of its corrections, and notes
    /// which moved.
    fn apply_fixes(&mut self, x: &mut [Vector], v: &mut [Vector]) {
        for i in 0..x.len() {
            self.moved[i] = self.count[i] > 0;
            if self.count[i] > 0 {
                let c = self.count[i] as Scalar;
                x[i] += self.dx[i] / c;
                v[i] += self.dv[i] / c;
            }
        }
    }
}

impl SelfCollider {
    /// From the scene's `[self_collision]`.
    pub fn new(s: &SelfCollision) -> SelfCollider {
        SelfCollider {
            thickness: s.thickness,
            iterations: s.iterations,
            culling: s.culling,
            patch_size: s.patch_size,
            built_for: Vec::new(),
            rest: Vec::new(),
            rest_bounds: RestBounds::default(),
            patches: Patches::default(),
            area: Vec::new(),
            trees_built: false,
            scratch: Scratch::default(),
        }
    }

    fn prepare(&mut self, mesh: &Mesh) {
        if self.built_for == mesh.triangles {
            return;
        }
        self.patches = Patches::build(mesh, self.patch_size);
        self.area = vec![0.0; mesh.vertex_count()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let a = mesh.rest_area(t) / 3.0;
            for &v in tri {
                self.area[v as usize] += a;
            }
        }
        mesh.rest_points(&mut self.rest);
        self.rest_bounds = RestBounds::new(&mesh.triangles, &self.rest);
        self.built_for = mesh.triangles.clone();
        self.trees_built = false;
    }

    /// Separates the cloth from itself: `x0` start-of-step positions, `x`/`v` the state
    /// to correct, `held` pinned vertices (never moved).
    pub fn resolve(
        &mut self,
        mesh: &Mesh,
        x0: &[Vector],
        x: &mut [Vector],
        v: &mut [Vector],
        held: &[bool],
    ) -> SelfStats {
        self.prepare(mesh);
        // Taken out for the step so that `&self` methods can fill it (no allocation:
        // the placeholder left behind is empty).
        let mut s = std::mem::take(&mut self.scratch);
        s.inv_mass.clear();
        s.inv_mass.extend((0..x.len()).map(|i| {
            if held.get(i).copied().unwrap_or(false) || self.area[i] <= 0.0 {
                0.0
            } else {
                1.0 / self.area[i]
            }
        }));
        let mut stats = self.candidates(mesh, x0, x, &mut s);
        let tris = &mesh.triangles;
        s.prims
            .par_iter()
            .map(|p| StartSide::of(*p, tris, x0))
            .collect_into_vec(&mut s.start);
        s.moved.clear();
        s.moved.resize(x.len(), true);
        for _ in 0..self.iterations {
            self.collect_fixes(tris, x, v, &mut s);
            let acted = s.sum_fixes(x.len());
            stats.resolved += acted;
            if acted == 0 {
                break;
            }
            s.apply_fixes(x, v);
        }
        self.scratch = s;
        stats
    }

    /// One pass's corrections into `s.fixes`: those of the pairs with a start
    /// normal and a vertex the last pass moved, in pair order.
    fn collect_fixes(&self, tris: &[[u32; 3]], x: &[Vector], v: &[Vector], s: &mut Scratch) {
        // A pair none of whose vertices the last pass moved gives what it
        // gave then: nothing (a pair that acted moved its vertices).
        let moved = &s.moved;
        // Only the pairs that act are kept, in pair order (few of them: a
        // list of every pair's outcome would be most of the step's traffic).
        s.fixes.clear();
        s.fixes.par_extend(
            s.prims
                .par_iter()
                .zip(s.start.par_iter())
                .filter_map(|(p, start)| {
                    // No start normal: the pair gives nothing.
                    let start = start.as_ref()?;
                    let touched = start.ids.iter().any(|&i| moved[i as usize]);
                    touched.then(|| self.fix(tris, *p, start, x, v, &s.inv_mass))?
                }),
        );
    }

    /// Primitive pairs of the box-overlapping, non-adjacent triangle pairs, into
    /// `s.prims`.
    fn candidates(
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

    /// The correction of one primitive pair, if it acts; `start`: its closest
    /// points at the start of the step.
    fn fix(
        &self,
        tris: &[[u32; 3]],
        p: Prim,
        start: &StartSide,
        x: &[Vector],
        v: &[Vector],
        inv_mass: &[Scalar],
    ) -> Option<Fix> {
        if self.apart_along(p, start, x) {
            return None;
        }
        self.fix_measured(tris, p, start, x, v, inv_mass)
    }

    /// [`Self::fix`] from the pair's closest points at `x`, without the
    /// test that spares them.
    fn fix_measured(
        &self,
        tris: &[[u32; 3]],
        p: Prim,
        start: &StartSide,
        x: &[Vector],
        v: &[Vector],
        inv_mass: &[Scalar],
    ) -> Option<Fix> {
        let at1 = |i: u32| x[i as usize];
        let (ids0, w0, n0) = (start.ids, start.weights, start.normal);
        let (ids1, w1) = p.weights(tris, &at1);
        let r1: Vector = (0..4).map(|k| at1(ids1[k]) * w1[k]).sum();
        let (ids, w, n, gap) = if r1.dot(n0) <= 0.0 {
            // Crossed during the step: push back to the start side along the start normal.
            let r1s: Vector = (0..4).map(|k| at1(ids0[k]) * w0[k]).sum();
            (ids0, w0, n0, self.thickness - r1s.dot(n0))
        } else {
            let d1 = r1.length();
            if d1 >= self.thickness {
                return None;
            }
            (ids1, w1, r1 / d1, self.thickness - d1)
        };
        let denom: Scalar = (0..4)
            .map(|k| w[k] * w[k] * inv_mass[ids[k] as usize])
            .sum();
        if gap <= 0.0 || denom <= 0.0 {
            return None;
        }
        let lambda = gap / denom;
        let vrel: Scalar = (0..4)
            .map(|k| v[ids[k] as usize] * w[k])
            .sum::<Vector>()
            .dot(n);
        // Inelastic: remove the approaching relative normal velocity (no bounce).
        let mu = if vrel < 0.0 { -vrel / denom } else { 0.0 };
        let mut f = Fix {
            vertex: ids,
            dx: [Vector::ZERO; 4],
            dv: [Vector::ZERO; 4],
        };
        for k in 0..4 {
            let s = w[k] * inv_mass[ids[k] as usize];
            f.dx[k] = n * (s * lambda);
            f.dv[k] = n * (s * mu);
        }
        Some(f)
    }
}

impl SelfCollider {
    /// True when at `x` every vertex of `p`'s first part lies more than a
    /// thickness (with a margin for rounding) beyond every vertex of its
    /// second part along the start normal. Then so do its closest points
    /// (convex combinations of each part's vertices): the pair has not
    /// crossed and is more than a thickness apart, and [`Self::fix`] would
    /// find that after computing them.
    #[inline(always)]
    fn apart_along(&self, p: Prim, start: &StartSide, x: &[Vector]) -> bool {
        let along = |k: usize| x[start.ids[k] as usize].dot(start.normal);
        let first = p.first_part();
        let low = (0..first).map(along).fold(Scalar::INFINITY, Scalar::min);
        let high = (first..4)
            .map(along)
            .fold(Scalar::NEG_INFINITY, Scalar::max);
        low - high > self.thickness * (1.0 + 1e-9)
    }
}

/// A primitive pair's closest points at the start of the step: the four
/// vertices, their weights ([`Prim::weights`]) and the unit normal from the
/// second part to the first.
#[derive(Debug, Clone, Copy)]
struct StartSide {
    ids: [u32; 4],
    weights: [Scalar; 4],
    normal: Vector,
}

impl StartSide {
    /// `p`'s closest points at the start positions `x0`; `None` when they
    /// coincide (no normal: the pair gives nothing).
    fn of(p: Prim, tris: &[[u32; 3]], x0: &[Vector]) -> Option<StartSide> {
        let at0 = |i: u32| x0[i as usize];
        let (ids, weights) = p.weights(tris, &at0);
        let r0: Vector = (0..4).map(|k| at0(ids[k]) * weights[k]).sum();
        let normal = r0.try_normalize()?;
        Some(StartSide {
            ids,
            weights,
            normal,
        })
    }
}

/// One pair's correction of its four vertices.
#[derive(Debug, Clone, Copy)]
struct Fix {
    vertex: [u32; 4],
    dx: [Vector; 4],
    dv: [Vector; 4],
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
fn pair_prims(tris: &[[u32; 3]], vb: &[Aabb], t: u32, u: u32, near: bool, out: &mut Vec<Prim>) {
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

#[cfg(test)]
mod tests;
