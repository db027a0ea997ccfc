//! The simulation state: mesh, positions, velocities, time and pins.
//!
//! Built from a validated [`Scene`]; the stepper's scratch memory lives elsewhere
//! ([`crate::physics::Stepper`]).

use std::path::Path;

use crate::math::{Scalar, Vector, rotation_from_euler_deg};
use crate::mesh::{self, Mesh, MeshError, ObjError};
use crate::physics::pins::{PinError, Pins};
use crate::physics::{ExternalForces, MaterialParams, Model, SolverSettings, WindForce};
use crate::scene::{ClothShape, DEFAULT_AIR_DENSITY, Scene};

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
    /// An obstacle could not be built (e.g. a broken OBJ mesh).
    #[error("{0}")]
    Collide(#[from] crate::collide::CollideError),
    /// A key the shape needs is missing (validation normally catches this first).
    #[error("cloth: `{0}` is required for this shape")]
    Missing(&'static str),
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

    /// Builds the cloth of `scene` and resolves its pins.
    pub fn from_scene(scene: &Scene) -> Result<World, BuildError> {
        let c = &scene.cloth;
        let need = |v: Option<Scalar>, name| v.ok_or(BuildError::Missing(name));
        let (mesh, local): (Mesh, Vec<Vector>) = match c.shape {
            ClothShape::Rectangle => {
                let res = c.resolution.ok_or(BuildError::Missing("resolution"))?;
                let m = mesh::rectangle(
                    need(c.width, "width")?,
                    need(c.height, "height")?,
                    res,
                    c.diagonals,
                )?;
                let local = m.material.iter().map(|p| p.extend(0.0)).collect();
                (m, local)
            }
            ClothShape::Disk => {
                let res = c.resolution.ok_or(BuildError::Missing("resolution"))?;
                let m = mesh::disk(need(c.radius, "radius")?, res)?;
                let local = m.material.iter().map(|p| p.extend(0.0)).collect();
                (m, local)
            }
            ClothShape::Obj => {
                let path = c.path.as_deref().ok_or(BuildError::Missing("path"))?;
                let obj = mesh::load_obj(Path::new(path), c.uv_scale)?;
                (obj.mesh, obj.positions)
            }
        };
        let rot = rotation_from_euler_deg(c.rotation);
        let origin = Vector::from_array(c.position);
        let x: Vec<Vector> = local.iter().map(|p| origin + rot * *p).collect();
        let pins = Pins::select(&scene.pin, &mesh, &x)?;
        let mut world = World::new(mesh, x);
        world.pins = pins;
        Ok(world)
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

impl Model {
    /// The physics a scene declares (undeclared forces are `None`).
    pub fn from_scene(scene: &Scene) -> Model {
        let m = &scene.material;
        let g = Vector::from_array(scene.simulation.gravity);
        let wind = scene.wind.as_ref().map(|w| WindForce {
            velocity: Vector::from_array(w.velocity),
            coefficient: w.coefficient,
            air_density: scene
                .air
                .as_ref()
                .map_or(DEFAULT_AIR_DENSITY, |a| a.density),
        });
        let external = ExternalForces {
            gravity: (g != Vector::ZERO).then_some(g),
            drag: scene.air.as_ref().map(|a| a.drag).filter(|&d| d > 0.0),
            air_velocity: wind.map_or(Vector::ZERO, |w| w.velocity),
            wind: wind.filter(|w| w.coefficient > 0.0),
        };
        Model {
            material: MaterialParams {
                density: m.density,
                stretch: m.stretch,
                bending: m.rigidity(scene.simulation.gravity),
                damping: m.damping,
                bending_model: m.bending_model,
                stiffness_rule: m.stiffness_rule,
            },
            external,
            integrator: scene.simulation.integrator,
            cg_tolerance: scene.simulation.cg_tolerance,
            cg_max_iterations: scene.simulation.cg_max_iterations,
            solver: SolverSettings {
                solver: scene.simulation.solver,
                refactor_iterations: scene.simulation.refactor_iterations,
                newton_iterations: scene.simulation.newton_iterations,
                newton_tolerance: scene.simulation.newton_tolerance,
            },
        }
    }
}
