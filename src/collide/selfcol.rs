//! Cloth self-collision: vertex-triangle and edge-edge proximity within the thickness,
//! resolved by repulsion (position correction plus an inelastic normal impulse).
//!
//! Each step: the swept box (start and end positions, inflated by the thickness) of every
//! triangle goes into one parry [`Bvh`] per Volino patch, rebuilt for the current
//! triangles; patches that pass Volino's test ([`super::volino`]) skip their self-test;
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

use super::geometry::{closest_on_segments, closest_on_triangle};
use super::volino::Patches;
use crate::math::{Scalar, Vector};
use crate::mesh::Mesh;
use crate::scene::SelfCollision;

/// Primitive pair: `(kind, a, b, c, d)`; kind 0: vertex `a` against triangle `b`;
/// kind 1: edge `(a, b)` against edge `(c, d)`.
type Prim = (u8, u32, u32, u32, u32);

/// What one self-collision pass did.
#[derive(Debug, Clone, Copy, Default)]
pub struct SelfStats {
    /// Triangle pairs given to the exact tests.
    pub pairs_tested: u64,
    /// Box-overlapping triangle pairs skipped by Volino culling.
    pub pairs_culled: u64,
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
            patches: Patches::default(),
            area: Vec::new(),
        }
    }

    /// Number of culling patches of the current mesh.
    pub fn patch_count(&self) -> usize {
        self.patches.len()
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
        self.built_for = mesh.triangles.clone();
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
        let inv_mass: Vec<Scalar> = (0..x.len())
            .map(|i| {
                if held.get(i).copied().unwrap_or(false) || self.area[i] <= 0.0 {
                    0.0
                } else {
                    1.0 / self.area[i]
                }
            })
            .collect();
        let (prims, mut stats) = self.candidates(mesh, x0, x);
        for _ in 0..self.iterations {
            let fixes: Vec<Option<Fix>> = prims
                .par_iter()
                .map(|p| self.fix(mesh, p, x0, x, v, &inv_mass))
                .collect();
            let mut dx = vec![Vector::ZERO; x.len()];
            let mut dv = vec![Vector::ZERO; x.len()];
            let mut count = vec![0u32; x.len()];
            let mut acted = 0u64;
            for f in fixes.iter().flatten() {
                acted += 1;
                for k in 0..4 {
                    let i = f.vertex[k] as usize;
                    if f.dx[k] != Vector::ZERO || f.dv[k] != Vector::ZERO {
                        dx[i] += f.dx[k];
                        dv[i] += f.dv[k];
                        count[i] += 1;
                    }
                }
            }
            stats.resolved += acted;
            if acted == 0 {
                break;
            }
            for i in 0..x.len() {
                if count[i] > 0 {
                    let c = count[i] as Scalar;
                    x[i] += dx[i] / c;
                    v[i] += dv[i] / c;
                }
            }
        }
        stats
    }

    /// Primitive pairs of the box-overlapping, non-adjacent triangle pairs.
    fn candidates(&self, mesh: &Mesh, x0: &[Vector], x: &[Vector]) -> (Vec<Prim>, SelfStats) {
        let tris = &mesh.triangles;
        let pad = Vector::splat(self.thickness);
        let boxes: Vec<Aabb> = tris
            .par_iter()
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
            .collect();
        let pt = &self.patches;
        let culled: Vec<bool> = (0..pt.len())
            .into_par_iter()
            .map(|p| self.culling && pt.cannot_self_intersect(p, tris, x0, x))
            .collect();
        // Leaves are numbered within their patch (0, 1, ...) and mapped back to triangles
        // on query: parry 0.31's `Bvh::from_iter` indexes its leaf table by position for
        // one or two leaves, so a small patch with global triangle ids panicked.
        let trees: Vec<Bvh> = pt
            .triangles
            .par_iter()
            .map(|ts| {
                Bvh::from_iter(
                    BvhBuildStrategy::Binned,
                    ts.iter().enumerate().map(|(k, &t)| (k, boxes[t as usize])),
                )
            })
            .collect();
        let patch_box: Vec<Aabb> = trees.iter().map(|b| b.root_aabb()).collect();
        let disjoint = |a: u32, b: u32| {
            let (ta, tb) = (tris[a as usize], tris[b as usize]);
            !ta.iter().any(|v| tb.contains(v))
        };
        // Per patch: its own pairs (or their count when culled) and its pairs with later patches.
        let per_patch: Vec<(Vec<(u32, u32)>, u64)> = (0..pt.len())
            .into_par_iter()
            .map(|p| {
                let mut pairs = Vec::new();
                let mut skipped = 0u64;
                for &t in &pt.triangles[p] {
                    for k in trees[p].intersect_aabb(&boxes[t as usize]) {
                        let u = pt.triangles[p][k as usize];
                        if u > t && disjoint(t, u) {
                            if culled[p] {
                                skipped += 1;
                            } else {
                                pairs.push((t, u));
                            }
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
                (pairs, skipped)
            })
            .collect();
        let mut stats = SelfStats::default();
        let mut prims: Vec<Prim> = Vec::new();
        for (pairs, skipped) in &per_patch {
            stats.pairs_culled += skipped;
            stats.pairs_tested += pairs.len() as u64;
            for &(t, u) in pairs {
                let (a, b) = (tris[t as usize], tris[u as usize]);
                for k in 0..3 {
                    prims.push((0, a[k], u, 0, 0));
                    prims.push((0, b[k], t, 0, 0));
                    let e = edge(a[k], a[(k + 1) % 3]);
                    for j in 0..3 {
                        let f = edge(b[j], b[(j + 1) % 3]);
                        let (lo, hi) = if e <= f { (e, f) } else { (f, e) };
                        prims.push((1, lo[0], lo[1], hi[0], hi[1]));
                    }
                }
            }
        }
        prims.par_sort_unstable();
        prims.dedup();
        // Parts that are close in the rest state cannot be held a thickness apart.
        let rest = |i: u32| mesh.material[i as usize].extend(0.0);
        prims.retain(|p| {
            let (ids, w) = weights(p, tris, &rest);
            let r: Vector = (0..4).map(|k| rest(ids[k]) * w[k]).sum();
            r.length() >= 1.5 * self.thickness
        });
        (prims, stats)
    }

    /// The correction of one primitive pair, if it acts.
    fn fix(
        &self,
        mesh: &Mesh,
        p: &Prim,
        x0: &[Vector],
        x: &[Vector],
        v: &[Vector],
        inv_mass: &[Scalar],
    ) -> Option<Fix> {
        let tris = &mesh.triangles;
        let at0 = |i: u32| x0[i as usize];
        let at1 = |i: u32| x[i as usize];
        let (ids0, w0) = weights(p, tris, &at0);
        let r0: Vector = (0..4).map(|k| at0(ids0[k]) * w0[k]).sum();
        let n0 = r0.try_normalize()?;
        let (ids1, w1) = weights(p, tris, &at1);
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

/// One pair's correction of its four vertices.
#[derive(Debug, Clone, Copy)]
struct Fix {
    vertex: [u32; 4],
    dx: [Vector; 4],
    dv: [Vector; 4],
}

fn edge(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// The four vertices of a primitive pair and their weights: the relative position of the
/// two closest points is `sum w_k x_k` (positive side first), at the positions `at`.
fn weights(p: &Prim, tris: &[[u32; 3]], at: &impl Fn(u32) -> Vector) -> ([u32; 4], [Scalar; 4]) {
    match p.0 {
        0 => {
            let t = tris[p.2 as usize];
            let [a, b, c] = t.map(at);
            let bary = closest_on_triangle(at(p.1), a, b, c);
            ([p.1, t[0], t[1], t[2]], [1.0, -bary[0], -bary[1], -bary[2]])
        }
        _ => {
            let (s, t) = closest_on_segments(at(p.1), at(p.2), at(p.3), at(p.4));
            ([p.1, p.2, p.3, p.4], [1.0 - s, s, -(1.0 - t), -t])
        }
    }
}
