//! The contact response of one vertex against one obstacle (the steps of the module
//! docs of [`super`]): continuous detection, proximity, placement and friction; and the
//! push-out and depth measurement of the pass after self-collision.

use super::deform::At;
use super::obstacle::Body;
use crate::math::{Scalar, Vector};
use crate::physics::Contact;

/// A vertex this close to a surface, in thicknesses, is in contact: resting cloth sits
/// exactly one thickness out, and rounding must not let it flicker in and out of
/// contact (and of the implicit solve's contact filter).
const CONTACT_MARGIN: Scalar = 1.0 + 1e-6;

/// The contact margin, in thicknesses, of a vertex the implicit solve held
/// against the surface (`pushed` > 0). The solve moves such a vertex along the
/// surface's tangent plane, which leaves it off a curved or faceted surface by
/// the square of its slide over twice the radius of curvature: it is still in
/// contact, and is placed back a thickness out. Without this margin it would
/// leave contact every other step on a ball, and the cloth it carries would
/// jitter with a period of two steps.
const PRESSED_MARGIN: Scalar = 1.1;

/// Contact response of one vertex against one obstacle (module docs, steps 1-3).
/// `p0` is the start-of-step position, `x`/`v` the state after the integrator;
/// `start` and `end` are the obstacle at the two ends of the step. The path
/// is taken relative to the obstacle: from `p0` carried with it over the step
/// ([`At::carried`]) to `x`, against its shape at the end of the step.
/// Returns the contact when the vertex touched the obstacle.
#[allow(clippy::too_many_arguments)]
pub(super) fn respond(
    b: &Body,
    (start, end): &(At, At),
    t1: Scalar,
    h: Scalar,
    pushed: Scalar,
    p0: Vector,
    x: &mut Vector,
    v: &mut Vector,
) -> Option<Contact> {
    let pose1 = &end.pose;
    let q1 = pose1.inverse_transform_point(*x);
    let rough = if end.surface.is_some() {
        p0
    } else {
        start.pose.inverse_transform_point(p0)
    };
    if !b.may_touch(end, rough, q1) {
        return None;
    }
    let q0 = start.carried(end, p0);
    let thick = b.thickness;
    // Signed distance of the start of the step from the surface.
    let start = b.probe(end, q0).signed;
    let margin = if pushed > 0.0 {
        PRESSED_MARGIN
    } else {
        CONTACT_MARGIN
    };
    let (n, offset) = contact_plane(b, end, q0, q1, start, margin)?;
    let mut q = q1 + n * (offset + thick - n.dot(q1));
    let rot = pose1.rotation;
    let mut u = rot.inverse() * (*v - b.velocity_at(t1, end, pose1.transform_point(q)));
    let un = u.dot(n);
    // Normal impulse per mass of the step: the approach removed here, plus what the
    // implicit solve's contact filter already removed.
    let dun = (-un).max(0.0) + pushed;
    if dun > 0.0 {
        let ut = u - n * un;
        let speed = ut.length();
        let ut_new = if speed <= b.mu_static * dun {
            Vector::ZERO
        } else {
            ut * (1.0 - b.mu_kinetic * dun / speed)
        };
        // The step's tangential displacement is corrected for the part of the
        // step after the vertex reached the surface (the contact layer a
        // thickness out): all of it for a vertex that began the step there,
        // which static friction so holds in place, none for one that reached
        // it only at the end. Correcting the whole step for a vertex that
        // landed within it would move it back along the surface after the
        // implicit solve, where its neighbours do not see it: the springs
        // around it would stretch and the landing create energy that grows
        // with the resolution (`drape_sphere` at 1/120 s steps without the
        // energy retries: 0.44 J at 64 segments and 0.96 J at 96, of 3.77 J;
        // test `energy::a_sheet_landing_on_a_ball_gains_no_energy_at_full_steps`).
        // Within the contact margin counts as on it (resting cloth sits
        // exactly a thickness out, to rounding).
        let gap0 = start - thick * CONTACT_MARGIN;
        let gap1 = n.dot(q1) - offset - thick;
        q += (ut_new - ut) * (h * (1.0 - before_contact(gap0, gap1)));
        u = ut_new + n * un.max(0.0);
    }
    // Curved surfaces and corners: make sure the final point is a thickness outside.
    let f = b.probe(end, q);
    if f.signed < thick {
        q += f.normal * (thick - f.signed);
    }
    *x = pose1.transform_point(q);
    let surface = b.velocity_at(t1, end, *x);
    *v = rot * u + surface;
    let normal = rot * n;
    Some(Contact {
        normal,
        normal_speed: surface.dot(normal),
        pressed: pushed > 0.0,
    })
}

