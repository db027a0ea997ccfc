//! The simulation state: mesh, positions, velocities, time and pins.
//!
//! Built from a resolved cloth ([`ClothSpec`], made from a validated scene by
//! `crate::scene`); the stepper's scratch memory lives elsewhere
//! ([`crate::physics::Stepper`]).

use std::path::Path;

use crate::math::{Scalar, Vector, rotation_from_euler_deg};
use crate::mesh::{self, Mesh, MeshError, ObjError};
use crate::pins::{PinError, Pins};
use crate::spec::{ClothMesh, ClothSpec, ObstacleSpec, Pin};

/// Why a world could not be built from a scene.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// The generated mesh was refused.
    #[error("cloth mesh: {0}")]
    Mesh(#[from] MeshError),
    /// The OBJ cloth could not be loaded.
    #[error("cloth mesh: {0}")]
    Obj(#[from] ObjError),
    /// A pin region could not be resolved.
    #[error("{0}")]
    Pin(#[from] PinError),
    /// The garment's panels or seams could not be built.
    #[error("garment: {0}")]
    Garment(#[from] crate::garment::GarmentError),
    /// A key the shape needs is missing (validation normally catches this first).
    #[error("cloth: `{0}` is required for this shape")]
    Missing(&'static str),
    /// An obstacle's table lacks a key its shape needs (validation normally catches
    /// this first).
    #[error("obstacle {index}: {why}")]
    Obstacle {
        /// Obstacle index.
        index: usize,
        /// What is missing.
        why: crate::spec::ObstacleSpecError,
    },
}

/// Simulation state of one cloth.
#[derive(Debug, Clone)]
pub struct World {
    /// The cloth mesh in material space.
    pub mesh: Mesh,
    /// World positions, m.
    pub x: Vec<Vector>,
    /// Velocities, m/s.
    pub v: Vec<Vector>,
    /// Simulated time, s.
    pub time: Scalar,
    /// Pinned vertices and their scripts.
    pub pins: Pins,
}

impl World {
    /// A world at rest with the given mesh and positions, no pins.
    pub fn new(mesh: Mesh, x: Vec<Vector>) -> World {
        let v = vec![Vector::ZERO; x.len()];
        World {
            mesh,
            x,
            v,
            time: 0.0,
            pins: Pins::default(),
        }
    }

    /// Builds the cloth and resolves its pins, whose `attach` names one of
    /// `obstacles`. A rectangle's grid has lines on the edges of the box pin
    /// regions ([`mesh::fitted_lines`]).
    pub fn from_spec(
        cloth: &ClothSpec,
        pins: &[Pin],
        obstacles: &[ObstacleSpec],
    ) -> Result<World, BuildError> {
        let (mesh, local): (Mesh, Vec<Vector>) = match &cloth.mesh {
            &ClothMesh::Rectangle {
                width,
                height,
                resolution,
                short_side_segments,
                diagonals,
            } => {
                let cuts = crate::pins::box_cuts(pins);
                let (us, vs) =
                    mesh::fitted_lines(width, height, resolution, short_side_segments, &cuts);
                let m = mesh::rectangle_on_lines(&us, &vs, diagonals)?;
                let local = m.material.iter().map(|p| p.extend(0.0)).collect();
                (m, local)
            }
            &ClothMesh::Disk { radius, resolution } => {
                let m = mesh::disk(radius, resolution)?;
                let local = m.material.iter().map(|p| p.extend(0.0)).collect();
                (m, local)
            }
            ClothMesh::Obj { path, uv_scale } => {
                let obj = mesh::load_obj(Path::new(path), *uv_scale)?;
                (obj.mesh, obj.positions)
            }
            ClothMesh::Panels(garment) => {
                let built = crate::garment::build(garment)?;
                (built.mesh, built.positions)
            }
        };
        let rot = rotation_from_euler_deg(cloth.rotation);
        let origin = Vector::from_array(cloth.position);
        let x: Vec<Vector> = local.iter().map(|p| origin + rot * *p).collect();
        let pins = Pins::select_among(pins, obstacles, &mesh, &x)?;
        let mut world = World::new(mesh, x);
        world.pins = pins;
        Ok(world)
    }

    /// Welds seam `s` of the garment (see [`Mesh::weld`]): each pair becomes one vertex at the pair's centre of mass, moving with
    /// its mean momentum (`mass`: the vertex masses before the weld), so mass
    /// and momentum are conserved. Pins follow their vertices. Returns the
    /// number of vertices merged away.
    pub fn weld_seam(&mut self, s: usize, mass: &[Scalar]) -> Result<usize, MeshError> {
        let weld = self.mesh.weld(s)?;
        let n = weld.mesh.vertex_count();
        let mut m = vec![0.0; n];
        let mut p = vec![Vector::ZERO; n];
        let mut q = vec![Vector::ZERO; n];
        for (old, &new) in weld.new_index.iter().enumerate() {
            let (i, mi) = (new as usize, mass[old]);
            m[i] += mi;
            p[i] += self.x[old] * mi;
            q[i] += self.v[old] * mi;
        }
        self.x = p.iter().zip(&m).map(|(p, m)| *p / *m).collect();
        self.v = q.iter().zip(&m).map(|(q, m)| *q / *m).collect();
        for a in &mut self.pins.anchors {
            a.vertex = weld.new_index[a.vertex as usize];
        }
        self.pins.anchors.sort_by_key(|a| a.vertex);
        self.pins.anchors.dedup_by_key(|a| a.vertex);
        self.mesh = weld.mesh;
        Ok(weld.merged)
    }

    /// Centre of mass for the given vertex masses.
    pub fn center_of_mass(&self, mass: &[Scalar]) -> Vector {
        let total: Scalar = mass.iter().sum();
        self.x
            .iter()
            .zip(mass)
            .map(|(x, m)| *x * *m)
            .sum::<Vector>()
            / total
    }

    /// Area-weighted unit normals at the vertices of the current shape.
    pub fn vertex_normals(&self, out: &mut Vec<Vector>) {
        out.clear();
        out.resize(self.x.len(), Vector::ZERO);
        for t in &self.mesh.triangles {
            let [a, b, c] = t.map(|i| self.x[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                out[i as usize] += n;
            }
        }
        for n in out.iter_mut() {
            *n = n.normalize_or_zero();
        }
    }
}
