//! Paper A's multirate stepping with RK4 (see [`super`]'s module docs).

use rayon::prelude::*;

use super::{Group, Rk4MultirateScratch, level_forces, take_levels};
use crate::math::{Scalar, Vector};
use crate::physics::forces::gather;
use crate::physics::{Model, Stepper};
use crate::world::World;

/// One RK4 macro step of `big` seconds. Each level integrates its own vertices
/// with RK4 at its own substep; the vertices of other levels that its elements
/// touch move at their velocity from the start of the macro step (paper A:
/// their motion is unchanged, zero acceleration). With one level this is RK4.
pub fn rk4_multirate(st: &mut Stepper, model: &Model, w: &mut World, big: Scalar) {
    let t = w.time;
    w.pins.held_at(t, &mut st.held);
    let levels = take_levels(st, model, w);
    let mut rk = std::mem::take(&mut st.rk4_multirate);
    for (buf, src) in [
        (&mut rk.xs, &w.x),
        (&mut rk.vs, &w.v),
        (&mut rk.x_new, &w.x),
        (&mut rk.v_new, &w.v),
    ] {
        buf.clear();
        buf.extend_from_slice(src);
    }
    size_force_scratch(st, model, w);
    for g in &levels.groups {
        let h = big / g.substeps as Scalar;
        for sub in 0..g.substeps {
            substep(st, model, w, &mut rk, g, sub as Scalar * h, h);
        }
    }
    std::mem::swap(&mut w.x, &mut rk.x_new);
    std::mem::swap(&mut w.v, &mut rk.v_new);
    st.rk4_multirate = rk;
    st.levels = Some(levels);
    w.pins.apply(t + big, &mut w.x, &mut w.v);
}

/// Sizes the per-element force slots for the current elements (no allocation
/// once they have grown to the mesh).
fn size_force_scratch(st: &mut Stepper, model: &Model, w: &World) {
    let (scratch, el) = (&mut st.forces, &st.elements);
    scratch.kinds.size(el);
    if model.external.wind.is_some() {
        scratch
            .triangle
            .resize(w.mesh.triangles.len(), Vector::ZERO);
    }
}

/// RK4's stage weights and the times of its stages within a step.
const WEIGHT: [Scalar; 4] = [1.0, 2.0, 2.0, 1.0];
const AT: [Scalar; 4] = [0.0, 0.5, 0.5, 1.0];

/// One RK4 substep of `h` seconds, starting `t_sub` after the macro step's start,
/// of group `g`'s vertices (in `rk.x_new`, `rk.v_new`).
fn substep(
    st: &mut Stepper,
    model: &Model,
    w: &World,
    rk: &mut Rk4MultirateScratch,
    g: &Group,
    t_sub: Scalar,
    h: Scalar,
) {
    // State of the group's vertices at the start of the substep.
    rk.y0.clear();
    rk.y0.extend(
        g.vertices
            .iter()
            .map(|&i| (rk.x_new[i as usize], rk.v_new[i as usize])),
    );
    rk.acc.clear();
    rk.acc.resize(rk.y0.len(), (Vector::ZERO, Vector::ZERO));
    rk.stage.clear();
    rk.stage.extend_from_slice(&rk.y0);
    for s in 0..4 {
        stage_derivatives(st, model, w, rk, g, t_sub + AT[s] * h);
        for (k, &(dx, dv)) in rk.derivs.iter().enumerate() {
            rk.acc[k].0 += dx * WEIGHT[s];
            rk.acc[k].1 += dv * WEIGHT[s];
            if s < 3 {
                let c = AT[s + 1] * h;
                rk.stage[k] = (rk.y0[k].0 + dx * c, rk.y0[k].1 + dv * c);
            }
        }
    }
    for (k, &i) in g.vertices.iter().enumerate() {
        let i = i as usize;
        if !st.held[i] {
            rk.x_new[i] = rk.y0[k].0 + rk.acc[k].0 * (h / 6.0);
            rk.v_new[i] = rk.y0[k].1 + rk.acc[k].1 * (h / 6.0);
        }
    }
}

/// The derivatives (velocity, acceleration) of group `g`'s vertices at the
/// current stage (`rk.stage`), `tau` after the macro step's start, into
/// `rk.derivs`.
fn stage_derivatives(
    st: &mut Stepper,
    model: &Model,
    w: &World,
    rk: &mut Rk4MultirateScratch,
    g: &Group,
    tau: Scalar,
) {
    // Other levels' vertices move at their macro-start velocity.
    for &o in &g.halo {
        let o = o as usize;
        rk.xs[o] = w.x[o] + w.v[o] * tau;
        rk.vs[o] = w.v[o];
    }
    for (&i, &(x, v)) in g.vertices.iter().zip(&rk.stage) {
        rk.xs[i as usize] = x;
        rk.vs[i as usize] = v;
    }
    let scratch = &mut st.forces;
    level_forces(
        &st.elements,
        &model.external,
        &w.mesh.triangles,
        &rk.xs,
        &rk.vs,
        g,
        scratch,
        &mut rk.level,
    );
    let (el, ext, held, forces) = (&st.elements, &model.external, &st.held, &*scratch);
    g.vertices
        .par_iter()
        .zip(rk.stage.par_iter())
        .with_min_len(256)
        .map(|(&i, &(_, v))| {
            let i = i as usize;
            let a = if held[i] {
                Vector::ZERO
            } else {
                gather(el, ext, forces, i, v) / el.mass[i]
            };
            (v, a)
        })
        .collect_into_vec(&mut rk.derivs);
}
