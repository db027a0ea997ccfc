//! Paper A's multirate stepping with RK4 (see [`super`]'s module docs).

use rayon::prelude::*;

use super::{level_forces, take_levels};
use crate::math::{Scalar, Vector};
use crate::physics::Stepper;
use crate::physics::forces::gather;
use crate::physics::shape::SHAPE_SLOTS;
use crate::world::World;

/// One RK4 macro step of `big` seconds. Each level integrates its own vertices
/// with RK4 at its own substep; the vertices of other levels that its elements
/// touch move at their velocity from the start of the macro step (paper A:
/// their motion is unchanged, zero acceleration). With one level this is RK4.
pub fn rk4_multirate(st: &mut Stepper, w: &mut World, big: Scalar) {
    let t = w.time;
    w.pins.held_at(t, &mut st.held);
    let levels = take_levels(st, w);
    let mut rk = std::mem::take(&mut st.rk4_multirate);
    let n = w.x.len();
    for (buf, src) in [
        (&mut rk.xs, &w.x),
        (&mut rk.vs, &w.v),
        (&mut rk.x_new, &w.x),
        (&mut rk.v_new, &w.v),
    ] {
        buf.clear();
        buf.extend_from_slice(src);
    }
    debug_assert_eq!(rk.xs.len(), n);
    let scratch = &mut st.forces;
    scratch
        .spring
        .resize(st.elements.springs.len(), Vector::ZERO);
    scratch
        .hinge
        .resize(4 * st.elements.hinges.len(), Vector::ZERO);
    scratch.shape.resize(
        SHAPE_SLOTS * st.elements.shape_triangles.len(),
        Vector::ZERO,
    );
    if st.model.external.wind.is_some() {
        scratch
            .triangle
            .resize(w.mesh.triangles.len(), Vector::ZERO);
    }
    const WEIGHT: [Scalar; 4] = [1.0, 2.0, 2.0, 1.0];
    const AT: [Scalar; 4] = [0.0, 0.5, 0.5, 1.0];
    for g in &levels.groups {
        let h = big / g.substeps as Scalar;
        for sub in 0..g.substeps {
            let t_sub = sub as Scalar * h;
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
                // Other levels' vertices move at their macro-start velocity.
                let tau = t_sub + AT[s] * h;
                for &o in &g.halo {
                    let o = o as usize;
                    rk.xs[o] = w.x[o] + w.v[o] * tau;
                    rk.vs[o] = w.v[o];
                }
                for (&i, &(x, v)) in g.vertices.iter().zip(&rk.stage) {
                    rk.xs[i as usize] = x;
                    rk.vs[i as usize] = v;
                }
                level_forces(
                    &st.elements,
                    &st.model.external,
                    &w.mesh.triangles,
                    &rk.xs,
                    &rk.vs,
                    g,
                    scratch,
                    &mut rk.level,
                );
                let (el, ext, held, forces) =
                    (&st.elements, &st.model.external, &st.held, &*scratch);
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
    }
    std::mem::swap(&mut w.x, &mut rk.x_new);
    std::mem::swap(&mut w.v, &mut rk.v_new);
    st.rk4_multirate = rk;
    st.levels = Some(levels);
    w.pins.apply(t + big, &mut w.x, &mut w.v);
}
