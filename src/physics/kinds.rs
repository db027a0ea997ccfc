//! Force element kinds: each kind of force element (springs, dihedral hinges,
//! shape triangles, membrane triangles) implements [`ForceKind`] in its own
//! file under `kinds/`, and [`kind_list!`] names them once. Every consumer
//! loops over that list through the types it generates: the element pass and
//! the per-vertex gather of the explicit integrators ([`KindForces`]), the
//! elastic energy ([`elastic_energy`]), the implicit step's linearisation, its
//! right-hand side and Jacobi diagonal and the CG solver's matrix-free product
//! ([`KindLinear`]), the block pattern of the direct solver ([`couplings`])
//! and the explicit step bound ([`gershgorin`]).
//!
//! The dispatch is static: the list expands to one call per kind, each a loop
//! over that kind's elements, so no element pays for a virtual call.
//!
//! # Order
//! Each vertex sums its kinds' slots in the list's order (and each kind's slots
//! in its incidence lists' order), so results do not depend on the thread
//! count and stay the same bit for bit as long as the list's order does. The
//! elastic energy sums the kinds' energies in an order of its own, each kind's
//! [`ForceKind::ENERGY_RANK`] (springs, membrane, hinges, shape triangles).
//!
//! # Adding a kind
//! A new file under `kinds/` with a type that implements [`ForceKind`] (its
//! elements read from [`Elements`]), and one line in the [`kind_list!`]
//! invocation below, at the end (a kind inserted earlier changes the order of
//! every sum after it).

mod hinges;
mod membrane;
mod shapes;
mod springs;

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

/// One kind of force element: its forces, its energy, its terms of the
/// linearised implicit step and its share of the explicit step bound. Every
/// function runs over all elements of the kind in `el`.
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

