//! Force elements built from the mesh and the material: lumped masses, the
//! triangles at each vertex, and every force element kind's elements with
//! their per-vertex incidence lists ([`KindSets`], each kind's
//! [`super::kinds::ForceKind::Set`] built by the kind from a [`BuildContext`]).
//!
//! Everything here derives from material coordinates, so it is rebuilt whenever
//! the mesh changes and means the same physical sheet at every resolution. The
//! rebuild after a remesh is incremental ([`Elements::rebuild`]): the buffers
//! are reused and shape triangles whose stencil did not change keep their
//! matrix (`kinds/shapes/reuse.rs`). It gains little: `cargo bench --bench implicit --
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
//! * Attachments ([`super::kinds::Attachments`]): a one-sided spring per held
//!   vertex, `k = stiffness * s` with `s` the vertex's share of the held sides'
//!   length, as for sewing.
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

use super::kinds::{KindDeferred, KindSets};
use super::membrane::Membrane;
use crate::math::Scalar;
use crate::mesh::Mesh;
use crate::spec::{Attachment, BendingModel, Sewing, StiffnessRule};

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
    pub(crate) fn fill(
        &mut self,
        vertices: usize,
        pairs: impl Iterator<Item = (u32, u32)> + Clone,
    ) {
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

/// What a kind builds its elements from ([`super::kinds::ForceKind::build`]).
#[derive(Debug, Clone, Copy)]
pub struct BuildContext<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// The material.
    pub mat: &'a MaterialParams,
    /// Each triangle's rest area, m^2.
    pub area: &'a [Scalar],
    /// Per vertex the pin that holds it for good, or `u32::MAX` (empty: no
    /// clamp).
    pub clamped: &'a [u32],
    /// The triangles at each vertex of the mesh the elements were built for
    /// before (empty before the first build), for a kind that keeps what it
    /// can of its previous elements.
    pub previous_vertex_triangles: &'a Incidence,
    /// The garment's attachments and the time they are built for.
    pub holding: Holding<'a>,
}

/// The attachments that pull on the mesh's holds ([`Mesh::holds`], in the
/// same order) and the time the elements are built for: an attachment whose
/// release time has come builds no elements.
#[derive(Debug, Clone, Copy)]
pub struct Holding<'a> {
    /// The attachments.
    pub attachments: &'a [Attachment],
    /// The time, s.
    pub time: Scalar,
}

impl Holding<'_> {
    /// No attachment.
    pub const NONE: Holding<'static> = Holding {
        attachments: &[],
        time: 0.0,
    };
}

/// All force elements of one mesh, with their per-vertex gather lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Elements {
    /// Lumped vertex masses `rho * sum(A_t) / 3`, kg.
    pub mass: Vec<Scalar>,
    /// Rest area attributed to each vertex (a third of each adjacent triangle), m^2.
    pub vertex_area: Vec<Scalar>,
    /// Triangles at each vertex (for per-triangle forces such as wind).
    pub vertex_triangles: Incidence,
    /// Every force element kind's elements and incidence lists.
    pub kinds: KindSets,
    /// Scratch memory of [`Elements::rebuild`] (never part of a comparison).
    scratch: Scratch,
}

/// Scratch memory of a rebuild, kept between rebuilds.
#[derive(Debug, Clone, Default)]
struct Scratch {
    area: Vec<Scalar>,
    previous_vertex_triangles: Incidence,
}

/// Scratch memory holds nothing the elements mean: two element sets are equal
/// whatever their scratch holds.
impl PartialEq for Scratch {
    fn eq(&self, _: &Scratch) -> bool {
        true
    }
}

impl Elements {
    /// Builds masses and every kind's elements for `mesh` from the material,
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
    /// reused, and a kind may keep what it can of its previous elements (each
    /// shape triangle whose whole stencil was already in the mesh these
    /// elements were built for keeps its matrix instead of computing it again;
    /// `kinds/shapes/reuse.rs`).
    pub fn rebuild(&mut self, mesh: &Mesh, mat: &MaterialParams, clamped: &[u32]) {
        self.rebuild_but_deferred(mesh, mat, clamped, Holding::NONE);
        let deferred = self.kinds.deferred();
        self.kinds.install(deferred);
    }

    /// [`Elements::rebuild`] but for what the kinds defer (the shape
    /// triangles' fold splits' system, left that of the mesh before):
    /// [`Elements::deferred`] makes it and may run beside other work that
    /// reads the rebuilt elements; [`Elements::install`] puts it in place.
    pub fn rebuild_but_deferred(
        &mut self,
        mesh: &Mesh,
        mat: &MaterialParams,
        clamped: &[u32],
        holding: Holding<'_>,
    ) {
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
        std::mem::swap(
            &mut scratch.previous_vertex_triangles,
            &mut self.vertex_triangles,
        );
        self.vertex_triangles.fill(
            n,
            mesh.triangles
                .iter()
                .enumerate()
                .flat_map(|(t, tri)| tri.iter().map(move |&v| (v, t as u32))),
        );
        let cx = BuildContext {
            mesh,
            mat,
            area,
            clamped,
            previous_vertex_triangles: &scratch.previous_vertex_triangles,
            holding,
        };
        self.kinds.build(&cx);
    }

    /// What the kinds defer of the last [`Elements::rebuild_but_deferred`],
    /// made from the rebuilt elements.
    pub fn deferred(&self) -> KindDeferred {
        self.kinds.deferred()
    }

    /// Puts what [`Elements::deferred`] made in place.
    pub fn install(&mut self, deferred: KindDeferred) {
        self.kinds.install(deferred);
    }

    /// Total mass, kg.
    pub fn total_mass(&self) -> Scalar {
        self.mass.iter().sum()
    }
}

/// The stiffening of a level-`level` element under the stiffness rule (paper
/// A: `2^(n/2)`; consistent: none).
pub(crate) fn level_factor(rule: StiffnessRule, level: u8) -> Scalar {
    match rule {
        StiffnessRule::Consistent => 1.0,
        StiffnessRule::PaperA => (2.0 as Scalar).powf(level as Scalar / 2.0),
    }
}
