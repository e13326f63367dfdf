//! An implicit volume grid triangulated as SPEC.md says ("Volume grid"): vertex (i, j, k) has
//! index `i + nx·(j + ny·k)` (x fastest, VTK's order), every cube is split into six
//! tetrahedra sharing its diagonal from (i, j, k) to (i+1, j+1, k+1) (Freudenthal/Kuhn), so an
//! interior vertex has 14 neighbours. Each z-slice is the 2D grid of [`super::Grid2d`].
//!
//! ```
//! use toposmooth::domain::{Domain, Grid3d};
//! let g = Grid3d::new(3, 3, 3)?;
//! assert_eq!(g.neighbors(g.index(1, 1, 1)).count(), 14);
//! assert_eq!(g.neighbors(0).count(), 7); // +x, +y, +z, three face diagonals, the body diagonal
//! # Ok::<(), toposmooth::Error>(())
//! ```

use super::{Domain, PairingRule, MAX_SPACING, MIN_SPACING};
use crate::error::{Error, Result};

/// The 14 neighbour offsets `(di, dj, dk)`: the three axes, then the face diagonals along
/// (+,+), then the body diagonal, each with its opposite.
pub const NEIGHBOUR_OFFSETS: [[i8; 3]; 14] = [
    [-1, 0, 0],
    [1, 0, 0],
    [0, -1, 0],
    [0, 1, 0],
    [0, 0, -1],
    [0, 0, 1],
    [-1, -1, 0],
    [1, 1, 0],
    [0, -1, -1],
    [0, 1, 1],
    [-1, 0, -1],
    [1, 0, 1],
    [-1, -1, -1],
    [1, 1, 1],
];

/// A grid of `nx × ny × nz` points with spacing `(dx, dy, dz)` (signs kept for derived
/// quantities; operators use magnitudes) and origin. Nothing per vertex or cell is stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid3d {
    n: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
}

impl Grid3d {
    /// A grid with unit spacing and origin 0.
    ///
    /// # Errors
    /// As [`Grid3d::with_geometry`].
    pub fn new(nx: usize, ny: usize, nz: usize) -> Result<Self> {
        Self::with_geometry([nx, ny, nz], [1.0; 3], [0.0; 3])
    }

    /// A grid with the given spacing and origin.
    ///
    /// # Errors
    /// An axis with fewer than 2 points (a flat volume is a 2D grid or a series: readers
    /// make those), a grid too large to index, a spacing that is zero, non-finite or outside
    /// [[`MIN_SPACING`], [`MAX_SPACING`]] in magnitude, a non-finite origin.
    pub fn with_geometry(n: [usize; 3], spacing: [f64; 3], origin: [f64; 3]) -> Result<Self> {
        if n.iter().any(|&a| a < 2) {
            return Err(Error::input(format!(
                "a volume grid needs at least 2 points along each axis, got {} × {} × {}",
                n[0], n[1], n[2]
            )));
        }
        // indices and the 14-neighbour pattern must fit
        if n[0].checked_mul(n[1]).and_then(|a| a.checked_mul(n[2])).and_then(|a| a.checked_mul(15)).is_none() {
            return Err(Error::input(format!(
                "a volume of {} × {} × {} points does not fit in memory",
                n[0], n[1], n[2]
            )));
        }
        if spacing.iter().any(|s| !(MIN_SPACING..=MAX_SPACING).contains(&s.abs())) {
            return Err(Error::input(format!(
                "grid spacing must be finite with {MIN_SPACING:e} ≤ |d| ≤ {MAX_SPACING:e}, got {spacing:?}"
            )));
        }
        // the voxel volume and the stencil's weights (d_y·d_z/d_x) must stay representable
        let volume = spacing.iter().map(|s| s.abs()).product::<f64>();
        let weights = [0, 1, 2].map(|a| volume / (spacing[a] * spacing[a]));
        if !(volume.is_normal() && weights.iter().all(|w| w.is_normal() && w.is_finite())) {
            return Err(Error::input(format!(
                "grid spacing {spacing:?} gives a voxel volume or stencil weight that double precision cannot hold"
            )));
        }
        if origin.iter().any(|o| !o.is_finite()) {
            return Err(Error::input(format!("grid origin must be finite, got {origin:?}")));
        }
        Ok(Grid3d { n, spacing, origin })
    }

