//! Force elements built from the mesh and the material: springs, bending hinges,
//! lumped masses, and the per-vertex incidence lists used to gather forces.
//!
//! Everything here derives from material coordinates, so it is rebuilt whenever
//! the mesh changes and means the same physical sheet at every resolution.
//!
//! # Stiffness derivations
//! * Stretch, consistent rule (Van Gelder 1998): `k_e = stretch * sum(A_t) / L_e^2`
//!   over the (one or two) rest triangles at edge e. Under a uniform strain the
//!   force per unit cut length is then independent of the edge length, so the
//!   sheet's stretch response does not depend on resolution.
//! * Stretch, `paper_a`: every spring of level n has `k = stretch * 2^(n/2)`
//!   (paper A, eq. 1, with `k_0 = stretch`). Level 0 springs of a uniform mesh
//!   all get the same constant, which in 2D is itself resolution independent; the
//!   inconsistency shows when refinement raises the level.
//! * Damping (paper B, eq. 2) is stiffness proportional: `c_e = damping * k_e`.
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

use super::shape::{SHAPE_SLOTS, ShapeTriangle, build_shape_triangles};
use crate::math::{Scalar, Vector2};
use crate::mesh::Mesh;
use crate::spec::{BendingModel, StiffnessRule};

/// Material parameters the elements are built from (per area, mesh independent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialParams {
    /// Area density, kg/m^2.
    pub density: Scalar,
    /// Stretch stiffness, N/m.
    pub stretch: Scalar,
    /// Bending rigidity, N m.
    pub bending: Scalar,
    /// Stiffness-proportional damping, s.
    pub damping: Scalar,
    /// Bending force model.
    pub bending_model: BendingModel,
    /// How spring constants are derived.
    pub stiffness_rule: StiffnessRule,
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
    /// Builds the lists from `(vertex, entry)` pairs; entries keep their order.
    fn from_pairs(vertices: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Self {
        let mut offsets = vec![0u32; vertices + 1];
        for (v, _) in pairs.clone() {
            offsets[v as usize + 1] += 1;
        }
        for i in 0..vertices {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut entries = vec![0u32; offsets[vertices] as usize];
        for (v, e) in pairs {
            entries[fill[v as usize] as usize] = e;
            fill[v as usize] += 1;
        }
        Incidence { offsets, entries }
    }

    /// The entries of vertex `i`.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.entries[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}

/// All force elements of one mesh, with their per-vertex gather lists.
#[derive(Debug, Clone, PartialEq)]
pub struct Elements {
    /// Lumped vertex masses `rho * sum(A_t) / 3`, kg.
    pub mass: Vec<Scalar>,
    /// Rest area attributed to each vertex (a third of each adjacent triangle), m^2.
    pub vertex_area: Vec<Scalar>,
    /// Stretch springs (one per edge) followed by hinge springs when that model is on.
    pub springs: Vec<Spring>,
    /// Dihedral hinges (only with the dihedral model and non-zero rigidity).
    pub hinges: Vec<Hinge>,
    /// Shape-operator bending elements, one per triangle (only with that model and
    /// non-zero rigidity).
    pub shape_triangles: Vec<ShapeTriangle>,
    /// Springs where the vertex is the first end (`v[0]`).
    pub spring_first: Incidence,
    /// Springs where the vertex is the second end (`v[1]`).
    pub spring_second: Incidence,
    /// Hinge slots `4 * hinge + k` where the vertex is `v[k]`.
    pub hinge_slots: Incidence,
    /// Shape-triangle slots `SHAPE_SLOTS * element + k` where the vertex is `v[k]`
    /// (used slots only).
    pub shape_slots: Incidence,
    /// Triangles at each vertex (for per-triangle forces such as wind).
    pub vertex_triangles: Incidence,
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
        let n = mesh.vertex_count();
        let area: Vec<Scalar> = (0..mesh.triangles.len())
            .map(|t| mesh.rest_area(t))
            .collect();
        let mut vertex_area = vec![0.0; n];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                vertex_area[v as usize] += area[t] / 3.0;
            }
        }
        let mass = vertex_area.iter().map(|a| mat.density * a).collect();
        let mut springs = stretch_springs(mesh, mat, &area);
        let shape_triangles =
            if mat.bending > 0.0 && mat.bending_model == BendingModel::ShapeOperator {
                build_shape_triangles(mesh, &area, mat.bending, clamped)
            } else {
                Vec::new()
            };
        let hinges = edge_bending(mesh, mat, &area, &mut springs);
        let tables = GatherTables::build(n, mesh, &springs, &hinges, &shape_triangles);
        Elements {
            mass,
            vertex_area,
            springs,
            hinges,
            shape_triangles,
            spring_first: tables.spring_first,
            spring_second: tables.spring_second,
            hinge_slots: tables.hinge_slots,
            shape_slots: tables.shape_slots,
            vertex_triangles: tables.vertex_triangles,
        }
    }

    /// Total mass, kg.
    pub fn total_mass(&self) -> Scalar {
        self.mass.iter().sum()
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

/// One stretch spring per edge (module docs: stiffness derivations); `area` is
/// each triangle's rest area.
fn stretch_springs(mesh: &Mesh, mat: &MaterialParams, area: &[Scalar]) -> Vec<Spring> {
    let mut springs = Vec::with_capacity(mesh.edges.len() * 2);
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
    springs
}

/// The bending elements of the edge-based models: dihedral hinges (returned) or
/// hinge springs (appended to `springs`); none for the shape-operator model or
/// zero rigidity.
fn edge_bending(
    mesh: &Mesh,
    mat: &MaterialParams,
    area: &[Scalar],
    springs: &mut Vec<Spring>,
) -> Vec<Hinge> {
    let mut hinges = Vec::new();
    if mat.bending <= 0.0 || mat.bending_model == BendingModel::ShapeOperator {
        return hinges;
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
                let rest = material_distance(&mesh.material, p, q);
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
    hinges
}

/// The per-vertex gather lists of a set of elements.
struct GatherTables {
    spring_first: Incidence,
    spring_second: Incidence,
    hinge_slots: Incidence,
    shape_slots: Incidence,
    vertex_triangles: Incidence,
}

impl GatherTables {
    fn build(
        n: usize,
        mesh: &Mesh,
        springs: &[Spring],
        hinges: &[Hinge],
        shape_triangles: &[ShapeTriangle],
    ) -> GatherTables {
        let ends = |end: usize| {
            let pairs = springs.iter().enumerate();
            Incidence::from_pairs(n, pairs.map(move |(s, sp)| (sp.v[end], s as u32)))
        };
        let hinge_slots = Incidence::from_pairs(
            n,
            hinges
                .iter()
                .enumerate()
                .flat_map(|(h, hg)| (0..4).map(move |k| (hg.v[k], (4 * h + k) as u32))),
        );
        let shape_pairs: Vec<(u32, u32)> = shape_triangles
            .iter()
            .enumerate()
            .flat_map(|(p, st)| {
                st.slots()
                    .map(move |(k, v)| (v, (SHAPE_SLOTS * p + k) as u32))
            })
            .collect();
        let vertex_triangles = Incidence::from_pairs(
            n,
            mesh.triangles
                .iter()
                .enumerate()
                .flat_map(|(t, tri)| tri.iter().map(move |&v| (v, t as u32))),
        );
        GatherTables {
            spring_first: ends(0),
            spring_second: ends(1),
            hinge_slots,
            shape_slots: Incidence::from_pairs(n, shape_pairs.iter().copied()),
            vertex_triangles,
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
