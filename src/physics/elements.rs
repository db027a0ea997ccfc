//! Force elements built from the mesh and the material: springs, bending hinges,
//! lumped masses, and the per-vertex incidence lists used to gather forces.
//!
//! Everything here derives from material coordinates, so it is rebuilt whenever
//! the mesh changes and means the same physical sheet at every resolution. The
//! rebuild after a remesh is incremental ([`Elements::rebuild`], module
//! [`reuse`]): the buffers are reused and shape triangles whose stencil did not
//! change keep their matrix. It gains little: `cargo bench --bench implicit --
//! remesh_and_back` (a 63 x 63 grid refined along one crease and back, 7,938
//! and 8,442 triangles, 7,560 of the refined mesh's matrices kept, 882
//! computed) measured 2.568 ms for the two fresh builds against 2.456 ms for the
//! two rebuilds in place (4 % less; 11.18 against 10.87 ms at 127 x 127). The
//! matching by material point costs about what the kept matrices save.
//!
//! # Stiffness derivations
//! * Stretch, consistent rule (Van Gelder 1998): `k_e = stretch * sum(A_t) / L_e^2`
//!   over the (one or two) rest triangles at edge e. Under a uniform strain the
//!   force per unit cut length is then independent of the edge length, so the
//!   sheet's stretch response does not depend on resolution. It is exact for an
//!   equal biaxial stretch on any triangulation, but not for other strains on
//!   triangles unlike the grid's: red-green's green closures store 9 to 10 %
//!   less energy than the grid under a stretch along an axis and 48 to 50 %
//!   more in shear, per area (test `green_closures_stretch_unlike_the_grid`;
//!   a mass-spring membrane does not pass the patch test in general).
//!   Fitting per-spring weights on such triangles to the grid's membrane
//!   tensor cuts that deviation several times but improves no benchmark
//!   error, so it is not adopted.
//! * Membrane triangles (`membrane = "triangles"`, module [`super::membrane`]):
//!   one constant-strain orthotropic element per triangle instead of the stretch
//!   springs; exact for every homogeneous strain on every triangulation.
//! * Stretch, `paper_a`: every spring of level n has `k = stretch * 2^(n/2)`
//!   (paper A, eq. 1, with `k_0 = stretch`). Level 0 springs of a uniform mesh
//!   all get the same constant, which in 2D is itself resolution independent; the
//!   inconsistency shows when refinement raises the level.
//! * Damping (paper B, eq. 2) is stiffness proportional: `c_e = damping * k_e`.
//! * Sewing ([`super::sewing`]): a zero-length spring per pair of an open seam,
//!   `k = stiffness * s` with `s` the pair's share of the seam's length, and
//!   with `max_force` a cap `max_force * s` on its force (a Huber energy).
//! * Dihedral bending: hinge energy `E_e = (B/2) * theta^2 * L_e^2 / (A1 + A2)`,
//!   i.e. curvature `theta / h_e` with `h_e = (A1 + A2) / L_e` (the mean height of
//!   the two wings over the edge) integrated over the hinge's area `A1 + A2`
//!   shared by its three edges. On a grid bent into a cylinder of radius R about
//!   an axis along one grid direction, each hinge across the bend has
//!   `theta = h / R` and the energy sums to `B A / (2 R^2)` (free boundary
//!   strips excepted), at every resolution. So `k_hinge = B * L_e^2 / (A1 + A2)`.
//! * Hinge springs (paper A): a spring between the two wing tips of each interior
//!   edge with `k = B / d0^2` (d0 the rest distance of the tips, times 2^(n/2)
//!   under `paper_a`). Its energy grows with theta^4, so no constant makes it
//!   match a bending rigidity; the tests print how far it deviates.
//! * Shape-operator bending (the default, [`super::shape`]): per triangle the
//!   curvature tensor from its three edge angles, energy `(B/2) A_t |S_t|^2`, the
//!   plate with Poisson ratio 0 whose beam rigidity is the textile cantilever's.
//!   The dihedral hinges above are kept as `bending_model = "dihedral"`: they
//!   reproduce a cylinder imposed on a grid, but a loaded strip is about 20% too
//!   soft (see `shape.rs` for why and the numbers).

mod reuse;

pub use reuse::RebuildCounts;

