//! Self-collision's primitive pairs (vertex against triangle, edge against
//! edge), packed into one sortable integer each, and the rest-space test that
//! tells which triangle pairs may hold parts that are close in the rest state.
//!
//! A triangle pair whose two triangles overlap in their swept boxes yields up
//! to 6 vertex-triangle and 9 edge-edge pairs (those whose own swept boxes
//! overlap too, `selfcol.rs`); neighbouring triangle pairs yield many of the
//! same ones, so the list is sorted and deduplicated every step.
//! Packed into a `u128` in the order of its fields, a pair sorts by one
//! integer comparison, in the same order as its fields would.
//!
//! Pairs of parts close in the rest state are dropped (a thickness cannot be
//! kept between them). Most triangle pairs are far apart in rest space, so
//! the test runs per triangle pair first: two triangles whose rest points'
//! centroids are farther apart than their radii and 1.5 thicknesses cannot
//! hold a pair closer than that, and their pairs are marked as kept. Only the
//! pairs of the other triangle pairs are measured one by one.

use rayon::prelude::*;

use crate::math::{Scalar, Vector};

use super::geometry::{closest_on_segments, closest_on_triangle};

/// Bits of each vertex or triangle id in a packed pair.
const ID_BITS: u32 = 31;
const ID_MASK: u128 = (1 << ID_BITS) - 1;

/// Bits of each id in a narrow key ([`sort_and_dedup`]): 4 ids, the kind and
/// the rest mark fill 62 of 64 bits.
const NARROW_ID_BITS: u32 = 15;

/// A primitive pair, packed: kind (0: vertex `a` against triangle `b`; 1:
/// edge `(a, b)` against edge `(c, d)`), the four ids, and a last bit set when
/// its triangle pair may be close in rest space (the pair is then measured).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Prim(u128);

impl Prim {
    fn pack(kind: u8, ids: [u32; 4], near: bool) -> Prim {
        debug_assert!(ids.iter().all(|&i| (i as u128) <= ID_MASK));
        let mut key = kind as u128;
        for i in ids {
            key = (key << ID_BITS) | i as u128;
        }
        Prim((key << 1) | near as u128)
    }

    /// Vertex `v` against triangle `t`.
    pub(super) fn vertex_triangle(v: u32, t: u32, near: bool) -> Prim {
        Prim::pack(0, [v, t, 0, 0], near)
    }

    /// Edge `e` against edge `f`, each with its smaller vertex first; the
    /// smaller edge comes first.
    pub(super) fn edge_edge(e: [u32; 2], f: [u32; 2], near: bool) -> Prim {
        let (lo, hi) = if e <= f { (e, f) } else { (f, e) };
        Prim::pack(1, [lo[0], lo[1], hi[0], hi[1]], near)
    }

    /// The narrow key of a pair whose ids fit in [`NARROW_ID_BITS`] bits.
    fn narrow(self) -> u64 {
        let (kind, ids) = self.fields();
        let mut key = u64::from(kind);
        for i in ids {
            key = (key << NARROW_ID_BITS) | u64::from(i);
        }
        (key << 1) | u64::from(self.near())
    }

    /// The pair of a narrow key ([`Prim::narrow`]).
    fn widen(key: u64) -> Prim {
        let mask = (1u64 << NARROW_ID_BITS) - 1;
        let fields = key >> 1;
        let id = |k: u32| ((fields >> (NARROW_ID_BITS * (3 - k))) & mask) as u32;
        let kind = (fields >> (4 * NARROW_ID_BITS)) as u8;
        Prim::pack(kind, [id(0), id(1), id(2), id(3)], key & 1 == 1)
    }

    /// Kind and ids.
    fn fields(self) -> (u8, [u32; 4]) {
        let key = self.0 >> 1;
        let id = |k: u32| ((key >> (ID_BITS * (3 - k))) & ID_MASK) as u32;
        ((key >> (4 * ID_BITS)) as u8, [id(0), id(1), id(2), id(3)])
    }

    /// True when its triangle pair may be close in rest space.
    pub(super) fn near(self) -> bool {
        self.0 & 1 == 1
    }

    /// The same primitive pair (whatever its rest mark).
    pub(super) fn same_pair(self, other: Prim) -> bool {
        self.0 >> 1 == other.0 >> 1
    }

    /// How many of its four vertices ([`Prim::weights`]' order) make its
    /// first part: 1 (the vertex) or 2 (the first edge).
    pub(super) fn first_part(self) -> usize {
        if self.fields().0 == 0 { 1 } else { 2 }
    }

