//! Paper A's state between passes: the refinement hierarchy (`red_green.rs`),
//! the criterion's marks for a pass with the merges the level rule refuses,
//! the world rebuilt from the hierarchy, and the counters of what a pass did
//! (`red_green_apply.rs` runs the pass).

use std::collections::{HashMap, HashSet};

use super::decision::{Reading, Reason, Refusal};
use super::gate::PassSize;
use super::red_green::{Applied, RedGreen, RedGreenOp};
use super::transfer::{Origin, PanelCorners, VertexOrder, compact, transfer};
use super::{AdaptConfig, AdaptEvent, EventKind, Measured};
use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::spec::AdaptCriterion;
use crate::world::World;

/// Nodes of the hierarchy to merge or split, each with why.
pub(super) type Marks = Vec<(u32, Reason)>;

/// What the criterion asks of one pass.
pub(super) struct PassMarks {
    /// Parents to merge (their children may merge by the level rule).
    pub(super) merges: Marks,
    /// Leaves to split.
    pub(super) splits: Marks,
    /// Parents the criterion would merge that a neighbour two splits finer
    /// keeps, each with the parent's reading.
    pub(super) kept: Vec<(u32, Reading)>,
}

/// What the red-green method keeps between passes: the hierarchy, which leaf
/// owns each triangle of the world's mesh, and what decides bounces.
#[derive(Debug, Clone)]
pub(super) struct RedGreenState {
    pub(super) hierarchy: RedGreen,
    /// Leaf of the hierarchy that owns each triangle of the world's mesh.
    pub(super) owner: Vec<u32>,
    /// The parents the latest pass merged, sorted (a split of one of them by
    /// the criterion before the next pass is a bounce).
    pub(super) merged_last_pass: Vec<u32>,
    /// The parents [`Adapter::apply`] merged since the pass began.
    pub(super) pass_merges: Vec<u32>,
    /// Per parent: how many of its merges bounced (its sizing hysteresis is
    /// doubled that many times; dropped when the parent itself merges away).
    pub(super) bounces: HashMap<u32, u32>,
    /// The parents whose merge the level rule refused in the latest pass,
    /// sorted (a refusal is logged when it is new).
    refused_last_pass: Vec<u32>,
    /// The nodes a rollback's refinement split that no merge has undone.
    pub(super) rollback_parents: HashSet<u32>,
}

impl RedGreenState {
    /// The hierarchy of `world`'s mesh, its triangles at level 0.
    pub(super) fn new(world: &World) -> RedGreenState {
        let m = &world.mesh;
        let hierarchy = match m.panels() {
            None => RedGreen::new(&m.triangles, &m.material),
            Some(p) => {
                RedGreen::with_corners(&m.triangles, &m.material, &p.corners, &p.of_triangle)
            }
        };
        RedGreenState {
            hierarchy,
            owner: (0..world.mesh.triangles.len() as u32).collect(),
            merged_last_pass: Vec::new(),
            pass_merges: Vec::new(),
            bounces: HashMap::new(),
            refused_last_pass: Vec::new(),
            rollback_parents: HashSet::new(),
        }
    }

    /// The merges and the splits the criterion asks for, each with its reason,
    /// and the merges it asks for that a finer neighbour keeps.
    pub(super) fn marks(
        &self,
        c: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
        known: Measured,
    ) -> PassMarks {
        let parents = self.hierarchy.leaf_parents();
        let all: Vec<u32> = parents.iter().map(|p| p.0).collect();
        let (merge_ok, splits) = match c.criterion {
            AdaptCriterion::Angle => (
                self.merge_marks(c, world, angles, &all),
                self.refinement_marks(c, world, angles),
            ),
            AdaptCriterion::Sizing => {
                let curv = self.leaf_curvatures(c, world, angles, known.obstacle_planes);
                let merges = self.sizing_merge_marks(c, &curv, &all);
                (merges, self.sizing_refinement_marks(c, &curv))
            }
        };
        // Whether each parent may merge alone; `merge_ok` follows `parents`' order.
        let alone: HashMap<u32, bool> = parents.iter().copied().collect();
        let mut marks = PassMarks {
            merges: Vec::new(),
            splits: splits
                .into_iter()
                .map(|(l, reading)| {
                    (
                        l,
                        Reason::Criterion {
                            reading,
                            limit: 1.0,
                        },
                    )
                })
                .collect(),
            kept: Vec::new(),
        };
        for &(p, reading, limit) in &merge_ok {
            match alone.get(&p).copied().unwrap_or(false) {
                true => marks.merges.push((p, Reason::Criterion { reading, limit })),
                false => marks.kept.push((p, reading)),
            }
        }
        marks
    }

    /// What the pass of `marks` would do, as the remesh gate weighs it: the
    /// triangles of `world`'s mesh owned by the leaves it splits and by the
    /// children of the parents it merges (those the level rule lets merge),
    /// and its splits' largest reading.
    pub(super) fn pass_size(&self, world: &World, marks: &PassMarks) -> PassSize {
        let candidates: Vec<u32> = marks.merges.iter().map(|m| m.0).collect();
        let (merged, _) = self.hierarchy.select_merges(&candidates);
        let mut leaves: Vec<u32> = marks.splits.iter().map(|m| m.0).collect();
        for p in merged {
            leaves.extend(self.hierarchy.children(p).unwrap_or_default());
        }
        leaves.sort_unstable();
        let replaced = match leaves.is_empty() {
            true => 0,
            false => self
                .owner
                .iter()
                .filter(|l| leaves.binary_search(l).is_ok())
                .count(),
        };
        let worst_ratio = marks
            .splits
            .iter()
            .filter_map(|(_, r)| match r {
                Reason::Criterion { reading, .. } => Some(reading.ratio),
                _ => None,
            })
            .fold(0.0, Scalar::max);
        PassSize {
            replaced,
            triangles: world.mesh.triangles.len(),
            worst_ratio,
        }
    }

