//! The sizing criterion: a target size from the curvature, so that
//! only the folds reach the finest level and a region coarsens again once a
//! fold has passed.
//!
//! Derivation. Two triangles whose centroids are `d` apart (material space)
//! on a surface bent with normal curvature `kappa` across their common edge
//! have normals about `kappa * d` apart: the normals turn by the arc between
//! the centroids over the radius. So the dihedral angle divided by the
//! centroid distance, `kappa_e = theta_e / d_e` (rad/m), estimates the
//! curvature across edge `e` independently of the size of the triangles at it
//! (an edge between a fine and a coarse triangle gets the mean of their
//! spacings as `d_e`, which is what the angle measured across it spans). A
//! triangle's curvature is the largest of its edges' (the largest principal
//! curvature, up to the orientation of its edges).
//!
//! A triangle's size is its centroid spacing `D = 4 A / (3 l_max)`, A its
//! material area and `l_max` its longest edge: twice the distance from its
//! centroid to its longest edge, i.e. the exact distance to the centroid of
//! its mirror image across that edge, the closest neighbour it can have (for
//! the right isosceles grid triangles with legs `a`: `0.471 a`, the distance
//! across the hypotenuse; across a leg it is `0.745 a`; equilateral, side
//! `s`: `0.577 s` across every edge). A 1-4 split halves `D` exactly. So on a
//! grid the rule below refines a triangle where the angle criterion would
//! refine at its hypotenuse, and holds its legs to the same curvature (a leg
//! triggers at 15 * 0.745 / 0.471 = 23.7 deg instead of 15).
//! (`D = (2/3) sqrt(2 A)`, between the two, would ask about 1.4 times the
//! curvature of the angle criterion's legs and refine more, with more
//! rollbacks.)
//!
//! Rule, with the budget `theta_b = refine_angle`:
//! - the target spacing of a triangle is `D* = theta_b / kappa` (no target,
//!   i.e. no refinement, where `kappa = 0`), clamped by `max_level` and
//!   `min_edge_length` like every split;
//! - refine a leaf when `D > D*`, i.e. `kappa * D > theta_b`;
//! - merge four children when their parent would still be finer than its
//!   target by the factor `hysteresis` (H > 1): `kappa_p * D_p <= theta_b / H`,
//!   with `kappa_p` the largest curvature at the children's edges and
//!   `D_p = 2 D_child`. A merged parent then carries at most `theta_b / H` at
//!   the curvature measured, so the next pass does not split it again
//!   (the papers' criterion has the same margin only through `coarsen_angle`
//!   on the children's angles: merging at 1.5 deg means a parent angle of about
//!   3 deg against 15, an effective H of 5, which is why regions stay refined
//!   long after a fold has passed).
//!
//! Against the angle criterion this changes two things: the threshold is per
//! unit length, so a diagonal edge (centroids 0.47 a apart) and a leg (0.75 a)
//! of a grid are held to the same curvature instead of the same angle, and the
//! coarsening threshold is tied to the refinement one by H instead of being a
//! separate, much lower angle.
//!
//! On hanging_sheet, tablecloth, flag and drape_sphere it carries 11 to 44 %
//! fewer vertices than the angle criterion, though
//! the last three are curved past the budget almost everywhere (61 to 72 % of
//! their triangles at the finest level on average). The default hysteresis is
//! 2: 3 gives more vertices and no fewer passes that change the mesh.
//!
//! # Strain jumps (`refine_strain`, off by default)
//! Curvature cannot see where the membrane strain concentrates. A sheet hung
//! from two point pins (`hanging_sheet_rest`) stretches most at the pins, a
//! singularity a finer mesh resolves further (a point load's displacement
//! grows like the log of the mesh size), so the whole sheet hangs a few
//! millimetres lower on each finer mesh: at rest, uniform 16 against uniform
//! 64, every vertex of the lower two thirds sat 4.8 to 5.3 mm apart (the
//! largest gaps, 18 to 32 mm, were along the swag of the top edge). The
//! uniform runs converge at only about first order there, and a curvature
//! rule leaves the pins coarse.
//!
//! The indicator: the Green strain `E = (F^T F - I) / 2` of each triangle (in
//! material axes, so neighbours compare directly) and, per interior edge, the
//! Frobenius norm of the difference between its two triangles' strains. Where
//! the strain is smooth the jump is about `|grad E| d` and halves with every
//! split, as `kappa * D` does; at a point pin it stays of order one however
//! fine the mesh, so the rule grades the mesh down to `max_level` there (the
//! mesh an a-posteriori estimator of the Zienkiewicz-Zhu kind asks for). A
//! leaf splits when a jump at its edges exceeds `refine_strain`; four children
//! merge only when twice their largest jump is at most `refine_strain / H`.
//! Red-green only (the edge method's collapse test has no such term).
//!
//! On `hanging_sheet_rest` (`drape bench`, red_green 16 L4 against uniform 64)
//! the term brings the error at rest from about 3 times uniform 64's to within
//! 10 to 30 % of it at under half its time; with base 8, `max_level = 6`, 8 /
//! 0.8 deg and no rollback, `refine_strain = 0.04` is within 7 % of uniform
//! 64's error at about 0.2 of its time. Not the default: it is measured on one
//! scene.
//!
//! # What neither measure sees: folds the coarse mesh has not formed
//! Both measures judge the mesh by what it shows, so they cannot refine a
//! feature that the coarse mesh does not form. On `hanging_sheet_rest` at
//! uniform 128's finest edges (from `drape bench`'s per-point errors) the
//! adaptive runs' remaining error is the folds of the sheet's lower half: a
//! few millimetres deep, they have
//! 0.24 to 0.58 of the reference's depth on a base of 16 or 32 (uniform 128
//! 0.74 to 0.83), and there the base-16 run's dihedral angles stay below
//! 5.7 deg, under a 6 deg budget, so nothing refines them; from a base of
//! 64 (8 deg, `refine_strain = 0.04`) the run has 0.94 of uniform 128's
//! error at 0.18 of its time. Lower angles (5 and 4 deg) add vertices, not
//! accuracy. A compression term (ARCSim refines where the cloth is
//! compressed, where it will buckle) would not help here: the compressed area
//! is the same on every mesh (about two thirds of the sheet), so it would
//! refine that whatever the folds do.
//!
//! # Bounces (the churn at rest)
//! Judging a merge by the children's measures assumes that the merged parent
//! will measure what they predict. Where the coarse mesh is too coarse for the
//! solution it is not so: right after the merge the positions are the fine
//! mesh's, but within the steps to the next pass the coarse mesh relaxes to
//! its own equilibrium, and that one has the larger curvature or strain jump
//! the split test then finds. So the next pass would split the parent again,
//! the fine mesh relax back, the pass after merge it, and so on for as long as
//! the run lasts, each pass paying a new ordering and factorization (on
//! `hanging_sheet_rest` with base 8 and `max_level = 6`, a parent whose
//! children's largest strain jump is 0.0033, merge allowed up to 0.01, has
//! green halves 0.030 apart four steps after the merge, split above 0.02).
//!
//! A merge that the criterion splits again before the next pass has run is a
//! *bounce* (counted as `bounces` in the summary's `adapt`): the coarse mesh
//! has shown that it does not hold that region. Each bounce doubles that
//! parent's hysteresis `H` in the merge test (for both measures), so it merges
//! again only when its children's measures have fallen that much further, as
//! they do when a fold has passed and not while the sheet hangs still. The
//! count is dropped when the parent itself merges away into its own parent.
//! The run above then bounces 14 times and its mesh stops changing (test
//! `a_sheet_at_rest_stops_remeshing`); a run that never bounces is the same
//! as without the rule.
//!
//! Predicting the merged parent's measures at the current positions does not
//! stop the churn, since what the merge changes is the positions, by the
//! relaxation above.
//!
//! The edge method (paper B) with this criterion keeps its splits (an edge's
//! measured angle is its own `kappa_e * d_e`, so the rule is the angle rule
//! there) and coarsens by the same hysteresis: a vertex's edges may collapse
//! when twice its largest angle (a collapse about doubles the spacing) is at
//! most `theta_b / H`.