use super::membrane::{MEMBRANE_SLOTS, Membrane, MembraneTriangle};
use super::sewing::{SpringCap, sewing_springs};
use super::shape::{
    FoldEdges, FoldSplits, SHAPE_SLOTS, ShapeScratch, ShapeTriangle, build_shape_triangles_into,
};
use crate::math::{Scalar, Vector2};
use crate::mesh::Mesh;
use crate::spec::{BendingModel, Sewing, StiffnessRule};
use reuse::{Previous, Reuse};

/// Material parameters the elements are built from (per area, mesh independent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialParams {
    /// Area density, kg/m^2.
    pub density: Scalar,
    /// Stretch stiffness of the springs, N/m (with [`Membrane::Springs`]).
    pub stretch: Scalar,
    /// The in-plane force model: springs from `stretch`, or the continuum
    /// membrane with its own moduli.
    pub membrane: Membrane,
    /// Bending rigidity, N m.
    pub bending: Scalar,
    /// Stiffness-proportional damping, s.
    pub damping: Scalar,
    /// Bending force model.
    pub bending_model: BendingModel,
    /// How spring constants are derived.
    pub stiffness_rule: StiffnessRule,
    /// How a garment's open seams are sewn (their springs' stiffness and cap;
    /// the weld gap is read by the pipeline's sewing phase).
    pub sewing: Sewing,
}

/// A linear spring with damping along its axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// End vertices `[a, b]`.
    pub v: [u32; 2],
    /// Rest length, m.
    pub rest: Scalar,
    /// Stiffness, N/m.
    pub k: Scalar,
    /// Damping coefficient, N s/m.
    pub c: Scalar,
}

/// A dihedral bending hinge: `v[0], v[1]` span the edge, `v[2], v[3]` are the wing tips.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hinge {
    /// Vertices: edge start, edge end, tip of the first wing, tip of the second.
    pub v: [u32; 4],
    /// Angular stiffness, N m (energy `k theta^2 / 2`).
    pub k: Scalar,
}

/// Compressed per-vertex lists (CSR): `entries[offsets[i]..offsets[i+1]]` belong to vertex i.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Incidence {
    /// Start of each vertex's list; length `vertices + 1`.
    pub offsets: Vec<u32>,
    /// The entries, grouped by vertex.
    pub entries: Vec<u32>,
}

impl Incidence {
    /// Refills the lists from `(vertex, entry)` pairs, reusing the buffers;
    /// entries keep their order.
    fn fill(&mut self, vertices: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) {
        let offsets = &mut self.offsets;
        offsets.clear();
        offsets.resize(vertices + 1, 0);
        for (v, _) in pairs.clone() {
            offsets[v as usize + 1] += 1;
        }
        for i in 0..vertices {
            offsets[i + 1] += offsets[i];
        }
        self.entries.clear();
        self.entries.resize(offsets[vertices] as usize, 0);
        // Each vertex's next free place, kept in its own start (then shifted back).
        for (v, e) in pairs {
            let at = &mut offsets[v as usize];
            self.entries[*at as usize] = e;
            *at += 1;
        }
        for i in (1..=vertices).rev() {
            offsets[i] = offsets[i - 1];
        }
        offsets[0] = 0;
    }

    /// The entries of vertex `i`.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.entries[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}

/// All force elements of one mesh, with their per-vertex gather lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Elements {
    /// Lumped vertex masses `rho * sum(A_t) / 3`, kg.
    pub mass: Vec<Scalar>,
    /// Rest area attributed to each vertex (a third of each adjacent triangle), m^2.
    pub vertex_area: Vec<Scalar>,
    /// Stretch springs (one per edge, with [`Membrane::Springs`]), then hinge
    /// springs when that bending model is on, then the sewing springs of a
    /// garment's open seams.
    pub springs: Vec<Spring>,
    /// The sewing springs with a maximum force, in spring order (empty unless a
    /// seam has `max_force`; `super::sewing`).
    pub sewing_caps: Vec<SpringCap>,
    /// Continuum membrane triangles, one per triangle (with [`Membrane::Triangles`]).
    pub membrane_triangles: Vec<MembraneTriangle>,
    /// Dihedral hinges (only with the dihedral model and non-zero rigidity).
    pub hinges: Vec<Hinge>,
    /// Shape-operator bending elements, one per triangle (only with that model and
    /// non-zero rigidity).
    pub shape_triangles: Vec<ShapeTriangle>,
    /// The factored system of the shape triangles' fold splits.
    pub fold_splits: FoldSplits,
    /// The shape triangles' interior edges, each once (their folds are
    /// computed per edge).
    pub fold_edges: FoldEdges,
    /// Springs where the vertex is the first end (`v[0]`).
    pub spring_first: Incidence,
    /// Springs where the vertex is the second end (`v[1]`).
    pub spring_second: Incidence,
    /// Hinge slots `4 * hinge + k` where the vertex is `v[k]`.
    pub hinge_slots: Incidence,
    /// Shape-triangle slots `SHAPE_SLOTS * element + k` where the vertex is `v[k]`
    /// (used slots only).
    pub shape_slots: Incidence,
    /// Membrane-triangle slots `MEMBRANE_SLOTS * element + k` where the vertex is `v[k]`.
    pub membrane_slots: Incidence,
    /// Triangles at each vertex (for per-triangle forces such as wind).
    pub vertex_triangles: Incidence,
    /// What these elements were built from, for the next [`Elements::rebuild`].
    previous: Previous,
    /// Scratch memory of [`Elements::rebuild`] (never part of a comparison).
    scratch: Scratch,
}

