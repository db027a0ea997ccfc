//! Each interior edge's fold computed once per step: two shape triangles
//! share an edge, and its dihedral angle and gradient are the same for both
//! (up to the order of the hinge's vertices), so the folds are computed per
//! edge ([`FoldEdges`]) and each triangle reads its three from there.
//!
//! Seen from the triangle on the other side, the hinge `[a, b, p, q]` of
//! [`super::dihedral_angle_and_gradient`] reads `[b, a, q, p]` (both triangles
//! counter-clockwise in material space): the same angle, to the last bit,
//! and the same gradient by vertex (the tips' to the last bit, the edge
//! ends' up to rounding).

use rayon::prelude::*;

use super::{HINGE_SLOTS, SHAPE_SLOTS, ShapeJacobian, ShapeTriangle};
use crate::math::{Scalar, Vector};
use crate::physics::bending::dihedral_angle_and_gradient;
use crate::physics::forces::PAR_MIN;

/// One edge's fold at the current positions: its dihedral angle and the
/// angle's gradient with respect to its hinge's four vertices.
pub type EdgeFold = (Scalar, [Vector; 4]);

/// The interior edges of the shape triangles, each once, and where each
/// triangle's edges are among them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FoldEdges {
    /// Per edge, its hinge `[a, b, p, q]` as the triangle that owns it sees
    /// it (the edge counter-clockwise in that triangle, its opposite vertex,
    /// the tip across).
    hinges: Vec<[u32; 4]>,
    /// Per shape triangle and edge: `2 e + 1` when the triangle sees edge
    /// `e` reversed (its hinge is `[b, a, q, p]`), `2 e` when it owns it,
    /// [`FoldEdges::NONE`] for a boundary edge.
    refs: Vec<[u32; 3]>,
}

impl FoldEdges {
    /// A triangle edge without a fold.
    const NONE: u32 = u32::MAX;

    /// The interior edges of `shapes`. An edge belongs to the triangle that
    /// runs it from its lower vertex to its higher one; the triangle across
    /// (if it is a shape triangle) reads it reversed. An edge whose owner has
    /// no shape triangle (next to a clamp) belongs to the other side.
    pub fn build(shapes: &[ShapeTriangle], vertices: usize) -> FoldEdges {
        let hinge = |t: &ShapeTriangle, a: usize| HINGE_SLOTS[a].map(|k| t.v[k]);
        let mut hinges: Vec<[u32; 4]> = Vec::new();
        let mut refs = vec![[Self::NONE; 3]; shapes.len()];
        // Owned edges by their first vertex, to find them from the other side.
        let mut owned: Vec<(u32, u32)> = Vec::new();
        for (t, shape) in shapes.iter().enumerate() {
            for a in (0..3).filter(|&a| shape.interior[a]) {
                let h = hinge(shape, a);
                if h[0] < h[1] {
                    refs[t][a] = 2 * hinges.len() as u32;
                    owned.push((h[0], hinges.len() as u32));
                    hinges.push(h);
                }
            }
        }
        let (start, edges) = crate::physics::block::group_by_key(vertices, &owned);
        for (t, shape) in shapes.iter().enumerate() {
            for a in (0..3).filter(|&a| shape.interior[a]) {
                let h = hinge(shape, a);
                if h[0] < h[1] {
                    continue;
                }
                let from = start[h[1] as usize] as usize..start[h[1] as usize + 1] as usize;
                let across = edges[from]
                    .iter()
                    .find(|&&e| hinges[e as usize] == [h[1], h[0], h[3], h[2]]);
                refs[t][a] = match across {
                    Some(&e) => 2 * e + 1,
                    None => {
                        hinges.push(h);
                        2 * (hinges.len() as u32 - 1)
                    }
                };
            }
        }
        FoldEdges { hinges, refs }
    }

    /// Into `edges`: every edge's fold at `x`.
    pub fn compute(&self, x: &[Vector], edges: &mut Vec<EdgeFold>) {
        edges.resize(self.hinges.len(), (0.0, [Vector::ZERO; 4]));
        edges
            .par_iter_mut()
            .zip(self.hinges.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|(out, h)| *out = dihedral_angle_and_gradient(h.map(|i| x[i as usize])));
    }

