//! The vertices an attachment holds: chains along panel sides, kept through
//! welds and remeshing as a seam's pairs are.
//!
//! A [`Hold`] keeps, for each side it holds, the chain of vertices along it in
//! order. A weld renumbers them ([`Hold::renumbered`]); a remesh keeps the
//! kept vertices and puts each new midpoint of two neighbours of a chain
//! between them ([`Hold::carried`]), so a side stays held however finely it
//! is split. Like a [`super::Seam`], a hold says only which vertices are held:
//! the plane they are held at and how hard is the physics model's
//! (`spec::Attachment`).

use super::Mesh;
use crate::math::Scalar;

/// The vertices one attachment holds: a chain of vertices along each of its
/// panel sides, in order along the side.
#[derive(Debug, Clone, PartialEq)]
pub struct Hold {
    /// The attachment's name.
    pub name: String,
    /// Per held side, its vertices in order along it.
    pub chains: Vec<Vec<u32>>,
}

impl Hold {
    /// The hold with every vertex `v` renamed `new_index[v]` (a weld), two
    /// neighbours merged into one kept once.
    pub fn renumbered(&self, new_index: &[u32]) -> Hold {
        let chains = self
            .chains
            .iter()
            .map(|c| {
                let mut chain: Vec<u32> = c.iter().map(|&v| new_index[v as usize]).collect();
                chain.dedup();
                chain
            })
            .collect();
        Hold {
            name: self.name.clone(),
            chains,
        }
    }

    /// The hold on a remeshed topology: `map(v)` is old vertex `v`'s new index
    /// (`None`: dropped), `midpoint(a, b)` the new vertex made at the midpoint
    /// of the new vertices `a` and `b`, if any. A dropped vertex leaves the
    /// chain; a midpoint between two neighbours of a chain joins it between
    /// them (midpoints of midpoints too).
    pub fn carried(
        &self,
        map: impl Fn(u32) -> Option<u32>,
        midpoint: impl Fn(u32, u32) -> Option<u32>,
    ) -> Hold {
        let chains = self
            .chains
            .iter()
            .map(|c| {
                let kept: Vec<u32> = c.iter().filter_map(|&v| map(v)).collect();
                let mut chain = Vec::with_capacity(kept.len());
                for w in kept.windows(2) {
                    chain.push(w[0]);
                    split(w[0], w[1], &midpoint, &mut chain);
                }
                chain.extend(kept.last());
                chain
            })
            .collect();
        Hold {
            name: self.name.clone(),
            chains,
        }
    }

    /// Each held vertex with its share of the held sides' rest length, m (half
    /// of each chain segment at each of its ends), in order of first
    /// appearance; a vertex on two held sides (a corner) appears once, with
    /// both shares. A chain of one vertex gives it no length.
    pub fn shares(&self, mesh: &Mesh) -> Vec<(u32, Scalar)> {
        let mut out: Vec<(u32, Scalar)> = Vec::new();
        let mut add = |v: u32, len: Scalar| match out.iter_mut().find(|(w, _)| *w == v) {
            Some(entry) => entry.1 += len,
            None => out.push((v, len)),
        };
        for chain in &self.chains {
            if let [only] = chain[..] {
                add(only, 0.0);
            }
            for w in chain.windows(2) {
                let half = 0.5 * segment_length(mesh, w[0], w[1]);
                add(w[0], half);
                add(w[1], half);
            }
        }
        out
    }
}

/// Pushes onto `chain` the midpoints between `a` and `b` (exclusive), in order
/// from `a` to `b`.
fn split(a: u32, b: u32, midpoint: &impl Fn(u32, u32) -> Option<u32>, chain: &mut Vec<u32>) {
    if let Some(m) = midpoint(a, b) {
        split(a, m, midpoint, chain);
        chain.push(m);
        split(m, b, midpoint, chain);
    }
}

/// The rest length of the mesh's edge between `a` and `b`, m (0 when they
/// share no edge, which a chain's neighbours always do).
fn segment_length(mesh: &Mesh, a: u32, b: u32) -> Scalar {
    let key = [a.min(b), a.max(b)];
    mesh.edges
        .binary_search_by_key(&key, |e| e.vertices)
        .map_or(0.0, |e| mesh.rest_length(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hold(chains: Vec<Vec<u32>>) -> Hold {
        Hold {
            name: "waist".into(),
            chains,
        }
    }

    #[test]
    fn a_weld_renames_the_chain_and_merges_neighbours_it_joined() {
        let h = hold(vec![vec![0, 1, 2, 3]]);
        let welded = h.renumbered(&[0, 1, 1, 2]);
        assert_eq!(welded.chains, vec![vec![0, 1, 2]]);
    }

    #[test]
    fn a_remesh_drops_removed_vertices_and_inserts_midpoints_in_order() {
        let h = hold(vec![vec![0, 1, 2]]);
        // Old 1 is dropped; old 0 -> 0, old 2 -> 1; new 2 halves (0, 1), new 3
        // halves (2, 1).
        let map = |v: u32| [Some(0), None, Some(1)][v as usize];
        let mid = |a: u32, b: u32| match (a.min(b), a.max(b)) {
            (0, 1) => Some(2),
            (1, 2) => Some(3),
            _ => None,
        };
        assert_eq!(h.carried(map, mid).chains, vec![vec![0, 2, 3, 1]]);
    }
}