/// Generates, from the list of kinds (`field: Kind`), the per-kind scratch
/// structs and the loops over kinds. Invoked once, below.
macro_rules! kind_list {
    ($($field:ident: $kind:ty),+ $(,)?) => {
        /// The number of force element kinds.
        pub const KIND_COUNT: usize = [$(stringify!($field)),+].len();

        // Each energy rank is below the number of kinds and taken once.
        const _: () = {
            let ranks = [$(<$kind as ForceKind>::ENERGY_RANK),+];
            let mut i = 0;
            while i < ranks.len() {
                assert!(ranks[i] < ranks.len());
                let mut j = i + 1;
                while j < ranks.len() {
                    assert!(ranks[i] != ranks[j]);
                    j += 1;
                }
                i += 1;
            }
        };

        /// Each kind's place in the list.
        #[allow(non_camel_case_types)]
        #[derive(Debug, Clone, Copy)]
        enum Place {
            $($field,)+
        }

        /// Per kind, element indices (for example those that touch a
        /// multirate group), in the list's order.
        pub type KindIds = [Vec<u32>; KIND_COUNT];

        /// Calls `f(kind, element, vertices)` for every element of every
        /// kind, kind by kind, each kind in element order (`kind` its place
        /// in the list).
        pub fn for_each_element(el: &Elements, mut f: impl FnMut(usize, u32, &[u32])) {
            let mut vertices = Vec::new();
            $(
                for e in 0..<$kind as ForceKind>::count(el) {
                    <$kind as ForceKind>::element_vertices(el, e, &mut vertices);
                    f(Place::$field as usize, e as u32, &vertices);
                }
            )+
        }

        /// Into `out` (cleared first): the vertices of element `e` of the kind
        /// at place `kind` in the list.
        pub fn element_vertices(el: &Elements, kind: usize, e: usize, out: &mut Vec<u32>) {
            $(
                if kind == Place::$field as usize {
                    <$kind as ForceKind>::element_vertices(el, e, out);
                }
            )+
        }

        /// Every kind's elements and incidence lists of one mesh.
        #[derive(Debug, Default, Clone, PartialEq)]
        pub struct KindSets {
            $(
                #[doc = concat!("The elements of [`", stringify!($kind), "`].")]
                pub $field: <$kind as ForceKind>::Set,
            )+
        }

        /// What every kind's build defers ([`ForceKind::Deferred`]).
        #[derive(Default)]
        pub struct KindDeferred {
            $(
                #[doc = concat!("The deferred part of [`", stringify!($kind), "`].")]
                pub $field: <$kind as ForceKind>::Deferred,
            )+
        }

        impl KindSets {
            /// Every kind's [`ForceKind::build`], kind by kind.
            pub fn build(&mut self, cx: &BuildContext<'_>) {
                $(<$kind as ForceKind>::build(cx, &mut self.$field);)+
            }

            /// Every kind's [`ForceKind::deferred`].
            pub fn deferred(&self) -> KindDeferred {
                KindDeferred {
                    $($field: <$kind as ForceKind>::deferred(&self.$field),)+
                }
            }

            /// Every kind's [`ForceKind::install`].
            pub fn install(&mut self, deferred: KindDeferred) {
                $(<$kind as ForceKind>::install(&mut self.$field, deferred.$field);)+
            }
        }

        /// Every kind's multirate scratch.
        #[derive(Debug, Default, Clone)]
        pub struct KindKicks {
            $(
                #[doc = concat!("The kick scratch of [`", stringify!($kind), "`].")]
                pub $field: <$kind as ForceKind>::Kick,
            )+
        }

        /// The element pass's scratch of every kind.
        #[derive(Debug, Default, Clone)]
        pub struct KindForces {
            $(
                #[doc = concat!("The scratch of [`", stringify!($kind), "`].")]
                pub $field: <$kind as ForceKind>::Forces,
            )+
        }

        impl KindForces {
            /// Sizes every kind's scratch for `el`.
            pub fn size(&mut self, el: &Elements) {
                $(<$kind as ForceKind>::size_forces(el, &mut self.$field);)+
            }

            /// Every kind's element pass at `(x, v)`.
            pub fn compute(&mut self, el: &Elements, x: &[Vector], v: &[Vector]) {
                $(<$kind as ForceKind>::forces(el, x, v, &mut self.$field);)+
            }

            /// Every kind's [`ForceKind::kick`] of its elements in `ids`.
            pub fn kick(
                &mut self,
                el: &Elements,
                ids: &KindIds,
                x: &[Vector],
                v: &[Vector],
                kicks: &mut KindKicks,
            ) {
                $(<$kind as ForceKind>::kick(
                    el,
                    &ids[Place::$field as usize],
                    x,
                    v,
                    &mut self.$field,
                    &mut kicks.$field,
                );)+
            }

            /// Adds every kind's slots of vertex `i` to `f`, kind by kind.
            #[inline(always)]
            pub fn gather(&self, el: &Elements, i: usize, f: &mut Vector) {
                $(<$kind as ForceKind>::gather_force(el, &self.$field, i, f);)+
            }
        }

        /// The linearised implicit step's terms of every kind.
        #[derive(Debug, Default, Clone)]
        pub struct KindLinear {
            $(
                #[doc = concat!("The terms of [`", stringify!($kind), "`].")]
                pub $field: <$kind as ForceKind>::Linear,
            )+
        }

        impl KindLinear {
            /// Every kind's [`ForceKind::linearise`].
            pub fn linearise(
                &mut self,
                el: &Elements,
                x: &[Vector],
                v: &[Vector],
                h: Scalar,
                k_term: Scalar,
            ) {
                $(<$kind as ForceKind>::linearise(el, x, v, h, k_term, &mut self.$field);)+
            }

            /// Every kind's [`ForceKind::linearise_solved`].
            pub fn linearise_solved(&mut self, el: &Elements, v: &[Vector], h: Scalar, k_term: Scalar) {
                $(<$kind as ForceKind>::linearise_solved(el, v, h, k_term, &mut self.$field);)+
            }

            /// Adds every kind's right-hand side slots (and with `jacobi`
            /// diagonal) of vertex `i`, kind by kind.
            #[inline(always)]
            pub fn gather(
                &self,
                el: &Elements,
                i: usize,
                h: Scalar,
                jacobi: bool,
                rhs: &mut Vector,
                diag: &mut Vector,
            ) {
                $(<$kind as ForceKind>::gather_linear(el, &self.$field, i, h, jacobi, rhs, diag);)+
            }

            /// Every kind's element pass of the product with `p`.
            pub fn product(&mut self, el: &Elements, p: &[Vector], h2: Scalar) {
                $(<$kind as ForceKind>::product(el, &mut self.$field, p, h2);)+
            }

            /// Adds every kind's product slots of vertex `i` to `acc`, kind by kind.
            #[inline(always)]
            pub fn gather_product(&self, el: &Elements, i: usize, acc: &mut Vector) {
                $(<$kind as ForceKind>::gather_product(el, &self.$field, i, acc);)+
            }
        }

        impl KindLinear {
            /// Every kind's [`ForceKind::write_blocks`].
            pub fn write_blocks(&mut self, el: &Elements) {
                $(<$kind as ForceKind>::write_blocks(el, &mut self.$field);)+
            }

            /// Every kind's [`ForceKind::block_values`], in the list's order.
            pub fn block_values(&self) -> [&[Matrix3]; KIND_COUNT] {
                [$(<$kind as ForceKind>::block_values(&self.$field)),+]
            }

            /// Every kind's [`ForceKind::add_in_place`] into `band`, kind by kind.
            #[inline(always)]
            pub fn add_in_place(
                &self,
                el: &Elements,
                data: &KindInPlace,
                h2: Scalar,
                band: &mut Band<'_>,
            ) {
                $(<$kind as ForceKind>::add_in_place(el, &self.$field, &data.$field, h2, band);)+
            }

            /// Adds to `m`, kind by kind, the compensation terms `terms[kind]`
            /// ([`ForceKind::dropped_block`]).
            #[inline(always)]
            pub fn add_dropped(&self, terms: [&[u32]; KIND_COUNT], m: &mut Matrix3) {
                $(
                    for &t in terms[Place::$field as usize] {
                        *m += <$kind as ForceKind>::dropped_block(&self.$field, t);
                    }
                )+
            }
        }

        /// The pattern data of every kind's in-place blocks.
        #[derive(Debug, Default, Clone)]
        pub struct KindInPlace {
            $(
                #[doc = concat!("The in-place pattern of [`", stringify!($kind), "`].")]
                pub(crate) $field: <$kind as ForceKind>::InPlace,
            )+
        }

        impl KindInPlace {
            /// Every kind's [`ForceKind::in_place_pattern`] on the built pattern `p`.
            pub fn build(el: &Elements, p: &BlockPattern) -> KindInPlace {
                KindInPlace {
                    $($field: <$kind as ForceKind>::in_place_pattern(el, p),)+
                }
            }
        }

        /// Every kind's [`ForceKind::listed_blocks`], kind by kind, as
        /// `f(kind, i, j, value, negate)` (`kind` the place in the list).
        pub fn listed_blocks(el: &Elements, mut f: impl FnMut(usize, u32, u32, u32, bool)) {
            $(<$kind as ForceKind>::listed_blocks(el, |i, j, value, negate| {
                f(Place::$field as usize, i, j, value, negate)
            });)+
        }

        /// Every kind's [`ForceKind::factored_pairs`].
        pub fn factored_pairs(el: &Elements, mut f: impl FnMut(u32, u32)) {
            $(<$kind as ForceKind>::factored_pairs(el, &mut f);)+
        }

        /// Every kind's [`ForceKind::dropped_terms`], kind by kind, as
        /// `f(kind, vertex, term)`.
        pub fn dropped_terms(
            el: &Elements,
            factored: impl Fn(u32, u32) -> bool,
            mut f: impl FnMut(usize, u32, u32),
        ) {
            $(<$kind as ForceKind>::dropped_terms(el, &factored, |vertex, term| {
                f(Place::$field as usize, vertex, term)
            });)+
        }

        /// The elastic energy of every kind at `x`, summed in the kinds'
        /// [`ForceKind::ENERGY_RANK`] order, J.
        pub fn elastic_energy(el: &Elements, x: &[Vector]) -> Scalar {
            let mut by_rank = [0.0; KIND_COUNT];
            $(by_rank[<$kind as ForceKind>::ENERGY_RANK] = <$kind as ForceKind>::energy(el, x);)+
            by_rank.into_iter().reduce(|a, b| a + b).unwrap_or(0.0)
        }

        /// The sum of every kind's [`ForceKind::coupling_count`].
        pub fn coupling_count(el: &Elements) -> usize {
            0 $(+ <$kind as ForceKind>::coupling_count(el))+
        }

        /// Every kind's [`ForceKind::couplings`], kind by kind.
        pub fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>) {
            $(<$kind as ForceKind>::couplings(el, pairs);)+
        }

        /// Every kind's [`ForceKind::gershgorin`], kind by kind.
        pub fn gershgorin(
            el: &Elements,
            mesh: &Mesh,
            flat: &mut [Vector],
            stiff: &mut [Scalar],
            damp: &mut [Scalar],
        ) {
            $(<$kind as ForceKind>::gershgorin(el, mesh, flat, stiff, damp);)+
        }
    };
}

// The force element kinds, in the order each vertex sums them.
kind_list! {
    springs: Springs,
    hinges: Hinges,
    shapes: ShapeTriangles,
    membrane: MembraneTriangles,
}

#[cfg(test)]
mod tests;