use std::collections::HashMap;

use super::AdaptConfig;
use super::decision::{Reading, Term};
use super::proximity::edge_obstacle_lean;
use super::red_green_pass::RedGreenState;
use crate::collide::ObstaclePlane;
use crate::math::{Scalar, Vector2};
use crate::mesh::{Edge, Mesh, NO_TRIANGLE};
use crate::world::World;

/// How many bounces (module docs) double a parent's hysteresis at most: 2^30
/// is past any measure, so the parent stays split for good; the limit only
/// keeps the factor finite.
const MAX_DOUBLINGS: u32 = 30;

/// Centroid spacing of a material triangle, m: `4 A / (3 l_max)`, the distance
/// from its centroid to that of its mirror image across its longest edge (see
/// the module notes).
pub fn spacing(p: [Vector2; 3]) -> Scalar {
    let area = 0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]).abs();
    let longest = (0..3)
        .map(|k| p[k].distance(p[(k + 1) % 3]))
        .fold(0.0, Scalar::max);
    if longest > 0.0 {
        4.0 * area / (3.0 * longest)
    } else {
        0.0
    }
}

/// Curvature across each edge of the world's mesh, rad/m: the dihedral angle
/// (`angles`, degrees, from [`super::edge_angles`]) over the distance between
/// the material centroids of the two triangles at it (0 at boundary edges).
pub fn edge_curvatures(world: &World, angles: &[Scalar]) -> Vec<Scalar> {
    let m = &world.mesh;
    m.edges
        .iter()
        .zip(angles)
        .map(|(e, &deg)| edge_curvature(world, e, deg))
        .collect()
}

