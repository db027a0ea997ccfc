//! The pattern's derived tables against the searches they replace (mirrors by
//! per-row cursors, the shape triangles' dropped blocks from one lookup per pair
//! of slots, the bands' triangles), and the assembly against references: each block summed term by
//! term in element order (to the last bit), a dense sum of every element's
//! full formula (to 1e-12), and the same matrix at one and two threads.

use super::{BlockPattern, ElementBlocks, outer};
use crate::adapt::{AdaptConfig, Adapter};
use crate::math::{Matrix3, Scalar, Vector};
use crate::mesh::{Mesh, rectangle};
use crate::physics::elements::{Elements, MaterialParams};
use crate::physics::kinds::{KindLinear, ShapeOp, frobenius, moved_angles};
use crate::physics::membrane::{ColumnBlocks, Membrane, Orthotropic};
use crate::physics::shape::ShapeJacobian;
use crate::physics::{Model, forces::PAR_MIN};
use crate::scene::{BendingModel, DiagonalPattern, default_scene};
use crate::world::World;

mod lumped;
mod projection;

/// The default scene's sheet at 12 x 12 and its fabric, and the same grid
/// refined by red-green (the papers' angle criterion) along a crease, so that
/// the pattern has transitions, green triangles and shape tips.
fn meshes() -> (Vec<Mesh>, MaterialParams) {
    let overrides = [
        "cloth.resolution=12",
        "adapt.method=red_green",
        "adapt.criterion=angle",
        "adapt.refine_strain=0",
    ];
    let scene = default_scene(&overrides.map(String::from)).expect("the default scene");
    let grid = World::from_scene(&scene).expect("its sheet").mesh;
    let mut world = World::new(grid.clone(), bent(&grid));
    let config = AdaptConfig::from_scene(scene.adapt.as_ref()).expect("it adapts");
    let mut adapter = Adapter::new(&config, &world, scene.material.density).unwrap();
    adapter
        .remesh(&config, &mut world, 0)
        .expect("the crease refines");
    assert!(world.mesh.triangles.len() > grid.triangles.len());
    (vec![grid, world.mesh], Model::from_scene(&scene).material)
}

/// `mesh` bent 45 degrees along `x = 0.1`, and rippled so that no two folds match.
fn bent(mesh: &Mesh) -> Vec<Vector> {
    mesh.material
        .iter()
        .map(|p| p.extend((p.x - 0.1).max(0.0) + 0.01 * (9.0 * p.y).sin() * (7.0 * p.x).cos()))
        .collect()
}

/// The shape operator with springs (the scenes' default), and dihedral hinges
/// with the membrane triangles: between them every kind of element.
fn materials(fabric: MaterialParams) -> [MaterialParams; 2] {
    [
        MaterialParams {
            bending_model: BendingModel::ShapeOperator,
            membrane: Membrane::Springs,
            ..fabric
        },
        MaterialParams {
            bending_model: BendingModel::Dihedral,
            membrane: Membrane::Triangles(Orthotropic::isotropic(200.0)),
            ..fabric
        },
    ]
}

