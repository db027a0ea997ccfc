//! The scene resolved into the engine's specifications ([`crate::spec`]): the one place
//! where scene data becomes engine input, so the engine never imports `crate::scene`.
//!
//! [`Scene::resolve`] makes all of them at once ([`SimSpec`]); the `from_scene`
//! constructors below make one part each, for callers that need only that part.

use crate::adapt::AdaptConfig;
use crate::collide::{CollideError, Obstacles, cusick::CusickSummary};
use crate::math::Vector;
use crate::physics::{ExternalForces, MaterialParams, Model, SolverSettings, WindForce};
use crate::spec::{
    ClothMesh, ClothSpec, Garment, Gather, ObstacleSpec, ObstacleSpecError, PanelSpec, Placement,
    SeamSpec, Sewing,
};
use crate::world::{BuildError, World};

use super::model::{PanelTable, SeamTable};
use super::{Cloth, ClothShape, DEFAULT_AIR_DENSITY, Scene, TimeStep};
use crate::sim::{AdaptiveStep, Settings, SimSpec, StepSize};
use crate::spec::AttachmentTable;

impl Scene {
    /// The engine's specification of this (validated) scene: the one input of
    /// [`crate::sim::build`].
    pub fn resolve(&self) -> Result<SimSpec, BuildError> {
        Ok(SimSpec {
            cloth: cloth_spec(&self.cloth, &self.panel, &self.seam, &self.attachment)?,
            pins: self.pin.clone(),
            model: Model::from_scene(self),
            obstacles: self
                .obstacle_specs()
                .map_err(|(index, why)| BuildError::Obstacle { index, why })?,
            settings: Settings {
                step: match self.simulation.dt {
                    TimeStep::Fixed(dt) => StepSize::Fixed(dt),
                    TimeStep::Auto => StepSize::Auto,
                    TimeStep::Adaptive => {
                        let a = self.simulation.adaptive_dt.unwrap_or_default();
                        StepSize::Adaptive(AdaptiveStep {
                            tolerance: a.tolerance,
                            penetration: a.penetration,
                            min: a.min,
                            max: a.max,
                        })
                    }
                },
                multirate: self.adapt.as_ref().is_some_and(|a| a.multirate),
                self_collision: self.self_collision.clone(),
                adapt: AdaptConfig::from_scene(self.adapt.as_ref()),
            },
            density: self.material.density,
        })
    }
}

/// `[cloth]` with the keys its shape needs checked present (validation normally
/// reports a missing one first, with its line).
pub fn cloth_spec(
    c: &Cloth,
    panels: &[PanelTable],
    seams: &[SeamTable],
    attachments: &[AttachmentTable],
) -> Result<ClothSpec, BuildError> {
    let need = |v: Option<f64>, name| v.ok_or(BuildError::Missing(name));
    let mesh = match c.shape {
        ClothShape::Rectangle => {
            let resolution = c.resolution.ok_or(BuildError::Missing("resolution"))?;
            ClothMesh::Rectangle {
                width: need(c.width, "width")?,
                height: need(c.height, "height")?,
                resolution,
                short_side_segments: c.short_side_segments,
                diagonals: c.diagonals,
            }
        }
        ClothShape::Disk => {
            let resolution = c.resolution.ok_or(BuildError::Missing("resolution"))?;
            ClothMesh::Disk {
                radius: need(c.radius, "radius")?,
                resolution,
            }
        }
        ClothShape::Obj => ClothMesh::Obj {
            path: c.path.clone().ok_or(BuildError::Missing("path"))?,
            uv_scale: c.uv_scale,
        },
        ClothShape::Panels => ClothMesh::Panels(Garment {
            panels: panels.iter().map(panel_spec).collect(),
            seams: seams
                .iter()
                .map(|s| SeamSpec {
                    name: s.name.clone(),
                    a: s.a.sides().to_vec(),
                    b: s.b.sides().to_vec(),
                    direction: s.direction,
                    gather: if s.gather { Gather::Any } else { Gather::None },
                })
                .collect(),
            holds: attachments.iter().map(AttachmentTable::hold).collect(),
            max_edge: need(c.max_edge, "max_edge")?,
        }),
    };
    Ok(ClothSpec {
        mesh,
        position: c.position,
        rotation: c.rotation,
    })
}