/// Curvature across one edge of the world's mesh whose dihedral angle is `deg`
/// degrees, rad/m (see [`edge_curvatures`]).
pub fn edge_curvature(world: &World, e: &Edge, deg: Scalar) -> Scalar {
    if !e.is_interior() || deg <= 0.0 {
        return 0.0;
    }
    let d = centroid_distance(&world.mesh, e);
    if d > 0.0 { deg.to_radians() / d } else { 0.0 }
}

/// The distance between the material centroids of the two triangles at interior
/// edge `e`, m. Across a garment's welded seam the second triangle is unfolded
/// into the first's pattern about the edge (`Mesh::unfold`).
fn centroid_distance(m: &Mesh, e: &Edge) -> Scalar {
    let [t0, t1] = e.triangles.map(|t| t as usize);
    let centroid = |p: [Vector2; 3]| p.into_iter().sum::<Vector2>() / 3.0;
    if m.panels().is_none() {
        return centroid(m.corners(t0)).distance(centroid(m.corners(t1)));
    }
    let edge = e.vertices;
    let tip = m.opposite_vertex(t1 as u32, e);
    let [a, b] = edge.map(|v| m.corner_at(t0, v));
    let other = [a, b, m.unfold(t0, t1, edge, tip)];
    centroid(m.corners(t0)).distance(centroid(other))
}

/// The membrane (Green) strain of world triangle `t` in material axes,
/// `[E_uu, E_vv, E_uv]`, from its deformation gradient `F = [x1 - x0, x2 - x0]
/// [m1 - m0, m2 - m0]^-1`: `E = (F^T F - I) / 2`.
pub fn triangle_strain(world: &World, t: u32) -> [Scalar; 3] {
    let tri = world.mesh.triangles[t as usize];
    let [m0, m1, m2] = world.mesh.corners(t as usize);
    let [x0, x1, x2] = tri.map(|v| world.x[v as usize]);
    let (d1, d2, e1, e2) = (m1 - m0, m2 - m0, x1 - x0, x2 - x0);
    let det = d1.perp_dot(d2);
    let fu = (e1 * d2.y - e2 * d1.y) / det;
    let fv = (e2 * d1.x - e1 * d2.x) / det;
    [
        0.5 * (fu.dot(fu) - 1.0),
        0.5 * (fv.dot(fv) - 1.0),
        0.5 * fu.dot(fv),
    ]
}

/// How much the membrane strain jumps across edge `e` of the world's mesh: the
/// Frobenius norm of the difference of its two triangles' strains (0 at boundary
/// edges). See the module docs, "Strain jumps".
pub fn edge_strain_jump(world: &World, e: &Edge) -> Scalar {
    if !e.is_interior() {
        return 0.0;
    }
    let [a, b] = [e.triangles[0], e.triangles[1]].map(|t| triangle_strain(world, t));
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (d[0] * d[0] + d[1] * d[1] + 2.0 * d[2] * d[2]).sqrt()
}

