//! Linear-time grouping of the pattern's lists by vertex or block.
//!
//! A pattern is rebuilt after every remesh, and sorting its lists with the
//! comparison sorts of `std` was most of that: on `tablecloth` (adaptive, about
//! 5,000 vertices, a remesh every other step) `perf` put 16% of the run's time in
//! `BlockPattern::build` and the sorts it called, against 5% in the ordering and
//! symbolic factorization. Every key here is a vertex or block index below a
//! known bound, so a counting sort gives the same order in linear time.

/// Groups `pairs` by key (each key below `keys`), keeping the pairs of one key in
/// their original order: the result of a stable sort by key. Returns `start`
/// (length `keys + 1`; the items of key `k` are `items[start[k]..start[k + 1]]`)
/// and the items.
pub(crate) fn group_by_key<T: Copy>(keys: usize, pairs: &[(u32, T)]) -> (Vec<u32>, Vec<T>) {
    let mut start = vec![0u32; keys + 1];
    for &(k, _) in pairs {
        start[k as usize + 1] += 1;
    }
    for k in 0..keys {
        start[k + 1] += start[k];
    }
    let Some(&(_, first)) = pairs.first() else {
        return (start, Vec::new());
    };
    let mut fill = start.clone();
    let mut items = vec![first; pairs.len()];
    for &(k, item) in pairs {
        items[fill[k as usize] as usize] = item;
        fill[k as usize] += 1;
    }
    (start, items)
}

/// The sorted, duplicate-free set of `(row, column)` pairs with rows below
/// `rows`, as a row start array (length `rows + 1`) and the columns: the same as
/// sorting the pairs and removing duplicates, in time linear in the pairs plus a
/// sort of each row's distinct columns. Duplicates are dropped before the sort
/// by marking each column with the last row that kept it (a pattern's pairs
/// repeat each block several times: every element that couples two vertices
/// adds the pair again).
pub(super) fn sorted_unique_rows(rows: usize, pairs: &[(u32, u32)]) -> (Vec<u32>, Vec<u32>) {
    let (start, mut columns) = group_by_key(rows, pairs);
    let bound = columns.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
    let mut kept_in_row = vec![u32::MAX; bound];
    let mut row_start = vec![0u32; rows + 1];
    let mut kept = 0usize;
    for r in 0..rows {
        let (s, e) = (start[r] as usize, start[r + 1] as usize);
        let first = kept;
        for k in s..e {
            let c = columns[k];
            if kept_in_row[c as usize] != r as u32 {
                kept_in_row[c as usize] = r as u32;
                columns[kept] = c;
                kept += 1;
            }
        }
        columns[first..kept].sort_unstable();
        row_start[r + 1] = kept as u32;
    }
    columns.truncate(kept);
    (row_start, columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grouping_is_a_stable_sort_by_key() {
        let pairs = [(2, 'a'), (0, 'b'), (2, 'c'), (1, 'd'), (0, 'e')];
        let mut sorted = pairs.to_vec();
        sorted.sort_by_key(|p| p.0);
        let (start, items) = group_by_key(4, &pairs);
        assert_eq!(start, vec![0, 2, 3, 5, 5]);
        assert_eq!(items, sorted.iter().map(|p| p.1).collect::<Vec<_>>());
    }

    #[test]
    fn unique_rows_match_sort_and_dedup() {
        let pairs = [(1, 5), (0, 3), (1, 2), (1, 5), (0, 0), (3, 1), (0, 3)];
        let mut sorted = pairs.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        let (row_start, columns) = sorted_unique_rows(4, &pairs);
        assert_eq!(row_start, vec![0, 2, 4, 4, 5]);
        assert_eq!(columns, sorted.iter().map(|p| p.1).collect::<Vec<_>>());
    }
}