    /// Points along x, y and z.
    pub fn dims(&self) -> [usize; 3] {
        self.n
    }
    /// Points along x.
    pub fn nx(&self) -> usize {
        self.n[0]
    }
    /// Points along y.
    pub fn ny(&self) -> usize {
        self.n[1]
    }
    /// Points along z.
    pub fn nz(&self) -> usize {
        self.n[2]
    }
    /// Spacing as given (may be negative).
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }
    /// Origin.
    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }
    /// Flat index of (i, j, k).
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.n[0] * (j + self.n[1] * k)
    }
    /// (i, j, k) of a flat index.
    pub fn ijk(&self, v: usize) -> [usize; 3] {
        let (nx, ny) = (self.n[0], self.n[1]);
        [v % nx, (v / nx) % ny, v / (nx * ny)]
    }
    /// Position with spacing magnitudes and no origin (for operators).
    pub fn position(&self, v: usize) -> [f64; 3] {
        let ijk = self.ijk(v);
        [0, 1, 2].map(|a| ijk[a] as f64 * self.spacing[a].abs())
    }
    /// Position in the file's coordinates: origin + index × spacing (signs kept).
    pub fn world(&self, v: usize) -> [f64; 3] {
        let ijk = self.ijk(v);
        [0, 1, 2].map(|a| self.origin[a] + ijk[a] as f64 * self.spacing[a])
    }
    /// Whether `v` lies on the grid's boundary.
    pub fn on_boundary(&self, v: usize) -> bool {
        let ijk = self.ijk(v);
        (0..3).any(|a| ijk[a] == 0 || ijk[a] + 1 == self.n[a])
    }

    /// The `6 (nx−1)(ny−1)(nz−1)` tetrahedra, positively oriented in (|dx|, |dy|, |dz|)
    /// coordinates: for each cube and each order (a, b, c) of the axes, the path from the
    /// cube's first corner along a, then b, then c.
    pub fn tetrahedra(&self) -> impl Iterator<Item = [usize; 4]> + '_ {
        let [nx, ny, nz] = self.n;
        let stride = [1, nx, nx * ny];
        // the six axis orders; odd permutations get two corners swapped to stay positive
        const ORDERS: [([usize; 3], bool); 6] = [
            ([0, 1, 2], true),
            ([1, 2, 0], true),
            ([2, 0, 1], true),
            ([0, 2, 1], false),
            ([1, 0, 2], false),
            ([2, 1, 0], false),
        ];
        (0..nz - 1).flat_map(move |k| {
            (0..ny - 1).flat_map(move |j| {
                (0..nx - 1).flat_map(move |i| {
                    let v0 = self.index(i, j, k);
                    ORDERS.into_iter().map(move |([a, b, c], even)| {
                        let v1 = v0 + stride[a];
                        let v2 = v1 + stride[b];
                        let v3 = v2 + stride[c];
                        if even {
                            [v0, v1, v2, v3]
                        } else {
                            [v0, v2, v1, v3]
                        }
                    })
                })
            })
        })
    }

    /// The neighbour offsets of `v` that stay inside, with the neighbour's index.
    fn neighbours_with_offsets(&self, v: usize) -> impl Iterator<Item = ([i8; 3], usize)> + '_ {
        let ijk = self.ijk(v).map(|a| a as isize);
        let n = self.n.map(|a| a as isize);
        NEIGHBOUR_OFFSETS.into_iter().filter_map(move |d| {
            let p = [0, 1, 2].map(|a| ijk[a] + d[a] as isize);
            (0..3).all(|a| p[a] >= 0 && p[a] < n[a]).then(|| (d, (p[0] + n[0] * (p[1] + n[1] * p[2])) as usize))
        })
    }

    /// Neighbours of `v` with the offset leading to each, for operators.
    pub fn offset_neighbours(&self, v: usize) -> Vec<([i8; 3], usize)> {
        self.neighbours_with_offsets(v).collect()
    }
}

impl Domain for Grid3d {
    fn n_vertices(&self) -> usize {
        self.n.iter().product()
    }

    fn neighbors(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        self.neighbours_with_offsets(v).map(|(_, w)| w)
    }

    fn pairing_rule(&self) -> PairingRule {
        PairingRule::Surface
    }

