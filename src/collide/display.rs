//! The obstacles as the recording draws them: meshes logged once and placed
//! by a pose each frame when they move rigidly (a moving plane, drawn around
//! the cloth, is redrawn every frame; a deforming mesh's vertex positions are
//! logged every frame, its triangles once).

use super::Obstacles;
use crate::math::{Scalar, Vector};

/// How the recording draws an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Drawn {
    /// It does not move: its mesh in world coordinates, logged once.
    Fixed,
    /// A moving rigid shape: its mesh in its local frame, logged once, placed
    /// by its pose each frame ([`Obstacles::poses`]).
    Rigid,
    /// A moving plane, drawn around the cloth: its mesh in world
    /// coordinates, logged every frame.
    Redrawn,
    /// A deforming mesh: its vertex positions in world coordinates, logged
    /// every frame, and its triangles, logged once (given with the first
    /// frame only).
    Deforming,
}

/// A triangulated obstacle for display: positions and triangles.
#[derive(Debug, Clone)]
pub struct ObstacleMesh {
    /// Name, `obstacle N (shape)` or `obstacle N part NAME`.
    pub name: String,
    /// How it is drawn (and in which frame `positions` are).
    pub drawn: Drawn,
    /// Vertex positions, m: local for [`Drawn::Rigid`], else world.
    pub positions: Vec<Vector>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// A moving rigid obstacle's pose at one time: its local frame in the world.
#[derive(Debug, Clone)]
pub struct ObstaclePose {
    /// Name, as its [`ObstacleMesh`].
    pub name: String,
    /// World position of the local origin, m.
    pub translation: Vector,
    /// World rotation of the local frame.
    pub rotation: glam::DQuat,
}

impl Obstacles {
    /// The obstacles triangulated at time `t` (see [`Drawn`]): every one
    /// with `first` (the first recorded frame), else only the redrawn ones;
    /// planes as a square of half side `plane.1` around `plane.0` (see
    /// [`super::obstacle::Body::world_triangles`]).
    pub fn meshes(&self, t: Scalar, plane: (Vector, Scalar), first: bool) -> Vec<ObstacleMesh> {
        self.bodies
            .iter()
            .filter_map(|b| {
                if b.deforming().is_some() {
                    let (positions, triangles) = b.world_triangles(t, plane);
                    return Some(ObstacleMesh {
                        name: b.name.clone(),
                        drawn: Drawn::Deforming,
                        positions,
                        triangles: if first { triangles } else { Vec::new() },
                    });
                }
                let local = b.local_triangles();
                let drawn = match (b.is_moving(), local.1.is_empty()) {
                    (false, _) => Drawn::Fixed,
                    (true, false) => Drawn::Rigid,
                    (true, true) => Drawn::Redrawn,
                };
                if !first && drawn != Drawn::Redrawn {
                    return None;
                }
                let (positions, triangles) = match drawn {
                    Drawn::Rigid => local,
                    _ => b.world_triangles(t, plane),
                };
                Some(ObstacleMesh {
                    name: b.name.clone(),
                    drawn,
                    positions,
                    triangles,
                })
            })
            .collect()
    }

    /// The poses at time `t` of the obstacles drawn as [`Drawn::Rigid`].
    pub fn poses(&self, t: Scalar) -> Vec<ObstaclePose> {
        self.bodies
            .iter()
            .filter(|b| b.is_moving() && !b.is_plane() && b.deforming().is_none())
            .map(|b| {
                let pose = b.pose(t);
                ObstaclePose {
                    name: b.name.clone(),
                    translation: pose.translation,
                    rotation: pose.rotation,
                }
            })
            .collect()
    }
}
