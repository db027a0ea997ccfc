//! Adaptive meshing (SPEC section 4): refine where the angle between the normals
//! of the two triangles at an interior edge exceeds the upper threshold, coarsen
//! where every relevant angle is below the lower one.
//!
//! An adaptation pass: measure angles -> choose operations -> apply them to the
//! refinement hierarchy -> close the mesh -> transfer the state onto the new
//! topology -> report events. The stepper must rebuild its elements afterwards.

mod check;
pub mod edge;
pub mod red_green;
pub mod transfer;

pub use check::{ConsistencyError, check_consistency};

use std::collections::HashMap;

use rayon::prelude::*;

use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::MeshError;
use crate::spec::{Adapt, AdaptMethod};
use crate::world::World;
use red_green::{Applied, RedGreen, RedGreenOp};
use transfer::{Origin, Remeshed, transfer};

/// What happened, for the recording and the counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// A 1-4 split asked for by the angle criterion.
    Split,
    /// A 1-4 split forced by closure (two hanging nodes) or by 1-irregularity.
    ClosureSplit,
    /// Four children merged back into their parent.
    Merge,
    /// A step restored, refined and integrated again.
    Rollback,
    /// An edge flipped for quality (edge method).
    Flip,
    /// An edge collapsed (edge method).
    Collapse,
}

/// One remeshing event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptEvent {
    /// What happened.
    pub kind: EventKind,
    /// Where (world position of the affected triangle's centroid), m.
    pub position: Vector,
    /// Level of the triangles created.
    pub level: u8,
    /// The largest angle at the triangle's edges that triggered it, degrees
    /// (`None` for forced splits).
    pub angle: Option<Scalar>,
    /// The step after which it happened.
    pub step: u64,
}

/// Counters over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct AdaptStats {
    /// 1-4 splits (asked for and forced).
    pub splits: u64,
    /// Of those, forced by closure or 1-irregularity.
    pub closure_splits: u64,
    /// Merges (red_green) or edge collapses (edge).
    pub merges: u64,
    /// Edge flips (edge method).
    pub flips: u64,
    /// Steps redone after refining.
    pub rollbacks: u64,
    /// Adaptation passes run.
    pub passes: u64,
    /// Passes that changed the mesh.
    pub changed_passes: u64,
    /// Largest number of operations in one pass.
    pub max_ops_per_pass: u64,
}

/// Adaptivity settings (the scene's `[adapt]`, resolved).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptConfig {
    /// The remeshing method (`red_green` or `edge`).
    pub method: AdaptMethod,
    /// Upper threshold, degrees.
    pub refine_angle: Scalar,
    /// Lower threshold, degrees.
    pub coarsen_angle: Scalar,
    /// Finest level.
    pub max_level: u8,
    /// Shortest edge refinement may create (material space), m.
    pub min_edge_length: Scalar,
    /// Adapt every this many steps.
    pub every: u64,
    /// Redo steps that bent too far.
    pub rollback: bool,
    /// Rollbacks per step.
    pub max_rollbacks: u32,
}

impl AdaptConfig {
    /// The configuration of a scene's `[adapt]`, or `None` when it does not adapt.
    pub fn from_scene(a: Option<&Adapt>) -> Option<AdaptConfig> {
        let a = a?;
        (a.method != AdaptMethod::None).then(|| AdaptConfig {
            method: a.method,
            refine_angle: a.refine_angle,
            coarsen_angle: a.coarsen_angle,
            max_level: a.max_level.min(254) as u8,
            min_edge_length: a.min_edge_length,
            every: a.every.max(1) as u64,
            rollback: a.rollback,
            max_rollbacks: a.max_rollbacks,
        })
    }
}

/// The adaptive state of a run: settings, refinement hierarchy, counters, and the
/// events not yet taken by the recorder.
#[derive(Debug, Clone)]
pub struct Adapter {
    /// Settings.
    pub config: AdaptConfig,
    /// Counters.
    pub stats: AdaptStats,
    /// Events since the last [`Adapter::take_events`].
    events: Vec<AdaptEvent>,
    hierarchy: RedGreen,
    /// Leaf of the hierarchy that owns each triangle of the world's mesh.
    owner: Vec<u32>,
    density: Scalar,
    /// Limits of the edge method (`None` for red_green).
    edge: Option<edge::Limits>,
}

/// Angle in degrees between the normals of the two triangles at each edge
/// (0 at boundary edges).
pub fn edge_angles(world: &World) -> Vec<Scalar> {
    let (x, tris) = (&world.x, &world.mesh.triangles);
    let normal = |t: u32| {
        let [a, b, c] = tris[t as usize].map(|i| x[i as usize]);
        (b - a).cross(c - a)
    };
    world
        .mesh
        .edges
        .par_iter()
        .with_min_len(1024)
        .map(|e| {
            if !e.is_interior() {
                return 0.0;
            }
            let (n0, n1) = (normal(e.triangles[0]), normal(e.triangles[1]));
            n0.cross(n1).length().atan2(n0.dot(n1)).to_degrees()
        })
        .collect()
}

