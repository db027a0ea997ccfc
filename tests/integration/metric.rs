//! The error metric: identical meshes give 0, a rigid offset gives exactly that
//! offset (all of it reported as offset, and a zero-mean deformation none), and
//! samples are the same cloth points on a uniform and an adapted mesh.

use drape::adapt::Adapter;
use drape::adapt::red_green::RedGreenOp;
use drape::bench::metric::{
    diagonal, grid_samples, locate, relative_offset, relative_rms, sample_positions,
};
use drape::math::{Scalar, Vector};
use drape::mesh;
use drape::scene::{AdaptMethod, DiagonalPattern};
use drape::world::World;

/// A 2 m x 1 m sheet bent into a smooth wave (so interpolation matters).
fn wavy(res: u32) -> World {
    let m = mesh::rectangle(2.0, 1.0, res, DiagonalPattern::Alternating).unwrap();
    let x = m
        .material
        .iter()
        .map(|p| Vector::new(p.x, p.y, 0.1 * (3.0 * p.x).sin() * p.y))
        .collect();
    World::new(m, x)
}

/// The 20 x 20 grid of samples located in `w`'s mesh (all inside it).
fn located_grid(w: &World) -> Vec<drape::bench::metric::Located> {
    let samples = grid_samples(&w.mesh, 20);
    locate(&w.mesh, &samples)
        .into_iter()
        .map(|l| l.expect("a grid sample inside the rectangle"))
        .collect()
}

#[test]
fn identical_meshes_have_zero_error() {
    let w = wavy(16);
    let samples = grid_samples(&w.mesh, 20);
    assert_eq!(
        samples.len(),
        400,
        "every grid sample lies inside a rectangle"
    );
    let located: Vec<_> = locate(&w.mesh, &samples)
        .into_iter()
        .map(Option::unwrap)
        .collect();
    let a = sample_positions(&w.mesh, &w.x, &located);
    assert_eq!(relative_rms(&a, &a, diagonal(&w.mesh)), 0.0);
}

#[test]
fn a_rigid_offset_gives_exactly_that_offset() {
    let w = wavy(16);
    let located = located_grid(&w);
    let a = sample_positions(&w.mesh, &w.x, &located);
    let shift = Vector::new(0.03, -0.04, 0.0); // 5 cm
    let moved: Vec<Vector> = w.x.iter().map(|p| *p + shift).collect();
    let b = sample_positions(&w.mesh, &moved, &located);
    let diag = diagonal(&w.mesh);
    let err = relative_rms(&a, &b, diag);
    assert!(
        (err - 0.05 / diag).abs() < 1e-14,
        "{err} vs {}",
        0.05 / diag
    );
    // All of it is offset: nothing is left once the translation is taken out.
    let offset = relative_offset(&b, &a, diag);
    assert!((offset - err).abs() < 1e-14, "{offset} vs {err}");
}

/// The offset is the translation part of the error only: a deformation whose
/// displacements average to zero (the wave made twice as deep, which moves the
/// samples up and down symmetrically) has no offset, and adding a rigid shift to
/// it gives an offset of exactly that shift and an error whose square is the sum
/// of the two parts' squares.
#[test]
fn the_offset_is_the_translation_part_of_the_error() {
    let w = wavy(16);
    let located = located_grid(&w);
    let diag = diagonal(&w.mesh);
    let a = sample_positions(&w.mesh, &w.x, &located);
    let deeper: Vec<Vector> =
        w.x.iter()
            .map(|p| Vector::new(p.x, p.y, 2.0 * p.z))
            .collect();
    let b = sample_positions(&w.mesh, &deeper, &located);
    let shape = relative_rms(&b, &a, diag);
    let mean_z = b.iter().zip(&a).map(|(p, q)| p.z - q.z).sum::<Scalar>() / a.len() as Scalar;
    let offset = relative_offset(&b, &a, diag);
    assert!(shape > 1e-3, "the wave changed: {shape}");
    assert!((offset - mean_z.abs() / diag).abs() < 1e-15);
    assert!(offset < 1e-3 * shape, "{offset} vs {shape}");
    let shift = Vector::new(0.0, 0.0, 0.02);
    let c: Vec<Vector> = b.iter().map(|p| *p + shift).collect();
    let total = relative_rms(&c, &a, diag);
    let moved = relative_offset(&c, &a, diag);
    let expected = (mean_z + 0.02).abs() / diag;
    assert!((moved - expected).abs() < 1e-14, "{moved} vs {expected}");
    let rest = (total * total - moved * moved).sqrt();
    assert!(
        (rest - shape_without_mean(&b, &a, diag)).abs() < 1e-12,
        "{rest}"
    );
}

/// The RMS of the displacements less their mean, relative to `diag`.
fn shape_without_mean(b: &[Vector], a: &[Vector], diag: Scalar) -> Scalar {
    let mean = b.iter().zip(a).map(|(p, q)| *p - *q).sum::<Vector>() / a.len() as Scalar;
    let sum: Scalar = b
        .iter()
        .zip(a)
        .map(|(p, q)| (*p - *q - mean).length_squared())
        .sum();
    (sum / a.len() as Scalar).sqrt() / diag
}

#[test]
fn samples_are_the_same_cloth_points_on_an_adapted_mesh() {
    // Refining a flat region keeps every sample's position: the new vertices lie
    // on the old triangles, so interpolation gives the same points.
    let mut w = wavy(8);
    let flat: Vec<Vector> = w.mesh.material.iter().map(|p| p.extend(0.0)).collect();
    w.x = flat;
    let samples = grid_samples(&w.mesh, 25);
    let before_loc: Vec<_> = locate(&w.mesh, &samples)
        .into_iter()
        .map(Option::unwrap)
        .collect();
    let before = sample_positions(&w.mesh, &w.x, &before_loc);
    let cfg = crate::common::angle_config(AdaptMethod::RedGreen);
    let mut ad = Adapter::new(&cfg, &w, 0.15).expect("the adapter starts");
    let leaves: Vec<_> = ad
        .hierarchy()
        .expect("red-green")
        .leaves()
        .into_iter()
        .step_by(3)
        .map(|l| (RedGreenOp::Split(l), None))
        .collect();
    ad.apply(&cfg, &mut w, &leaves, 0).unwrap();
    let after_loc: Vec<_> = locate(&w.mesh, &samples)
        .into_iter()
        .map(Option::unwrap)
        .collect();
    let after = sample_positions(&w.mesh, &w.x, &after_loc);
    let err: Scalar = relative_rms(&before, &after, diagonal(&w.mesh));
    assert!(err < 1e-15, "{err}");
    assert!(w.mesh.vertex_count() > 45, "the mesh was refined");
}

#[test]
fn points_outside_a_disk_are_not_located() {
    let m = mesh::disk(0.5, 8).unwrap();
    let samples = grid_samples(&m, 10);
    assert!(
        samples.len() < 100 && samples.len() > 50,
        "{}",
        samples.len()
    );
    let outside = locate(&m, &[drape::math::Vector2::new(0.49, 0.49)]);
    assert!(outside[0].is_none());
}
