//! Hash maps keyed by vertex pairs (edges), with a small fixed hasher.
//!
//! The remeshing tables (`adapt::red_green`, `adapt::soup`) look up and insert
//! tens of thousands of `(u32, u32)` keys per pass. The standard library's
//! SipHash is built to resist hash flooding, which keys computed from our own
//! mesh do not need; with SipHash, `perf` on the tablecloth scene puts its
//! symbols (`Hasher::write`, `hash_one`) at 2.8% of the run. This is the
//! multiply-rotate hash of rustc's `FxHasher` with a final fold of the high
//! half into the low one (hashbrown takes the bucket from the low bits and the
//! control byte from the top 7). Iteration order is fixed too (no random seed),
//! though no result here depends on it.

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// A map keyed by vertex pairs (or other small integer keys).
pub type PairMap<K, V> = HashMap<K, V, BuildHasherDefault<PairHasher>>;

/// A set of vertex pairs (or other small integer keys).
pub type PairSet<K> = HashSet<K, BuildHasherDefault<PairHasher>>;

const K: u64 = 0x517c_c1b7_2722_0a95;

/// FxHash-style hasher for small integer keys (see the module docs).
#[derive(Debug, Default, Clone, Copy)]
pub struct PairHasher(u64);

impl PairHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(K);
    }
}

impl Hasher for PairHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(i as u64);
    }

    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }

    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0 ^ (self.0 >> 32)
    }
}
