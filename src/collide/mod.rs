//! Collisions (`docs/model.md`, "Collisions"): cloth against rigid obstacles and
//! against itself.
//!
//! This is the only module that imports `parry3d_f64`. Engine vectors are glam 0.33
//! `DVec3`, which is parry's own `Vector`, so no conversion happens at the boundary.
//!
//! Around each integrator step the run driver calls [`Collider::begin_step`] (stores the
//! start-of-step positions and which vertices are pinned) and [`Collider::end_step`],
//! which, for every unpinned vertex and every obstacle near it:
//! 1. **continuous detection**: in the obstacle's frame (its pose at the start and at the
//!    end of the step), casts the vertex's path from its start position to its end
//!    position against the shape; a path entering the solid is stopped at the entry point,
//!    so no step size lets a vertex tunnel through a thin obstacle;
//! 2. **proximity**: otherwise, a vertex closer than the obstacle's `thickness` to the
//!    surface (or inside it) is in contact at its nearest surface point; one the
//!    implicit solve held against a surface is in contact within 1.1 thicknesses
//!    (the solve slides it along the tangent plane, off a curved surface);
//! 3. **response**: the vertex is placed `thickness` outside the surface along the normal;
//!    its velocity relative to the obstacle loses its approaching normal part `dvn`
//!    (inelastic), and Coulomb friction acts on the tangential part `vt` (paper A; Bridson
//!    et al. 2002): it stops when `|vt| <= mu_s dvn`, else shrinks by `mu_k dvn`. The
//!    tangential displacement of the part of the step after the vertex reached the surface
//!    is corrected to match (all of it for a vertex that began the step there), so static
//!    friction holds the cloth in place and a moving obstacle carries it along; correcting
//!    the whole step for a vertex that landed within it created energy at every landing
//!    (`response.rs`).
//!
//! Then self-collision runs if the scene turns it on ([`selfcol`], with Volino culling,
//! [`volino`]), followed by a last proximity pass against the obstacles. Finally the
//! largest depth of a vertex below an obstacle surface is measured.
//!
//! No per-vertex state survives a step except what `begin_step` stores, so the mesh may
//! change between steps (adaptivity). Every per-vertex pass writes only its own vertex,
//! and every reduction is exact (integer sums, maxima), so results are the same at any
//! thread count.

pub mod cusick;
pub mod deform;
mod display;
pub mod geometry;
pub mod obstacle;
mod response;
mod self_prims;
pub mod selfcol;
pub mod sequence;
mod shapes;
pub mod volino;

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::math::{Scalar, Vector};
use crate::physics::Contact;
use crate::spec::{ObstacleSpec, SelfCollision};
use crate::world::World;
use deform::At;
use obstacle::Body;
use response::{contact_work, depth_below, push_out, respond};
use selfcol::SelfCollider;

pub use display::{Drawn, ObstacleMesh, ObstaclePose};

/// The tangent plane of the obstacle surface point nearest to one cloth
/// vertex: what the collision code finds (`Obstacles::nearest_planes`) and
/// the sizing criterion's obstacle term reads (`crate::adapt::proximity`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstaclePlane {
    /// The nearest surface point, world coordinates, m.
    pub point: Vector,
    /// The outward unit normal there.
    pub normal: Vector,
    /// The obstacle's contact thickness, m: the smallest height the measure
    /// divides by.
    pub thickness: Scalar,
}

/// Why the collision setup of a scene failed.
#[derive(Debug, thiserror::Error)]
pub enum CollideError {
    /// An articulated body's joints are invalid.
    #[error(transparent)]
    Kinematics(#[from] crate::kinematics::KinematicsError),
    /// An obstacle's OBJ file is unreadable or unusable.
    #[error("obstacle {index}: {path}: cannot use the OBJ mesh: {reason}")]
    Obj {
        /// Obstacle index.
        index: usize,
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// A mesh sequence's `files` pattern reached the engine unexpanded (the scene loader
    /// expands it into the list of files).
    #[error("obstacle {index}: the `files` pattern was not expanded into a list of files")]
    Unexpanded {
        /// Obstacle index.
        index: usize,
    },
    /// An obstacle's table lacks a key its shape needs (validation normally catches
    /// this first).
    #[error("obstacle {index}: {why}")]
    Spec {
        /// Obstacle index.
        index: usize,
        /// What is missing.
        why: crate::spec::ObstacleSpecError,
    },
}

/// Collision counters over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct CollisionStats {
    /// Steps with collision handling.
    pub steps: u64,
    /// Vertex-obstacle contacts, summed over the steps.
    pub contacts: u64,
    /// Largest depth of a vertex below an obstacle surface after resolution, m.
    pub max_penetration: Scalar,
    /// Contacts in the last step.
    pub last_contacts: u64,
    /// Largest depth below an obstacle surface in the last step, m.
    pub last_penetration: Scalar,
    /// Triangle pairs given to the exact self-collision tests, summed over the steps.
    pub self_pairs_tested: u64,
    /// Triangles whose patch skipped its self-test (Volino culling), summed over
    /// the steps.
    pub self_triangles_culled: u64,
    /// Triangles given to self-collision, summed over the steps.
    pub self_triangles: u64,
    /// Work the moving obstacles did on the cloth, J (zero with static obstacles).
    pub obstacle_work: Scalar,
    /// Self-collision primitive pairs that acted, summed over steps and iterations.
    pub self_resolved: u64,
    /// Wall time in obstacle passes, s.
    pub collision_wall_s: Scalar,
    /// Wall time in self-collision, s.
    pub self_collision_wall_s: Scalar,
}

impl CollisionStats {
    /// Mean contacts per step.
    pub fn mean_contacts(&self) -> Scalar {
        self.contacts as Scalar / self.steps.max(1) as Scalar
    }

