//! The continuum membrane (`material.membrane = "triangles"`): the patch test on
//! five kinds of mesh (a homogeneous deformation gives the continuum's energy,
//! zero force on interior vertices and the analytic stress, to rounding), the
//! springs' deviation printed beside it, force against the energy's gradient,
//! and the element Hessian against finite differences of its forces.
//!
//! Run with `--nocapture` to see the springs' deviations.

use drape::adapt::{AdaptConfig, Adapter};
use drape::math::{Matrix3, Scalar, Vector, Vector2, rotation_from_euler_deg};
use drape::mesh::{self, Mesh};
use drape::physics::forces::{ForceScratch, element_pass, energy, gather};
use drape::physics::membrane::{green_strain, positive_part};
use drape::physics::{Elements, ExternalForces, MaterialParams, Membrane, Orthotropic};
use drape::scene::{AdaptMethod, BendingModel, DiagonalPattern, StiffnessRule};
use drape::world::World;

/// Deterministic uniform numbers in [-1, 1) from `seed` (no extra crates).
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> Scalar {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as Scalar / (1u64 << 53) as Scalar) * 2.0 - 1.0
    }
}

/// The vertices on the mesh's boundary (an end of an edge with one triangle).
pub(crate) fn boundary(m: &Mesh) -> Vec<bool> {
    let mut on = vec![false; m.vertex_count()];
    for e in m.edges.iter().filter(|e| !e.is_interior()) {
        for v in e.vertices {
            on[v as usize] = true;
        }
    }
    on
}

