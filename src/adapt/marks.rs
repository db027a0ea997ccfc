//! What the criteria measure and mark: the dihedral angle at every edge, the
//! leaves the angle criterion (or the sizing one, `sizing.rs`) asks to split,
//! the parents it lets merge, and the allocation-free check paper A's rollback
//! asks after every step.

use rayon::prelude::*;

use super::decision::Reading;
use super::red_green_pass::RedGreenState;
use super::{AdaptConfig, Adapter, MethodState, sizing};
use crate::math::Scalar;
use crate::spec::AdaptCriterion;
use crate::world::World;

/// Angle in degrees between the normals of the two triangles at each edge
/// (0 at boundary edges).
pub fn edge_angles(world: &World) -> Vec<Scalar> {
    let mut angles = Vec::new();
    edge_angles_into(world, &mut angles);
    angles
}

/// [`edge_angles`] into `out` (its buffer reused: no allocation once it has
/// grown to the mesh's edge count).
pub fn edge_angles_into(world: &World, out: &mut Vec<Scalar>) {
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
        .collect_into_vec(out);
}

impl Adapter {
    /// Leaves the criterion asks to split, with the (largest) angle that asked,
    /// from angles measured on the world's current shape (red-green only: the
    /// other methods mark nothing for paper A's rollback).
    pub fn refinement_marks(
        &self,
        config: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
    ) -> Vec<(u32, Scalar)> {
        self.rollback_marks(config, world, angles)
            .into_iter()
            .map(|(l, r)| (l, r.angle))
            .collect()
    }

    /// [`Adapter::refinement_marks`] with the criterion's reading at each leaf
    /// (what [`Adapter::note_rollback`] takes).
    pub fn rollback_marks(
        &self,
        config: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
    ) -> Vec<(u32, Reading)> {
        match &self.method {
            MethodState::RedGreen(rg) => {
                debug_assert_eq!(
                    !rg.refinement_marks(config, world, angles).is_empty(),
                    rg.needs_refinement(config, world, angles),
                    "needs_refinement disagrees with refinement_marks"
                );
                rg.refinement_marks(config, world, angles)
            }
            _ => Vec::new(),
        }
    }

    /// True when [`Adapter::refinement_marks`] would mark a leaf: the same rule,
    /// checked edge by edge without allocating (paper A's rollback asks it after
    /// every step, and nearly always gets no).
    pub fn needs_refinement(&self, config: &AdaptConfig, world: &World, angles: &[Scalar]) -> bool {
        match &self.method {
            MethodState::RedGreen(rg) => rg.needs_refinement(config, world, angles),
            _ => false,
        }
    }
}

impl RedGreenState {
    /// [`Adapter::needs_refinement`] of the red-green method.
    fn needs_refinement(&self, c: &AdaptConfig, world: &World, angles: &[Scalar]) -> bool {
        let sizing = c.criterion == AdaptCriterion::Sizing;
        let strain = sizing && c.refine_strain.is_some();
        // The cheap test first: most leaves of a refined mesh are at the finest
        // level and may not split, and for them nothing is measured. The edge's
        // curvature and strain jump are measured once, for its first leaf that
        // may split.
        world.mesh.edges.iter().enumerate().any(|(e, edge)| {
            let mut measured: Option<(Scalar, Scalar)> = None;
            edge.triangles
                .iter()
                .filter(|&&t| t != crate::mesh::NO_TRIANGLE)
                .any(|&t| {
                    let leaf = self.owner[t as usize];
                    if !self.may_split(c, leaf) {
                        return false;
                    }
                    if !sizing {
                        return angles[e] > c.refine_angle;
                    }
                    let (kappa, jump) = *measured.get_or_insert_with(|| {
                        let kappa = sizing::edge_curvature(world, edge, angles[e]);
                        let jump = if strain {
                            sizing::edge_strain_jump(world, edge)
                        } else {
                            0.0
                        };
                        (kappa, jump)
                    });
                    self.sizing_wants_split(c, leaf, kappa, jump)
                })
        })
    }

    /// [`Adapter::refinement_marks`] of the red-green method.
    pub(super) fn refinement_marks(
        &self,
        c: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
    ) -> Vec<(u32, Reading)> {
        if c.criterion == AdaptCriterion::Sizing {
            return self.sizing_refinement_marks(c, &self.leaf_curvatures(c, world, angles, &[]));
        }
        let mut marks: Vec<(u32, Reading)> = Vec::new();
        for (e, edge) in world.mesh.edges.iter().enumerate() {
            if angles[e] <= c.refine_angle {
                continue;
            }
            for &t in &edge.triangles {
                let leaf = self.owner[t as usize];
                if self.may_split(c, leaf) {
                    marks.push((leaf, Reading::of_angle(angles[e], c.refine_angle)));
                }
            }
        }
        marks.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.angle.total_cmp(&a.1.angle)));
        marks.dedup_by_key(|m| m.0);
        marks
    }

    /// Of `parents` (nodes whose children are leaves), those whose children may
    /// merge: every angle at the edges of their triangles is below the lower
    /// threshold, and below half the upper one (a merge about doubles the
    /// angles, so this keeps a merge from being split again at once when the
    /// thresholds are close). Each with the children's reading and the ratio
    /// it stays under.
    pub(super) fn merge_marks(
        &self,
        c: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
        parents: &[u32],
    ) -> Vec<(u32, Reading, Scalar)> {
        let leaf_max = self.leaf_max_angles(world, angles);
        let limit = c.coarsen_angle.min(0.5 * c.refine_angle);
        let mut out = Vec::new();
        for &p in parents {
            let children = self.hierarchy.children(p).unwrap_or_default();
            let worst = children
                .iter()
                .map(|c| leaf_max.get(c).copied().unwrap_or(0.0))
                .fold(0.0, Scalar::max);
            if worst < limit {
                let reading = Reading::of_angle(worst, c.refine_angle);
                out.push((p, reading, limit / c.refine_angle));
            }
        }
        out
    }

    /// The largest angle at the edges of each leaf's world triangles, degrees.
    pub(super) fn leaf_max_angles(
        &self,
        world: &World,
        angles: &[Scalar],
    ) -> std::collections::HashMap<u32, Scalar> {
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
        leaf_max
    }
}