    /// Mean triangle pairs tested per step.
    pub fn mean_self_pairs_tested(&self) -> Scalar {
        self.self_pairs_tested as Scalar / self.steps.max(1) as Scalar
    }

    /// Share of the triangles whose patch culling spared its self-test (0 without
    /// self-collision).
    pub fn self_culled_fraction(&self) -> Scalar {
        if self.self_triangles == 0 {
            0.0
        } else {
            self.self_triangles_culled as Scalar / self.self_triangles as Scalar
        }
    }
}

/// What the collision pass needs from the stepper after a step.
#[derive(Debug, Clone, Copy)]
pub struct StepCloth<'a> {
    /// [`crate::physics::Stepper::contact_push`]: the normal velocity change the
    /// implicit solve's contact filters imposed, per vertex (may be empty), which
    /// counts as normal impulse for friction.
    pub pushed: &'a [Scalar],
    /// Vertex masses, kg (for the work moving obstacles do on the cloth).
    pub mass: &'a [Scalar],
}

/// The rigid obstacles of a scene: their shapes, poses, motions and friction,
/// fixed for the run (the simulation's [`crate::sim::Setup`] holds them; the
/// [`Collider`] is given them every step).
#[derive(Debug, Default)]
pub struct Obstacles {
    bodies: Vec<Body>,
}

impl Obstacles {
    /// The obstacles of a scene's `[[obstacle]]` tables (none: an empty set).
    /// `crate::scene` builds them from a scene (`Obstacles::from_scene`).
    pub fn new(obstacles: &[ObstacleSpec]) -> Result<Obstacles, CollideError> {
        let bodies = obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| Body::from_spec(i, o))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .flatten()
            .collect();
        Ok(Obstacles { bodies })
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }

    /// The obstacles, for `drape check`: name, friction, thickness, moving, and
    /// what the obstacle passes do (empty when there are none).
    pub fn describe(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .bodies
            .iter()
            .map(|b| {
                format!(
                    "{}: thickness {} m, friction static {} kinetic {}{}",
                    b.name,
                    b.thickness,
                    b.mu_static,
                    b.mu_kinetic,
                    b.deforming()
                        .map_or_else(|| b.motion().describe(), |d| d.describe())
                )
            })
            .collect();
        if !self.bodies.is_empty() {
            out.push(
                "obstacle passes: continuous detection along each vertex's path, proximity within the thickness, Coulomb friction"
                    .into(),
            );
        }
        out
    }

    /// Per group of vertices (vertex `i` is in group `group[i]`, groups
    /// `0..groups`), the vertex of `x` deepest inside an obstacle at time `t`;
    /// `None` for a group with no vertex inside one.
    pub fn deepest_inside(
        &self,
        x: &[Vector],
        t: Scalar,
        group: &[u16],
        groups: usize,
    ) -> Vec<Option<Inside>> {
        let mut deepest: Vec<Option<Inside>> = vec![None; groups];
        for body in &self.bodies {
            let at = body.at(t);
            for (i, &p) in x.iter().enumerate() {
                let probe = body.probe(&at, at.pose.inverse_transform_point(p));
                let depth = -probe.signed;
                let slot = &mut deepest[group[i] as usize];
                if depth > 0.0 && slot.as_ref().is_none_or(|d| depth > d.depth) {
                    *slot = Some(Inside {
                        vertex: i,
                        obstacle: body.name.clone(),
                        depth,
                        normal: at.pose.rotation * probe.normal,
                    });
                }
            }
        }
        deepest
    }

    /// Per vertex of `x`, the tangent plane of the nearest obstacle surface
    /// point at time `t` (over every obstacle), into `out`; `out` is left empty
    /// when there are no obstacles. For the sizing criterion's obstacle term
    /// (`crate::adapt::proximity`).
    pub fn nearest_planes(&self, x: &[Vector], t: Scalar, out: &mut Vec<ObstaclePlane>) {
        out.clear();
        if self.bodies.is_empty() {
            return;
        }
        let ats: Vec<At> = self.bodies.iter().map(|b| b.at(t)).collect();
        out.extend(x.iter().map(|&p| {
            self.bodies
                .iter()
                .zip(&ats)
                .map(|(b, at)| b.nearest_plane(at, p))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, plane)| plane)
                .expect("at least one obstacle")
        }));
    }
}

