//! Paper A's multirate stepping for the explicit integrators: each level of the
//! adapted mesh takes its own time step. Symplectic Euler uses the kick-drift
//! scheme below; RK4 is in [`rk4_multirate`].
//!
//! A vertex's level is the highest level of its triangles. Paper A divides the
//! step by sqrt(2) per level, `t_L = t_0 / 2^(L/2)` (a 1-4 split adds two levels
//! and halves the edges, and with stiffness held per area the stability limit
//! of symplectic Euler halves with the edge length). Here level `L` takes
//! `2^ceil(L/2)` substeps per macro step `t_0`, so that the substeps nest:
//! exactly paper A's step for even levels, sqrt(2) shorter for the odd (1-2
//! closure) levels. `t_0` is the largest step for which every level's substep
//! is within that level's own stability estimate (0.4 of its vertices'
//! Gershgorin limits).
//!
//! While a level is stepped, paper A keeps the other levels' motion unchanged
//! (zero acceleration): they keep moving at their velocity. So the macro step
//! is a kick-drift sequence on the finest substep: each level's forces change
//! its velocities at its own substep times ("kick"), and every vertex moves
//! with its velocity at every finest substep ("drift"). With one level this is
//! symplectic Euler exactly. (Holding the other levels still instead was tried
//! first and is unstable at the level interfaces.)
//!
//! A kick computes only the force elements of every kind (`kinds.rs`; the
//! capped sewing springs with their cap) and the wind triangles that touch the
//! level's vertices. Element forces are computed in parallel and written back
//! in a fixed order, so results do not depend on the thread count.

use rayon::prelude::*;

mod rk4;
pub use rk4::rk4_multirate;

use super::elements::Elements;
use super::forces::{ForceScratch, gather, wind_share};
use super::kinds::{KindIds, KindKicks, element_vertices, for_each_element};
use super::shape::SHAPE_SLOTS;
use super::timestep::{SAFETY, vertex_limits};
use super::{Model, Stepper};
use crate::math::{Scalar, Vector};
use crate::mesh::Mesh;
use crate::world::World;

/// The vertices of one level and the elements that touch them.
#[derive(Debug, Clone, Default, PartialEq)]
struct Group {
    level: u8,
    substeps: u32,
    vertices: Vec<u32>,
    /// Per force element kind, its elements that touch the vertices.
    kinds: KindIds,
    /// The triangles that touch the vertices (for the wind).
    triangles: Vec<u32>,
    /// Vertices of other levels that the group's elements touch.
    halo: Vec<u32>,
}

/// Level groups of the current mesh, finest first, and the macro step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Levels {
    groups: Vec<Group>,
    /// The macro step `t_0` (the automatic step of a multirate run), s.
    pub macro_dt: Scalar,
}

impl Levels {
    /// Groups the mesh's vertices by level.
    pub fn build(mesh: &Mesh, el: &Elements, drag_per_area: Scalar) -> Levels {
        let n = mesh.vertex_count();
        let mut vlevel = vec![0u8; n];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                vlevel[v as usize] = vlevel[v as usize].max(mesh.levels[t]);
            }
        }
        let top = vlevel.iter().copied().max().unwrap_or(0) as usize;
        let mut groups: Vec<Group> = (0..=top)
            .map(|l| Group {
                level: l as u8,
                ..Default::default()
            })
            .collect();
        for (v, &l) in vlevel.iter().enumerate() {
            groups[l as usize].vertices.push(v as u32);
        }
        let mark = assign_elements(&mut groups, mesh, el);
        for g in groups.iter_mut() {
            g.halo = halo_of(g, mesh, el, &mark);
        }
        let limits = vertex_limits(mesh, el, drag_per_area);
        let mut macro_dt = Scalar::INFINITY;
        for g in groups.iter_mut().filter(|g| !g.vertices.is_empty()) {
            let own = SAFETY
                * g.vertices
                    .iter()
                    .map(|&v| limits[v as usize])
                    .fold(Scalar::INFINITY, Scalar::min);
            macro_dt = macro_dt.min(own * (1u32 << g.level.div_ceil(2)) as Scalar);
            g.substeps = 1u32 << g.level.div_ceil(2);
        }
        groups.retain(|g| !g.vertices.is_empty());
        groups.reverse(); // finest first
        Levels { groups, macro_dt }
    }

    /// (level, vertices, substeps per macro step) of each group, finest first.
    pub fn summary(&self) -> Vec<(u8, usize, u32)> {
        self.groups
            .iter()
            .map(|g| (g.level, g.vertices.len(), g.substeps))
            .collect()
    }
}

/// Each vertex's group (its level), and every element added to the groups of
/// the vertices it touches.
fn assign_elements(groups: &mut [Group], mesh: &Mesh, el: &Elements) -> Vec<usize> {
    let mut mark = vec![usize::MAX; mesh.vertex_count()];
    for g in groups.iter() {
        for &v in &g.vertices {
            mark[v as usize] = g.level as usize;
        }
    }
    for_each_element(el, |kind, e, vertices| {
        touch(groups, vertices.iter().map(|&v| mark[v as usize]), e, |g| {
            &mut g.kinds[kind]
        });
    });
    for (t, tri) in mesh.triangles.iter().enumerate() {
        touch(
            groups,
            tri.iter().map(|&v| mark[v as usize]),
            t as u32,
            |g| &mut g.triangles,
        );
    }
    mark
}

