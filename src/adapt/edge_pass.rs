//! Paper B's pass on the adapter: marks edges, runs the soup's operations
//! (`edge.rs`, `soup.rs`), moves the world onto the result and reports events.

use std::collections::HashMap;

use super::transfer::{PanelCorners, VertexOrder, compact, transfer};
use super::{
    AdaptConfig, AdaptEvent, Adapter, EventKind, MethodState, Reading, Reason, edge, edge_angles,
};
use crate::math::{Scalar, Vector};
use crate::mesh::MeshError;
use crate::spec::AdaptCriterion;
use crate::world::World;

impl Adapter {
    /// The stated minimum angle of the edge method, degrees (`None` for red_green).
    pub fn min_angle(&self) -> Option<Scalar> {
        match &self.method {
            MethodState::Edge(l) => Some(l.min_angle),
            _ => None,
        }
    }

    /// One pass of paper B's method: split edges above the upper threshold
    /// (longest-edge bisection), flip around the new vertices for quality, then
    /// collapse short edges at vertices whose every edge is flat.
    pub(super) fn edge_pass(
        &mut self,
        c: &AdaptConfig,
        world: &mut World,
        step: u64,
        limits: edge::Limits,
    ) -> Result<bool, MeshError> {
        let angles = edge_angles(world);
        self.stats.passes += 1;
        let m = &world.mesh;
        let mut soup = edge::Soup::of_mesh(m);
        let mut ops = Vec::new();
        let mut marks: Vec<(usize, Scalar)> = angles
            .iter()
            .enumerate()
            .filter(|(_, a)| **a > c.refine_angle)
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
        let by_length = collapse_candidates(c, world, &angles, &limits);
        let mut pinned = vec![false; m.vertex_count()];
        for a in &world.pins.anchors {
            pinned[a.vertex as usize] = true;
        }
        for (_, a, b) in by_length {
            // Remove the vertex made later (refinement vertices carry larger ids).
            let (v, u) = if a > b { (a, b) } else { (b, a) };
            if !soup.collapse(v, u, &pinned, &limits, &mut ops) {
                soup.collapse(u, v, &pinned, &limits, &mut ops);
            }
        }
        let max_level = c.max_level;
        if ops.is_empty() {
            self.stats.note_levels(world, max_level);
            return Ok(false);
        }
        if cfg!(debug_assertions)
            && let Err(e) = soup.check_tables()
        {
            panic!("edge method soup after {} operations: {e}", ops.len());
        }
        let map = self.rebuild_from_soup(world, &soup)?;
        self.report_edge_ops(world, &ops, &map, &asked, (c.refine_angle, step));
        self.stats.changed_passes += 1;
        self.stats.max_ops_per_pass = self.stats.max_ops_per_pass.max(ops.len() as u64);
        self.stats.note_levels(world, max_level);
        self.debug_check(world);
        Ok(true)
    }

    /// Counts the pass's operations and reports them as events, at the world's
    /// new positions (`map` takes soup vertex ids to the new indices).
    fn report_edge_ops(
        &mut self,
        world: &World,
        ops: &[edge::EdgeOp],
        map: &[u32],
        asked: &HashMap<(u32, u32), Scalar>,
        (refine_angle, step): (Scalar, u64),
    ) {
        for op in ops {
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
            let reason = match (kind, angle) {
                (EventKind::Flip, _) => Reason::Quality,
                (EventKind::Collapse, _) => Reason::Flat,
                (_, Some(a)) => Reason::Criterion {
                    reading: Reading::of_angle(a, refine_angle),
                    limit: 1.0,
                },
                (_, None) => Reason::Given { angle: None },
            };
            let level = world.mesh.levels.iter().copied().max().unwrap_or(0);
            self.events.push(AdaptEvent {
                kind,
                position,
                level,
                angle,
                step,
                reason,
                corners: None,
            });
        }
    }

    /// Compacts the soup's live vertices and moves the world onto it; returns the
    /// map from soup vertex ids to new indices (`u32::MAX` for removed ones).
    fn rebuild_from_soup(
        &mut self,
        world: &mut World,
        soup: &edge::Soup,
    ) -> Result<Vec<u32>, MeshError> {
        let (tris, levels) = soup.live();
        let (map, mut remeshed) = compact(
            &soup.material,
            (soup.first_new, &soup.created),
            &tris,
            levels,
            VertexOrder::Kept,
        );
        if world.mesh.panels().is_some() {
            let (corners, of_triangle) = soup.live_corners();
            remeshed.corners = Some(PanelCorners {
                corners,
                of_triangle,
            });
        }
        self.last_origins = transfer(world, self.density, remeshed)?;
        Ok(map)
    }
}

/// Edges shorter than the collapse limit whose both ends are flat (every
/// edge at them below both thresholds' limit), shortest first.
fn collapse_candidates(
    c: &AdaptConfig,
    world: &World,
    angles: &[Scalar],
    limits: &edge::Limits,
) -> Vec<(Scalar, u32, u32)> {
    let m = &world.mesh;
    // Flat vertices: every edge at them below both thresholds' limit, or
    // for the sizing criterion (`sizing.rs`) below refine / (2 hysteresis).
    let flat_limit = match c.criterion {
        AdaptCriterion::Angle => c.coarsen_angle.min(0.5 * c.refine_angle),
        AdaptCriterion::Sizing => 0.5 * c.refine_angle / c.hysteresis,
    };
    let mut vertex_max = vec![0.0 as Scalar; m.vertex_count()];
    for (e, edge) in m.edges.iter().enumerate() {
        for &v in &edge.vertices {
            vertex_max[v as usize] = vertex_max[v as usize].max(angles[e]);
        }
    }
    let mut by_length: Vec<(Scalar, u32, u32)> = (0..m.edges.len())
        .filter(|&e| {
            m.edges[e]
                .vertices
                .iter()
                .all(|&v| vertex_max[v as usize] < flat_limit)
        })
        .map(|e| {
            let [a, b] = m.edges[e].vertices;
            (m.rest_length(e), a, b)
        })
        .filter(|&(len, _, _)| len < limits.collapse_below)
        .collect();
    by_length.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    by_length
}
