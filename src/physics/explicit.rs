//! Explicit integrators: symplectic Euler (paper A) and classic RK4 (paper B).
//!
//! Each stage is one element pass plus one fused per-vertex pass that gathers
//! the force and updates that vertex only, so the loops need no atomics. Pinned
//! vertices are not integrated: they follow their scripts at every stage time.

use rayon::prelude::*;

use super::forces::{PAR_MIN, element_pass, gather};
use super::{Model, Stepper};
use crate::math::{Scalar, Vector};
use crate::world::World;

/// Scratch state of RK4 (kept between steps to avoid allocation).
#[derive(Debug, Default, Clone)]
pub struct Rk4Scratch {
    x: Vec<Vector>,
    v: Vec<Vector>,
    dx: Vec<Vector>,
    dv: Vec<Vector>,
}

/// One symplectic Euler step: `v += dt f(x, v) / m; x += dt v`.
pub fn symplectic_euler(st: &mut Stepper, model: &Model, w: &mut World, dt: Scalar) {
    let t = w.time;
    w.pins.held_at(t, &mut st.held);
    element_pass(
        &st.elements,
        &model.external,
        &w.mesh.triangles,
        &w.x,
        &w.v,
        &mut st.forces,
    );
    let (el, ext, forces, held) = (&st.elements, &model.external, &st.forces, &st.held);
    w.x.par_iter_mut()
        .zip(w.v.par_iter_mut())
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, (x, v))| {
            if !held[i] {
                let f = gather(el, ext, forces, i, *v);
                *v += f * (dt / el.mass[i]);
                *x += *v * dt;
            }
        });
    w.pins.apply(t + dt, &mut w.x, &mut w.v);
}

/// One classic fourth-order Runge-Kutta step on `(x, v)`.
pub fn rk4(st: &mut Stepper, model: &Model, w: &mut World, dt: Scalar) {
    let t = w.time;
    let n = w.x.len();
    w.pins.held_at(t, &mut st.held);
    let rk = &mut st.rk4;
    for buf in [&mut rk.x, &mut rk.v, &mut rk.dx, &mut rk.dv] {
        buf.resize(n, Vector::ZERO);
    }
    const WEIGHT: [Scalar; 4] = [1.0, 2.0, 2.0, 1.0];
    const NEXT: [Scalar; 3] = [0.5, 0.5, 1.0];
    for stage in 0..4 {
        {
            let (xs, vs) = if stage == 0 {
                (&w.x, &w.v)
            } else {
                (&rk.x, &rk.v)
            };
            element_pass(
                &st.elements,
                &model.external,
                &w.mesh.triangles,
                xs,
                vs,
                &mut st.forces,
            );
        }
        let (el, ext, forces, held) = (&st.elements, &model.external, &st.forces, &st.held);
        let (x0, v0) = (&w.x, &w.v);
        let w_s = WEIGHT[stage];
        let c = if stage < 3 { NEXT[stage] * dt } else { 0.0 };
        rk.x.par_iter_mut()
            .zip(rk.v.par_iter_mut())
            .zip(rk.dx.par_iter_mut().zip(rk.dv.par_iter_mut()))
            .enumerate()
            .with_min_len(PAR_MIN)
            .for_each(|(i, ((xs, vs), (dx, dv)))| {
                let vel = if stage == 0 { v0[i] } else { *vs };
                let acc = if held[i] {
                    Vector::ZERO
                } else {
                    gather(el, ext, forces, i, vel) / el.mass[i]
                };
                if stage == 0 {
                    *dx = vel;
                    *dv = acc;
                } else {
                    *dx += vel * w_s;
                    *dv += acc * w_s;
                }
                if stage < 3 {
                    *xs = x0[i] + vel * c;
                    *vs = v0[i] + acc * c;
                }
            });
        if stage < 3 {
            w.pins.apply(t + NEXT[stage] * dt, &mut rk.x, &mut rk.v);
        }
    }
    let (dx, dv, held) = (&rk.dx, &rk.dv, &st.held);
    w.x.par_iter_mut()
        .zip(w.v.par_iter_mut())
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, (x, v))| {
            if !held[i] {
                *x += dx[i] * (dt / 6.0);
                *v += dv[i] * (dt / 6.0);
            }
        });
    w.pins.apply(t + dt, &mut w.x, &mut w.v);
}