/// A fixed pseudo-random number in [-1, 1) for `(i, salt)`.
fn noise(i: usize, salt: u64) -> Scalar {
    let mut z =
        (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ salt.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 31;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 29;
    (z >> 11) as Scalar / (1u64 << 52) as Scalar - 1.0
}

fn noise_vector(i: usize, salt: u64) -> Vector {
    Vector::new(
        noise(3 * i, salt),
        noise(3 * i + 1, salt),
        noise(3 * i + 2, salt),
    )
}

/// A pseudo-random symmetric matrix (springs' and membrane blocks are symmetric,
/// so that an upper block is its mirror's transpose).
fn noise_symmetric(i: usize, salt: u64) -> Matrix3 {
    let m = Matrix3::from_cols(
        noise_vector(3 * i, salt),
        noise_vector(3 * i + 1, salt),
        noise_vector(3 * i + 2, salt),
    );
    m + m.transpose()
}

/// Terms of one step: pseudo-random blocks, gradients and masses, and the
/// shape triangles' true folds at `x` (their Jacobians' zeros are structural),
/// with the kinds' block values written.
struct Terms {
    kinds: KindLinear,
    diagonal_mass: Vec<Scalar>,
}

impl Terms {
    fn new(elements: &Elements, x: &[Vector]) -> Terms {
        let mut kinds = KindLinear::default();
        kinds.springs.block = (0..elements.kinds.springs.springs.len())
            .map(|e| noise_symmetric(e, 1))
            .collect();
        kinds.hinges.grad = (0..4 * elements.kinds.hinges.hinges.len())
            .map(|k| noise_vector(k, 2))
            .collect();
        kinds.hinges.coef = (0..elements.kinds.hinges.hinges.len())
            .map(|h| 1.5 + noise(h, 3))
            .collect();
        elements
            .kinds
            .shapes
            .fold_edges
            .compute(x, &mut kinds.shapes.edge_folds);
        kinds.membrane.block = (0..elements.kinds.membrane.triangles.len())
            .map(|t| ColumnBlocks {
                aa: noise_symmetric(t, 5),
                ab: Matrix3::from_cols(
                    noise_vector(3 * t, 6),
                    noise_vector(3 * t + 1, 6),
                    noise_vector(3 * t + 2, 6),
                ),
                bb: noise_symmetric(t, 9),
            })
            .collect();
        kinds.write_blocks(elements);
        Terms {
            kinds,
            diagonal_mass: (0..x.len()).map(|i| 2.0 + noise(i, 4)).collect(),
        }
    }

    fn view<'a>(&'a self, elements: &'a Elements) -> ElementBlocks<'a> {
        ElementBlocks {
            elements,
            kinds: &self.kinds,
            h2: 0.7e-4,
            diagonal_mass: &self.diagonal_mass,
        }
    }
}

/// Shape triangle `t`'s angle gradients by slot, read from its edges' folds.
fn shape_jacobian(terms: &ElementBlocks<'_>, t: usize) -> ShapeJacobian {
    let edges = &terms.kinds.shapes.edge_folds;
    terms.elements.kinds.shapes.fold_edges.angles(t, edges).1
}

/// Block `(k, l)` of shape triangle `tri` computed alone, from the Jacobians:
/// `h^2 sum_ab M_ab J_ak J_bl^T`, summed as the per-triangle pass does (the
/// tests' reference).
fn shape_block(terms: &ElementBlocks<'_>, tri: usize, k: usize, l: usize) -> Matrix3 {
    let m = &terms.elements.kinds.shapes.triangles[tri].m;
    let jac = &shape_jacobian(terms, tri);
    let mut out = Matrix3::ZERO;
    for a in moved_angles(k) {
        let row = &m[a];
        let right = match l {
            0..3 => jac[0][l] * row[0] + jac[1][l] * row[1] + jac[2][l] * row[2],
            _ => jac[l - 3][l] * row[l - 3],
        };
        out += outer(jac[a][k], right);
    }
    out * terms.h2
}

/// The assembly's outputs: lower blocks, compensation, projected system.
fn assemble(p: &BlockPattern, terms: &ElementBlocks<'_>) -> [Vec<Matrix3>; 3] {
    let n = p.vertices();
    let mut lumps = Vec::new();
    let (mut lower, mut extra, mut system) = (Vec::new(), Vec::new(), Vec::new());
    p.gather(terms, &mut lumps, &mut lower);
    let projection: Vec<Option<Vector>> = (0..n)
        .map(|i| match i % 7 {
            0 => Some(Vector::ZERO),
            3 => Some(noise_vector(i, 10).normalize()),
            _ => None,
        })
        .collect();
    p.compensation(terms, &lumps, &projection, &mut extra);
    let scale: Vec<Scalar> = (0..n).map(|i| 1.0 + noise(i, 11)).collect();
    let mut touched = Vec::new();
    p.touched_rows(&projection, &mut touched);
    p.project(&lower, &projection, &touched, &scale, &mut system);
    [lower, extra, system]
}

#[test]
fn mirrors_and_dropped_blocks_match_the_searches() {
    let (meshes, material) = meshes();
    for m in meshes {
        let elements = Elements::build(&m, &material);
        let n = m.vertex_count();
        for factor_tips in [false, true] {
            let p = BlockPattern::build(n, &elements, factor_tips);
            for b in 0..p.blocks() {
                assert_eq!(p.mirror[b], p.slot(p.columns[b], p.rows[b]), "block {b}");
            }
            let mut bands = vec![Vec::new(); p.bands()];
            for (ti, t) in elements.kinds.shapes.triangles.iter().enumerate() {
                let mut ops = Vec::new();
                for (k, i) in t.slots() {
                    for (l, j) in t.slots() {
                        let dropped = i != j && !p.factored[p.slot(i, j) as usize];
                        let slot = p.slot(i, j);
                        if j <= i {
                            let (k, l) = (k as u8, l as u8);
                            ops.push(ShapeOp {
                                slot,
                                k,
                                l,
                                dropped,
                            });
                        }
                    }
                }
                let shapes = &p.in_place.shapes;
                let range = shapes.op_start[ti] as usize..shapes.op_start[ti + 1] as usize;
                assert_eq!(&shapes.ops[range], &ops[..], "triangle {ti}");
                for b in 0..p.bands() {
                    if t.slots()
                        .any(|(_, i)| p.band_rows(b).contains(&(i as usize)))
                    {
                        bands[b].push(ti as u32);
                    }
                }
            }
            for (b, expected) in bands.iter().enumerate() {
                let shapes = &p.in_place.shapes;
                let range = shapes.band_start[b] as usize..shapes.band_start[b + 1] as usize;
                assert_eq!(&shapes.band_shapes[range], &expected[..], "band {b}");
            }
            assert_eq!(
                p.in_place.shapes.ops.iter().all(|op| !op.dropped),
                factor_tips,
                "the reduced pattern drops tip blocks, the full one none"
            );
        }
    }
}

/// Each lower block summed term by term, every term computed alone, in element
/// order (springs, hinges, membrane triangles, shape triangles), then the mass:
/// what the flat array and its index lists must reproduce to the last bit.
fn per_term_sum(p: &BlockPattern, el: &Elements, t: &ElementBlocks<'_>) -> Vec<Matrix3> {
    let mut acc = vec![Matrix3::ZERO; p.blocks()];
    for (e, sp) in el.kinds.springs.springs.iter().enumerate() {
        let [a, b] = sp.v;
        acc[p.diagonal[a as usize] as usize] += t.kinds.springs.block[e];
        acc[p.diagonal[b as usize] as usize] += t.kinds.springs.block[e];
        acc[p.lower_slot(a, b) as usize] += -t.kinds.springs.block[e];
    }
    for (h, hg) in el.kinds.hinges.hinges.iter().enumerate() {
        let g = &t.kinds.hinges.grad[4 * h..4 * h + 4];
        for k in 0..4 {
            for l in 0..4 {
                if hg.v[l] <= hg.v[k] {
                    let slot = p.slot(hg.v[k], hg.v[l]) as usize;
                    acc[slot] += outer(g[k], g[l]) * t.kinds.hinges.coef[h];
                }
            }
        }
    }
    for (ti, tri) in el.kinds.membrane.triangles.iter().enumerate() {
        for k in 0..3 {
            for l in 0..3 {
                if tri.v[l] <= tri.v[k] {
                    let slot = p.slot(tri.v[k], tri.v[l]) as usize;
                    acc[slot] += tri.block(&t.kinds.membrane.block[ti], k, l);
                }
            }
        }
    }
    for (ti, tri) in el.kinds.shapes.triangles.iter().enumerate() {
        for (k, i) in tri.slots() {
            for (l, j) in tri.slots() {
                if j <= i {
                    acc[p.slot(i, j) as usize] += shape_block(t, ti, k, l);
                }
            }
        }
    }
    for i in 0..p.vertices() {
        acc[p.diagonal[i] as usize] += Matrix3::from_diagonal(Vector::splat(t.diagonal_mass[i]));
    }
    acc
}

/// Every block of `A` (both triangles) from each element's full formula, and
/// per block the sum of the norms of the products it adds (the scale of its
/// rounding).
fn dense(p: &BlockPattern, el: &Elements, t: &ElementBlocks<'_>) -> (Vec<Matrix3>, Vec<Scalar>) {
    let mut a = vec![Matrix3::ZERO; p.blocks()];
    let mut scale = vec![0.0; p.blocks()];
    let norm = frobenius;
    let mut add = |i: u32, j: u32, m: Matrix3, size: Scalar| {
        let s = p.slot(i, j) as usize;
        a[s] += m;
        scale[s] += size;
    };
    for (e, sp) in el.kinds.springs.springs.iter().enumerate() {
        let [x, y] = sp.v;
        let k = t.kinds.springs.block[e];
        for (i, j, m) in [(x, x, k), (y, y, k), (x, y, -k), (y, x, -k)] {
            add(i, j, m, norm(&m));
        }
    }
    for (h, hg) in el.kinds.hinges.hinges.iter().enumerate() {
        let g = &t.kinds.hinges.grad[4 * h..4 * h + 4];
        for k in 0..4 {
            for l in 0..4 {
                let m = outer(g[k], g[l]) * t.kinds.hinges.coef[h];
                add(hg.v[k], hg.v[l], m, norm(&m));
            }
        }
    }
    for (ti, tri) in el.kinds.membrane.triangles.iter().enumerate() {
        let (c, uv) = (&t.kinds.membrane.block[ti], [tri.du, tri.dv]);
        for k in 0..3 {
            for l in 0..3 {
                let size = [(c.aa, 0, 0), (c.ab, 0, 1), (c.ab, 1, 0), (c.bb, 1, 1)]
                    .map(|(m, x, y)| norm(&m) * (uv[x][k] * uv[y][l]).abs())
                    .iter()
                    .sum();
                add(tri.v[k], tri.v[l], tri.block(c, k, l), size);
            }
        }
    }
    for (ti, tri) in el.kinds.shapes.triangles.iter().enumerate() {
        let jac = &shape_jacobian(t, ti);
        for (k, i) in tri.slots() {
            for (l, j) in tri.slots() {
                let (mut m, mut size) = (Matrix3::ZERO, 0.0);
                for (x, row) in tri.m.iter().enumerate() {
                    for (y, &mxy) in row.iter().enumerate() {
                        let term = outer(jac[x][k], jac[y][l]) * (t.h2 * mxy);
                        m += term;
                        size += norm(&term);
                    }
                }
                add(i, j, m, size);
            }
        }
    }
    for i in 0..p.vertices() as u32 {
        let m = Matrix3::from_diagonal(Vector::splat(t.diagonal_mass[i as usize]));
        add(i, i, m, norm(&m));
    }
    (a, scale)
}

#[test]
fn gather_matches_the_per_term_sum_and_a_dense_assembly() {
    let (mut meshes, fabric) = meshes();
    // Several bands, with triangles straddling their boundaries.
    meshes.push(rectangle(1.0, 1.0, 48, DiagonalPattern::Alternating).expect("a grid"));
    for m in &meshes {
        let x = bent(m);
        for material in materials(fabric) {
            let el = Elements::build(m, &material);
            let terms = Terms::new(&el, &x);
            let t = terms.view(&el);
            let p = BlockPattern::build(m.vertex_count(), &el, false);
            let [lower, extra, _] = assemble(&p, &t);
            let reference = per_term_sum(&p, &el, &t);
            let (a, scale) = dense(&p, &el, &t);
            for s in 0..p.blocks() {
                let got = p.full_block(&lower, s);
                if p.columns[s] <= p.rows[s] {
                    let bits = |m: Matrix3| m.to_cols_array().map(Scalar::to_bits);
                    assert_eq!(
                        bits(got),
                        bits(reference[s]),
                        "block {s}: not the per-term sum"
                    );
                }
                let error = frobenius(&(got - a[s]));
                assert!(
                    error <= 1e-12 * scale[s],
                    "block {s}: {error:e} of {:e}",
                    scale[s]
                );
            }
            // The compensation of a free vertex: its dropped hinge tips' c g g^T
            // and its dropped shape blocks' rank-one lumps, `B B^T / |B|` for
            // the block `B = x y^T` of a pair from its row vertex (one vertex
            // in 7 is free of both projections in `assemble`).
            let mut lumps = vec![Matrix3::ZERO; p.vertices()];
            for (ti, tri) in el.kinds.shapes.triangles.iter().enumerate() {
                for (k, i) in tri.slots() {
                    for (l, j) in tri.slots() {
                        if i != j && !p.factored[p.lower_slot(i, j) as usize] {
                            let b = shape_block(&t, ti, k, l);
                            if frobenius(&b) > 0.0 {
                                lumps[i as usize] += b * b.transpose() * (1.0 / frobenius(&b));
                            }
                        }
                    }
                }
            }
            let mut tips = vec![Matrix3::ZERO; p.vertices()];
            for (h, hg) in el.kinds.hinges.hinges.iter().enumerate() {
                if !p.factored[p.slot(hg.v[2], hg.v[3]) as usize] {
                    for k in [2, 3] {
                        let g = t.kinds.hinges.grad[4 * h + k];
                        tips[hg.v[k] as usize] += outer(g, g) * t.kinds.hinges.coef[h];
                    }
                }
            }
            for i in (0..p.vertices()).filter(|i| ![0, 3].contains(&(i % 7))) {
                let expected = lumps[i] + tips[i];
                let error = frobenius(&(extra[i] - expected));
                assert!(error <= 1e-12 * frobenius(&expected), "vertex {i}");
            }
        }
    }
}

#[test]
fn assembly_is_identical_at_one_and_two_threads() {
    // 49 x 49 vertices: every pass splits (PAR_MIN blocks, PAR_MIN / 6 triangles).
    let m = rectangle(1.0, 1.0, 48, DiagonalPattern::Alternating).expect("a grid");
    let x = bent(&m);
    let (_, fabric) = meshes();
    for material in materials(fabric) {
        let el = Elements::build(&m, &material);
        let terms = Terms::new(&el, &x);
        let t = terms.view(&el);
        let p = BlockPattern::build(m.vertex_count(), &el, false);
        assert!(p.blocks() > 8 * PAR_MIN && m.triangles.len() > 2 * PAR_MIN);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            pool.install(|| assemble(&p, &t))
        };
        let bits = |m: &[Vec<Matrix3>; 3]| -> Vec<u64> {
            m.iter()
                .flatten()
                .flat_map(|b| b.to_cols_array().map(Scalar::to_bits))
                .collect()
        };
        assert_eq!(bits(&run(1)), bits(&run(2)));
    }
}
