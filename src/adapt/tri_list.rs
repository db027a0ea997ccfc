//! A sorted list of triangle ids at one edge that holds two ids without
//! allocating. A manifold soup has at most two triangles at an edge, so a
//! `Vec` per edge would cost one heap allocation per edge per pass. More than
//! two (a non-manifold state, which `Mesh::from_parts` refuses later) spill
//! into `more`.

/// Sorted triangle ids at an edge.
#[derive(Debug, Clone, Default)]
pub struct TriList {
    head: [u32; 2],
    n: u8,
    more: Vec<u32>,
}

impl TriList {
    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.n as usize + self.more.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The ids, ascending.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.head[..self.n as usize]
            .iter()
            .chain(self.more.iter())
            .copied()
    }

    /// The ids, ascending, as a vector.
    pub fn to_vec(&self) -> Vec<u32> {
        self.iter().collect()
    }

    /// The two ids when there are exactly two (an interior edge).
    pub fn to_pair(&self) -> Option<[u32; 2]> {
        (self.n == 2 && self.more.is_empty()).then_some(self.head)
    }

    fn set(&mut self, all: Vec<u32>) {
        self.n = all.len().min(2) as u8;
        self.head[..self.n as usize].copy_from_slice(&all[..self.n as usize]);
        self.more = all[self.n as usize..].to_vec();
    }

    /// Inserts `id` at its sorted place.
    pub fn insert(&mut self, id: u32) {
        if self.n < 2 && self.more.is_empty() {
            let at = self.head[..self.n as usize].partition_point(|&t| t < id);
            if at == 0 && self.n == 1 {
                self.head[1] = self.head[0];
            }
            self.head[at] = id;
            self.n += 1;
            return;
        }
        let mut all = self.to_vec();
        let at = all.partition_point(|&t| t < id);
        all.insert(at, id);
        self.set(all);
    }

    /// Removes `id` if present.
    pub fn remove(&mut self, id: u32) {
        if self.more.is_empty() {
            if let Some(k) = self.head[..self.n as usize].iter().position(|&t| t == id) {
                if k == 0 && self.n == 2 {
                    self.head[0] = self.head[1];
                }
                self.n -= 1;
            }
            return;
        }
        let mut all = self.to_vec();
        all.retain(|&t| t != id);
        self.set(all);
    }
}

/// Equal when they hold the same ids (unused inline slots do not count).
impl PartialEq for TriList {
    fn eq(&self, other: &TriList) -> bool {
        self.iter().eq(other.iter())
    }
}

impl Eq for TriList {}