/// The contact plane of a vertex moving from `q0` (signed distance `start`) to `q1`
/// in the body's frame: outward normal and its offset `n . s` at the surface point
/// `s`. The plane where the step first enters the surface, else the one under `q1`
/// when it ends within the contact margin; `None` when the vertex stays clear.
fn contact_plane(
    b: &Body,
    end: &At,
    q0: Vector,
    q1: Vector,
    start: Scalar,
    margin: Scalar,
) -> Option<(Vector, Scalar)> {
    if start >= 0.0
        && let Some((toi, n)) = b.first_entry(end, q0, q1)
    {
        return Some((n, n.dot(q0 + (q1 - q0) * toi)));
    }
    let p = b.probe(end, q1);
    if p.signed < b.thickness * margin {
        return Some((p.normal, p.normal.dot(q1) - p.signed));
    }
    None
}

/// The fraction of the step before the vertex reached the contact layer, from its
/// gaps to the layer at the start and the end of the step (zero when it began
/// the step there).
fn before_contact(gap0: Scalar, gap1: Scalar) -> Scalar {
    if gap0 > 0.0 && gap0 > gap1 {
        (gap0 / (gap0 - gap1)).min(1.0)
    } else {
        0.0
    }
}

/// The work, J, an obstacle whose surface at the contact moves at `surface` does on
/// a vertex of mass `m` when its response, within a step of `h` seconds, moves the
/// vertex by `dx` and changes its velocity by `dv`.
///
/// A moving rigid surface that gives a vertex an impulse `J` works `J . surface` on
/// it (the power of the contact force is that force times the velocity of the
/// surface point it acts from). The response makes two changes, each an impulse of
/// the obstacle: the velocity change is the impulse `m dv` at the end of the step,
/// and the displacement is the one an impulse `m dx / h` at its start gives over
/// the step (positions advance by `h` times the velocity). Both count: a fast
/// surface that reaches a vertex within the step moves it out to itself, carrying
/// it along and lifting it against gravity, and pulls its neighbours after it;
/// counting the velocity change alone leaves that out, and a fast obstacle lifting
/// the cloth looks like an explosion. Against a still surface both terms are zero,
/// so the check of a static scene is unchanged. The work grows with the surface's
/// speed and with `|dx|`, not with the cloth's stiffness: the elastic energy a
/// displacement stores in stiff cloth is not counted as work, so a response that
/// stretches the cloth far is not passed off as the obstacle's doing.
pub(super) fn contact_work(
    m: Scalar,
    h: Scalar,
    dx: Vector,
    dv: Vector,
    surface: Vector,
) -> Scalar {
    let moved = if h > 0.0 { dx / h } else { Vector::ZERO };
    m * (dv + moved).dot(surface)
}

/// Pushes a vertex that came within the thickness back out along the normal and removes
/// its approaching normal velocity (the pass after self-collision).
pub(super) fn push_out(b: &Body, at: &At, t: Scalar, x: &mut Vector, v: &mut Vector) {
    let pose = &at.pose;
    let q = pose.inverse_transform_point(*x);
    if !b.may_touch(at, q, q) {
        return;
    }
    let p = b.probe(at, q);
    if p.signed >= b.thickness {
        return;
    }
    *x = pose.transform_point(q + p.normal * (b.thickness - p.signed));
    let n = pose.rotation * p.normal;
    let rel = *v - b.velocity_at(t, at, *x);
    let vn = rel.dot(n);
    if vn < 0.0 {
        *v -= n * vn;
    }
}

/// Depth of `x` below the obstacle's surface, m (0 outside).
pub(super) fn depth_below(b: &Body, at: &At, x: Vector) -> Scalar {
    let q = at.pose.inverse_transform_point(x);
    if !b.may_touch(at, q, q) {
        return 0.0;
    }
    (-b.probe(at, q).signed).max(0.0)
}
