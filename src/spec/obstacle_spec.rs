//! An `[[obstacle]]` table resolved for the engine ([`ObstacleSpec`]): its shape as an
//! enum whose variants hold exactly the keys that shape uses, and its motion as an enum,
//! so that the collision and kinematics code never checks an `Option` the scene's
//! validation has already checked.

use super::{
    BodySurface, Keyframe, KeyframeAfter, KeyframeEasing, Obstacle, ObstacleShape, Part,
    SequenceFiles,
};

/// A rigid, moving or deforming obstacle, resolved from its table ([`Obstacle::resolve`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleSpec {
    /// The name pins attach to (`[[pin]] attach`); absent: no pin can attach to it.
    pub name: Option<String>,
    /// The shape and the keys it needs.
    pub geometry: Geometry,
    /// World position of the local origin (a point on a plane), m.
    pub position: [f64; 3],
    /// Euler angles in degrees (about x, then y, then z), as for the cloth.
    pub rotation: [f64; 3],
    /// Static friction coefficient (Coulomb), >= 0.
    pub friction_static: f64,
    /// Kinetic friction coefficient, 0 <= kinetic <= static (the static one when the
    /// table leaves it out).
    pub friction_kinetic: f64,
    /// Cloth thickness against this obstacle, m.
    pub thickness: f64,
    /// How the obstacle's frame moves from its placement at rest.
    pub motion: ObstacleMotion,
}

/// The shape of an obstacle with its sizes.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// A rigid primitive: a sphere, box or capsule.
    Primitive(Primitive),
    /// A half-space below the plane through the position, with this outward normal
    /// (local frame; not normalised).
    Plane {
        /// The outward normal.
        normal: [f64; 3],
    },
    /// A cylinder along local z (a disk on a stand).
    Cylinder {
        /// Radius, m.
        radius: f64,
        /// Half its length, m.
        half_height: f64,
    },
    /// A triangle mesh from an OBJ file (the path resolved by the scene loader).
    Mesh {
        /// The OBJ file.
        path: String,
        /// Scale applied to its coordinates.
        scale: f64,
    },
    /// Primitives in a joint hierarchy, moved by forward kinematics.
    Articulated {
        /// The parts, in the table's order.
        parts: Vec<PartSpec>,
        /// Rigid parts, or one mesh skinned to them.
        surface: BodySurface,
    },
    /// A triangle mesh deformed by a sequence of OBJ files of one topology.
    MeshSequence {
        /// The frames' files: the scene loader expands a pattern into the list of
        /// files, in order, before the engine builds the obstacle.
        files: SequenceFiles,
        /// Frames per second.
        frame_rate: f64,
        /// Scale applied to the coordinates.
        scale: f64,
        /// What the sequence does after its last frame.
        after_last: KeyframeAfter,
    },
}

/// A primitive shape: an obstacle's own or an articulated body's part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// A ball.
    Sphere {
        /// Radius, m.
        radius: f64,
    },
    /// A cuboid.
    Box {
        /// Half the size along local x, y, z, m.
        half_extents: [f64; 3],
    },
    /// A capsule along local z.
    Capsule {
        /// Radius, m.
        radius: f64,
        /// Half the length of the segment between the caps, m.
        half_height: f64,
    },
}

/// One part of an articulated obstacle, resolved (see [`Part`] for the frames).
#[derive(Debug, Clone, PartialEq)]
pub struct PartSpec {
    /// The part's name, unique within its obstacle.
    pub name: String,
    /// The name of the part it hangs from; absent: the obstacle's own frame.
    pub parent: Option<String>,
    /// Its shape.
    pub primitive: Primitive,
    /// Position of the joint in the parent's frame, m.
    pub joint: [f64; 3],
    /// Rotation of the part's frame at rest relative to the parent's (Euler degrees).
    pub rotation: [f64; 3],
    /// Position of the shape's centre in the part's frame, m.
    pub center: [f64; 3],
    /// Joint rotations at increasing times (none: the joint stays at rest).
    pub keyframes: Vec<Keyframe>,
    /// How joint rotations between keys are interpolated.
    pub easing: KeyframeEasing,
    /// What the joint does after its last key.
    pub after_last: KeyframeAfter,
}

