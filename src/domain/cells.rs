//! What triangle and tetrahedral meshes share: the checks for cells given twice, vertices no
//! cell uses and vertices at one position (each returns what it found, sorted; the mesh's
//! validation words the error), and the vertex adjacency in compressed rows.

/// Every later copy of a cell with the first cell of the same corners (in any order), as
/// `(copy, first)` pairs sorted by copy.
pub(super) fn duplicate_cells<const K: usize>(cells: &[[usize; K]]) -> Vec<(usize, usize)> {
    let mut keyed: Vec<([usize; K], usize)> = cells
        .iter()
        .enumerate()
        .map(|(c, cell)| {
            let mut key = *cell;
            key.sort_unstable();
            (key, c)
        })
        .collect();
    keyed.sort_unstable();
    let mut dups = Vec::new();
    for group in keyed.chunk_by(|a, b| a.0 == b.0) {
        dups.extend(group[1..].iter().map(|&(_, c)| (c, group[0].1)));
    }
    dups.sort_unstable();
    dups
}

/// The vertices of `0..n` that no cell uses.
pub(super) fn unused_vertices<const K: usize>(n: usize, cells: &[[usize; K]]) -> Vec<usize> {
    let mut used = vec![false; n];
    for cell in cells {
        for &v in cell {
            used[v] = true;
        }
    }
    (0..n).filter(|&v| !used[v]).collect()
}

/// Pairs `(a, b)`, `a < b`, of vertices at the same (finite) position, sorted.
pub(super) fn coincident_vertices(positions: &[[f64; 3]]) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..positions.len()).collect();
    order.sort_unstable_by(|&a, &b| positions[a].partial_cmp(&positions[b]).expect("finite"));
    let mut pairs: Vec<(usize, usize)> = order
        .windows(2)
        .filter(|w| positions[w[0]] == positions[w[1]])
        .map(|w| (w[0].min(w[1]), w[0].max(w[1])))
        .collect();
    pairs.sort_unstable();
    pairs
}

/// The neighbours of every vertex as compressed rows: `adj[start[v]..start[v + 1]]`, sorted.
pub(super) fn adjacency(n: usize, edges: &[(usize, usize)]) -> (Vec<usize>, Vec<usize>) {
    let mut start = vec![0usize; n + 1];
    for &(a, b) in edges {
        start[a + 1] += 1;
        start[b + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut adj = vec![0usize; start[n]];
    for &(a, b) in edges {
        adj[fill[a]] = b;
        fill[a] += 1;
        adj[fill[b]] = a;
        fill[b] += 1;
    }
    for v in 0..n {
        adj[start[v]..start[v + 1]].sort_unstable();
    }
    (start, adj)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_pair_with_the_first_cell_and_unused_and_coincident_vertices_are_found() {
        let cells = [[0, 1, 2], [2, 1, 0], [1, 2, 3], [0, 2, 1]];
        assert_eq!(duplicate_cells(&cells), vec![(1, 0), (3, 0)]);
        assert_eq!(unused_vertices(6, &cells), vec![4, 5]);
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        assert_eq!(coincident_vertices(&p), vec![(0, 2), (1, 3)]);
    }
}
