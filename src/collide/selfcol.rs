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

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::Bvh;
use rayon::prelude::*;

use super::self_prims::{PairSort, Prim, RestBounds};
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

mod broad;
#[cfg(test)]
mod tests;
