//! Test and example tetrahedral meshes: the Freudenthal/Kuhn split of a box (SPEC.md, "Volume
//! grid") and the same with its interior vertices jittered.

use super::{signed_volume6, TetMesh};

/// The axis orders of the six tetrahedra of a cube: tetrahedron σ runs from corner (0, 0, 0)
/// along axis σ₀, then σ₁, then σ₂, to (1, 1, 1).
const AXIS_ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];

/// The box's vertices (vertex (i, j, k) at `(i·dx, j·dy, k·dz)`, index `i + nx·(j + ny·k)`)
/// and its tetrahedra, positively oriented.
fn box_cells(nx: usize, ny: usize, nz: usize, spacing: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[usize; 4]>) {
    assert!(nx >= 2 && ny >= 2 && nz >= 2, "a box grid needs at least 2 points along each axis");
    assert!(spacing.iter().all(|s| s.is_finite() && *s != 0.0), "the spacing must be finite and non-zero");
    let index = |c: [usize; 3]| c[0] + nx * (c[1] + ny * c[2]);
    let mut positions = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                positions.push([i as f64 * spacing[0], j as f64 * spacing[1], k as f64 * spacing[2]]);
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * (nx - 1) * (ny - 1) * (nz - 1));
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                for order in AXIS_ORDERS {
                    let mut c = [i, j, k];
                    let mut tet = [index(c); 4];
                    for (step, &axis) in order.iter().enumerate() {
                        c[axis] += 1;
                        tet[step + 1] = index(c);
                    }
                    let [a, b, cc, d] = tet.map(|v| positions[v]);
                    if signed_volume6(a, b, cc, d) < 0.0 {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    (positions, tets)
}

/// A deterministic number in `[−1, 1)` from a seed and a counter (SplitMix64).
fn jitter(seed: u64, counter: u64) -> f64 {
    let mut z = seed.wrapping_add(counter.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

impl TetMesh {
    /// The box of `nx × ny × nz` points with `spacing` (vertex (i, j, k) at
    /// `(i·dx, j·dy, k·dz)`, index `i + nx·(j + ny·k)`), every cube split into the six
    /// tetrahedra sharing its diagonal from (i, j, k) to (i+1, j+1, k+1) (Freudenthal/Kuhn,
    /// SPEC.md "Volume grid": every face split along its +,+ diagonal). An interior vertex has
    /// 14 neighbours.
    ///
    /// # Panics
    /// If an extent is below 2 or a spacing is zero or not finite.
    pub fn box_grid(nx: usize, ny: usize, nz: usize, spacing: [f64; 3]) -> TetMesh {
        let (positions, tets) = box_cells(nx, ny, nz, spacing);
        TetMesh::new(positions, tets).expect("a valid box grid")
    }

    /// [`TetMesh::box_grid`] with every interior vertex moved by up to `amount × spacing` along
    /// each axis, deterministically from `seed` (the boundary stays a box). The tetrahedra are
    /// those of the box; `amount ≤ 0.05` provably keeps every one positively oriented (each
    /// Kuhn tetrahedron's determinant, 1 in units of the spacing, moves by less than
    /// `7.7 r + 17 r² + 8 r³` for corner displacements `r = √3 · amount`).
    ///
    /// # Panics
    /// As [`TetMesh::box_grid`], and if the jitter inverts or flattens a tetrahedron (possible
    /// only above `amount = 0.05`).
    pub fn jittered_box(nx: usize, ny: usize, nz: usize, spacing: [f64; 3], amount: f64, seed: u64) -> TetMesh {
        let (mut positions, tets) = box_cells(nx, ny, nz, spacing);
        for k in 1..nz - 1 {
            for j in 1..ny - 1 {
                for i in 1..nx - 1 {
                    let v = i + nx * (j + ny * k);
                    for a in 0..3 {
                        positions[v][a] += amount * spacing[a] * jitter(seed, 3 * v as u64 + a as u64);
                    }
                }
            }
        }
        let mesh = TetMesh::new(positions, tets).expect("a valid jittered box");
        assert!(mesh.repairs().is_empty(), "the jitter inverted tetrahedra: {:?}", mesh.repairs());
        mesh
    }
}