    /// The four vertices of the pair and their weights: the relative position of
    /// the two closest points is `sum w_k x_k` (positive side first), at the
    /// positions `at`.
    pub(super) fn weights(
        self,
        tris: &[[u32; 3]],
        at: &impl Fn(u32) -> Vector,
    ) -> ([u32; 4], [Scalar; 4]) {
        match self.fields() {
            (0, [v, t, ..]) => {
                let t = tris[t as usize];
                let [a, b, c] = t.map(at);
                let bary = closest_on_triangle(at(v), a, b, c);
                ([v, t[0], t[1], t[2]], [1.0, -bary[0], -bary[1], -bary[2]])
            }
            (_, [a, b, c, d]) => {
                let (s, t) = closest_on_segments(at(a), at(b), at(c), at(d));
                ([a, b, c, d], [1.0 - s, s, -(1.0 - t), -t])
            }
        }
    }
}

/// Every triangle's rest-space centroid and radius (the largest distance
/// from the centroid to one of its rest points), for [`RestBounds::far`].
#[derive(Debug, Clone, Default)]
pub(super) struct RestBounds {
    centre: Vec<Vector>,
    radius: Vec<Scalar>,
}

impl RestBounds {
    /// The bounds of `tris` at the vertices' `rest` points.
    pub(super) fn new(tris: &[[u32; 3]], rest: &[Vector]) -> RestBounds {
        let (centre, radius) = tris
            .iter()
            .map(|t| {
                let p = t.map(|i| rest[i as usize]);
                let c = (p[0] + p[1] + p[2]) / 3.0;
                let r = p.iter().map(|q| q.distance(c)).fold(0.0, Scalar::max);
                (c, r)
            })
            .unzip();
        RestBounds { centre, radius }
    }

    /// True when no point of triangle `t` is within `limit` of a point of
    /// triangle `u` in rest space (with a margin for rounding).
    pub(super) fn far(&self, t: u32, u: u32, limit: Scalar) -> bool {
        let (t, u) = (t as usize, u as usize);
        let gap = self.centre[t].distance(self.centre[u]) - self.radius[t] - self.radius[u];
        gap > limit * (1.0 + 1e-9) + 1e-12
    }
}

/// Scratch memory of [`sort_and_dedup`], kept between steps.
#[derive(Debug, Clone, Default)]
pub(super) struct PairSort {
    /// The pairs' narrow keys as packed.
    keys: Vec<u64>,
    /// The keys grouped by bucket, then sorted.
    sorted: Vec<u64>,
    /// Per bucket, the start of its keys in `sorted` (then its end).
    start: Vec<u32>,
}

/// Below this many keys a range of buckets is sorted on one thread.
const SEQUENTIAL_KEYS: usize = 4096;

