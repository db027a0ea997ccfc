//! The decision at every triangle of the world's mesh, as the criterion and the
//! level rule see it now (`decision.rs` has the values): read-only, for the
//! recording, which measures it on the frame's state without changing what
//! the passes decide.

use std::collections::{HashMap, HashSet};

use super::decision::{Reading, TriangleDecision, TriangleState};
use super::red_green_pass::RedGreenState;
use super::{AdaptConfig, Adapter, MethodState, edge_angles};
use crate::collide::ObstaclePlane;
use crate::math::Scalar;
use crate::spec::AdaptCriterion;
use crate::world::World;

impl Adapter {
    /// The criterion's reading and the state of every triangle of `world`'s
    /// mesh, in its triangle order. Red-green reads each leaf as its pass
    /// would (the sizing criterion's obstacle term from `obstacle_planes`, one
    /// per vertex, when `refine_obstacle` is set) and gives it to the leaf's
    /// triangles. The edge and tensor methods, and a garment waiting for its
    /// welds, read the angle criterion at each triangle, its state `AtMaxLevel`
    /// when it would refine at `max_level`, for the edge method `AtMinEdge` when
    /// it would refine but halving its longest edge (the split the method
    /// makes) would go below `min_edge_length`, and `Free` otherwise.
    pub fn decisions(
        &self,
        config: &AdaptConfig,
        world: &World,
        obstacle_planes: &[ObstaclePlane],
    ) -> Vec<TriangleDecision> {
        let angles = edge_angles(world);
        match &self.method {
            MethodState::RedGreen(rg) => rg.decisions(config, world, &angles, obstacle_planes),
            MethodState::Edge(limits) => {
                angle_decisions(config, world, &angles, Some(limits.min_edge))
            }
            MethodState::Tensor(_) | MethodState::AwaitingWelds => {
                angle_decisions(config, world, &angles, None)
            }
        }
    }
}

/// The angle criterion at each world triangle: its largest edge angle over
/// `refine_angle`, at `max_level` when it would refine there, and (with
/// `min_edge`, the edge method's limit) at the smallest edge when half its
/// longest material edge is below `min_edge`.
fn angle_decisions(
    c: &AdaptConfig,
    world: &World,
    angles: &[Scalar],
    min_edge: Option<Scalar>,
) -> Vec<TriangleDecision> {
    let m = &world.mesh;
    let mut largest = vec![0.0 as Scalar; m.triangles.len()];
    for (e, edge) in m.edges.iter().enumerate() {
        for &t in edge
            .triangles
            .iter()
            .filter(|&&t| t != crate::mesh::NO_TRIANGLE)
        {
            let a = &mut largest[t as usize];
            *a = a.max(angles[e]);
        }
    }
    let too_short = |t: usize| {
        min_edge.is_some_and(|min| {
            let p = m.corners(t);
            let longest = (0..3)
                .map(|k| p[k].distance(p[(k + 1) % 3]))
                .fold(0.0, Scalar::max);
            0.5 * longest < min
        })
    };
    largest
        .iter()
        .zip(&m.levels)
        .enumerate()
        .map(|(t, (&angle, &level))| {
            let reading = Reading::of_angle(angle, c.refine_angle);
            let wants = angle > c.refine_angle;
            let state = if wants && level >= c.max_level {
                TriangleState::AtMaxLevel
            } else if wants && too_short(t) {
                TriangleState::AtMinEdge
            } else {
                TriangleState::Free
            };
            TriangleDecision { reading, state }
        })
        .collect()
}

impl RedGreenState {
    /// [`Adapter::decisions`] of the red-green method.
    fn decisions(
        &self,
        c: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
        planes: &[ObstaclePlane],
    ) -> Vec<TriangleDecision> {
        let parents = self.hierarchy.leaf_parents();
        let all: Vec<u32> = parents.iter().map(|p| p.0).collect();
        let mut readings: HashMap<u32, (Reading, bool)> = HashMap::new();
        let merge_ok = match c.criterion {
            AdaptCriterion::Angle => {
                for (l, angle) in self.leaf_max_angles(world, angles) {
                    let reading = Reading::of_angle(angle, c.refine_angle);
                    readings.insert(l, (reading, angle > c.refine_angle));
                }
                self.merge_marks(c, world, angles, &all)
            }
            AdaptCriterion::Sizing => {
                let curv = self.leaf_curvatures(c, world, angles, planes);
                for &l in &self.owner {
                    let m = curv.get(l);
                    let reading = self.sizing_reading(c, &m, self.node_spacing(l), 1.0);
                    readings.insert(l, (reading, self.sizing_leaf_wants_split(c, l, &m)));
                }
                self.sizing_merge_marks(c, &curv, &all)
            }
        };
        let kept = self.kept_by_level_rule(&parents, &merge_ok);
        self.owner
            .iter()
            .map(|&leaf| {
                let (reading, wants) = readings.get(&leaf).copied().unwrap_or_default();
                let parent = self.hierarchy.parent(leaf);
                let state = if wants && !self.may_split(c, leaf) {
                    match self.hierarchy.level(leaf) as u32 + 2 > c.max_level as u32 {
                        true => TriangleState::AtMaxLevel,
                        false => TriangleState::AtMinEdge,
                    }
                } else if parent.is_some_and(|p| kept.contains(&p)) {
                    TriangleState::KeptByLevelRule
                } else if parent.is_some_and(|p| self.rollback_parents.contains(&p)) {
                    TriangleState::HeldByRollback
                } else {
                    TriangleState::Free
                };
                TriangleDecision { reading, state }
            })
            .collect()
    }

    /// The parents the criterion would merge (`merge_ok`) that the level rule
    /// keeps: a neighbour two splits finer, or neighbours keeping more than one
    /// edge midpoint (`parents`: every parent of leaves, with whether it could
    /// merge alone).
    fn kept_by_level_rule(
        &self,
        parents: &[(u32, bool)],
        merge_ok: &[(u32, Reading, Scalar)],
    ) -> HashSet<u32> {
        let alone: HashSet<u32> = parents.iter().filter(|p| p.1).map(|p| p.0).collect();
        let candidates: Vec<u32> = merge_ok
            .iter()
            .map(|m| m.0)
            .filter(|p| alone.contains(p))
            .collect();
        let (_, dropped) = self.hierarchy.select_merges(&candidates);
        merge_ok
            .iter()
            .map(|m| m.0)
            .filter(|p| !alone.contains(p))
            .chain(dropped.iter().map(|d| d.0))
            .collect()
    }
}
