//! A garment's rest space: where parts are close in the rest state, and a
//! flat rest shape for each element's stencil. A garment has no one flat rest
//! shape (a skirt closes into a tube), and its panels' patterns may overlap, so
//! both are made panel by panel.

use super::Mesh;
use crate::math::{Scalar, Vector, Vector2};

impl Mesh {
    /// A point per vertex in rest space, for telling apart parts that are close in
    /// the rest state (self-collision leaves those alone): the home material
    /// coordinate, with each panel lifted to its own plane far from the others'
    /// (panels' patterns may overlap), and the second vertex of every open seam
    /// pair at its partner's point, so the two sides of a seam being sewn are
    /// close in rest and free to meet.
    pub fn rest_points(&self, out: &mut Vec<Vector>) {
        out.clear();
        let Some(panels) = self.panels() else {
            out.extend(self.material.iter().map(|m| m.extend(0.0)));
            return;
        };
        out.extend(
            self.material
                .iter()
                .zip(&panels.of_vertex)
                .map(|(m, &p)| m.extend(p as Scalar * PANEL_PLANE_SPACING)),
        );
        for seam in panels.seams.iter().filter(|s| s.is_open()) {
            for &[a, b] in &seam.pairs {
                out[b as usize] = out[a as usize];
            }
        }
    }

    /// Writes a flat rest embedding of a stencil into `flat` (z = 0): `ids[..3]` is
    /// a triangle (in any order), placed at its corners; every further id is a
    /// wing tip across one of that triangle's edges, unfolded into its pattern
    /// about the shared edge. A garment has no one flat rest shape (a skirt
    /// closes into a tube), but every stencil has.
    pub fn lay_flat(&self, ids: &[u32], flat: &mut [Vector]) {
        let base = self
            .triangle_with(ids[0], ids[1], ids[2])
            .expect("a stencil starts with a triangle of the mesh");
        let tri = self.triangles[base];
        for &v in &ids[..3] {
            flat[v as usize] = self.corner_at(base, v).extend(0.0);
        }
        for &tip in &ids[3..] {
            let (other, a, b) = (0..3)
                .map(|k| (tri[k], tri[(k + 1) % 3]))
                .find_map(|(a, b)| self.triangle_with(a, b, tip).map(|t| (t, a, b)))
                .expect("a stencil's tip lies across one of its triangle's edges");
            flat[tip as usize] = self.unfold(base, other, [a, b], tip).extend(0.0);
        }
    }

    /// Vertex `tip` of triangle `other`, unfolded into triangle `base`'s pattern
    /// about their shared edge `edge`: the same distances from the edge's ends,
    /// on the other side of it. Both wind counter-clockwise in their own
    /// patterns, so a rotation does it.
    pub fn unfold(&self, base: usize, other: usize, edge: [u32; 2], tip: u32) -> Vector2 {
        let [a, b] = edge;
        let frame = |t: usize| {
            let (pa, pb) = (self.corner_at(t, a), self.corner_at(t, b));
            (pa, (pb - pa).normalize())
        };
        let ((a0, u0), (a1, u1)) = (frame(base), frame(other));
        let d = self.corner_at(other, tip) - a1;
        a0 + u0 * d.dot(u1) + u0.perp() * u1.perp_dot(d)
    }

    /// The triangle with corners `a`, `b` and `c`, if any.
    fn triangle_with(&self, a: u32, b: u32, c: u32) -> Option<usize> {
        let key = [a.min(b), a.max(b)];
        let e = self.edges.binary_search_by_key(&key, |e| e.vertices).ok()?;
        self.edges[e]
            .triangles
            .into_iter()
            .filter(|&t| t != super::NO_TRIANGLE)
            .map(|t| t as usize)
            .find(|&t| self.triangles[t].contains(&c))
    }
}

/// How far apart [`Mesh::rest_points`] puts the panels' planes, m: far beyond any
/// garment, so no two panels are ever close in rest space.
const PANEL_PLANE_SPACING: Scalar = 1.0e3;
