//! Work done on the cloth by what drives it from outside: wind and moving air, moving
//! pins (obstacles report theirs from the collision pass). With gravity counted as
//! potential energy and springs, hinges and still-air drag internal or dissipative,
//! the cloth's total energy can never exceed its initial value plus this work; the
//! run checks that bound ([`crate::run`]) and the stability suite reports it.
//!
//! Both are integrated over a step from the states at its ends:
//! - air: the power `sum_i (f_wind,i + c_i w) . v_i` (the wind's force and the
//!   driving part `c_i w` of drag against moving air `w`; the `-c_i v_i` part only
//!   dissipates and is left out, so the bound stays an upper bound), trapezoidal rule;
//! - pins: a held vertex `i` receives from its pin the force `m_i a_i - f_i` (what
//!   moves it along its script against the cloth's force `f_i` on it), whose work over
//!   the step is `(m_i (v1 - v0) / h - f_i(x0, v0)) . (x1 - x0)`. Only vertices of
//!   pins that move are evaluated, and only then is the force pass run.

use rayon::prelude::*;

use super::forces::{PAR_MIN, element_pass, gather, wind_share};
use super::{Model, Stepper};
use crate::math::{Scalar, Vector, deterministic_sum};
use crate::world::World;

/// A held vertex of a moving pin at the start of a step.
#[derive(Debug, Clone, Copy)]
pub struct PinnedStart {
    vertex: u32,
    x: Vector,
    v: Vector,
    force: Vector,
}

impl Stepper {
    /// Power of the wind and of moving air on the cloth, W (zero in still air).
    pub fn air_power(&self, model: &Model, world: &World) -> Scalar {
        let ext = &model.external;
        let el = &self.elements;
        let (x, v) = (&world.x, &world.v);
        let mut power = 0.0;
        if let Some(wind) = &ext.wind {
            let tris = &world.mesh.triangles;
            power += deterministic_sum(tris.len(), |k| {
                let t = tris[k];
                let share = wind_share(t.map(|i| x[i as usize]), t.map(|i| v[i as usize]), wind);
                share.dot(v[t[0] as usize] + v[t[1] as usize] + v[t[2] as usize])
            });
        }
        if let Some(drag) = ext.drag
            && ext.air_velocity != Vector::ZERO
        {
            power += deterministic_sum(x.len(), |i| {
                (ext.air_velocity * (drag * el.vertex_area[i])).dot(v[i])
            });
        }
        power
    }

    /// The held vertices of moving pins with the cloth's force on them, at the start
    /// of a step (empty when no moving pin holds; then no force pass runs).
    pub fn pinned_start(&mut self, model: &Model, world: &World) -> Vec<PinnedStart> {
        let pins = &world.pins;
        let moving: Vec<u32> = pins
            .anchors
            .iter()
            .filter(|a| {
                let s = &pins.scripts[a.pin as usize];
                s.moves() && s.holds_at(world.time)
            })
            .map(|a| a.vertex)
            .collect();
        if moving.is_empty() {
            return Vec::new();
        }
        element_pass(
            &self.elements,
            &model.external,
            &world.mesh.triangles,
            &world.x,
            &world.v,
            &mut self.forces,
        );
        let (el, ext, scratch) = (&self.elements, &model.external, &self.forces);
        moving
            .par_iter()
            .with_min_len(PAR_MIN)
            .map(|&i| {
                let k = i as usize;
                PinnedStart {
                    vertex: i,
                    x: world.x[k],
                    v: world.v[k],
                    force: gather(el, ext, scratch, k, world.v[k]),
                }
            })
            .collect()
    }

    /// Work of the pins over a step of `h` s that began at `start`, J.
    pub fn pin_work(&self, start: &[PinnedStart], world: &World, h: Scalar) -> Scalar {
        let mass = &self.elements.mass;
        deterministic_sum(start.len(), |k| {
            let p = start[k];
            let i = p.vertex as usize;
            let push = (world.v[i] - p.v) * (mass[i] / h) - p.force;
            push.dot(world.x[i] - p.x)
        })
    }
}
