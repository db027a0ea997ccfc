//! Force element kinds: each kind of force element (springs, dihedral hinges,
//! shape triangles, membrane triangles, held vertices of attachments) implements [`ForceKind`] in its own
//! file under `kinds/`, and [`kind_list!`] names them once. Each kind owns its
//! elements of one mesh and their incidence lists ([`ForceKind::Set`], all
//! kinds' in [`KindSets`], held by [`Elements`]) and builds them
//! ([`ForceKind::build`]). Every consumer loops over that list through the
//! types it generates: the element build ([`KindSets`]), the element pass and
//! the per-vertex gather of the explicit integrators ([`KindForces`]), the
//! elastic energy ([`elastic_energy`]), the implicit step's linearisation, its
//! right-hand side and Jacobi diagonal, the CG solver's matrix-free product
//! and the direct solver's block assembly ([`KindLinear`], [`KindInPlace`],
//! [`listed_blocks`]), the block pattern's couplings and factored pairs
//! ([`couplings`], [`factored_pairs`], [`dropped_terms`]) and the explicit
//! step bound ([`gershgorin`]).
//!
//! The dispatch is static: the list expands to one call per kind, each a loop
//! over that kind's elements, so no element pays for a virtual call.
//!
//! # Order
//! Each vertex sums its kinds' slots in the list's order (and each kind's slots
//! in its incidence lists' order), so results do not depend on the thread
//! count and stay the same bit for bit as long as the list's order does. Each
//! block of the direct solver's matrix sums every kind's listed blocks in the
//! list's order, then every kind's in-place blocks (`block.rs`, "Assembly").
//! The elastic energy sums the kinds' energies in an order of its own, each
//! kind's [`ForceKind::ENERGY_RANK`] (springs, membrane, hinges, shape
//! triangles).
//!
//! # Adding a kind
//! A new file under `kinds/` with a type that implements [`ForceKind`] (its
//! elements in its own [`ForceKind::Set`], built from a
//! [`super::elements::BuildContext`]; the direct solver's hooks have
//! defaults that add nothing), and one line in the [`kind_list!`] invocation
//! below, at the end (a kind inserted earlier changes the order of every sum
//! after it): `field: Type`, the file being `kinds/field.rs` (the list
//! declares each kind's module).

#[macro_use]
mod list;

pub use attachments::{AttachmentLinear, AttachmentSet, Attachments, HeldVertex};
pub use hinges::{Hinge, HingeLinear, HingeSet, Hinges};
pub use membrane::{MembraneLinear, MembraneSet, MembraneTriangles};
pub use shapes::{
    RebuildCounts, ShapeBlocks, ShapeForces, ShapeLinear, ShapeSet, ShapeTriangles, edge_folds,
    fold_angles, fold_angles_and_splits, solve_splits, splits_at,
};
#[cfg(test)]
pub(crate) use shapes::{ShapeOp, frobenius, moved_angles};
pub use springs::{Spring, SpringLinear, SpringSet, Springs};

use rayon::prelude::*;

use super::block::{Band, BlockPattern};
use super::elements::{BuildContext, Elements};
use crate::math::{Matrix3, Scalar, Vector};
use crate::mesh::Mesh;

/// One kind of force element: its elements and their build, its forces, its
/// energy, its terms of the linearised implicit step and of the direct
/// solver's matrix, and its share of the explicit step bound. Every function
/// runs over all elements of the kind in `el` (its set in [`Elements::kinds`]).
pub trait ForceKind {
    /// The kind's elements of one mesh and their incidence lists, built by
    /// [`ForceKind::build`] and held in [`Elements::kinds`].
    type Set: std::fmt::Debug + Default + Clone + PartialEq + Send + Sync;
    /// What [`ForceKind::build`] leaves to [`ForceKind::deferred`], which may
    /// run beside other work that reads the rebuilt elements (`()`: nothing).
    type Deferred: Default + Send;
    /// The element pass's scratch of this kind (its per-slot forces and
    /// whatever it computes on the way).
    type Forces: std::fmt::Debug + Default + Clone + Send + Sync;
    /// The linearised step's terms of this kind (blocks, slots, gradients).
    type Linear: std::fmt::Debug + Default + Clone + Send + Sync;
    /// A multirate kick's scratch: the forces of a group's elements between
    /// the parallel pass and their write into the slots.
    type Kick: std::fmt::Debug + Default + Clone + Send + Sync;
    /// The place of this kind's energy in the elastic energy's sum.
    const ENERGY_RANK: usize;

