//! One rigid obstacle: a parry3d shape in its local frame, a pose that may move with time,
//! friction and the cloth thickness kept against it.

use std::path::Path;
use std::sync::Arc;

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::Pose;
use parry3d_f64::query::Ray;
use parry3d_f64::shape::{Ball, Capsule, Cuboid, Cylinder, HalfSpace, Shape, TriMesh};

use super::CollideError;
use super::ObstaclePlane;
use super::deform::{Animation, At, Deforming};
use super::sequence::{Sequence, load_frames};
use super::shapes::{load_mesh, primitive};
use crate::kinematics::motion::{Motion, obstacle_motion};
use crate::kinematics::skeleton::Skeleton;
use crate::kinematics::skin::Skin;
use crate::math::{Scalar, Vector, rotation_from_euler_deg};
use crate::spec::{BodySurface, Geometry, ObstacleShape, ObstacleSpec, PartSpec, SequenceFiles};

/// A rigid obstacle the cloth collides with.
pub struct Body {
    /// Name for messages and the recording: `obstacle N (shape)`.
    pub name: String,
    /// The scene's shape keyword.
    pub kind: ObstacleShape,
    shape: Box<dyn Shape>,
    /// Pose of the shape's local frame at t = 0 (includes the z-up fix of parry's y-axis cylinder).
    pose0: Pose,
    /// World position of the obstacle's origin at rest (the rotation centre).
    origin: Vector,
    /// How it moves from its placement at rest.
    motion: Motion,
    /// Static friction coefficient.
    pub mu_static: Scalar,
    /// Kinetic friction coefficient.
    pub mu_kinetic: Scalar,
    /// Cloth thickness kept against this obstacle, m.
    pub thickness: Scalar,
    /// Local bounding box inflated by the thickness (quick rejection).
    local_box: Aabb,
    /// A deforming mesh's triangles and animation (`shape` is then its mesh
    /// at rest, the pose the identity and `motion` fixed).
    deform: Option<Deforming>,
}

impl std::fmt::Debug for Body {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Body").field("name", &self.name).finish()
    }
}

/// Where a point lies relative to an obstacle's surface (local frame).
#[derive(Debug, Clone, Copy)]
pub struct Probe {
    /// Signed distance to the surface, m (negative inside the solid).
    pub signed: Scalar,
    /// Outward unit normal at the nearest surface point.
    pub normal: Vector,
}

impl Body {
    /// Builds obstacle `index` of a scene (OBJ paths are already resolved by
    /// the loader): one body, or one per part of an articulated obstacle.
    pub fn from_spec(index: usize, o: &ObstacleSpec) -> Result<Vec<Body>, CollideError> {
        // parry's cylinder is along local y; ours stand along local z.
        let y_to_z = glam::DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let mut fix = glam::DQuat::IDENTITY;
        let shape: Box<dyn Shape> = match &o.geometry {
            Geometry::Articulated { parts, surface } => {
                let skeleton = Arc::new(Skeleton::new(index, o, obstacle_motion(&o.motion))?);
                if *surface == BodySurface::SkinnedMesh {
                    return Ok(vec![Body::skinned(index, o, parts, skeleton)]);
                }
                return Ok(parts
                    .iter()
                    .enumerate()
                    .map(|(i, p)| Body::part(index, o, &skeleton, i, p))
                    .collect());
            }
            Geometry::MeshSequence {
                files,
                frame_rate,
                scale,
                after_last,
            } => {
                let rot = rotation_from_euler_deg(o.rotation);
                let origin = Vector::from_array(o.position);
                let SequenceFiles::List(files) = files else {
                    return Err(CollideError::Unexpanded { index });
                };
                let (triangles, frames) = load_frames(index, files, *scale, &|p| origin + rot * p)?;
                let animation =
                    Animation::Sequence(Sequence::new(frames, *frame_rate, *after_last));
                let name = format!("obstacle {index} (mesh sequence)");
                let deform = Deforming::new(triangles, animation);
                return Ok(vec![Body::with_deform(name, o, deform)]);
            }
            Geometry::Plane { normal } => Box::new(HalfSpace::new(
                Vector::from_array(*normal).normalize_or(Vector::Z),
            )),
            Geometry::Cylinder {
                radius,
                half_height,
            } => {
                fix = y_to_z;
                Box::new(Cylinder::new(*half_height, *radius))
            }
            Geometry::Mesh { path, scale } => Box::new(load_mesh(index, Path::new(path), *scale)?),
            Geometry::Primitive(p) => primitive(p),
        };
        let rot = glam::DQuat::from_mat3(&rotation_from_euler_deg(o.rotation));
        let origin = Vector::from_array(o.position);
        let pose0 = Pose::from_parts(origin, rot * fix);
        let kind = o.geometry.kind();
        let name = format!("obstacle {index} ({})", kind.name());
        Ok(vec![Body::rigid(
            name,
            kind,
            o,
            shape,
            pose0,
            obstacle_motion(&o.motion),
        )])
    }