    /// Shape triangle `t`'s three folds and their gradients by slot, from the
    /// edges' folds `edges` ([`FoldEdges::compute`]): what
    /// [`ShapeTriangle::angles`] computes.
    #[inline(always)]
    pub fn angles(&self, t: usize, edges: &[EdgeFold]) -> ([Scalar; 3], ShapeJacobian) {
        let mut theta = [0.0; 3];
        let mut jac = [[Vector::ZERO; SHAPE_SLOTS]; 3];
        for (a, &r) in self.refs[t].iter().enumerate() {
            if r == Self::NONE {
                continue;
            }
            let (angle, g) = &edges[r as usize / 2];
            // Reversed, the hinge's vertices pair off: 0 <-> 1, 2 <-> 3.
            let flip = r as usize & 1;
            theta[a] = *angle;
            for (j, &k) in HINGE_SLOTS[a].iter().enumerate() {
                jac[a][k] = g[j ^ flip];
            }
        }
        (theta, jac)
    }

    /// Shape triangle `t`'s three folds alone, from the edges' folds `edges`:
    /// the angles of [`FoldEdges::angles`].
    #[inline(always)]
    pub fn folds(&self, t: usize, edges: &[EdgeFold]) -> [Scalar; 3] {
        self.refs[t].map(|r| {
            if r == Self::NONE {
                0.0
            } else {
                edges[r as usize / 2].0
            }
        })
    }

    /// Number of edges.
    pub fn len(&self) -> usize {
        self.hinges.len()
    }

    /// Whether there are no edges.
    pub fn is_empty(&self) -> bool {
        self.hinges.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::physics::Model;
    use crate::physics::elements::Elements;
    use crate::scene::default_scene;
    use crate::world::World;

    /// The default scene's sheet at 12 x 12 and its fabric, bent 45 degrees
    /// along `x = 0.1` and rippled so that no two folds match.
    fn bent_sheet() -> (Mesh, Vec<Vector>, Model) {
        let scene = default_scene(&["cloth.resolution=12".to_string()]).expect("the default scene");
        let mesh = World::from_scene(&scene).expect("its sheet").mesh;
        let x = mesh
            .material
            .iter()
            .map(|p| p.extend((p.x - 0.1).max(0.0) + 0.01 * (9.0 * p.y).sin() * (7.0 * p.x).cos()))
            .collect();
        (mesh, x, Model::from_scene(&scene))
    }

    /// Every triangle's folds read from the shared edges equal its own
    /// [`ShapeTriangle::angles`]: the angles to the last bit, the gradients
    /// to rounding; every interior edge is computed once, and next to a
    /// clamp (no shape triangle on one side) the free side's edges too.
    #[test]
    fn folds_read_from_shared_edges_match_each_triangles_own() {
        let (mesh, x, model) = bent_sheet();
        let lowest = mesh
            .material
            .iter()
            .map(|p| p.y)
            .fold(Scalar::INFINITY, Scalar::min);
        // The bottom row of cells held by one pin: their triangles have no element.
        let clamped: Vec<u32> = mesh
            .material
            .iter()
            .map(|p| if p.y < lowest + 0.1 { 0 } else { u32::MAX })
            .collect();
        for clamp in [&[][..], &clamped[..]] {
            let el = Elements::build_clamped(&mesh, &model.material, clamp);
            let folds = FoldEdges::build(&el.kinds.shapes.triangles, mesh.vertex_count());
            let sides: usize = el
                .kinds
                .shapes
                .triangles
                .iter()
                .map(|t| t.interior.iter().filter(|&&i| i).count())
                .sum();
            let shared = sides - folds.len();
            println!(
                "{} shape triangles, {sides} interior sides, {} edges, {shared} shared",
                el.kinds.shapes.triangles.len(),
                folds.len()
            );
            let interior = mesh.edges.iter().filter(|e| e.is_interior()).count();
            if clamp.is_empty() {
                assert_eq!(folds.len(), interior);
                assert_eq!(shared, interior);
            } else {
                assert!(el.kinds.shapes.triangles.len() < mesh.triangles.len());
                assert!(folds.len() < interior && shared < folds.len());
            }
            let mut edges = Vec::new();
            folds.compute(&x, &mut edges);
            let mut worst: Scalar = 0.0;
            for (t, shape) in el.kinds.shapes.triangles.iter().enumerate() {
                let (theta, jac) = shape.angles(&x);
                let (read, read_jac) = folds.angles(t, &edges);
                assert_eq!(theta, read, "triangle {t}");
                for a in 0..3 {
                    for k in 0..SHAPE_SLOTS {
                        let scale = jac[a][k].length().max(1.0);
                        worst = worst.max((jac[a][k] - read_jac[a][k]).length() / scale);
                    }
                }
            }
            println!("largest gradient difference, relative: {worst:.3e}");
            assert!(worst < 1e-12, "gradients differ by {worst:e}");
        }
    }
}