    /// Makes `set` the kind's elements of the mesh of `cx` (after a remesh:
    /// reusing its buffers, and keeping of its elements what it can), but for
    /// what it defers ([`ForceKind::Deferred`]).
    fn build(cx: &BuildContext<'_>, set: &mut Self::Set);
    /// The deferred part of the build, made from the built `set`. Default:
    /// nothing.
    fn deferred(_set: &Self::Set) -> Self::Deferred {
        Self::Deferred::default()
    }
    /// Puts the deferred part into `set`. Default: nothing.
    fn install(_set: &mut Self::Set, _deferred: Self::Deferred) {}
    /// The number of elements.
    fn count(el: &Elements) -> usize;
    /// Into `out` (cleared first): the vertices of element `e`, in slot order.
    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>);
    /// Writes the forces at `(x, v)` of the elements `ids` (ascending) into
    /// their slots of `out` (a multirate kick); `kick` is scratch.
    fn kick(
        el: &Elements,
        ids: &[u32],
        x: &[Vector],
        v: &[Vector],
        out: &mut Self::Forces,
        kick: &mut Self::Kick,
    );
    /// Sizes `out` for the elements of `el` (no allocation once grown).
    fn size_forces(el: &Elements, out: &mut Self::Forces);
    /// Fills `out` with every element's forces at `(x, v)`, each into its own slots.
    fn forces(el: &Elements, x: &[Vector], v: &[Vector], out: &mut Self::Forces);
    /// Adds the slots of vertex `i` in `out` to `f`, in incidence order.
    fn gather_force(el: &Elements, out: &Self::Forces, i: usize, f: &mut Vector);
    /// The elastic energy of all elements at `x` (a thread-count independent sum), J.
    fn energy(el: &Elements, x: &[Vector]) -> Scalar;
    /// The linearised step's terms at `(x, v)` for step `h` (`k_term` 1 for
    /// the `-h^2 K v` term of the right-hand side, 0 in a Newton residual);
    /// runs while the shape triangles' fold splits are solved.
    fn linearise(
        el: &Elements,
        x: &[Vector],
        v: &[Vector],
        h: Scalar,
        k_term: Scalar,
        lin: &mut Self::Linear,
    );
    /// The terms that need the fold splits, after they are solved.
    fn linearise_solved(
        _el: &Elements,
        _v: &[Vector],
        _h: Scalar,
        _k_term: Scalar,
        _lin: &mut Self::Linear,
    ) {
    }
    /// Adds the right-hand side slots of vertex `i` to `rhs` and, with
    /// `jacobi`, its diagonal of `h^2 K + h D` to `diag`.
    fn gather_linear(
        el: &Elements,
        lin: &Self::Linear,
        i: usize,
        h: Scalar,
        jacobi: bool,
        rhs: &mut Vector,
        diag: &mut Vector,
    );
    /// The element pass of the product `(h^2 K + h D) p` into the slots of `lin`.
    fn product(el: &Elements, lin: &mut Self::Linear, p: &[Vector], h2: Scalar);
    /// Adds the product's slots of vertex `i` to `acc`, in incidence order.
    fn gather_product(el: &Elements, lin: &Self::Linear, i: usize, acc: &mut Vector);
    /// An upper bound of the pairs [`ForceKind::couplings`] adds.
    fn coupling_count(el: &Elements) -> usize;
    /// Adds every ordered pair of distinct vertices that one of the kind's
    /// blocks couples (each as often as it comes).
    fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>);
    /// Pattern data of the blocks the kind adds in place, band by band
    /// ([`ForceKind::add_in_place`]); `()` for a kind that adds none.
    type InPlace: std::fmt::Debug + Default + Clone + Send + Sync;

    /// For the direct solver's assembly (`block.rs`, "Assembly"): calls
    /// `f(i, j, value, negate)` for every block `(i, j)` (`j <= i`) that an
    /// element adds to the lower triangle of the implicit matrix from a value
    /// of [`ForceKind::block_values`], element by element in element order:
    /// `value` its index there, `negate` true where the block is subtracted.
    /// Default: none.
    fn listed_blocks(_el: &Elements, _f: impl FnMut(u32, u32, u32, bool)) {}
    /// Writes the values that [`ForceKind::listed_blocks`] index into `lin`,
    /// after [`ForceKind::linearise`] (the direct solver only). Default: none.
    fn write_blocks(_el: &Elements, _lin: &mut Self::Linear) {}
    /// The values that [`ForceKind::listed_blocks`] index.
    fn block_values(_lin: &Self::Linear) -> &[Matrix3] {
        &[]
    }
    /// The pattern of the blocks the kind adds in place instead
    /// ([`ForceKind::add_in_place`]), from the built pattern `p`.
    fn in_place_pattern(_el: &Elements, _p: &BlockPattern) -> Self::InPlace {
        Self::InPlace::default()
    }
    /// Adds the kind's in-place blocks (`h2` the step squared) whose row lies
    /// in `band` straight into its lower blocks, after every kind's listed
    /// blocks, and the norms of those the factorization drops to the band's
    /// diagonal compensation. Default: none.
    fn add_in_place(
        _el: &Elements,
        _lin: &Self::Linear,
        _data: &Self::InPlace,
        _h2: Scalar,
        _band: &mut Band<'_>,
    ) {
    }
    /// Calls `f(i, j)` for the pairs whose blocks the reduced factorization
    /// keeps for the kind (`block.rs`, "The factored matrix"), each way.
    /// Default: none.
    fn factored_pairs(_el: &Elements, _f: impl FnMut(u32, u32)) {}
    /// Calls `f(vertex, term)` for each term that compensates on `vertex`'s
    /// diagonal a block that the factorization drops (`factored(i, j)`: whether
    /// it keeps block `(i, j)`), in the order they are summed. Default: none.
    fn dropped_terms(
        _el: &Elements,
        _factored: impl Fn(u32, u32) -> bool,
        _f: impl FnMut(u32, u32),
    ) {
    }
    /// Compensation term `term` of [`ForceKind::dropped_terms`].
    fn dropped_block(_lin: &Self::Linear, _term: u32) -> Matrix3 {
        Matrix3::ZERO
    }
    /// Adds each vertex's Gershgorin bound of this kind's rest stiffness to
    /// `stiff` and of its damping to `damp`; `flat` holds the material
    /// positions (a garment's stencils laid flat one by one into it).
    fn gershgorin(
        el: &Elements,
        mesh: &Mesh,
        flat: &mut [Vector],
        stiff: &mut [Scalar],
        damp: &mut [Scalar],
    );
}