/// Scratch memory of a rebuild, kept between rebuilds.
#[derive(Debug, Clone, Default)]
struct Scratch {
    area: Vec<Scalar>,
    shapes: Vec<ShapeTriangle>,
    shape: ShapeScratch,
    shape_pairs: Vec<(u32, u32)>,
    reuse: Reuse,
    counts: RebuildCounts,
}

/// Scratch memory holds nothing the elements mean: two element sets are equal
/// whatever their scratch holds.
impl PartialEq for Scratch {
    fn eq(&self, _: &Scratch) -> bool {
        true
    }
}

impl Elements {
    /// Builds masses, springs and bending elements for `mesh` from the material,
    /// with no clamp.
    pub fn build(mesh: &Mesh, mat: &MaterialParams) -> Elements {
        Self::build_clamped(mesh, mat, &[])
    }

    /// As [`Elements::build`], with `clamped[i]` the pin that holds vertex i for
    /// good, or `u32::MAX` (or an empty slice: no clamp). A triangle held by one
    /// such pin cannot bend; the shape-operator model gives the bend at its edges
    /// wholly to the free side (see `shape.rs`).
    pub fn build_clamped(mesh: &Mesh, mat: &MaterialParams, clamped: &[u32]) -> Elements {
        let mut elements = Elements::default();
        elements.rebuild(mesh, mat, clamped);
        elements
    }

    /// Makes these the elements of `mesh` (after a remesh), equal to
    /// [`Elements::build_clamped`]'s bit for bit, incrementally: every buffer is
    /// reused, and each shape triangle whose whole stencil was already in the
    /// mesh these elements were built for keeps its matrix instead of computing
    /// it again (module [`reuse`]). [`Elements::last_rebuild`] says how many did.
    pub fn rebuild(&mut self, mesh: &Mesh, mat: &MaterialParams, clamped: &[u32]) {
        let splits = self.rebuild_but_splits(mesh, mat, clamped);
        self.fold_splits = self.renewed_fold_splits(splits);
    }

