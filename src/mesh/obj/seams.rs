//! Seams from an OBJ file's `l` elements (sewing edges, as Blender exports
//! loose edges between the two sides of a seam).

use std::collections::{HashMap, HashSet};

use super::ObjError;
use super::merge::MergedObj;
use super::text::{LineElement, ObjText};
use crate::mesh::{Edge, Seam};

/// A sewing pair read from the file.
struct Pair {
    /// The two vertices, the first on the seam's first side.
    ends: [u32; 2],
    /// The line of its `l` element.
    line: usize,
    /// The object or group its `l` element lies in.
    group: usize,
}

/// What the seams are checked against: the mesh's edges and panels.
pub(super) struct SeamMesh<'a> {
    /// The mesh's edges.
    pub edges: &'a [Edge],
    /// Each vertex's home panel.
    pub of_vertex: &'a [u16],
}

/// Reads the seams of the file's `l` elements: each element pairs its
/// consecutive vertices. Pairs are oriented with the first vertex in the
/// lower-numbered (home) panel, or the lower-numbered vertex within one panel;
/// the same pair given twice in one object or group (`o`, `g`) counts once.
/// Two pairs of one object or group are on one seam when their first vertices
/// are joined by a boundary edge and so are their second ones, or the first of
/// each and the second of the other (then one is turned round); pairs of
/// different objects or groups are on different seams. A seam is named `lN`, N the line of its first element (`lN_2`,
/// `lN_3`, ... for further seams that start on that line).
pub(super) fn read_seams(
    text: &ObjText,
    merged: &MergedObj,
    mesh: &SeamMesh,
    name: &str,
) -> Result<Vec<Seam>, ObjError> {
    let pairs = read_pairs(text, merged, mesh, name)?;
    let (groups, flipped) = group_pairs(&pairs, mesh.edges);
    let mut names: HashSet<String> = HashSet::new();
    let seams = groups
        .into_iter()
        .map(|group| {
            let line = pairs[group[0]].line;
            let mut seam_name = format!("l{line}");
            let mut k = 2;
            while names.contains(&seam_name) {
                seam_name = format!("l{line}_{k}");
                k += 1;
            }
            names.insert(seam_name.clone());
            let pairs = group
                .iter()
                .map(|&i| {
                    let [a, b] = pairs[i].ends;
                    if flipped[i] { [b, a] } else { [a, b] }
                })
                .collect();
            Seam {
                name: seam_name,
                pairs,
            }
        })
        .collect();
    Ok(seams)
}

/// The sewing pairs of every `l` element, checked and oriented, in file order.
fn read_pairs(
    text: &ObjText,
    merged: &MergedObj,
    mesh: &SeamMesh,
    name: &str,
) -> Result<Vec<Pair>, ObjError> {
    let mut on_boundary = vec![false; merged.positions.len()];
    let mut joined: HashSet<[u32; 2]> = HashSet::new();
    for e in mesh.edges {
        joined.insert(e.vertices);
        if !e.is_interior() {
            for v in e.vertices {
                on_boundary[v as usize] = true;
            }
        }
    }
    let mut pairs = Vec::new();
    let mut seen: HashSet<(usize, [u32; 2])> = HashSet::new();
    for element in &text.lines {
        let bad = |reason: String| ObjError::BadLine {
            path: name.to_string(),
            line: element.line,
            reason,
        };
        let vertices = element_vertices(element, text, merged, &on_boundary).map_err(bad)?;
        for (k, w) in vertices.windows(2).enumerate() {
            let ([a, b], [i, j]) = ([w[0], w[1]], [element.vertices[k], element.vertices[k + 1]]);
            let along = if a == b {
                Some("the same vertex of the cloth")
            } else if joined.contains(&[a.min(b), a.max(b)]) {
                Some("already joined by an edge of the mesh")
            } else {
                None
            };
            if let Some(what) = along {
                return Err(bad(format!(
                    "`l` sews vertex {} to vertex {}, {what}: a seam's two sides must \
                     be different boundary segments",
                    i + 1,
                    j + 1
                )));
            }
            let key = |v: u32| (mesh.of_vertex[v as usize], v);
            let ends = if key(a) <= key(b) { [a, b] } else { [b, a] };
            if seen.insert((element.group, ends)) {
                pairs.push(Pair {
                    ends,
                    line: element.line,
                    group: element.group,
                });
            }
        }
    }
    Ok(pairs)
}

/// The cloth vertices of an `l` element's vertices, each on the boundary.
fn element_vertices(
    element: &LineElement,
    text: &ObjText,
    merged: &MergedObj,
    on_boundary: &[bool],
) -> Result<Vec<u32>, String> {
    element
        .vertices
        .iter()
        .map(|&i| {
            let v = merged.vertex_of_line(text, i).ok_or_else(|| {
                format!(
                    "`l` vertex {} is used by no face, so it is not a vertex of the cloth",
                    i + 1
                )
            })?;
            if !on_boundary[v as usize] {
                return Err(format!(
                    "`l` vertex {} is not a boundary vertex: it lies on no boundary edge of \
                     the mesh (a seam sews the boundaries of panels)",
                    i + 1
                ));
            }
            Ok(v)
        })
        .collect()
}

/// Groups the pairs into seams, pairs of one object or group only (each seam
/// in file order, the seams in the order of their first pairs) and says which pairs to turn round so that each
/// seam's first vertices are on one side.
fn group_pairs(pairs: &[Pair], edges: &[Edge]) -> (Vec<Vec<usize>>, Vec<bool>) {
    let mut boundary: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut is_boundary: HashSet<[u32; 2]> = HashSet::new();
    for e in edges.iter().filter(|e| !e.is_interior()) {
        let [a, b] = e.vertices;
        boundary.entry(a).or_default().push(b);
        boundary.entry(b).or_default().push(a);
        is_boundary.insert(e.vertices);
    }
    let boundary_edge = |a: u32, b: u32| is_boundary.contains(&[a.min(b), a.max(b)]);
    let mut at_end: [HashMap<u32, Vec<usize>>; 2] = Default::default();
    for (i, p) in pairs.iter().enumerate() {
        for (side, at) in at_end.iter_mut().enumerate() {
            at.entry(p.ends[side]).or_default().push(i);
        }
    }
    // links[i]: (j, turned) where j's orientation relative to i's is turned.
    let mut links: Vec<Vec<(usize, bool)>> = vec![Vec::new(); pairs.len()];
    for (i, p) in pairs.iter().enumerate() {
        let [a, b] = p.ends;
        for &u in boundary.get(&a).into_iter().flatten() {
            for (side, turned) in [(0, false), (1, true)] {
                for &j in at_end[side].get(&u).into_iter().flatten() {
                    if pairs[j].group == p.group && boundary_edge(b, pairs[j].ends[1 - side]) {
                        links[i].push((j, turned));
                        links[j].push((i, turned));
                    }
                }
            }
        }
    }
    let mut flipped = vec![false; pairs.len()];
    let mut visited = vec![false; pairs.len()];
    let mut groups = Vec::new();
    for start in 0..pairs.len() {
        if visited[start] {
            continue;
        }
        visited[start] = true;
        let mut group = vec![start];
        let mut stack = vec![start];
        while let Some(i) = stack.pop() {
            for &(j, turned) in &links[i] {
                if !visited[j] {
                    visited[j] = true;
                    flipped[j] = flipped[i] ^ turned;
                    group.push(j);
                    stack.push(j);
                }
            }
        }
        group.sort_unstable();
        groups.push(group);
    }
    (groups, flipped)
}