    fn diameter(&self) -> f64 {
        let l = [0, 1, 2].map(|a| (self.n[a] - 1) as f64 * self.spacing[a].abs());
        (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt()
    }

    fn point(&self, v: usize) -> [f64; 3] {
        self.position(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    fn signed_volume(g: &Grid3d, t: [usize; 4]) -> f64 {
        let p = t.map(|v| g.position(v));
        let e = [1, 2, 3].map(|c| [0, 1, 2].map(|a| p[c][a] - p[0][a]));
        e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0])
            + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])
    }

    #[test]
    fn fourteen_neighbours_inside_fewer_on_the_boundary() {
        let g = Grid3d::new(4, 3, 5).unwrap();
        let c = g.index(1, 1, 1);
        let n: BTreeSet<usize> = g.neighbors(c).collect();
        assert_eq!(n.len(), 14);
        // the body diagonal along (+,+,+) is a neighbour, the one along (+,−,+) is not
        assert!(n.contains(&g.index(2, 2, 2)) && n.contains(&g.index(0, 0, 0)));
        assert!(!n.contains(&g.index(2, 0, 2)));
        // face diagonals only along (+,+) in each plane
        assert!(n.contains(&g.index(2, 2, 1)) && !n.contains(&g.index(2, 0, 1)));
        assert!(n.contains(&g.index(1, 2, 2)) && !n.contains(&g.index(1, 0, 2)));
        assert!(n.contains(&g.index(2, 1, 2)) && !n.contains(&g.index(0, 1, 2)));
        // corners: (0,0,0) has +x, +y, +z, three face diagonals and the body diagonal
        assert_eq!(g.neighbors(0).count(), 7);
        // (nx−1, 0, 0): −x, +y, +z and the face diagonal (0, +1, +1)
        assert_eq!(g.neighbors(g.index(3, 0, 0)).count(), 4);
        for v in 0..g.n_vertices() {
            for w in g.neighbors(v) {
                assert!(g.neighbors(w).any(|x| x == v), "neighbourhood is symmetric");
            }
        }
    }

    #[test]
    fn edges_are_the_tetrahedra_s_edges_and_each_slice_is_the_2d_grid() {
        let g = Grid3d::new(4, 3, 3).unwrap();
        let mut from_tets = BTreeSet::new();
        let mut faces = std::collections::BTreeMap::new();
        let mut volume = 0.0;
        for t in g.tetrahedra() {
            let v = signed_volume(&g, t);
            assert!(v > 0.0, "positively oriented");
            volume += v / 6.0;
            for a in 0..4 {
                for b in a + 1..4 {
                    from_tets.insert((t[a].min(t[b]), t[a].max(t[b])));
                }
                let mut f: Vec<usize> = (0..4).filter(|&c| c != a).map(|c| t[c]).collect();
                f.sort();
                *faces.entry(f).or_insert(0) += 1;
            }
        }
        assert!((volume - 3.0 * 2.0 * 2.0).abs() < 1e-12);
        let edges: BTreeSet<_> = g.edges().into_iter().collect();
        assert_eq!(edges, from_tets);
        // every face on one or two tetrahedra; V − E + F − T = 1 (a ball)
        assert!(faces.values().all(|&c| c == 1 || c == 2));
        let (v, e, f, t) =
            (g.n_vertices() as i64, edges.len() as i64, faces.len() as i64, g.tetrahedra().count() as i64);
        assert_eq!(v - e + f - t, 1);
        // a z-slice: the 2D grid's neighbours
        let g2 = crate::domain::Grid2d::new(4, 3).unwrap();
        for r in 0..3 {
            for c in 0..4 {
                let in_slice: BTreeSet<usize> =
                    g.neighbors(g.index(c, r, 1)).filter(|&w| g.ijk(w)[2] == 1).map(|w| w - 12).collect();
                let flat: BTreeSet<usize> = g2.neighbors(g2.index(r, c)).collect();
                assert_eq!(in_slice, flat);
            }
        }
    }

    #[test]
    fn rejects_degenerate_volumes() {
        assert!(Grid3d::new(1, 5, 5).is_err());
        assert!(Grid3d::with_geometry([3, 3, 3], [1.0, 0.0, 1.0], [0.0; 3]).is_err());
        assert!(Grid3d::with_geometry([3, 3, 3], [1.0, 1.0, f64::NAN], [0.0; 3]).is_err());
        assert!(Grid3d::with_geometry([3, 3, 3], [1e-105, 1e-105, 1e-105], [0.0; 3]).is_err());
        assert!(Grid3d::with_geometry([3, 3, 3], [1.0; 3], [0.0, f64::INFINITY, 0.0]).is_err());
        let g = Grid3d::with_geometry([3, 2, 2], [0.5, -2.0, 1.0], [1.0, 2.0, 3.0]).unwrap();
        assert_eq!(g.diameter(), (1.0f64 + 4.0 + 1.0).sqrt());
        assert_eq!(g.position(g.index(2, 1, 1)), [1.0, 2.0, 1.0]);
        assert_eq!(g.world(g.index(2, 1, 1)), [2.0, 0.0, 4.0]);
        assert_eq!(g.ijk(g.index(2, 1, 1)), [2, 1, 1]);
    }
}