    /// [`Elements::rebuild`] but for the fold splits' system, which is left
    /// that of the mesh before: [`Elements::renewed_fold_splits`] makes it,
    /// given the number of split unknowns this returns, and may run beside
    /// other work that reads the rebuilt elements.
    pub fn rebuild_but_splits(
        &mut self,
        mesh: &Mesh,
        mat: &MaterialParams,
        clamped: &[u32],
    ) -> usize {
        let n = mesh.vertex_count();
        let scratch = &mut self.scratch;
        scratch.area.clear();
        scratch
            .area
            .extend((0..mesh.triangles.len()).map(|t| mesh.rest_area(t)));
        let area = &scratch.area;
        self.vertex_area.clear();
        self.vertex_area.resize(n, 0.0);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                self.vertex_area[v as usize] += area[t] / 3.0;
            }
        }
        self.mass.clear();
        self.mass
            .extend(self.vertex_area.iter().map(|a| mat.density * a));
        stretch_springs(mesh, mat, area, &mut self.springs);
        membrane_triangles(mesh, mat, area, &mut self.membrane_triangles);
        scratch.shapes.clear();
        let mut kept = 0;
        let mut splits = 0;
        if mat.bending > 0.0 && mat.bending_model == BendingModel::ShapeOperator {
            let (old, previous) = (&self.shape_triangles, &self.previous);
            let reuse = &mut scratch.reuse;
            reuse.match_previous(previous, &self.vertex_triangles, mesh, mat);
            let reuse = &*reuse;
            splits = build_shape_triangles_into(
                mesh,
                area,
                mat.bending,
                clamped,
                &mut scratch.shape,
                |t, stencil, across| {
                    let m = reuse.kept(previous, old, t, stencil, across, clamped);
                    kept += usize::from(m.is_some());
                    m
                },
                &mut scratch.shapes,
            );
        }
        scratch.counts = RebuildCounts {
            kept,
            computed: scratch.shapes.len() - kept,
        };
        std::mem::swap(&mut self.shape_triangles, &mut scratch.shapes);
        self.fold_edges = FoldEdges::build(&self.shape_triangles, n);
        edge_bending(mesh, mat, area, &mut self.springs, &mut self.hinges);
        sewing_springs(mesh, mat, &mut self.springs, &mut self.sewing_caps);
        self.fill_tables(n, mesh);
        self.previous
            .record(mesh, mat, clamped, &self.shape_triangles);
        splits
    }

    /// The fold splits' system of the current shape triangles, whose split
    /// indices run over `0..splits` (reusing what it shares with the present
    /// one: [`FoldSplits::renew`]).
    pub fn renewed_fold_splits(&self, splits: usize) -> FoldSplits {
        self.fold_splits
            .renew(&self.shape_triangles, splits)
            .expect("the plate matrices of a valid mesh are positive definite")
    }

    /// How the last [`Elements::rebuild`] made its shape triangles.
    pub fn last_rebuild(&self) -> RebuildCounts {
        self.scratch.counts
    }

    /// Total mass, kg.
    pub fn total_mass(&self) -> Scalar {
        self.mass.iter().sum()
    }

    /// Refills the per-vertex gather lists of the current elements.
    fn fill_tables(&mut self, n: usize, mesh: &Mesh) {
        let springs = &self.springs;
        let ends = |end: usize| {
            let pairs = springs.iter().enumerate();
            pairs.map(move |(s, sp)| (sp.v[end], s as u32))
        };
        self.spring_first.fill(n, ends(0));
        self.spring_second.fill(n, ends(1));
        self.hinge_slots.fill(
            n,
            self.hinges
                .iter()
                .enumerate()
                .flat_map(|(h, hg)| (0..4).map(move |k| (hg.v[k], (4 * h + k) as u32))),
        );
        self.membrane_slots.fill(
            n,
            self.membrane_triangles
                .iter()
                .enumerate()
                .flat_map(|(t, m)| {
                    (0..MEMBRANE_SLOTS).map(move |k| (m.v[k], (MEMBRANE_SLOTS * t + k) as u32))
                }),
        );
        let pairs = &mut self.scratch.shape_pairs;
        pairs.clear();
        pairs.extend(self.shape_triangles.iter().enumerate().flat_map(|(p, st)| {
            st.slots()
                .map(move |(k, v)| (v, (SHAPE_SLOTS * p + k) as u32))
        }));
        self.shape_slots.fill(n, pairs.iter().copied());
        self.vertex_triangles.fill(
            n,
            mesh.triangles
                .iter()
                .enumerate()
                .flat_map(|(t, tri)| tri.iter().map(move |&v| (v, t as u32))),
        );
    }
}

/// The stiffening of a level-`level` spring under the stiffness rule (paper A:
/// `2^(n/2)`; consistent: none).
fn level_factor(rule: StiffnessRule, level: u8) -> Scalar {
    match rule {
        StiffnessRule::Consistent => 1.0,
        StiffnessRule::PaperA => (2.0 as Scalar).powf(level as Scalar / 2.0),
    }
}