impl Adapter {
    /// Starts adapting `world`'s mesh (its current triangles become level 0).
    pub fn new(config: AdaptConfig, world: &World, density: Scalar) -> Adapter {
        let hierarchy = RedGreen::new(&world.mesh.triangles, &world.mesh.material);
        let owner = (0..world.mesh.triangles.len() as u32).collect();
        let m = &world.mesh;
        let edge = (config.method == AdaptMethod::Edge).then(|| {
            edge::Limits::for_mesh(
                &m.material,
                &m.triangles,
                config.max_level,
                config.min_edge_length,
            )
        });
        Adapter {
            config,
            stats: AdaptStats::default(),
            events: Vec::new(),
            hierarchy,
            owner,
            density,
            edge,
        }
    }

    /// Events since the last call.
    pub fn take_events(&mut self) -> Vec<AdaptEvent> {
        std::mem::take(&mut self.events)
    }

    /// The refinement hierarchy (for tests and inspection).
    pub fn hierarchy(&self) -> &RedGreen {
        &self.hierarchy
    }

    /// Leaves the angle criterion asks to split, with the angle that asked,
    /// from angles measured on the world's current shape.
    pub fn refinement_marks(&self, world: &World, angles: &[Scalar]) -> Vec<(u32, Scalar)> {
        if self.edge.is_some() {
            return Vec::new(); // rollback is paper A's, with red_green only
        }
        let mut marks: Vec<(u32, Scalar)> = Vec::new();
        for (e, edge) in world.mesh.edges.iter().enumerate() {
            if angles[e] <= self.config.refine_angle {
                continue;
            }
            for &t in &edge.triangles {
                let leaf = self.owner[t as usize];
                let finer = self.hierarchy.level(leaf) as u32 + 2;
                let long_enough = self.config.min_edge_length <= 0.0
                    || 0.5 * self.hierarchy.shortest_edge(leaf) >= self.config.min_edge_length;
                if finer <= self.config.max_level as u32 && long_enough {
                    marks.push((leaf, angles[e]));
                }
            }
        }
        marks.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
        marks.dedup_by_key(|m| m.0);
        marks
    }

    /// Parents whose children may merge: every angle at the edges of their
    /// triangles is below the lower threshold, and below half the upper one (a
    /// merge about doubles the angles, so this keeps a merge from being split
    /// again at once when the thresholds are close).
    fn merge_marks(&self, world: &World, angles: &[Scalar]) -> Vec<(u32, Scalar)> {
        let mut leaf_max: std::collections::HashMap<u32, Scalar> = std::collections::HashMap::new();
        for (e, edge) in world.mesh.edges.iter().enumerate() {
            for &t in edge
                .triangles
                .iter()
                .filter(|&&t| t != crate::mesh::NO_TRIANGLE)
            {
                let m = leaf_max.entry(self.owner[t as usize]).or_insert(0.0);
                *m = m.max(angles[e]);
            }
        }
        let limit = self
            .config
            .coarsen_angle
            .min(0.5 * self.config.refine_angle);
        let mut out = Vec::new();
        for p in self.hierarchy.mergeable_parents() {
            let children = self.hierarchy.children(p).unwrap_or_default();
            let worst = children
                .iter()
                .map(|c| leaf_max.get(c).copied().unwrap_or(0.0))
                .fold(0.0, Scalar::max);
            if worst < limit {
                out.push((p, worst));
            }
        }
        out
    }

    /// One adaptation pass on `world` after step `step`: merges, then splits,
    /// then closure; returns true when the mesh changed.
    pub fn pass(&mut self, world: &mut World, step: u64) -> Result<bool, MeshError> {
        if let Some(limits) = self.edge {
            return self.edge_pass(world, step, limits);
        }
        let angles = edge_angles(world);
        let merges = self.merge_marks(world, &angles);
        let splits = self.refinement_marks(world, &angles);
        self.stats.passes += 1;
        let mut ops: Vec<(RedGreenOp, Option<Scalar>)> = merges
            .iter()
            .map(|&(p, a)| (RedGreenOp::Merge(p), Some(a)))
            .collect();
        ops.extend(splits.iter().map(|&(l, a)| (RedGreenOp::Split(l), Some(a))));
        self.apply(world, &ops, step)
    }