/// The 1 m grid at `res` with every interior vertex moved by up to `jitter`
/// of a cell along each axis (a fixed sequence from `seed`), each cell split
/// along its shorter diagonal. Should the moves fold a cell, the next seed is
/// taken, so the result is the same on every run.
pub(crate) fn jittered_grid(res: u32, jitter: Scalar, seed: u64) -> Mesh {
    let n = res as usize;
    let cell = 1.0 / res as Scalar;
    for attempt in seed.. {
        let mut next = uniform(attempt);
        let mut material = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let p = Vector2::new(i as Scalar, j as Scalar) * cell - Vector2::splat(0.5);
                let d = Vector2::new(next(), next()) * (jitter * cell);
                let inside = i > 0 && i < n && j > 0 && j < n;
                material.push(if inside { p + d } else { p });
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let length = |p: u32, q: u32| (material[p as usize] - material[q as usize]).length();
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if length(a, c) <= length(b, d) {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        if let Ok(m) = Mesh::new(material, triangles) {
            return m;
        }
    }
    unreachable!("the seeds run out")
}

/// A Delaunay triangulation (spade) of the 1 m square: `side` points along each
/// edge and `inner` points placed at random inside.
pub(crate) fn delaunay_square(side: u32, inner: usize, seed: u64) -> Mesh {
    use spade::{DelaunayTriangulation, Point2, Triangulation};
    let mut points = Vec::new();
    for k in 0..side {
        let s = -0.5 + k as Scalar / side as Scalar;
        points.extend([[s, -0.5], [0.5, s], [-s, 0.5], [-0.5, -s]]);
    }
    let mut next = uniform(seed);
    let margin = 0.3 / side as Scalar;
    for _ in 0..inner {
        points.push([next(), next()].map(|c| c * (0.5 - margin)));
    }
    let mut t: DelaunayTriangulation<Point2<Scalar>> = DelaunayTriangulation::new();
    for [x, y] in points {
        t.insert(Point2::new(x, y)).expect("a finite point");
    }
    let material = t
        .vertices()
        .map(|v| Vector2::new(v.position().x, v.position().y))
        .collect();
    let triangles = t
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    Mesh::new(material, triangles).expect("the Delaunay mesh is a valid mesh")
}

/// The 1 m alternating grid at `res` with a round patch refined two red-green
/// levels (red triangles inside, green closures around them).
pub(crate) fn red_green_patch(res: u32) -> Mesh {
    let grid = mesh::rectangle(1.0, 1.0, res, DiagonalPattern::Alternating).unwrap();
    let x0 = grid.material.iter().map(|p| p.extend(0.0)).collect();
    let mut world = World::new(grid, x0);
    let config = AdaptConfig {
        max_level: 6,
        ..crate::common::angle_config(AdaptMethod::RedGreen)
    };
    let mut adapter = Adapter::new(&config, &world, 0.15).unwrap();
    let centre = Vector2::new(0.1, -0.05);
    crate::common::refine_around(&mut adapter, &config, &mut world, (centre, 0.25), 2);
    assert!(
        world.mesh.levels.iter().any(|l| l % 2 == 1),
        "green closures"
    );
    world.mesh
}

/// The meshes of the patch tests, all of the 1 m square.
pub(crate) fn patch_meshes() -> Vec<(&'static str, Mesh)> {
    let grid = |d| mesh::rectangle(1.0, 1.0, 12, d).unwrap();
    vec![
        ("regular grid", grid(DiagonalPattern::Regular)),
        ("alternating grid", grid(DiagonalPattern::Alternating)),
        ("flipped grid", grid(DiagonalPattern::AlternatingFlipped)),
        ("jittered 0.4", jittered_grid(12, 0.4, 3)),
        ("Delaunay", delaunay_square(12, 140, 5)),
        ("red-green", red_green_patch(8)),
    ]
}

/// An elastic material (no bending, no damping) with the given membrane.
pub(crate) fn membrane_material(membrane: Membrane) -> MaterialParams {
    MaterialParams {
        density: 0.15,
        stretch: 200.0,
        membrane,
        bending: 0.0,
        damping: 0.0,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
        sewing: Default::default(),
    }
}

/// What a membrane does under one homogeneous deformation of one mesh.
struct Patch {
    /// Elastic energy per rest area, J/m^2.
    density: Scalar,
    /// The virial stress `-(1/A) sum_i f_i X_i^T` (the columns along u and v), N/m.
    stress: [Vector; 2],
    /// Largest force on an interior vertex, N.
    interior: Scalar,
}

/// Deforms `m` homogeneously, `x = R (G X) + t`, and measures `mat`'s response.
fn patch(m: &Mesh, mat: &MaterialParams, g: [[Scalar; 2]; 2], r: Matrix3) -> Patch {
    let el = Elements::build(m, mat);
    let t = Vector::new(0.3, -0.2, 1.0);
    let x: Vec<Vector> = m
        .material
        .iter()
        .map(|p| {
            let q = Vector::new(
                g[0][0] * p.x + g[0][1] * p.y,
                g[1][0] * p.x + g[1][1] * p.y,
                0.0,
            );
            r * q + t
        })
        .collect();
    let v = vec![Vector::ZERO; x.len()];
    let ext = ExternalForces::default();
    let mut scratch = ForceScratch::default();
    element_pass(&el, &ext, &m.triangles, &x, &v, &mut scratch);
    let on = boundary(m);
    let area = m.total_rest_area();
    let (mut stress, mut interior) = ([Vector::ZERO; 2], 0.0 as Scalar);
    for (i, p) in m.material.iter().enumerate() {
        let f = gather(&el, &ext, &scratch, i, v[i]);
        stress[0] -= f * (p.x / area);
        stress[1] -= f * (p.y / area);
        if !on[i] {
            interior = interior.max(f.length());
        }
    }
    Patch {
        density: energy(&el, &ext, &x, &v).elastic / area,
        stress,
        interior,
    }
}

/// The homogeneous deformations `G` of the patch tests.
const DEFORMATIONS: [(&str, [[Scalar; 2]; 2]); 6] = [
    ("stretch along u", [[1.02, 0.0], [0.0, 1.0]]),
    ("stretch along v", [[1.0, 0.0], [0.0, 1.03]]),
    ("biaxial stretch", [[1.02, 0.0], [0.0, 1.02]]),
    ("pure shear", [[1.0, 0.02], [0.02, 1.0]]),
    ("simple shear", [[1.0, 0.03], [0.0, 1.0]]),
    ("large strain", [[1.3, 0.2], [0.1, 0.9]]),
];

/// The patch test: on the regular, alternating and flipped grids, a grid with
/// interior vertices moved by up to 0.4 of a cell, a Delaunay mesh and a
/// red-green mesh with green closures, every homogeneous deformation (in a
/// rotated, shifted frame) gives the triangles the continuum's energy, its
/// stress and no force on interior vertices, to rounding, with orthotropic
/// moduli. The springs' deviations (from the isotropic continuum of the same
/// `stretch`, and from their own regular grid) are printed, not asserted.
#[test]
fn triangle_membrane_passes_the_patch_test_on_every_mesh() {
    let moduli = Orthotropic {
        warp: 300.0,
        weft: 120.0,
        shear: 25.0,
    };
    let iso = Orthotropic::isotropic(200.0);
    let r = rotation_from_euler_deg([20.0, -35.0, 50.0]);
    let meshes = patch_meshes();
    let springs = membrane_material(Membrane::Springs);
    println!(
        "patch test: springs (stretch 200 N/m) against the continuum of the triangles' isotropic shorthand (warp = weft = 200, shear = 100 N/m)"
    );
    println!(
        "{:<18} {:<16} {:>10} {:>11} {:>10} {:>10}",
        "mesh", "deformation", "E/cont", "E/reg grid", "stress err", "interior"
    );
    for (name, g) in DEFORMATIONS {
        let col = |c: usize| r * Vector::new(g[0][c], g[1][c], 0.0);
        let (a, b) = (col(0), col(1));
        let reference = patch(&meshes[0].1, &springs, g, r);
        for (mesh_name, m) in &meshes {
            let h = (m.total_rest_area() / m.triangles.len() as Scalar).sqrt();
            let tri = patch(m, &membrane_material(Membrane::Triangles(moduli)), g, r);
            let (w, p) = (moduli.energy_density(a, b), moduli.first_piola(a, b));
            let scale = p[0].length().max(p[1].length());
            let stress_err = (tri.stress[0] - p[0])
                .length()
                .max((tri.stress[1] - p[1]).length());
            assert!(
                (tri.density / w - 1.0).abs() < 1e-11,
                "{mesh_name}, {name}: energy {} against the continuum's {w}",
                tri.density
            );
            assert!(
                stress_err < 1e-11 * scale,
                "{mesh_name}, {name}: stress off by {stress_err:e}"
            );
            assert!(
                tri.interior < 1e-11 * scale * h,
                "{mesh_name}, {name}: {:e} N on an interior vertex",
                tri.interior
            );
            let sp = patch(m, &springs, g, r);
            let (wi, pi) = (iso.energy_density(a, b), iso.first_piola(a, b));
            let iso_scale = pi[0].length().max(pi[1].length());
            let err = (sp.stress[0] - pi[0])
                .length()
                .max((sp.stress[1] - pi[1]).length());
            println!(
                "{mesh_name:<18} {name:<16} {:>10.4} {:>11.4} {:>10.4} {:>10.2e}",
                sp.density / wi,
                sp.density / reference.density,
                err / iso_scale,
                sp.interior / (iso_scale * h)
            );
        }
    }
}

/// A bent, stretched and slightly rough placement of material point `p`.
fn place(p: Vector2, i: usize) -> Vector {
    let rough = ((i * 7919 % 104729) as Scalar / 104729.0 - 0.5) * 2e-3;
    let (r, s) = (0.4, 1.03);
    let a = s * p.x / r;
    Vector::new(
        r * a.sin(),
        0.98 * p.y + 0.1 * p.x * p.y,
        r * (1.0 - a.cos()) + rough,
    )
}

/// The total force on every vertex (triangle membrane, shape-operator bending
/// and gravity gathered as the integrators see them) is minus the central
/// finite difference of the total energy, on all the patch meshes.
#[test]
fn triangle_membrane_force_is_minus_the_energy_gradient() {
    let moduli = Orthotropic {
        warp: 3.0,
        weft: 1.2,
        shear: 0.4,
    };
    for (name, m) in patch_meshes() {
        let mat = MaterialParams {
            bending: 1e-3,
            ..membrane_material(Membrane::Triangles(moduli))
        };
        let el = Elements::build(&m, &mat);
        let ext = ExternalForces {
            gravity: Some(Vector::new(0.3, 0.0, -9.81)),
            ..Default::default()
        };
        let mut x: Vec<Vector> = m
            .material
            .iter()
            .enumerate()
            .map(|(i, p)| place(*p, i))
            .collect();
        let v = vec![Vector::ZERO; x.len()];
        let mut scratch = ForceScratch::default();
        element_pass(&el, &ext, &m.triangles, &x, &v, &mut scratch);
        let f: Vec<Vector> = (0..x.len())
            .map(|i| gather(&el, &ext, &scratch, i, v[i]))
            .collect();
        let scale = f.iter().map(|f| f.length()).fold(0.0, Scalar::max);
        let total = |x: &[Vector]| {
            let e = energy(&el, &ext, x, &v);
            e.elastic + e.gravitational
        };
        let h = 1e-6;
        let mut worst: Scalar = 0.0;
        for i in 0..x.len() {
            for d in 0..3 {
                let x0 = x[i][d];
                x[i][d] = x0 + h;
                let ep = total(&x);
                x[i][d] = x0 - h;
                let em = total(&x);
                x[i][d] = x0;
                worst = worst.max((-(ep - em) / (2.0 * h) - f[i][d]).abs());
            }
        }
        assert!(worst < 1e-5 * scale, "{name}: {worst} against {scale}");
    }
}

/// Each element's stiffness blocks against central differences of its forces:
/// the Gauss-Newton part plus the geometric part with the full stress `S` is
/// the exact Hessian; the solver's geometric part is the positive part of `S`
/// (equal to `S` in tension); and the blocks the direct solver assembles apply
/// as the product the conjugate gradients use. On the deformed jittered grid,
/// whose triangles are stretched one way and compressed the other.
#[test]
fn membrane_stiffness_blocks_match_finite_differences_of_the_forces() {
    let m = jittered_grid(6, 0.4, 11);
    let moduli = Orthotropic {
        warp: 300.0,
        weft: 120.0,
        shear: 25.0,
    };
    let el = Elements::build(&m, &membrane_material(Membrane::Triangles(moduli)));
    let mut x: Vec<Vector> = m
        .material
        .iter()
        .enumerate()
        .map(|(i, p)| place(*p, i))
        .collect();
    let v = vec![Vector::ZERO; x.len()];
    let (mut tension, mut compression) = (0, 0);
    for t in &el.kinds.membrane.triangles {
        let (gauss_newton, geometric) = t.stiffness(&x);
        let (a, b) = t.columns(&x);
        let [euu, evv, g] = green_strain(a, b);
        let s = [t.k[0] * euu, t.k[2] * g, t.k[1] * evv];
        let clamped = positive_part(s);
        let exact_geometric = drape::physics::membrane::ColumnBlocks {
            aa: Matrix3::from_diagonal(Vector::splat(s[0])),
            ab: Matrix3::from_diagonal(Vector::splat(s[1])),
            bb: Matrix3::from_diagonal(Vector::splat(s[2])),
        };
        if clamped == s {
            tension += 1;
            assert_eq!(geometric, exact_geometric);
        } else {
            compression += 1;
        }
        let exact = gauss_newton.combine(1.0, &exact_geometric, 1.0);
        let scale = t
            .block(&exact, 0, 0)
            .to_cols_array()
            .iter()
            .fold(0.0, |a: Scalar, b| a.max(b.abs()));
        let h = 1e-6;
        for j in 0..3 {
            for d in 0..3 {
                let vj = t.v[j] as usize;
                let x0 = x[vj][d];
                let mut f = [[Vector::ZERO; 3]; 2];
                for (k, sign) in [1.0, -1.0].into_iter().enumerate() {
                    x[vj][d] = x0 + sign * h;
                    t.forces(&x, &v, &mut f[k]);
                }
                x[vj][d] = x0;
                for (i, (plus, minus)) in f[0].iter().zip(&f[1]).enumerate() {
                    let fd = -(*plus - *minus) / (2.0 * h);
                    let column = t.block(&exact, i, j).col(d);
                    let off = (fd - column).length();
                    assert!(
                        off < 1e-6 * scale,
                        "block ({i}, {j}) column {d}: {fd} against {column}"
                    );
                }
            }
        }
        // The solver's blocks: through the product and block by block alike.
        let solver = gauss_newton.combine(1.0, &geometric, 1.0);
        let p: Vec<Vector> = (0..x.len()).map(|i| place(m.material[i], i + 5)).collect();
        let mut product = [Vector::ZERO; 3];
        t.apply(&solver, &p, &mut product);
        for (i, q) in product.iter().enumerate() {
            let by_blocks: Vector = (0..3)
                .map(|j| t.block(&solver, i, j) * p[t.v[j] as usize])
                .sum();
            assert!((*q - by_blocks).length() <= 1e-12 * q.length().max(1.0));
        }
    }
    assert!(
        tension > 0 && compression > 0,
        "{tension} in tension, {compression} not"
    );
}
