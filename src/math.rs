//! Scalar and vector aliases used by the whole engine.
//!
//! The engine computes in `f64` with glam 0.33, the glam that parry3d-f64 uses, so
//! the collision module can hand vectors to parry without conversion. The recording
//! module converts to rerun's own glam at the edge with `to_array()`.

/// The floating-point type of every physical quantity.
pub type Scalar = f64;
/// A point or vector in world space (metres, m/s, newtons, ...).
pub type Vector = glam::DVec3;
/// A point in material (rest) space, the flat 2D parameter domain of the cloth.
pub type Vector2 = glam::DVec2;
/// A 3x3 matrix (spring Jacobian blocks, rotations).
pub type Matrix3 = glam::DMat3;

/// Rotation matrix from Euler angles in degrees, applied about x, then y, then z
/// (extrinsic axes), i.e. `R = Rz * Ry * Rx`.
pub fn rotation_from_euler_deg(angles: [Scalar; 3]) -> Matrix3 {
    let [x, y, z] = angles.map(|a| a.to_radians());
    Matrix3::from_rotation_z(z) * Matrix3::from_rotation_y(y) * Matrix3::from_rotation_x(x)
}

/// Sum of `values` in a fixed association order, independent of the thread count.
///
/// Rayon's `sum` splits work adaptively, so its rounding depends on the number of
/// threads. This sums fixed-size chunks in parallel, then the chunk sums in order.
pub fn deterministic_sum<F>(len: usize, term: F) -> Scalar
where
    F: Fn(usize) -> Scalar + Sync,
{
    let (a, _) = deterministic_sum2(len, |i| (term(i), 0.0));
    a
}

/// Two sums at once, each in exactly the association order of
/// [`deterministic_sum`] (same chunks, same order), so each result is
/// bit-identical to summing that component alone.
pub fn deterministic_sum2<F>(len: usize, term: F) -> (Scalar, Scalar)
where
    F: Fn(usize) -> (Scalar, Scalar) + Sync,
{
    use rayon::prelude::*;
    let chunks = len.div_ceil(SUM_CHUNK);
    let chunk_sum = |c: usize| {
        let end = ((c + 1) * SUM_CHUNK).min(len);
        // `Iterator::sum` for floats folds from -0.0; do the same.
        (c * SUM_CHUNK..end)
            .map(&term)
            .fold((-0.0, -0.0), |(a, b), (x, y)| (a + x, b + y))
    };
    let total = |partial: &[(Scalar, Scalar)]| {
        let a = partial.iter().map(|p| p.0).sum();
        let b = partial.iter().map(|p| p.1).sum();
        (a, b)
    };
    if chunks <= STACK_CHUNKS {
        // The chunk sums on the stack: no allocation per call (these sums run
        // several times a step). Same chunks, same order as below.
        let mut partial = [(0.0, 0.0); STACK_CHUNKS];
        partial[..chunks]
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, p)| *p = chunk_sum(c));
        return total(&partial[..chunks]);
    }
    let partial: Vec<(Scalar, Scalar)> = (0..chunks).into_par_iter().map(chunk_sum).collect();
    total(&partial)
}

/// Terms per chunk of [`deterministic_sum`] and [`deterministic_sum2`]: the
/// chunking (and so the rounding) depends on this alone.
const SUM_CHUNK: usize = 2048;

/// Chunk sums kept on the stack (meshes up to `STACK_CHUNKS * SUM_CHUNK`, about
/// 520k vertices, sum without allocating); larger ones collect into a vector.
const STACK_CHUNKS: usize = 256;