    /// Refines the leaves in `marks` (from [`Adapter::refinement_marks`]) and
    /// rebuilds the world; used by rollback on the restored state.
    pub fn refine(
        &mut self,
        world: &mut World,
        marks: &[(u32, Scalar)],
        step: u64,
    ) -> Result<bool, MeshError> {
        let ops: Vec<_> = marks
            .iter()
            .map(|&(l, a)| (RedGreenOp::Split(l), Some(a)))
            .collect();
        self.apply(world, &ops, step)
    }

    /// Records a rollback of step `step`.
    pub fn note_rollback(&mut self, world: &World, step: u64) {
        self.stats.rollbacks += 1;
        let centre = world.x.iter().copied().sum::<Vector>() / world.x.len().max(1) as Scalar;
        self.events.push(AdaptEvent {
            kind: EventKind::Rollback,
            position: centre,
            level: 0,
            angle: None,
            step,
        });
    }

    /// Applies operations (each with the angle that asked for it), closes the
    /// mesh and moves the world onto it.
    pub fn apply(
        &mut self,
        world: &mut World,
        ops: &[(RedGreenOp, Option<Scalar>)],
        step: u64,
    ) -> Result<bool, MeshError> {
        let mut applied: Vec<Applied> = Vec::new();
        let plain: Vec<RedGreenOp> = ops.iter().map(|o| o.0).collect();
        self.hierarchy.apply(&plain, &mut applied);
        // The angle that asked for each operation (forced splits have none).
        let asked_for = |op: RedGreenOp| ops.iter().find(|o| o.0 == op).and_then(|o| o.1);
        let mut asked: Vec<Option<Scalar>> = applied.iter().map(|a| asked_for(a.op)).collect();
        let before = applied.len();
        self.hierarchy.close(&mut applied);
        asked.extend(std::iter::repeat_n(None, applied.len() - before));
        if applied.is_empty() {
            return Ok(false);
        }
        for (a, angle) in applied.iter().zip(asked) {
            let centre = a
                .vertices
                .iter()
                .map(|&v| world.x[v as usize])
                .sum::<Vector>()
                / 3.0;
            let kind = match a.op {
                RedGreenOp::Merge(_) => {
                    self.stats.merges += 1;
                    EventKind::Merge
                }
                RedGreenOp::Split(_) if a.forced => {
                    self.stats.splits += 1;
                    self.stats.closure_splits += 1;
                    EventKind::ClosureSplit
                }
                RedGreenOp::Split(_) => {
                    self.stats.splits += 1;
                    EventKind::Split
                }
            };
            let angle = if a.forced { None } else { angle };
            self.events.push(AdaptEvent {
                kind,
                position: centre,
                level: a.level,
                angle,
                step,
            });
        }
        self.stats.changed_passes += 1;
        self.stats.max_ops_per_pass = self.stats.max_ops_per_pass.max(applied.len() as u64);
        self.rebuild_world(world)?;
        Ok(true)
    }

    /// Builds the conforming mesh from the hierarchy, compacts the vertices and
    /// transfers the world's state onto it.
    fn rebuild_world(&mut self, world: &mut World) -> Result<(), MeshError> {
        let (tris, levels, owner) = self.hierarchy.build();
        let (first_new, created) = self.hierarchy.created();
        let (map, remeshed) = compact(self.hierarchy.material(), first_new, created, &tris, levels);
        let material = remeshed.material.clone();
        transfer(world, self.density, remeshed)?;
        self.hierarchy.remap(&map, &material);
        self.owner = owner;
        Ok(())
    }
}

impl Adapter {
    /// The stated minimum angle of the edge method, degrees (`None` for red_green).
    pub fn min_angle(&self) -> Option<Scalar> {
        self.edge.map(|l| l.min_angle)
    }