/// How an obstacle's frame moves.
#[derive(Debug, Clone, PartialEq)]
pub enum ObstacleMotion {
    /// It stays at its placement.
    Still,
    /// At a constant velocity, spinning about an axis through its (moving) position.
    Constant {
        /// Linear velocity, m/s.
        velocity: [f64; 3],
        /// Angular velocity about `axis`, rad/s.
        angular_velocity: f64,
        /// The rotation axis, world frame (not normalised).
        axis: [f64; 3],
    },
    /// Through poses at increasing times, relative to the placement at rest.
    Keyframed {
        /// The keys (at least two).
        keyframes: Vec<Keyframe>,
        /// How poses between keys are interpolated.
        easing: KeyframeEasing,
        /// What it does after the last key.
        after_last: KeyframeAfter,
    },
}

/// Why a table could not be resolved (the scene's validation reports each case first,
/// with its line; this is the engine's guard).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObstacleSpecError {
    /// A key the shape needs is absent.
    #[error("missing required key `{key}` for a {shape}")]
    Missing {
        /// The shape's word.
        shape: &'static str,
        /// The key (`part.radius` for a part's).
        key: &'static str,
    },
    /// A part of an articulated body is not a sphere, box or capsule.
    #[error("part `{part}`: a part cannot be a {shape}: parts are spheres, capsules or boxes")]
    PartShape {
        /// The part.
        part: String,
        /// Its shape's word.
        shape: &'static str,
    },
}

impl Obstacle {
    /// The table resolved: the keys its shape needs, present; its motion as an enum.
    pub fn resolve(&self) -> Result<ObstacleSpec, ObstacleSpecError> {
        Ok(ObstacleSpec {
            name: self.name.clone(),
            geometry: self.geometry()?,
            position: self.position,
            rotation: self.rotation,
            friction_static: self.friction_static,
            friction_kinetic: self.friction_kinetic.unwrap_or(self.friction_static),
            thickness: self.thickness,
            motion: self.motion(),
        })
    }

    /// The shape with its keys.
    fn geometry(&self) -> Result<Geometry, ObstacleSpecError> {
        let shape = self.shape.name();
        let need = |v: Option<f64>, key| v.ok_or(ObstacleSpecError::Missing { shape, key });
        Ok(match self.shape {
            ObstacleShape::Sphere | ObstacleShape::Box | ObstacleShape::Capsule => {
                Geometry::Primitive(primitive(
                    self.shape,
                    self.radius,
                    self.half_height,
                    self.half_extents,
                    None,
                )?)
            }
            ObstacleShape::Plane => Geometry::Plane {
                normal: self.normal,
            },
            ObstacleShape::Cylinder => Geometry::Cylinder {
                radius: need(self.radius, "radius")?,
                half_height: need(self.half_height, "half_height")?,
            },
            ObstacleShape::Mesh => Geometry::Mesh {
                path: self
                    .path
                    .clone()
                    .ok_or(ObstacleSpecError::Missing { shape, key: "path" })?,
                scale: self.scale,
            },
            ObstacleShape::Articulated => Geometry::Articulated {
                parts: self
                    .part
                    .iter()
                    .map(Part::resolve)
                    .collect::<Result<_, _>>()?,
                surface: self.surface,
            },
            ObstacleShape::MeshSequence => Geometry::MeshSequence {
                files: self.files.clone().ok_or(ObstacleSpecError::Missing {
                    shape,
                    key: "files",
                })?,
                frame_rate: need(self.frame_rate, "frame_rate")?,
                scale: self.scale,
                after_last: self.after_last,
            },
        })
    }

    /// The motion its keys ask for: keyframes, else a constant velocity and spin, else none.
    fn motion(&self) -> ObstacleMotion {
        if !self.keyframes.is_empty() {
            ObstacleMotion::Keyframed {
                keyframes: self.keyframes.clone(),
                easing: self.easing,
                after_last: self.after_last,
            }
        } else if self.velocity != [0.0; 3] || self.angular_velocity != 0.0 {
            ObstacleMotion::Constant {
                velocity: self.velocity,
                angular_velocity: self.angular_velocity,
                axis: self.axis,
            }
        } else {
            ObstacleMotion::Still
        }
    }
}

impl Part {
    /// The part resolved: its primitive with the keys it needs.
    pub fn resolve(&self) -> Result<PartSpec, ObstacleSpecError> {
        Ok(PartSpec {
            name: self.name.clone(),
            parent: self.parent.clone(),
            primitive: primitive(
                self.shape,
                self.radius,
                self.half_height,
                self.half_extents,
                Some(&self.name),
            )?,
            joint: self.joint,
            rotation: self.rotation,
            center: self.center,
            keyframes: self.keyframes.clone(),
            easing: self.easing,
            after_last: self.after_last,
        })
    }
}