/// What the sizing criterion measured at one leaf of the hierarchy, over the
/// edges of the world triangles it owns (0 where nothing was measured).
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct LeafMeasure {
    /// The largest curvature, rad/m.
    pub kappa: Scalar,
    /// The largest dihedral angle, degrees.
    pub angle: Scalar,
    /// The largest strain jump (0 unless `refine_strain` is set).
    pub jump: Scalar,
    /// The largest lean towards an obstacle (0 unless `refine_obstacle` is
    /// set and the pass was given the obstacles' planes; `proximity.rs`).
    pub lean: Scalar,
}

impl LeafMeasure {
    fn max(self, o: LeafMeasure) -> LeafMeasure {
        LeafMeasure {
            kappa: self.kappa.max(o.kappa),
            angle: self.angle.max(o.angle),
            jump: self.jump.max(o.jump),
            lean: self.lean.max(o.lean),
        }
    }
}

/// Per leaf of the hierarchy: its [`LeafMeasure`].
#[derive(Debug, Default)]
pub(super) struct LeafCurvature {
    by_leaf: HashMap<u32, LeafMeasure>,
}

impl LeafCurvature {
    /// What was measured at leaf `l`.
    pub(super) fn get(&self, l: u32) -> LeafMeasure {
        self.by_leaf.get(&l).copied().unwrap_or_default()
    }
}

impl RedGreenState {
    /// The curvature of every leaf from the edge angles of the world's mesh
    /// (and the strain jumps, when `refine_strain` is set, and the leans towards
    /// the obstacles whose `planes` are given, one per vertex, when
    /// `refine_obstacle` is set).
    pub(super) fn leaf_curvatures(
        &self,
        c: &AdaptConfig,
        world: &World,
        angles: &[Scalar],
        planes: &[ObstaclePlane],
    ) -> LeafCurvature {
        let kappa = edge_curvatures(world, angles);
        let strain = c.refine_strain.is_some();
        let planes = if c.refine_obstacle.is_some() {
            debug_assert!(planes.is_empty() || planes.len() == world.x.len());
            planes
        } else {
            &[]
        };
        let mut by_leaf: HashMap<u32, LeafMeasure> = HashMap::new();
        for (e, edge) in world.mesh.edges.iter().enumerate() {
            let here = LeafMeasure {
                kappa: kappa[e],
                angle: angles[e],
                jump: if strain {
                    edge_strain_jump(world, edge)
                } else {
                    0.0
                },
                lean: edge_obstacle_lean(&world.x, planes, edge),
            };
            for &t in edge.triangles.iter().filter(|&&t| t != NO_TRIANGLE) {
                let m = by_leaf.entry(self.owner[t as usize]).or_default();
                *m = m.max(here);
            }
        }
        LeafCurvature { by_leaf }
    }

    /// Centroid spacing of hierarchy node `n`, m.
    pub(super) fn node_spacing(&self, n: u32) -> Scalar {
        spacing(self.hierarchy.corners(n))
    }

    /// Leaves coarser than their target (`kappa * D > refine_angle`, or a strain
    /// jump above `refine_strain`) that may still split, each with its reading.
    pub(super) fn sizing_refinement_marks(
        &self,
        c: &AdaptConfig,
        curv: &LeafCurvature,
    ) -> Vec<(u32, Reading)> {
        let mut marks: Vec<(u32, Reading)> = curv
            .by_leaf
            .iter()
            .filter(|&(&l, m)| self.sizing_leaf_wants_split(c, l, m) && self.may_split(c, l))
            .map(|(&l, m)| (l, self.sizing_reading(c, m, self.node_spacing(l), 1.0)))
            .collect();
        marks.sort_by_key(|m| m.0);
        marks
    }

    /// True when the sizing criterion asks to split leaf `l`, measured `m`: one
    /// of [`RedGreenState::sizing_wants_split`] and the obstacle term.
    pub(super) fn sizing_leaf_wants_split(&self, c: &AdaptConfig, l: u32, m: &LeafMeasure) -> bool {
        self.sizing_wants_split(c, l, m.kappa, m.jump) || obstacle_wants_split(c, m.lean)
    }

