//! The [`kind_list!`] macro: from the list of force element kinds, the
//! structs of every kind's sets, scratch and terms, and the loops over kinds
//! (module docs of `kinds.rs`).

/// Generates, from the list of kinds (`field: Kind`), each kind's module
/// (`kinds/field.rs`), the per-kind scratch structs and the loops over
/// kinds. Invoked once, in `kinds.rs`.
macro_rules! kind_list {
    ($($field:ident: $kind:ty),+ $(,)?) => {
        // Each kind's file, `kinds/FIELD.rs`.
        $(mod $field;)+

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