/// Sorts `prims` and keeps the first of each pair's copies (the smallest rest
/// mark: far before near). While every id fits in [`NARROW_ID_BITS`] bits
/// (`id_bound`: larger than every vertex and triangle id), the pairs are
/// sorted as 64-bit keys: the same fields in the same order, so the same
/// order, at half the bytes moved. The keys are first grouped by their
/// leading fields, the kind and the first id (a counting sort, one bucket per
/// kind and id), and each bucket, a few dozen keys, is then sorted alone: the
/// order of one sort of the whole list, in fewer comparisons.
pub(super) fn sort_and_dedup(prims: &mut Vec<Prim>, scratch: &mut PairSort, id_bound: usize) {
    if id_bound > 1 << NARROW_ID_BITS {
        prims.par_sort_unstable();
        prims.dedup_by(|later, kept| later.same_pair(*kept));
        return;
    }
    let PairSort {
        keys,
        sorted,
        start,
    } = scratch;
    keys.clear();
    keys.par_extend(prims.par_iter().map(|p| p.narrow()));
    // Bucket: the kind and the first id, the key's leading bits.
    let shift = 3 * NARROW_ID_BITS + 1;
    let buckets = 2 * id_bound;
    let bucket = |key: u64| {
        let (kind, id) = (
            key >> (shift + NARROW_ID_BITS),
            (key >> shift) & ((1 << NARROW_ID_BITS) - 1),
        );
        kind as usize * id_bound + id as usize
    };
    start.clear();
    start.resize(buckets + 1, 0);
    for &k in keys.iter() {
        start[bucket(k) + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    sorted.clear();
    sorted.resize(keys.len(), 0);
    for &k in keys.iter() {
        let b = bucket(k);
        sorted[start[b] as usize] = k;
        start[b] += 1;
    }
    // `start[b]` is now bucket b's end, and bucket b starts at `start[b - 1]`.
    sort_buckets(sorted, &start[..buckets], 0);
    sorted.dedup_by(|later, kept| *later >> 1 == *kept >> 1);
    prims.clear();
    prims.par_extend(sorted.par_iter().map(|&k| Prim::widen(k)));
}

/// Sorts each bucket of `keys` alone, in parallel over ranges of buckets:
/// `ends[b]` is the end of bucket `b` in the whole list, whose first
/// `offset` keys lie before `keys`.
fn sort_buckets(keys: &mut [u64], ends: &[u32], offset: usize) {
    if keys.len() <= SEQUENTIAL_KEYS || ends.len() < 2 {
        let mut from = 0;
        for &end in ends {
            let end = end as usize - offset;
            keys[from..end].sort_unstable();
            from = end;
        }
        return;
    }
    let mid = ends.len() / 2;
    let split = ends[mid - 1] as usize - offset;
    let (first, second) = keys.split_at_mut(split);
    rayon::join(
        || sort_buckets(first, &ends[..mid], offset),
        || sort_buckets(second, &ends[mid..], offset + split),
    );
}

/// The edge `(a, b)` with its smaller vertex first.
pub(super) fn edge(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded stream of numbers below a bound (a linear congruential
    /// generator: the same stream on every machine).
    fn numbers(mut seed: u64) -> impl FnMut(u32) -> u32 {
        move |m: u32| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) as u32) % m
        }
    }

    /// Packed pairs sort as their fields do (kind, then the ids in order), and
    /// unpack to the same fields.
    #[test]
    fn packed_pairs_sort_like_their_fields() {
        let mut fields: Vec<(u8, [u32; 4])> = Vec::new();
        let mut next = numbers(12345);
        for _ in 0..500 {
            let big = if next(4) == 0 { (1 << ID_BITS) - 1 } else { 50 };
            let ids = [next(big), next(big), next(big), next(big)];
            fields.push((next(2) as u8, ids));
        }
        let mut packed: Vec<Prim> = fields
            .iter()
            .map(|&(k, ids)| Prim::pack(k, ids, next(2) == 1))
            .collect();
        fields.sort_unstable();
        packed.sort_unstable();
        let unpacked: Vec<(u8, [u32; 4])> = packed.iter().map(|p| p.fields()).collect();
        assert_eq!(unpacked, fields);
    }

    /// Sorted through narrow keys, pairs come out as the plain sort leaves
    /// them, duplicates (whatever their rest mark) reduced to their first copy.
    #[test]
    fn narrow_keys_sort_and_deduplicate_like_the_packed_pairs() {
        let mut next = numbers(777);
        let bound = 1u32 << NARROW_ID_BITS;
        let mut prims = Vec::new();
        for _ in 0..2000 {
            let big = if next(3) == 0 { bound } else { 9 };
            let ids = [next(big), next(big), next(big), next(big)];
            prims.push(Prim::pack(next(2) as u8, ids, next(2) == 1));
        }
        let mut plain = prims.clone();
        plain.sort_unstable();
        plain.dedup_by(|later, kept| later.same_pair(*kept));
        let mut scratch = PairSort::default();
        sort_and_dedup(&mut prims, &mut scratch, bound as usize);
        assert!(plain.len() < 2000, "no duplicates: the test checks nothing");
        assert_eq!(prims, plain);
    }

    /// Triangles 0.2 m apart are not far at a limit of 0.2 m or 0.1 m (the
    /// bound is conservative, not tight); 5 m apart they are.
    #[test]
    fn far_triangles_hold_no_close_points() {
        let rest = |shift: Scalar| {
            vec![
                Vector::new(0.0, 0.0, 0.0),
                Vector::new(1.0, 0.0, 0.0),
                Vector::new(0.0, 1.0, 0.0),
                Vector::new(1.2 + shift, 0.0, 0.0),
                Vector::new(2.0 + shift, 0.0, 0.0),
                Vector::new(1.2 + shift, 1.0, 0.0),
            ]
        };
        let tris = [[0, 1, 2], [3, 4, 5]];
        let near = RestBounds::new(&tris, &rest(0.0));
        assert!(!near.far(0, 1, 0.2));
        assert!(!near.far(0, 1, 0.1));
        assert!(RestBounds::new(&tris, &rest(5.0)).far(0, 1, 0.2));
    }
}