/// The sewing of `[cloth.sewing]`.
fn sewing(c: &Cloth) -> Sewing {
    Sewing {
        stiffness: c.sewing.stiffness,
        weld_gap: c.sewing.weld_gap,
        max_force: c.sewing.max_force,
    }
}

/// A `[[panel]]` table resolved: flat unless it wraps.
fn panel_spec(p: &PanelTable) -> PanelSpec {
    let placement = match p.wrap {
        Some(w) => Placement::Cylinder {
            radius: w.radius,
            angle: w.angle,
            position: p.position,
        },
        None => Placement::Flat {
            position: p.position,
            rotation: p.rotation.unwrap_or([0.0; 3]),
        },
    };
    PanelSpec {
        name: p.name.clone(),
        outline: p.outline.clone(),
        curves: p.curves.clone(),
        placement,
    }
}

impl Scene {
    /// The `[[obstacle]]` tables resolved for the engine; on a key a shape needs and
    /// lacks (validation reports it first), the obstacle's index and the key.
    pub fn obstacle_specs(&self) -> Result<Vec<ObstacleSpec>, (usize, ObstacleSpecError)> {
        self.obstacle
            .iter()
            .enumerate()
            .map(|(i, o)| o.resolve().map_err(|e| (i, e)))
            .collect()
    }
}

impl World {
    /// Builds the cloth of `scene` and resolves its pins.
    pub fn from_scene(scene: &Scene) -> Result<World, BuildError> {
        let obstacles = scene
            .obstacle_specs()
            .map_err(|(index, why)| BuildError::Obstacle { index, why })?;
        World::from_spec(
            &cloth_spec(&scene.cloth, &scene.panel, &scene.seam, &scene.attachment)?,
            &scene.pin,
            &obstacles,
        )
    }
}

impl Obstacles {
    /// The obstacles `scene` declares (none: an empty set).
    pub fn from_scene(scene: &Scene) -> Result<Obstacles, CollideError> {
        let specs = scene
            .obstacle_specs()
            .map_err(|(index, why)| CollideError::Spec { index, why })?;
        Obstacles::new(&specs)
    }

    /// The Cusick drape measurements, when the scene is a disk specimen lying on a
    /// vertical cylinder (the support disk) centred under it.
    pub fn cusick(&self, scene: &Scene, world: &World) -> Option<CusickSummary> {
        self.cusick_of(
            &cloth_spec(&scene.cloth, &scene.panel, &scene.seam, &scene.attachment).ok()?,
            world,
        )
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
                membrane: m.membrane(),
                bending: m.rigidity(scene.simulation.gravity),
                damping: m.damping,
                bending_model: m.bending_model,
                stiffness_rule: m.stiffness_rule,
                sewing: sewing(&scene.cloth),
            },
            external,
            integrator: scene.simulation.integrator,
            cg_tolerance: scene.simulation.cg_tolerance,
            cg_max_iterations: scene.simulation.cg_max_iterations,
            solver: SolverSettings {
                solver: scene.simulation.solver,
                refactor_iterations: scene.simulation.refactor_iterations,
                refactor: scene.simulation.refactor,
                preconditioner: scene.simulation.preconditioner,
                bending_matrix: scene.simulation.bending_matrix,
                newton_iterations: scene.simulation.newton_iterations,
                newton_tolerance: scene.simulation.newton_tolerance,
                quasi_newton_iterations: scene.simulation.quasi_newton_iterations,
            },
            attachments: scene.attachment.iter().map(AttachmentTable::pull).collect(),
        }
    }
}
