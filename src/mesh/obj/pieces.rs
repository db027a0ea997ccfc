//! The pieces of an OBJ cloth (its texture islands) and the panels made of them.

use std::collections::{HashMap, HashSet};

use crate::math::Vector2;
use crate::mesh::{Panels, topology::UnionFind};

/// The name tobj gives an object the file does not name.
const UNNAMED: &str = "unnamed_object";

/// How the triangles fall into pieces.
pub(super) struct Pieces {
    /// The piece of each triangle, numbered in file order of first triangles.
    pub of_triangle: Vec<u32>,
    /// The number of pieces.
    pub count: usize,
    /// True when some vertex has two different corner coordinates.
    pub welded: bool,
}

/// A corner's identity: its vertex and its material coordinate's bits (with
/// -0 read as +0, so that equal coordinates are one corner).
type CornerKey = (u32, [u64; 2]);

fn corner_key(v: u32, p: Vector2) -> CornerKey {
    (v, [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits()])
}

/// Splits the triangles into pieces: two triangles are in one piece when they
/// share an edge whose two corners have the same vertex and the same material
/// coordinate in both (texture islands; connected components when every vertex
/// has one coordinate).
pub(super) fn find_pieces(triangles: &[[u32; 3]], corners: &[[Vector2; 3]]) -> Pieces {
    let mut joins = UnionFind::new(triangles.len());
    let mut first_at: HashMap<[CornerKey; 2], usize> = HashMap::new();
    let mut coordinate: HashMap<u32, Vector2> = HashMap::new();
    let mut welded = false;
    for (t, (tri, c)) in triangles.iter().zip(corners).enumerate() {
        let keys = [0, 1, 2].map(|k| corner_key(tri[k], c[k]));
        for k in 0..3 {
            let (a, b) = (keys[k], keys[(k + 1) % 3]);
            let edge = if a <= b { [a, b] } else { [b, a] };
            let other = *first_at.entry(edge).or_insert(t);
            joins.union(t, other);
            let old = *coordinate.entry(tri[k]).or_insert(c[k]);
            welded |= old != c[k];
        }
    }
    let mut number: HashMap<usize, u32> = HashMap::new();
    let of_triangle: Vec<u32> = (0..triangles.len())
        .map(|t| {
            let root = joins.find(t);
            let next = number.len() as u32;
            *number.entry(root).or_insert(next)
        })
        .collect();
    Pieces {
        of_triangle,
        count: number.len(),
        welded,
    }
}

/// The panels of a cloth in pieces, without seams, and each vertex's home
/// coordinate: the corner of the first triangle (in file order) that uses it,
/// whose piece is the vertex's home panel. `model_of` and `model_names` give
/// each triangle's OBJ object, which names the panels ([`panel_names`]).
pub(super) fn panels(
    vertex_count: usize,
    triangles: &[[u32; 3]],
    corners: Vec<[Vector2; 3]>,
    pieces: &Pieces,
    model_of: &[u32],
    model_names: &[&str],
) -> (Vec<Vector2>, Panels) {
    let mut material = vec![Vector2::ZERO; vertex_count];
    let mut of_vertex = vec![0u16; vertex_count];
    let mut placed = vec![false; vertex_count];
    for (t, tri) in triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            if !std::mem::replace(&mut placed[v as usize], true) {
                of_vertex[v as usize] = pieces.of_triangle[t] as u16;
                material[v as usize] = corners[t][k];
            }
        }
    }
    let names = panel_names(pieces, model_of, model_names);
    let of_triangle = pieces.of_triangle.iter().map(|&p| p as u16).collect();
    let panels = Panels {
        names,
        of_triangle,
        corners,
        of_vertex,
        seams: Vec::new(),
        holds: Vec::new(),
    };
    (material, panels)
}

/// Names each piece after the OBJ object (or group) it lies in, when all its
/// triangles lie in objects of one name that no other piece's triangles use
/// (tobj's `unnamed_object`, given to faces before any `o` or `g`, names
/// nothing); any other piece is `pieceN`, N its number in file order (1 for
/// the first), with `_2`, `_3`, ... added should an object already have that
/// name.
pub(super) fn panel_names(pieces: &Pieces, model_of: &[u32], model_names: &[&str]) -> Vec<String> {
    let mut names_of: Vec<HashSet<&str>> = vec![HashSet::new(); pieces.count];
    for (&p, &m) in pieces.of_triangle.iter().zip(model_of) {
        let name = model_names.get(m as usize).copied().unwrap_or(UNNAMED);
        names_of[p as usize].insert(name);
    }
    let mut pieces_using: HashMap<&str, usize> = HashMap::new();
    for names in &names_of {
        for &name in names {
            *pieces_using.entry(name).or_insert(0) += 1;
        }
    }
    let own = |names: &HashSet<&str>| -> Option<String> {
        let mut iter = names.iter();
        match (iter.next(), iter.next()) {
            (Some(&name), None) if name != UNNAMED && pieces_using[name] == 1 => {
                Some(name.to_string())
            }
            _ => None,
        }
    };
    let mut names: Vec<Option<String>> = names_of.iter().map(own).collect();
    let mut taken: HashSet<String> = names.iter().flatten().cloned().collect();
    for (p, name) in names.iter_mut().enumerate() {
        if name.is_none() {
            let base = format!("piece{}", p + 1);
            let mut candidate = base.clone();
            let mut k = 2;
            while taken.contains(&candidate) {
                candidate = format!("{base}_{k}");
                k += 1;
            }
            taken.insert(candidate.clone());
            *name = Some(candidate);
        }
    }
    names.into_iter().flatten().collect()
}