/// A sphere, box or capsule from its optional keys; `part` names an articulated body's
/// part (whose keys are `part.*`), `None` the obstacle's own shape.
fn primitive(
    shape: ObstacleShape,
    radius: Option<f64>,
    half_height: Option<f64>,
    half_extents: Option<[f64; 3]>,
    part: Option<&str>,
) -> Result<Primitive, ObstacleSpecError> {
    let missing = |own: &'static str, of_part: &'static str| ObstacleSpecError::Missing {
        shape: shape.name(),
        key: if part.is_some() { of_part } else { own },
    };
    Ok(match shape {
        ObstacleShape::Sphere => Primitive::Sphere {
            radius: radius.ok_or_else(|| missing("radius", "part.radius"))?,
        },
        ObstacleShape::Box => Primitive::Box {
            half_extents: half_extents
                .ok_or_else(|| missing("half_extents", "part.half_extents"))?,
        },
        ObstacleShape::Capsule => Primitive::Capsule {
            radius: radius.ok_or_else(|| missing("radius", "part.radius"))?,
            half_height: half_height.ok_or_else(|| missing("half_height", "part.half_height"))?,
        },
        other => {
            return Err(ObstacleSpecError::PartShape {
                part: part.unwrap_or_default().to_owned(),
                shape: other.name(),
            });
        }
    })
}

impl Geometry {
    /// The scene's word for the shape.
    pub fn kind(&self) -> ObstacleShape {
        match self {
            Geometry::Primitive(Primitive::Sphere { .. }) => ObstacleShape::Sphere,
            Geometry::Primitive(Primitive::Box { .. }) => ObstacleShape::Box,
            Geometry::Primitive(Primitive::Capsule { .. }) => ObstacleShape::Capsule,
            Geometry::Plane { .. } => ObstacleShape::Plane,
            Geometry::Cylinder { .. } => ObstacleShape::Cylinder,
            Geometry::Mesh { .. } => ObstacleShape::Mesh,
            Geometry::Articulated { .. } => ObstacleShape::Articulated,
            Geometry::MeshSequence { .. } => ObstacleShape::MeshSequence,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Obstacle {
        toml::from_str(text).expect("obstacle table")
    }

    #[test]
    fn a_cylinder_resolves_to_its_two_sizes_and_fails_without_one() {
        let o = table("shape = \"cylinder\"\nradius = 0.1\nhalf_height = 0.2");
        let spec = o.resolve().expect("resolved");
        assert_eq!(
            spec.geometry,
            Geometry::Cylinder {
                radius: 0.1,
                half_height: 0.2
            }
        );
        let e = table("shape = \"cylinder\"\nradius = 0.1").resolve();
        assert_eq!(
            e,
            Err(ObstacleSpecError::Missing {
                shape: "cylinder",
                key: "half_height"
            })
        );
    }

    #[test]
    fn keyframes_win_over_velocity_and_no_motion_is_still() {
        let keyed = table(
            "shape = \"sphere\"\nradius = 1.0\nvelocity = [1.0, 0.0, 0.0]\n\
             [[keyframes]]\ntime = 0.0\n[[keyframes]]\ntime = 1.0",
        );
        let spec = keyed.resolve().expect("resolved");
        assert!(
            matches!(spec.motion, ObstacleMotion::Keyframed { ref keyframes, .. } if keyframes.len() == 2)
        );
        let still = table("shape = \"sphere\"\nradius = 1.0").resolve();
        assert_eq!(still.map(|s| s.motion), Ok(ObstacleMotion::Still));
        let spinning = table("shape = \"plane\"\nangular_velocity = 2.0").resolve();
        assert!(matches!(
            spinning.map(|s| s.motion),
            Ok(ObstacleMotion::Constant { angular_velocity, .. }) if angular_velocity == 2.0
        ));
    }

    #[test]
    fn a_part_that_is_not_a_primitive_is_refused_by_name() {
        let o = table("shape = \"articulated\"\n[[part]]\nname = \"arm\"\nshape = \"plane\"");
        assert_eq!(
            o.resolve(),
            Err(ObstacleSpecError::PartShape {
                part: "arm".into(),
                shape: "plane"
            })
        );
    }

    #[test]
    fn the_kinetic_friction_defaults_to_the_static_one() {
        let o = table("shape = \"sphere\"\nradius = 1.0\nfriction_static = 0.7");
        assert_eq!(o.resolve().map(|s| s.friction_kinetic), Ok(0.7));
    }
}
