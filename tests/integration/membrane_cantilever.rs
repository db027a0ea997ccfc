//! The large-deflection cantilever (overhang twice the bending length, shape
//! operator bending) with each membrane, on the regular strip and on strips
//! whose free vertices are moved by up to a quarter and 0.4 of a cell: the
//! chord angles side by side, printed (`--nocapture`). The strip barely
//! stretches (`stretch = 1e4` N/m against its weight), so the membrane moves
//! the chord angle little; what it changes is pinned loosely here.

use drape::math::{Scalar, Vector};
use drape::physics::{Membrane, Orthotropic};

use crate::elastica::{irregular_strip, large_strip, settle_on};

/// Each strip settles with either membrane, and the triangles' chord angle is
/// within 0.5 deg of the springs' on every strip.
#[test]
fn cantilever_chord_angle_barely_depends_on_the_membrane() {
    let (c, springs, exact) = large_strip();
    let triangles = drape::physics::MaterialParams {
        membrane: Membrane::Triangles(Orthotropic::isotropic(springs.stretch)),
        ..springs
    };
    println!(
        "cantilever, overhang 2c, elastica {exact:.4} deg; chord angle minus the elastica's, deg"
    );
    println!("{:<28} {:>9} {:>10}", "strip", "springs", "triangles");
    for (name, jitter, seed, res) in [
        ("regular, 32 along", 0.0, 1, 32),
        ("jitter 0.25, 32 along", 0.25, 1, 32),
        ("jitter 0.4, 32 along", 0.4, 1, 32),
        ("jitter 0.4, 32 along", 0.4, 2, 32),
    ] {
        let m = irregular_strip(2.0 * c, res, res / 4, 0.0, jitter, seed);
        let mut off = [0.0 as Scalar; 2];
        for (k, mat) in [springs, triangles].iter().enumerate() {
            let mut x: Vec<Vector> = m.material.iter().map(|p| p.extend(0.0)).collect();
            let s = settle_on(&m, &mut x, mat, 2.0 * c);
            assert!(
                s.residual < 1e-9,
                "{name}: not settled ({:.1e} N)",
                s.residual
            );
            off[k] = s.chord_deg - exact;
        }
        println!("{name:<22} s{seed} {:>+9.3} {:>+10.3}", off[0], off[1]);
        assert!((off[1] - off[0]).abs() < 0.5, "{name}: {off:?}");
    }
}