    /// Part `i` (`p`) of articulated obstacle `index` (`o`), moved by `skeleton`.
    fn part(
        index: usize,
        o: &ObstacleSpec,
        skeleton: &Arc<Skeleton>,
        i: usize,
        p: &PartSpec,
    ) -> Body {
        let shape = primitive(&p.primitive);
        let rest = skeleton.rest(i);
        let centre = rest.position + rest.rotation * Vector::from_array(p.center);
        let pose0 = Pose::from_parts(centre, rest.rotation);
        let motion = Motion::Articulated {
            skeleton: Arc::clone(skeleton),
            part: i,
        };
        let name = format!("obstacle {index} part {}", p.name);
        let kind = ObstacleShape::Articulated;
        let mut body = Body::rigid(name, kind, o, shape, pose0, motion);
        body.origin = rest.position;
        body
    }

    /// Articulated obstacle `index` (`o`, with `parts`) as one mesh skinned to its parts.
    fn skinned(
        index: usize,
        o: &ObstacleSpec,
        parts: &[PartSpec],
        skeleton: Arc<Skeleton>,
    ) -> Body {
        let shapes: Vec<Box<dyn Shape>> = parts.iter().map(|p| primitive(&p.primitive)).collect();
        let centres: Vec<Vector> = parts.iter().map(|p| Vector::from_array(p.center)).collect();
        let (skin, triangles) = Skin::new(skeleton, &shapes, &centres);
        let name = format!("obstacle {index} (skinned mesh)");
        Body::with_deform(name, o, Deforming::new(triangles, Animation::Skinned(skin)))
    }

    /// A deforming mesh body with `o`'s friction and thickness.
    fn with_deform(name: String, o: &ObstacleSpec, deform: Deforming) -> Body {
        let rest = deform.at(0.0);
        let shape = Box::new(rest.mesh().clone());
        let kind = o.geometry.kind();
        let mut body = Body::rigid(name, kind, o, shape, Pose::IDENTITY, Motion::Fixed);
        body.origin = Vector::ZERO;
        body.deform = Some(deform);
        body
    }

    /// A body of `shape` placed at rest by `pose0` (rotating about its
    /// translation), with `o`'s friction and thickness.
    fn rigid(
        name: String,
        kind: ObstacleShape,
        o: &ObstacleSpec,
        shape: Box<dyn Shape>,
        pose0: Pose,
        motion: Motion,
    ) -> Body {
        let t = o.thickness;
        let local = shape.compute_local_aabb();
        let local_box = Aabb::new(local.mins - Vector::splat(t), local.maxs + Vector::splat(t));
        Body {
            name,
            kind,
            shape,
            origin: pose0.translation,
            pose0,
            motion,
            mu_static: o.friction_static,
            mu_kinetic: o.friction_kinetic,
            thickness: t,
            local_box,
            deform: None,
        }
    }

    /// True when the obstacle moves.
    pub fn is_moving(&self) -> bool {
        self.deform.is_some() || self.motion.is_moving()
    }

    /// The deforming mesh, when the obstacle is one.
    pub fn deforming(&self) -> Option<&Deforming> {
        self.deform.as_ref()
    }

    /// The obstacle at time `t`: its pose and, for a deforming mesh, its
    /// surface then.
    pub fn at(&self, t: Scalar) -> At {
        At {
            pose: self.pose(t),
            surface: self.deform.as_ref().map(|d| d.at(t)),
        }
    }

    /// The shape the queries at `at` use: the deforming mesh's surface then,
    /// else the rigid shape.
    fn shape_at<'a>(&'a self, at: &'a At) -> &'a dyn Shape {
        match &at.surface {
            Some(s) => s.mesh(),
            None => self.shape.as_ref(),
        }
    }

    /// How the obstacle moves.
    pub fn motion(&self) -> &Motion {
        &self.motion
    }

    /// Pose of the local frame at time `t`: the placement at rest turned about
    /// the origin and the origin moved, as the motion says at `t`.
    pub fn pose(&self, t: Scalar) -> Pose {
        if !self.is_moving() {
            return self.pose0;
        }
        let state = self.motion.state(t);
        let centre = self.origin + state.shift;
        let offset = state.rotation * (self.pose0.translation - self.origin);
        Pose::from_parts(centre + offset, state.rotation * self.pose0.rotation)
    }

    /// Velocity at time `t` of the obstacle's material point at world position `x`
    /// (of a deforming mesh: of its surface point nearest to `x`).
    pub fn point_velocity(&self, t: Scalar, x: Vector) -> Vector {
        self.velocity_at(t, &self.at(t), x)
    }

    /// As [`Body::point_velocity`], with the obstacle at `t` given as `at`.
    pub fn velocity_at(&self, t: Scalar, at: &At, x: Vector) -> Vector {
        if let Some(s) = &at.surface {
            return s.velocity_at(x);
        }
        self.motion.state(t).point_velocity(self.origin, x)
    }

    /// True when the shape is a plane (a half-space).
    pub fn is_plane(&self) -> bool {
        self.shape.as_shape::<HalfSpace>().is_some()
    }