    /// The events of the merges the level rule refuses this pass that it did
    /// not refuse in the previous one (the criterion's merges a finer
    /// neighbour keeps, and those [`RedGreen::select_merges`] drops), at the
    /// world's positions before the pass.
    pub(super) fn refusal_events(
        &mut self,
        world: &World,
        marks: &PassMarks,
        step: u64,
    ) -> Vec<AdaptEvent> {
        let candidates: Vec<u32> = marks.merges.iter().map(|m| m.0).collect();
        let (_, dropped) = self.hierarchy.select_merges(&candidates);
        let reading_of = |p: u32| match marks.merges.iter().find(|m| m.0 == p) {
            Some((_, Reason::Criterion { reading, .. })) => *reading,
            _ => Reading::default(),
        };
        let mut refused: Vec<(u32, Refusal, Reading)> = marks
            .kept
            .iter()
            .map(|&(p, r)| (p, Refusal::NeighbourTwoFiner, r))
            .collect();
        refused.extend(
            dropped
                .iter()
                .map(|&(p, n)| (p, Refusal::MidpointsInUse(n), reading_of(p))),
        );
        refused.sort_by_key(|r| r.0);
        let events = refused
            .iter()
            .filter(|r| self.refused_last_pass.binary_search(&r.0).is_err())
            .map(|&(p, refusal, reading)| {
                let corners = self.node_corners(world, p);
                AdaptEvent {
                    kind: EventKind::MergeRefused,
                    position: (corners[0] + corners[1] + corners[2]) / 3.0,
                    level: self.hierarchy.level(p),
                    angle: Some(reading.angle),
                    step,
                    reason: Reason::Refused(refusal),
                    corners: Some(corners),
                }
            })
            .collect();
        self.refused_last_pass = refused.iter().map(|r| r.0).collect();
        events
    }

    /// The world positions of node `n`'s corners, before the pass's remesh: a
    /// vertex the pass made sits at the midpoint of its parent edge.
    pub(super) fn node_corners(&self, world: &World, n: u32) -> [Vector; 3] {
        self.hierarchy
            .vertices(n)
            .map(|v| vertex_position(world, &self.hierarchy, v))
    }

    /// Builds the conforming mesh from the hierarchy, compacts the vertices and
    /// transfers the world's state onto it; returns where the new vertices came
    /// from (the world and the hierarchy are unchanged on error).
    pub(super) fn rebuild_world(
        &mut self,
        world: &mut World,
        density: Scalar,
        alternate_diagonals: bool,
    ) -> Result<Vec<Origin>, MeshError> {
        let built = self.hierarchy.build_with_corners(alternate_diagonals);
        let (first_new, created) = self.hierarchy.created();
        let (map, mut remeshed) = compact(
            self.hierarchy.material(),
            (first_new, created),
            &built.triangles,
            built.levels,
            VertexOrder::FirstUse,
        );
        if world.mesh.panels().is_some() {
            remeshed.corners = Some(PanelCorners {
                corners: built.corners,
                of_triangle: built.panels,
            });
        }
        let origins = transfer(world, density, remeshed)?;
        // A garment's home coordinates are chosen by the transfer.
        self.hierarchy.remap(&map, &world.mesh.material);
        self.owner = built.owner;
        Ok(origins)
    }

    /// Counts the applied operations (merges, splits, bounces), turns the
    /// events of the criterion's splits that undo a merge into bounces, and
    /// keeps track of the nodes a rollback (`rollback`) split.
    pub(super) fn count(
        &mut self,
        applied: &[Applied],
        events: &mut [AdaptEvent],
        stats: &mut super::AdaptStats,
        rollback: bool,
    ) {
        for (a, event) in applied.iter().zip(events.iter_mut()) {
            match a.op {
                RedGreenOp::Merge(n) => {
                    stats.merges += 1;
                    self.pass_merges.push(n);
                    self.rollback_parents.remove(&n);
                    for c in a.children {
                        self.bounces.remove(&c);
                        self.rollback_parents.remove(&c);
                    }
                }
                RedGreenOp::Split(l) => {
                    stats.splits += 1;
                    stats.closure_splits += a.forced as u64;
                    if rollback {
                        self.rollback_parents.insert(l);
                    }
                    if !a.forced && self.merged_last_pass.binary_search(&l).is_ok() {
                        let bounces = self.bounces.entry(l).or_default();
                        *bounces += 1;
                        stats.bounces += 1;
                        event.kind = EventKind::Bounce;
                        if let Reason::Criterion { reading, .. } = event.reason {
                            event.reason = Reason::Bounce {
                                reading,
                                bounces: *bounces,
                            };
                        }
                    }
                }
            }
        }
    }
}

/// The world position of vertex `v` of the hierarchy before the pass's
/// remesh: its own for a vertex of the world's mesh, the midpoint of its
/// parent edge for one the pass made.
pub(super) fn vertex_position(world: &World, h: &RedGreen, v: u32) -> Vector {
    if let Some(&x) = world.x.get(v as usize) {
        return x;
    }
    let (first_new, created) = h.created();
    match v
        .checked_sub(first_new)
        .and_then(|k| created.get(k as usize))
    {
        Some(&(a, b)) => 0.5 * (vertex_position(world, h, a) + vertex_position(world, h, b)),
        // Every vertex of the hierarchy is the world's or made by the pass.
        None => unreachable!("vertex {v} is neither the world's nor made by the pass"),
    }
}