    /// One pass of paper B's method: split edges above the upper threshold
    /// (longest-edge bisection), flip around the new vertices for quality, then
    /// collapse short edges at vertices whose every edge is flat.
    fn edge_pass(
        &mut self,
        world: &mut World,
        step: u64,
        limits: edge::Limits,
    ) -> Result<bool, MeshError> {
        let angles = edge_angles(world);
        self.stats.passes += 1;
        let m = &world.mesh;
        let mut soup = edge::Soup::new(&m.material, &m.triangles, &m.levels);
        let mut ops = Vec::new();
        let mut marks: Vec<(usize, Scalar)> = angles
            .iter()
            .enumerate()
            .filter(|(_, a)| **a > self.config.refine_angle)
            .map(|(e, a)| (e, *a))
            .collect();
        marks.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
        let mut asked: HashMap<(u32, u32), Scalar> = HashMap::new();
        for &(e, a) in &marks {
            let [p, q] = m.edges[e].vertices;
            asked.insert((p.min(q), p.max(q)), a);
            soup.split(p, q, &limits, &mut ops, 0);
        }
        let seeds: Vec<u32> = (soup.first_new..soup.material.len() as u32).collect();
        soup.flip_around(&seeds, &limits, &mut ops);
        // Flat vertices: every edge at them below both thresholds' limit.
        let flat_limit = self
            .config
            .coarsen_angle
            .min(0.5 * self.config.refine_angle);
        let mut vertex_max = vec![0.0 as Scalar; m.vertex_count()];
        for (e, edge) in m.edges.iter().enumerate() {
            for &v in &edge.vertices {
                vertex_max[v as usize] = vertex_max[v as usize].max(angles[e]);
            }
        }
        let mut pinned = vec![false; m.vertex_count()];
        for a in &world.pins.anchors {
            pinned[a.vertex as usize] = true;
        }
        let mut by_length: Vec<(Scalar, u32, u32)> = m
            .edges
            .iter()
            .filter(|e| {
                e.vertices
                    .iter()
                    .all(|&v| vertex_max[v as usize] < flat_limit)
            })
            .map(|e| {
                let [a, b] = e.vertices;
                (
                    m.material[a as usize].distance(m.material[b as usize]),
                    a,
                    b,
                )
            })
            .filter(|&(len, _, _)| len < limits.collapse_below)
            .collect();
        by_length.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        for (_, a, b) in by_length {
            // Remove the vertex made later (refinement vertices carry larger ids).
            let (v, u) = if a > b { (a, b) } else { (b, a) };
            if !soup.collapse(v, u, &pinned, &limits, &mut ops) {
                soup.collapse(u, v, &pinned, &limits, &mut ops);
            }
        }
        if ops.is_empty() {
            return Ok(false);
        }
        let map = self.rebuild_from_soup(world, &soup)?;
        for op in &ops {
            let at = |v: u32| {
                world
                    .x
                    .get(map[v as usize] as usize)
                    .copied()
                    .unwrap_or(Vector::ZERO)
            };
            let (kind, position, angle) = match *op {
                edge::EdgeOp::Split(a, b) => {
                    self.stats.splits += 1;
                    (
                        EventKind::Split,
                        (at(a) + at(b)) * 0.5,
                        asked.get(&(a.min(b), a.max(b))).copied(),
                    )
                }
                edge::EdgeOp::Flip(a, b) => {
                    self.stats.flips += 1;
                    (EventKind::Flip, (at(a) + at(b)) * 0.5, None)
                }
                edge::EdgeOp::Collapse(_, u) => {
                    self.stats.merges += 1;
                    (EventKind::Collapse, at(u), None)
                }
            };
            let level = world.mesh.levels.iter().copied().max().unwrap_or(0);
            self.events.push(AdaptEvent {
                kind,
                position,
                level,
                angle,
                step,
            });
        }
        self.stats.changed_passes += 1;
        self.stats.max_ops_per_pass = self.stats.max_ops_per_pass.max(ops.len() as u64);
        Ok(true)
    }

    /// Compacts the soup's live vertices and moves the world onto it; returns the
    /// map from soup vertex ids to new indices (`u32::MAX` for removed ones).
    fn rebuild_from_soup(
        &mut self,
        world: &mut World,
        soup: &edge::Soup,
    ) -> Result<Vec<u32>, MeshError> {
        let (tris, levels) = soup.live();
        let (map, remeshed) = compact(&soup.material, soup.first_new, &soup.created, &tris, levels);
        transfer(world, self.density, remeshed)?;
        Ok(map)
    }
}

/// Keeps the vertices the triangles use, in their order: returns the map from
/// old ids to new indices (`u32::MAX` for dropped ones) and the new topology.
/// Ids below `first_new` are old world vertices; `created[k]` is the parent edge
/// of vertex `first_new + k`.
fn compact(
    material: &[Vector2],
    first_new: u32,
    created: &[(u32, u32)],
    tris: &[[u32; 3]],
    levels: Vec<u8>,
) -> (Vec<u32>, Remeshed) {
    let mut used = vec![false; material.len()];
    for t in tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut map = vec![u32::MAX; material.len()];
    let mut kept = Vec::new();
    for (v, _) in used.iter().enumerate().filter(|(_, u)| **u) {
        map[v] = kept.len() as u32;
        kept.push(v);
    }
    let origin = kept
        .iter()
        .map(|&v| {
            if (v as u32) < first_new {
                Origin::Old(v as u32)
            } else {
                let (a, b) = created[v - first_new as usize];
                Origin::Midpoint(map[a as usize], map[b as usize])
            }
        })
        .collect();
    let remeshed = Remeshed {
        material: kept.iter().map(|&v| material[v]).collect(),
        triangles: tris.iter().map(|t| t.map(|v| map[v as usize])).collect(),
        levels,
        origin,
    };
    (map, remeshed)
}