/// The vertices of other groups that group `g`'s elements touch, sorted.
fn halo_of(g: &Group, mesh: &Mesh, el: &Elements, mark: &[usize]) -> Vec<u32> {
    let mut halo: Vec<u32> = Vec::new();
    let mut vertices = Vec::new();
    for (kind, ids) in g.kinds.iter().enumerate() {
        for &e in ids {
            element_vertices(el, kind, e as usize, &mut vertices);
            halo.extend(
                vertices
                    .iter()
                    .filter(|&&v| mark[v as usize] != g.level as usize),
            );
        }
    }
    let triangles = g.triangles.iter().flat_map(|&t| mesh.triangles[t as usize]);
    halo.extend(triangles.filter(|&v| mark[v as usize] != g.level as usize));
    halo.sort_unstable();
    halo.dedup();
    halo
}

/// Adds element `e` to every group one of whose vertices it touches (once).
fn touch(
    groups: &mut [Group],
    levels: impl Iterator<Item = usize>,
    e: u32,
    list: impl Fn(&mut Group) -> &mut Vec<u32>,
) {
    let mut seen: [usize; SHAPE_SLOTS] = [usize::MAX; SHAPE_SLOTS];
    for (k, l) in levels.enumerate() {
        if l != usize::MAX && !seen[..k.min(SHAPE_SLOTS)].contains(&l) {
            list(&mut groups[l]).push(e);
        }
        if k < SHAPE_SLOTS {
            seen[k] = l;
        }
    }
}

/// The stepper's levels, built for the current mesh if it has none (they are
/// dropped when the mesh changes); the caller puts them back after the step.
pub(super) fn take_levels(st: &mut Stepper, model: &Model, w: &World) -> Levels {
    match st.levels.take() {
        Some(levels) => levels,
        None => {
            let drag = model.external.drag.unwrap_or(0.0);
            Levels::build(&w.mesh, &st.elements, drag)
        }
    }
}

/// One macro step of `big` seconds: each level in turn, finest first.
pub fn symplectic_multirate(st: &mut Stepper, model: &Model, w: &mut World, big: Scalar) {
    let t = w.time;
    w.pins.held_at(t, &mut st.held);
    let levels = take_levels(st, model, w);
    let mut rk = std::mem::take(&mut st.rk4_multirate);
    let scratch = &mut st.forces;
    scratch.kinds.size(&st.elements);
    if model.external.wind.is_some() {
        scratch
            .triangle
            .resize(w.mesh.triangles.len(), Vector::ZERO);
    }
    let finest = levels.groups.iter().map(|g| g.substeps).max().unwrap_or(1);
    let drift = big / finest as Scalar;
    for j in 0..finest {
        // Kick every level whose substep starts now, finest first.
        for g in levels
            .groups
            .iter()
            .filter(|g| j % (finest / g.substeps) == 0)
        {
            let h = big / g.substeps as Scalar;
            level_forces(
                &st.elements,
                &model.external,
                &w.mesh.triangles,
                &w.x,
                &w.v,
                g,
                scratch,
                &mut rk.level,
            );
            let (el, ext, held, forces) = (&st.elements, &model.external, &st.held, &*scratch);
            g.vertices
                .par_iter()
                .with_min_len(256)
                .map(|&i| {
                    let i = i as usize;
                    if held[i] {
                        w.v[i]
                    } else {
                        w.v[i] + gather(el, ext, forces, i, w.v[i]) * (h / el.mass[i])
                    }
                })
                .collect_into_vec(&mut rk.kicked);
            for (&i, &v) in g.vertices.iter().zip(&rk.kicked) {
                w.v[i as usize] = v;
            }
        }
        // Drift every free vertex.
        let held = &st.held;
        w.x.par_iter_mut()
            .zip(w.v.par_iter())
            .enumerate()
            .with_min_len(1024)
            .for_each(|(i, (x, v))| {
                if !held[i] {
                    *x += *v * drift;
                }
            });
    }
    st.rk4_multirate = rk;
    st.levels = Some(levels);
    w.pins.apply(t + big, &mut w.x, &mut w.v);
}

/// Forces of the elements touching group `g`, written into their slots (`level` holds
/// them between the parallel pass and the write).
#[allow(clippy::too_many_arguments)]
fn level_forces(
    el: &Elements,
    ext: &super::ExternalForces,
    triangles: &[[u32; 3]],
    x: &[Vector],
    v: &[Vector],
    g: &Group,
    scratch: &mut ForceScratch,
    level: &mut LevelScratch,
) {
    scratch.kinds.kick(el, &g.kinds, x, v, &mut level.kinds);
    if let Some(wind) = &ext.wind {
        for &t in &g.triangles {
            let tri = triangles[t as usize];
            scratch.triangle[t as usize] =
                wind_share(tri.map(|i| x[i as usize]), tri.map(|i| v[i as usize]), wind);
        }
    }
}

/// Scratch of the multirate steps (both integrators; the name is kept from when only
/// RK4 had one), kept between steps so that a kick or substep allocates nothing once
/// the buffers have grown to the mesh's size.
#[derive(Debug, Clone, Default)]
pub struct Rk4MultirateScratch {
    xs: Vec<Vector>,
    vs: Vec<Vector>,
    x_new: Vec<Vector>,
    v_new: Vec<Vector>,
    /// Symplectic Euler: the kicked velocities of a group's vertices.
    kicked: Vec<Vector>,
    /// RK4: a group's state at the start of the substep, the weighted sum of the
    /// stages' derivatives, the current stage's state and its derivatives.
    y0: Vec<(Vector, Vector)>,
    acc: Vec<(Vector, Vector)>,
    stage: Vec<(Vector, Vector)>,
    derivs: Vec<(Vector, Vector)>,
    level: LevelScratch,
}

/// The element forces of one group, computed in parallel before they are written into
/// their slots.
#[derive(Debug, Clone, Default)]
struct LevelScratch {
    kinds: KindKicks,
}
