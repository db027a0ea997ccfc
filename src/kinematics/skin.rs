//! A body mesh made by code: the surfaces of an articulated body's parts,
//! tessellated in their own frames and put together into one triangle mesh,
//! each vertex skinned rigidly to its part (weight one on one joint).
//!
//! Posed by forward kinematics ([`Skeleton::frame`]): a vertex at `l` in its
//! part's frame is at `x = p + R l` and moves at `v = v_p + w x (x - p)`
//! with its part's frame `(p, R)`, velocity `v_p` and angular velocity `w`,
//! exactly, so the barycentric interpolation of the vertex velocities over a
//! triangle (which lies on one part) is the part's own surface velocity.
//!
//! The parts' surfaces are not fused: where two parts overlap (a shoulder in
//! the chest) the surface of one runs inside the other, as the union of the
//! rigid parts does.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::Arc;

use parry3d_f64::shape::{Ball, Capsule, Cuboid, Shape};

use super::skeleton::Skeleton;
use crate::math::{Scalar, Vector};

/// Subdivisions around a round part (sphere, capsule) and along a quarter
/// circle of its cap: 24 x 6 makes a capsule of 672 triangles.
const AROUND: u32 = 24;
const ALONG: u32 = 6;

/// The vertices of a skinned body: each one's part and its position in that
/// part's frame.
#[derive(Debug, Clone)]
pub struct Skin {
    skeleton: Arc<Skeleton>,
    part: Vec<u32>,
    local: Vec<Vector>,
}

impl Skin {
    /// Tessellates each part `i`'s shape (`shapes[i]`: a ball, capsule or
    /// cuboid, centred at `centres[i]` in the part's frame) and skins it to
    /// the part. Returns the skin and the triangles.
    pub fn new(
        skeleton: Arc<Skeleton>,
        shapes: &[Box<dyn Shape>],
        centres: &[Vector],
    ) -> (Skin, Vec<[u32; 3]>) {
        let mut skin = Skin {
            skeleton,
            part: Vec::new(),
            local: Vec::new(),
        };
        let mut triangles = Vec::new();
        for (i, (shape, &c)) in shapes.iter().zip(centres).enumerate() {
            let (points, tris) = welded(tessellate(shape.as_ref()));
            let base = skin.local.len() as u32;
            skin.local.extend(points.iter().map(|&p| c + p));
            skin.part.extend(points.iter().map(|_| i as u32));
            triangles.extend(tris.iter().map(|t| t.map(|k| base + k)));
        }
        (skin, triangles)
    }

    /// The vertex positions and velocities at time `t` (module docs).
    pub fn sample(&self, t: Scalar, x: &mut Vec<Vector>, v: &mut Vec<Vector>) {
        let frames: Vec<_> = (0..self.skeleton.len())
            .map(|i| self.skeleton.frame(i, t))
            .collect();
        x.clear();
        v.clear();
        for (&part, &l) in self.part.iter().zip(&self.local) {
            let f = &frames[part as usize];
            let p = f.position + f.rotation * l;
            x.push(p);
            v.push(f.velocity + f.omega.cross(p - f.position));
        }
    }

    /// For `drape check`.
    pub fn describe(&self) -> String {
        format!(
            "{} parts of an articulated body, tessellated and skinned rigidly (forward kinematics)",
            self.skeleton.len()
        )
    }
}

/// The mesh with coincident vertices merged (a tessellation repeats the
/// vertices along its seams), so that the surface is closed and its
/// pseudo-normals tell inside from outside everywhere.
fn welded((points, tris): (Vec<Vector>, Vec<[u32; 3]>)) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let mut index = HashMap::new();
    let mut kept = Vec::new();
    let map: Vec<u32> = points
        .iter()
        .map(|p| {
            let key = p.to_array().map(Scalar::to_bits);
            *index.entry(key).or_insert_with(|| {
                kept.push(*p);
                kept.len() as u32 - 1
            })
        })
        .collect();
    let tris = tris
        .iter()
        .map(|t| t.map(|k| map[k as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    (kept, tris)
}

/// A part's surface: a ball or capsule at `AROUND` x `ALONG` subdivisions, a
/// cuboid with its faces cut into 4 x 4 squares (so that its vertices are
/// spread over its surface, as a body mesh's are).
fn tessellate(shape: &dyn Shape) -> (Vec<Vector>, Vec<[u32; 3]>) {
    if let Some(b) = shape.as_shape::<Ball>() {
        return b.to_trimesh(AROUND, 2 * ALONG);
    }
    if let Some(c) = shape.as_shape::<Capsule>() {
        return c.to_trimesh(AROUND, ALONG);
    }
    if let Some(c) = shape.as_shape::<Cuboid>() {
        return subdivided_box(c.half_extents, 4);
    }
    (Vec::new(), Vec::new())
}

/// The surface of the box of `half` extents, each face an `n` x `n` grid of
/// squares (two triangles each, counter-clockwise seen from outside).
fn subdivided_box(half: Vector, n: u32) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let mut points = Vec::new();
    let mut tris = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            // The face's normal `e`, and two in-plane axes with u x w = e.
            let mut e = Vector::ZERO;
            e[axis] = sign;
            let (mut u, mut w) = (Vector::ZERO, Vector::ZERO);
            u[(axis + 1) % 3] = 1.0;
            w[(axis + 2) % 3] = sign;
            let base = points.len() as u32;
            for j in 0..=n {
                for i in 0..=n {
                    let a = 2.0 * i as Scalar / n as Scalar - 1.0;
                    let b = 2.0 * j as Scalar / n as Scalar - 1.0;
                    points.push((e + u * a + w * b) * half);
                }
            }
            let at = |i: u32, j: u32| base + j * (n + 1) + i;
            for j in 0..n {
                for i in 0..n {
                    tris.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                    tris.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
    }
    (points, tris)
}

/// A Wavefront OBJ text of `positions` and `triangles` (1-based `f` lines),
/// numbers in Rust's shortest round-trip form, so the file reads back exactly.
pub fn obj_text(positions: &[Vector], triangles: &[[u32; 3]]) -> String {
    let mut s = String::with_capacity(40 * (positions.len() + triangles.len()));
    for p in positions {
        // Writing to a String cannot fail.
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}