    /// True when the local segment `a`-`b` may come within the thickness of
    /// the shape at `at`.
    pub fn may_touch(&self, at: &At, a: Vector, b: Vector) -> bool {
        let seg = Aabb::new(a.min(b), a.max(b));
        match &at.surface {
            Some(s) => s.bounds().loosened(self.thickness).intersects(&seg),
            None => self.local_box.intersects(&seg),
        }
    }

    /// Signed distance and outward normal of local point `q`, the shape at `at`.
    pub fn probe(&self, at: &At, q: Vector) -> Probe {
        let shape = self.shape_at(at);
        let proj = shape.project_local_point(q, false);
        let d = q - proj.point;
        let dist = d.length();
        let normal = if dist > 1e-12 {
            if proj.is_inside { -d / dist } else { d / dist }
        } else {
            // On the surface: ask parry for the normal of the feature there.
            let (p, feature) = shape.project_local_point_and_get_feature(q);
            shape
                .feature_normal_at_point(p.subshape, feature, q)
                .unwrap_or(Vector::Z)
        };
        Probe {
            signed: if proj.is_inside { -dist } else { dist },
            normal,
        }
    }

    /// The obstacle surface point nearest to world point `x` at time `t`: its
    /// distance from `x` (m, unsigned) and the tangent plane there, in world
    /// coordinates (for the sizing criterion's obstacle term,
    /// `crate::adapt::proximity`).
    pub fn nearest_plane(&self, at: &At, x: Vector) -> (Scalar, ObstaclePlane) {
        let pose = at.pose;
        let q = pose.inverse_transform_point(x);
        let probe = self.probe(at, q);
        let local_point = q - probe.normal * probe.signed;
        (
            probe.signed.abs(),
            ObstaclePlane {
                point: pose.transform_point(local_point),
                normal: pose.rotation * probe.normal,
                thickness: self.thickness,
            },
        )
    }

    /// Where the local segment `a` -> `b` first enters the solid from outside:
    /// `(fraction of the segment, outward normal)`, the shape at `at`.
    pub fn first_entry(&self, at: &At, a: Vector, b: Vector) -> Option<(Scalar, Vector)> {
        let dir = b - a;
        if dir.length_squared() == 0.0 {
            return None;
        }
        let hit = self
            .shape_at(at)
            .cast_local_ray_and_get_normal(&Ray::new(a, dir), 1.0, false)?;
        (hit.normal.dot(dir) < 0.0).then_some((hit.time_of_impact, hit.normal))
    }

    /// A triangulation of the obstacle in its local frame, for display (a plane
    /// has none: [`Body::world_triangles`] draws it around the cloth).
    pub fn local_triangles(&self) -> (Vec<Vector>, Vec<[u32; 3]>) {
        if let Some(b) = self.shape.as_shape::<Ball>() {
            return b.to_trimesh(32, 16);
        }
        if let Some(c) = self.shape.as_shape::<Cuboid>() {
            return c.to_trimesh();
        }
        if let Some(c) = self.shape.as_shape::<Capsule>() {
            return c.to_trimesh(32, 8);
        }
        if let Some(c) = self.shape.as_shape::<Cylinder>() {
            return c.to_trimesh(48);
        }
        if let Some(m) = self.shape.as_shape::<TriMesh>() {
            return (m.vertices().to_vec(), m.indices().to_vec());
        }
        (Vec::new(), Vec::new())
    }

    /// The display triangulation in world coordinates at time `t`. A plane,
    /// which has no extent, is drawn as a square of half side `plane.1`
    /// centred below (or above) `plane.0`: the cloth's place, so that the
    /// viewer frames the cloth rather than a floor many times its size.
    pub fn world_triangles(
        &self,
        t: Scalar,
        plane: (Vector, Scalar),
    ) -> (Vec<Vector>, Vec<[u32; 3]>) {
        if let Some(d) = &self.deform {
            let s = d.at(t);
            return (s.mesh().vertices().to_vec(), d.triangles().to_vec());
        }
        let pose = self.pose(t);
        if let Some(h) = self.shape.as_shape::<HalfSpace>() {
            let n = pose.rotation * h.normal;
            let (focus, half) = plane;
            let centre = focus - n * n.dot(focus - pose.translation);
            let u = n.any_orthonormal_vector() * half;
            let v = n.cross(u);
            let corners = [-u - v, u - v, u + v, -u + v].map(|c| centre + c);
            return (corners.to_vec(), vec![[0, 1, 2], [0, 2, 3]]);
        }
        let (mut v, i) = self.local_triangles();
        for p in &mut v {
            *p = pose.transform_point(*p);
        }
        (v, i)
    }

    /// The shape as a cylinder with a vertical axis: `(centre of the top face, radius)`.
    pub fn vertical_cylinder_top(&self) -> Option<(Vector, Scalar)> {
        let c = self.shape.as_shape::<Cylinder>()?;
        let pose = self.pose(0.0);
        let axis = pose.rotation * Vector::Y;
        (axis.z.abs() > 1.0 - 1e-9)
            .then(|| (pose.translation + Vector::Z * c.half_height, c.radius))
    }
}
