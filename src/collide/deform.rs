//! Deforming mesh obstacles: one triangle mesh of fixed topology whose
//! vertices move, each with its own velocity.
//!
//! A deforming body gives, at any time `t`, every vertex's world position and
//! velocity: an OBJ sequence interpolated between frames
//! ([`super::sequence`]), or the parts of an articulated body tessellated
//! and skinned to them ([`crate::kinematics::skin`]). The collision passes query its
//! surface at the two ends of each step, a parry [`TriMesh`] built from the
//! positions at that time (its bounding volume hierarchy and pseudo-normals
//! rebuilt, not refitted), kept in a small cache so that each time is built
//! once: the end of one step is the start of the next.
//!
//! - The velocity of the surface at a point is the barycentric interpolation
//!   of the vertex velocities of the triangle under it, so friction acts on
//!   the velocity relative to the deforming surface and cloth resting on it
//!   moves with it.
//! - Continuous detection carries a vertex's start position with the surface
//!   point nearest to it (the same triangle and barycentric coordinates on
//!   the end-of-step surface) and casts the path from there to the vertex's
//!   end position against the end-of-step surface: the vertex's path
//!   relative to the surface under it, which is exact where the surface
//!   near the vertex translates and first order where it turns or stretches.

use std::sync::{Arc, Mutex};

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Pose;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

use super::sequence::Sequence;
use crate::kinematics::skin::Skin;
use crate::math::{Scalar, Vector};

/// Where a deforming mesh's vertex positions and velocities come from.
#[derive(Debug)]
pub enum Animation {
    /// OBJ frames interpolated linearly.
    Sequence(Sequence),
    /// Vertices fixed to the parts of an articulated body.
    Skinned(Skin),
}

impl Animation {
    /// The world positions and velocities of the vertices at time `t`.
    fn sample(&self, t: Scalar, x: &mut Vec<Vector>, v: &mut Vec<Vector>) {
        match self {
            Animation::Sequence(s) => s.sample(t, x, v),
            Animation::Skinned(s) => s.sample(t, x, v),
        }
    }

    /// For `drape check`.
    fn describe(&self) -> String {
        match self {
            Animation::Sequence(s) => s.describe(),
            Animation::Skinned(s) => s.describe(),
        }
    }
}

/// A deforming mesh at one time: the parry mesh of the vertex positions and
/// the vertex velocities.
#[derive(Debug)]
pub struct Surface {
    time: Scalar,
    mesh: TriMesh,
    velocity: Vec<Vector>,
}

impl Surface {
    /// The mesh (world coordinates).
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The vertex velocities, m/s.
    pub fn velocities(&self) -> &[Vector] {
        &self.velocity
    }

    /// The triangle of the surface point nearest to `x` and that point's
    /// barycentric coordinates in it.
    pub fn locate(&self, x: Vector) -> (u32, [Scalar; 3]) {
        let (_, (tri, loc)) = self.mesh.project_local_point_and_get_location(x, false);
        let bary = loc.barycentric_coordinates().unwrap_or([1.0, 0.0, 0.0]);
        (tri, bary)
    }

    /// The point of triangle `tri` at barycentric coordinates `b`.
    pub fn point(&self, tri: u32, b: [Scalar; 3]) -> Vector {
        let idx = self.mesh.indices()[tri as usize];
        let p = self.mesh.vertices();
        idx.iter().zip(b).map(|(&i, w)| p[i as usize] * w).sum()
    }

    /// The velocity of the surface point nearest to `x`: its triangle's vertex
    /// velocities interpolated barycentrically.
    pub fn velocity_at(&self, x: Vector) -> Vector {
        let (tri, b) = self.locate(x);
        let idx = self.mesh.indices()[tri as usize];
        idx.iter()
            .zip(b)
            .map(|(&i, w)| self.velocity[i as usize] * w)
            .sum()
    }

    /// The bounding box of the surface.
    pub fn bounds(&self) -> Aabb {
        self.mesh.local_aabb()
    }
}

/// A deforming mesh: fixed triangles, vertices moved by an [`Animation`],
/// and the surfaces already built (see the module docs).
#[derive(Debug)]
pub struct Deforming {
    triangles: Vec<[u32; 3]>,
    animation: Animation,
    cache: Mutex<Vec<Arc<Surface>>>,
}

/// How many surfaces the cache keeps (the two ends of a step, and those of a
/// retried step).
const CACHED: usize = 4;

impl Deforming {
    /// The mesh of `triangles` (not empty, every index below the animation's
    /// vertex count: the loaders check both) moved by `animation`.
    pub fn new(triangles: Vec<[u32; 3]>, animation: Animation) -> Deforming {
        Deforming {
            triangles,
            animation,
            cache: Mutex::new(Vec::new()),
        }
    }

    /// The triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// For `drape check`.
    pub fn describe(&self) -> String {
        format!(
            ", a deforming mesh of {} triangles: {}",
            self.triangles.len(),
            self.animation.describe()
        )
    }

    /// The surface at time `t`, built once per time (module docs).
    pub fn at(&self, t: Scalar) -> Arc<Surface> {
        let lock = || self.cache.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(s) = lock().iter().find(|s| s.time.to_bits() == t.to_bits()) {
            return Arc::clone(s);
        }
        let surface = Arc::new(self.build(t));
        let mut cache = lock();
        if cache.len() >= CACHED {
            cache.remove(0);
        }
        cache.push(Arc::clone(&surface));
        surface
    }

    fn build(&self, t: Scalar) -> Surface {
        let (mut x, mut velocity) = (Vec::new(), Vec::new());
        self.animation.sample(t, &mut x, &mut velocity);
        // Not empty: the loaders refuse a mesh without triangles, the only
        // case `with_flags` fails on.
        let mesh = TriMesh::with_flags(x, self.triangles.clone(), TriMeshFlags::ORIENTED)
            .expect("a deforming mesh has triangles");
        Surface {
            time: t,
            mesh,
            velocity,
        }
    }
}

/// An obstacle at one time, as the collision passes query it: the pose of its
/// local frame and, for a deforming mesh, its surface then (in world
/// coordinates; the pose is then the identity).
#[derive(Debug, Clone)]
pub struct At {
    /// The local frame in the world.
    pub pose: Pose,
    /// The deforming mesh's surface; `None` for a rigid shape.
    pub surface: Option<Arc<Surface>>,
}

impl At {
    /// A vertex's start-of-step position `p0` in the end-of-step frame
    /// `end`, carried along with the obstacle over the step: for a rigid
    /// shape its position in the local frame at the start (`self`); for a
    /// deforming mesh, moved by the displacement of its nearest surface point
    /// (module docs).
    pub fn carried(&self, end: &At, p0: Vector) -> Vector {
        match (&self.surface, &end.surface) {
            (Some(a), Some(b)) => {
                let (tri, w) = a.locate(p0);
                p0 + b.point(tri, w) - a.point(tri, w)
            }
            _ => self.pose.inverse_transform_point(p0),
        }
    }
}
