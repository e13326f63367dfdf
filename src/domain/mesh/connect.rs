//! How a validated mesh hangs together: triangles oriented consistently per component, the
//! boundary loops (the vertex adjacency is `domain::cells`).

use super::validate::EdgeTable;

/// The triangles' components and what orienting them did.
pub(super) struct Orientation {
    /// Component of each triangle.
    pub tri_comp: Vec<usize>,
    /// Number of components.
    pub n_components: usize,
    /// Triangles flipped to agree with their neighbours.
    pub flipped: usize,
    /// Edges across which the orientation stays inconsistent (a non-orientable surface).
    pub non_orientable: usize,
}

/// Orients each component of the triangle graph consistently, breadth first from its first
/// triangle (a neighbour that runs the shared edge the same way is flipped).
pub(super) fn orient(triangles: &mut [[usize; 3]], table: &EdgeTable) -> Orientation {
    let nt = triangles.len();
    let mut tri_comp = vec![usize::MAX; nt];
    let mut n_components = 0;
    let mut flipped = 0usize;
    let mut non_orientable = 0usize;
    for seed in 0..nt {
        if tri_comp[seed] != usize::MAX {
            continue;
        }
        tri_comp[seed] = n_components;
        let mut queue = std::collections::VecDeque::from([seed]);
        while let Some(t) = queue.pop_front() {
            let tri = triangles[t];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let [t1, t2] = table.edge_tris[table.edge_of(t, a, b)];
                let other = if t1 == t { t2 } else { t1 };
                if other == usize::MAX {
                    continue;
                }
                // the neighbour agrees with t when it runs the shared edge b → a
                let o = triangles[other];
                let same = (0..3).any(|j| o[j] == a && o[(j + 1) % 3] == b);
                if tri_comp[other] == usize::MAX {
                    tri_comp[other] = n_components;
                    if same {
                        triangles[other].swap(1, 2);
                        flipped += 1;
                    }
                    queue.push_back(other);
                } else if same {
                    non_orientable += 1;
                }
            }
        }
        n_components += 1;
    }
    Orientation { tri_comp, n_components, flipped, non_orientable }
}

/// Boundary loops: the components of the boundary edges (manifold vertices: each boundary
/// vertex has exactly two boundary edges, so these are cycles).
pub(super) fn boundary_loops(n: usize, table: &EdgeTable) -> usize {
    let boundary: Vec<(usize, usize)> =
        table.edges.iter().zip(&table.edge_tris).filter(|(_, t)| t[1] == usize::MAX).map(|(e, _)| *e).collect();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for &(a, b) in &boundary {
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra] = rb;
        }
    }
    let mut roots: Vec<usize> = boundary.iter().map(|&(a, _)| find(&mut parent, a)).collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}