/// A vertex inside an obstacle ([`Obstacles::deepest_inside`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Inside {
    /// The vertex.
    pub vertex: usize,
    /// The obstacle (and part) it is inside.
    pub obstacle: String,
    /// How deep below the surface, m.
    pub depth: Scalar,
    /// The outward unit normal of the surface point nearest to it, world frame.
    pub normal: Vector,
}

/// The collision passes of a run and their per-step scratch (the obstacles
/// themselves are the run's [`Obstacles`], given to every step).
#[derive(Debug)]
pub struct Collider {
    self_collider: Option<SelfCollider>,
    x0: Vec<Vector>,
    held: Vec<bool>,
    t0: Scalar,
    /// Per-step scratch, kept so that a step allocates nothing: each body at the
    /// start and the end of the step.
    poses: Vec<(At, At)>,
    /// Per-step scratch: per vertex, whether it touched an obstacle and the work done on it.
    hits: Vec<(u64, Scalar)>,
    /// Per-step scratch of the last pass: per vertex, its depth below an obstacle
    /// surface and the work done on it.
    pushes: Vec<(Scalar, Scalar)>,
}

impl Collider {
    /// The collision passes of a run with `obstacles` and self-collision; `None`
    /// when it has neither (nothing runs, nothing costs).
    pub fn new(obstacles: &Obstacles, self_collision: Option<&SelfCollision>) -> Option<Collider> {
        if obstacles.is_empty() && self_collision.is_none() {
            return None;
        }
        Some(Collider {
            self_collider: self_collision.map(SelfCollider::new),
            x0: Vec::new(),
            held: Vec::new(),
            t0: 0.0,
            poses: Vec::new(),
            hits: Vec::new(),
            pushes: Vec::new(),
        })
    }

    /// The self-collision pass, for `drape check` (`None`: it does not run).
    pub fn describe_self_collision(&self) -> Option<String> {
        self.self_collider.as_ref().map(|s| {
            format!(
                "self-collision: thickness {} m, {} repulsion passes, vertex-triangle and edge-edge, Volino culling {}",
                s.thickness,
                s.iterations,
                if s.culling { "on" } else { "off" }
            )
        })
    }

    /// True when self-collision runs.
    pub fn has_self_collision(&self) -> bool {
        self.self_collider.is_some()
    }

    /// Stores the start-of-step state; call right before the integrator step.
    pub fn begin_step(&mut self, world: &World) {
        self.x0.clear();
        self.x0.extend_from_slice(&world.x);
        self.held.resize(world.x.len(), false);
        world.pins.held_at(world.time, &mut self.held);
        self.t0 = world.time;
    }

    /// Resolves collisions after an integrator step of `h` seconds (see the module docs).
    /// With obstacles, `contacts` becomes the contacts the step ended in, one per
    /// vertex (the simulation state's resting contacts, for the next implicit step).
    pub fn end_step(
        &mut self,
        obstacles: &Obstacles,
        world: &mut World,
        h: Scalar,
        cloth: StepCloth,
        contacts: &mut Vec<Contact>,
        stats: &mut CollisionStats,
    ) {
        let (t0, t1) = (self.t0, world.time);
        let started = Instant::now();
        self.poses.clear();
        let bodies = &obstacles.bodies;
        self.poses
            .extend(bodies.iter().map(|b| (b.at(t0), b.at(t1))));
        let touching = if bodies.is_empty() {
            0
        } else {
            self.obstacle_pass(bodies, world, h, cloth, contacts, stats)
        };
        stats.collision_wall_s += started.elapsed().as_secs_f64();
        if let Some(sc) = self.self_collider.as_mut() {
            let started = Instant::now();
            let s = sc.resolve(
                &world.mesh,
                &self.x0,
                &mut world.x,
                &mut world.v,
                &self.held,
            );
            stats.self_pairs_tested += s.pairs_tested;
            stats.self_triangles_culled += s.triangles_culled;
            stats.self_triangles += s.triangles;
            stats.self_resolved += s.resolved;
            stats.self_collision_wall_s += started.elapsed().as_secs_f64();
        }
        let started = Instant::now();
        if !bodies.is_empty() {
            let depth = self.final_obstacle_pass(bodies, world, h, cloth.mass, stats);
            stats.max_penetration = stats.max_penetration.max(depth);
            stats.last_penetration = depth;
        }
        stats.steps += 1;
        stats.contacts += touching;
        stats.last_contacts = touching;
        stats.collision_wall_s += started.elapsed().as_secs_f64();
    }