/// One stretch spring per edge (module docs: stiffness derivations) with the
/// springs membrane, none with the triangles; `area` is each triangle's rest area.
fn stretch_springs(mesh: &Mesh, mat: &MaterialParams, area: &[Scalar], springs: &mut Vec<Spring>) {
    springs.clear();
    if mat.membrane != Membrane::Springs {
        return;
    }
    for (e, edge) in mesh.edges.iter().enumerate() {
        let rest = mesh.rest_length(e);
        let tris = edge
            .triangles
            .iter()
            .filter(|&&t| t != crate::mesh::NO_TRIANGLE);
        let level = tris
            .clone()
            .map(|&t| mesh.levels[t as usize])
            .max()
            .unwrap_or(0);
        let k = match mat.stiffness_rule {
            StiffnessRule::Consistent => {
                mat.stretch * tris.map(|&t| area[t as usize]).sum::<Scalar>() / (rest * rest)
            }
            StiffnessRule::PaperA => mat.stretch * level_factor(mat.stiffness_rule, level),
        };
        springs.push(Spring {
            v: edge.vertices,
            rest,
            k,
            c: mat.damping * k,
        });
    }
}

/// One membrane triangle per triangle with the triangles membrane (`membrane.rs`),
/// none with the springs; `area` is each triangle's rest area.
fn membrane_triangles(
    mesh: &Mesh,
    mat: &MaterialParams,
    area: &[Scalar],
    out: &mut Vec<MembraneTriangle>,
) {
    out.clear();
    let Membrane::Triangles(moduli) = &mat.membrane else {
        return;
    };
    out.extend(
        mesh.triangles
            .iter()
            .zip(area)
            .enumerate()
            .map(|(t, (tri, &a))| {
                MembraneTriangle::new(*tri, mesh.corners(t), a, moduli, mat.damping)
            }),
    );
}

/// The bending elements of the edge-based models: dihedral hinges (into
/// `hinges`, cleared first) or hinge springs (appended to `springs`); none for
/// the shape-operator model or zero rigidity.
fn edge_bending(
    mesh: &Mesh,
    mat: &MaterialParams,
    area: &[Scalar],
    springs: &mut Vec<Spring>,
    hinges: &mut Vec<Hinge>,
) {
    hinges.clear();
    if mat.bending <= 0.0 || mat.bending_model == BendingModel::ShapeOperator {
        return;
    }
    for (e, edge) in mesh
        .edges
        .iter()
        .enumerate()
        .filter(|(_, e)| e.is_interior())
    {
        let [t0, t1] = edge.triangles;
        // Orient the edge as it runs in t0 (counter-clockwise) so that the
        // signed angle has a consistent meaning.
        let [a, b] = oriented_in(&mesh.triangles[t0 as usize], edge.vertices);
        let (p, q) = (
            mesh.opposite_vertex(t0, edge),
            mesh.opposite_vertex(t1, edge),
        );
        let level = mesh.levels[t0 as usize].max(mesh.levels[t1 as usize]);
        match mat.bending_model {
            BendingModel::Dihedral => {
                let len = mesh.rest_length(e);
                let k = mat.bending * len * len / (area[t0 as usize] + area[t1 as usize]);
                hinges.push(Hinge { v: [a, b, p, q], k });
            }
            BendingModel::ShapeOperator => unreachable!("returned above"),
            BendingModel::HingeSpring => {
                let rest = tip_distance(mesh, e);
                let k = mat.bending / (rest * rest) * level_factor(mat.stiffness_rule, level);
                springs.push(Spring {
                    v: [p, q],
                    rest,
                    k,
                    c: mat.damping * k,
                });
            }
        }
    }
}

/// The edge `[a, b]` in the order it runs inside triangle `tri`.
fn oriented_in(tri: &[u32; 3], [a, b]: [u32; 2]) -> [u32; 2] {
    for k in 0..3 {
        if tri[k] == a && tri[(k + 1) % 3] == b {
            return [a, b];
        }
    }
    [b, a]
}

fn material_distance(material: &[Vector2], p: u32, q: u32) -> Scalar {
    material[p as usize].distance(material[q as usize])
}

/// The rest distance between the wing tips of interior edge `e`. On a garment the
/// second wing may lie in another panel's pattern: it is unfolded into the first
/// wing's pattern about their shared edge ([`Mesh::unfold`]).
fn tip_distance(mesh: &Mesh, e: usize) -> Scalar {
    let edge = &mesh.edges[e];
    let [t0, t1] = edge.triangles;
    let (p, q) = (
        mesh.opposite_vertex(t0, edge),
        mesh.opposite_vertex(t1, edge),
    );
    if mesh.panels().is_none() {
        return material_distance(&mesh.material, p, q);
    }
    let (t0, t1) = (t0 as usize, t1 as usize);
    let unfolded = mesh.unfold(t0, t1, edge.vertices, q);
    mesh.corner_at(t0, p).distance(unfolded)
}