/// A multirate kick's forces: `force(e)`, the `N` slot forces of element `e`,
/// for every element in `ids`, computed in parallel (at least `min_len` a
/// task) into the scratch `kick` and then written into the element's slots
/// of `out` (`N` per element), in `ids`' order.
pub(crate) fn kick_slots<const N: usize>(
    ids: &[u32],
    min_len: usize,
    out: &mut [Vector],
    kick: &mut Vec<[Vector; N]>,
    force: impl Fn(usize) -> [Vector; N] + Sync + Send,
) {
    ids.par_iter()
        .with_min_len(min_len)
        .map(|&e| force(e as usize))
        .collect_into_vec(kick);
    for (&e, f) in ids.iter().zip(kick.iter()) {
        let at = N * e as usize;
        out[at..at + N].copy_from_slice(f);
    }
}

/// Adds to `pairs` every ordered pair `(i, j)` of an element's slots `(k, i)`
/// and `(l, j)` (local slot, vertex) with `k != l` and `i != j`, in slot
/// order: the couplings of an element whose blocks join all its vertices.
pub(crate) fn slot_pairs(
    slots: impl Iterator<Item = (usize, u32)> + Clone,
    pairs: &mut Vec<(u32, u32)>,
) {
    for (k, i) in slots.clone() {
        for (l, j) in slots.clone() {
            if k != l && i != j {
                pairs.push((i, j));
            }
        }
    }
}

/// Calls `f(k, l)` for every block that an element with vertices `v` adds to
/// the lower triangle: local vertices `k` and `l`, both set in `active` (bit
/// `k`), with `v[l] <= v[k]`; `k` outer and `l` inner, each ascending. The
/// pattern (where each block goes) and the values both enumerate through
/// here, so they agree.
#[inline(always)]
pub(crate) fn lower_pairs(v: &[u32], active: u32, mut f: impl FnMut(usize, usize)) {
    for k in (0..v.len()).filter(|&k| active >> k & 1 != 0) {
        for l in (0..v.len()).filter(|&l| active >> l & 1 != 0) {
            if v[l] <= v[k] {
                f(k, l);
            }
        }
    }
}

/// The listed blocks ([`ForceKind::listed_blocks`]) of a kind whose
/// elements (their vertices, in element order) each own a stretch of
/// `stride` values: `f(v[k], v[l], value, false)` for every lower pair of
/// the slots in `active` ([`lower_pairs`]), values counting up from the
/// element's stretch.
pub(crate) fn stretch_blocks<'a>(
    elements: impl Iterator<Item = &'a [u32]>,
    active: u32,
    stride: usize,
    mut f: impl FnMut(u32, u32, u32, bool),
) {
    for (e, v) in elements.enumerate() {
        let mut value = (e * stride) as u32;
        lower_pairs(v, active, |k, l| {
            f(v[k], v[l], value, false);
            value += 1;
        });
    }
}

/// The most lower blocks ([`lower_pairs`], all slots active) of one of the
/// elements `vertices`: the stretch each element owns in its kind's values.
pub(crate) fn lower_stride<'a>(vertices: impl Iterator<Item = &'a [u32]>) -> usize {
    let count = |v: &[u32]| {
        let mut c = 0;
        lower_pairs(v, u32::MAX, |_, _| c += 1);
        c
    };
    vertices.map(count).max().unwrap_or(0)
}

// The force element kinds, in the order each vertex sums them.
kind_list! {
    springs: Springs,
    hinges: Hinges,
    shapes: ShapeTriangles,
    membrane: MembraneTriangles,
    attachments: Attachments,
}

#[cfg(test)]
mod tests;