    /// Steps 1 to 3 of the module docs for every unpinned vertex against every obstacle:
    /// continuous detection or proximity, then the response with friction. Fills
    /// `contacts` (one per vertex), adds the work moving obstacles did to
    /// `stats.obstacle_work`, and returns how many vertices touch an obstacle.
    fn obstacle_pass(
        &mut self,
        bodies: &[Body],
        world: &mut World,
        h: Scalar,
        cloth: StepCloth,
        contacts: &mut Vec<Contact>,
        stats: &mut CollisionStats,
    ) -> u64 {
        let StepCloth { pushed, mass } = cloth;
        let t1 = world.time;
        let (x0, held, poses) = (&self.x0, &self.held, &self.poses);
        contacts.clear();
        contacts.resize(world.x.len(), Contact::default());
        let moving = bodies.iter().any(Body::is_moving);
        world
            .x
            .par_iter_mut()
            .zip(world.v.par_iter_mut())
            .zip(contacts.par_iter_mut())
            .enumerate()
            .with_min_len(256)
            .map(|(i, ((x, v), contact))| {
                if held[i] {
                    return (0u64, 0.0);
                }
                let mut hit = false;
                let push = pushed.get(i).copied().unwrap_or(0.0);
                let mut work = 0.0;
                for (b, pose) in bodies.iter().zip(poses) {
                    let (xb, vb) = (*x, *v);
                    if let Some(c) = respond(b, pose, t1, h, push, x0[i], x, v) {
                        // A moving surface works on the cloth: its impulses, those of
                        // the velocity change, the displacement and the filter, dotted
                        // with the surface velocity (`contact_work`).
                        if moving {
                            let surface = b.velocity_at(t1, &pose.1, *x);
                            let m = mass.get(i).copied().unwrap_or(0.0);
                            work += contact_work(m, h, *x - xb, *v - vb, surface)
                                + m * push * c.normal_speed;
                        }
                        *contact = c;
                        hit = true;
                    }
                }
                (u64::from(hit), work)
            })
            .collect_into_vec(&mut self.hits);
        // Summed in vertex order, so the work is the same at any thread count.
        let (touching, work) = self
            .hits
            .iter()
            .fold((0u64, 0.0), |(n, w), &(a, b)| (n + a, w + b));
        stats.obstacle_work += work;
        touching
    }

    /// The last proximity pass: when self-collision ran (it may have moved vertices
    /// into an obstacle), pushes unpinned vertices back out of every obstacle at its
    /// end-of-step pose, adding the work moving obstacles do so (`contact_work`) to
    /// `stats.obstacle_work`. Returns the largest depth of a vertex below an obstacle
    /// surface.
    fn final_obstacle_pass(
        &mut self,
        bodies: &[Body],
        world: &mut World,
        h: Scalar,
        mass: &[Scalar],
        stats: &mut CollisionStats,
    ) -> Scalar {
        let t1 = world.time;
        let (held, poses) = (&self.held, &self.poses);
        let after_self = self.self_collider.is_some();
        let moving = bodies.iter().any(Body::is_moving);
        world
            .x
            .par_iter_mut()
            .zip(world.v.par_iter_mut())
            .enumerate()
            .with_min_len(256)
            .map(|(i, (x, v))| {
                let (mut deepest, mut work): (Scalar, Scalar) = (0.0, 0.0);
                for (b, pose) in bodies.iter().zip(poses) {
                    if after_self && !held[i] {
                        let (xb, vb) = (*x, *v);
                        push_out(b, &pose.1, t1, x, v);
                        if moving && (*x != xb || *v != vb) {
                            let surface = b.velocity_at(t1, &pose.1, *x);
                            let m = mass.get(i).copied().unwrap_or(0.0);
                            work += contact_work(m, h, *x - xb, *v - vb, surface);
                        }
                    }
                    deepest = deepest.max(depth_below(b, &pose.1, *x));
                }
                (deepest, work)
            })
            .collect_into_vec(&mut self.pushes);
        // Summed in vertex order, so the work is the same at any thread count.
        let (deepest, work) = self
            .pushes
            .iter()
            .fold((0.0, 0.0), |(d, w): (Scalar, Scalar), &(a, b)| {
                (d.max(a), w + b)
            });
        stats.obstacle_work += work;
        deepest
    }
}