    /// The sizing criterion's reading of a node of centroid spacing `spacing`
    /// whose edges measured `m`, each term over its threshold; the strain and
    /// obstacle terms scaled by `scale` (2 for a merged parent, whose spacing
    /// the jumps span doubles).
    pub(super) fn sizing_reading(
        &self,
        c: &AdaptConfig,
        m: &LeafMeasure,
        spacing: Scalar,
        scale: Scalar,
    ) -> Reading {
        let mut terms = vec![(
            Term::Curvature,
            m.kappa * spacing / c.refine_angle.to_radians(),
        )];
        if let Some(s) = c.refine_strain {
            terms.push((Term::Strain, scale * m.jump / s));
        }
        if let Some(r) = c.refine_obstacle {
            terms.push((Term::Obstacle, scale * m.lean / r));
        }
        Reading::largest(&terms, m.angle)
    }

    /// True when leaf `l`, with curvature `kappa` (rad/m) and strain jump `jump`
    /// measured at it, is coarser than its target: `kappa * D > refine_angle`,
    /// or `jump > refine_strain` when that is set.
    pub(super) fn sizing_wants_split(
        &self,
        c: &AdaptConfig,
        l: u32,
        kappa: Scalar,
        jump: Scalar,
    ) -> bool {
        // The strain test first: it needs no spacing.
        c.refine_strain.is_some_and(|s| jump > s)
            || kappa * self.node_spacing(l) > c.refine_angle.to_radians()
    }

    /// Parents whose four leaf children would, merged, still be finer than
    /// their target by the hysteresis: `kappa_p * 2 D_child <= refine_angle / H`,
    /// and with `refine_strain` set, twice the children's largest strain jump
    /// (a merge doubles the spacing the jump spans) at most `refine_strain / H`.
    /// Of `parents` (nodes whose children are leaves), each with the merged
    /// parent's reading and the ratio it stays under (`1 / H`).
    ///
    /// A parent whose merges bounced (module docs, "Bounces") is held to `H`
    /// doubled once per bounce.
    pub(super) fn sizing_merge_marks(
        &self,
        c: &AdaptConfig,
        curv: &LeafCurvature,
        parents: &[u32],
    ) -> Vec<(u32, Reading, Scalar)> {
        let mut out = Vec::new();
        for &p in parents {
            let bounced = self.bounces.get(&p).copied().unwrap_or(0);
            let h = c.hysteresis * Scalar::powi(2.0, bounced.min(MAX_DOUBLINGS) as i32);
            let limit = c.refine_angle.to_radians() / h;
            let children = self.hierarchy.children(p).unwrap_or_default();
            let m = children
                .iter()
                .map(|&child| curv.get(child))
                .fold(LeafMeasure::default(), LeafMeasure::max);
            let strain_ok = c.refine_strain.is_none_or(|s| 2.0 * m.jump <= s / h);
            let obstacle_ok = c.refine_obstacle.is_none_or(|r| 2.0 * m.lean <= r / h);
            let spacing = self.node_spacing(p);
            if m.kappa * spacing <= limit && strain_ok && obstacle_ok {
                out.push((p, self.sizing_reading(c, &m, spacing, 2.0), 1.0 / h));
            }
        }
        out
    }

    /// True when leaf `l` may split: below the finest level and, with a
    /// minimum edge length, not making edges shorter than it.
    pub(super) fn may_split(&self, c: &AdaptConfig, l: u32) -> bool {
        let finer = self.hierarchy.level(l) as u32 + 2;
        let long_enough =
            c.min_edge_length <= 0.0 || 0.5 * self.hierarchy.shortest_edge(l) >= c.min_edge_length;
        finer <= c.max_level as u32 && long_enough
    }
}

/// True when a leaf whose edges lean towards an obstacle by `lean` at most
/// (`proximity.rs`) is too coarse there: `lean > refine_obstacle`.
fn obstacle_wants_split(c: &AdaptConfig, lean: Scalar) -> bool {
    c.refine_obstacle.is_some_and(|r| lean > r)
}
