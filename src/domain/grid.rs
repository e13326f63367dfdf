//! An implicit 2D grid triangulated as SPEC.md says: vertex (row r, column c) has index
//! `r·nx + c`, every cell is split by the diagonal from (c, r) to (c+1, r+1), so an interior
//! vertex has 6 neighbours: left, right, up, down, (r−1, c−1) and (r+1, c+1).

use super::{Domain, PairingRule};
use crate::error::{Error, Result};

/// Smallest accepted spacing magnitude.
pub const MIN_SPACING: f64 = 1e-100;
/// Largest accepted spacing magnitude.
pub const MAX_SPACING: f64 = 1e100;

/// Where a grid lies in space: its columns run along physical axis `axes[0]` and its rows
/// along `axes[1]` (0 x, 1 y, 2 z; `axes[0] < axes[1]`), at coordinate `level` along the third
/// axis. An image in the x-z plane is `axes = [0, 2]`, `level` its y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// The physical axes of the grid's x and y.
    pub axes: [usize; 2],
    /// The coordinate along the remaining axis.
    pub level: f64,
}

impl Plane {
    /// The x-y plane at z = 0.
    pub const XY: Plane = Plane { axes: [0, 1], level: 0.0 };

    /// The axis the plane is normal to.
    pub fn normal(&self) -> usize {
        3 - self.axes[0] - self.axes[1]
    }
}

/// A grid of `nx` columns × `ny` rows with spacing `(dx, dy)` (signs kept for derived
/// quantities; operators use |dx|, |dy|) and origin, lying in a [`Plane`] of space (the x-y
/// plane unless [`Grid2d::in_plane`] puts it elsewhere). Nothing per vertex is stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid2d {
    nx: usize,
    ny: usize,
    spacing: [f64; 2],
    origin: [f64; 2],
    plane: Plane,
}

impl Grid2d {
    /// A grid with unit spacing and origin 0.
    ///
    /// # Errors
    /// Fewer than 2 columns or 2 rows.
    pub fn new(nx: usize, ny: usize) -> Result<Self> {
        Self::with_geometry(nx, ny, [1.0, 1.0], [0.0, 0.0])
    }

    /// A grid with the given spacing and origin.
    ///
    /// # Errors
    /// Fewer than 2 columns or rows, a spacing that is zero, non-finite or outside
    /// [[`MIN_SPACING`], [`MAX_SPACING`]] in magnitude, a non-finite origin.
    pub fn with_geometry(nx: usize, ny: usize, spacing: [f64; 2], origin: [f64; 2]) -> Result<Self> {
        if nx < 2 || ny < 2 {
            return Err(Error::input(format!("a grid needs at least 2 columns and 2 rows, got {nx} × {ny}")));
        }
        if nx.checked_mul(ny).is_none() {
            return Err(Error::input(format!("a grid of {nx} × {ny} vertices does not fit in memory")));
        }
        if spacing.iter().any(|s| !(MIN_SPACING..=MAX_SPACING).contains(&s.abs())) {
            return Err(Error::input(format!(
                "grid spacing must be finite with {MIN_SPACING:e} ≤ |d| ≤ {MAX_SPACING:e} (so that the \
                 operators' weights and the cell areas stay representable), got {spacing:?}"
            )));
        }
        if origin.iter().any(|o| !o.is_finite()) {
            return Err(Error::input(format!("grid origin must be finite, got {origin:?}")));
        }
        Ok(Grid2d { nx, ny, spacing, origin, plane: Plane::XY })
    }

    /// The grid placed in `plane` (its geometry otherwise unchanged).
    ///
    /// # Errors
    /// Axes that are not two increasing axes of x, y, z; a non-finite level.
    pub fn in_plane(mut self, plane: Plane) -> Result<Self> {
        let [a, b] = plane.axes;
        if !(a < b && b < 3 && plane.level.is_finite()) {
            return Err(Error::input(format!(
                "a grid's plane needs two increasing axes of 0, 1, 2 and a finite level, got {plane:?}"
            )));
        }
        self.plane = plane;
        Ok(self)
    }

    /// The plane the grid lies in.
    pub fn plane(&self) -> Plane {
        self.plane
    }

    /// Physical position of a vertex: origin + (c·dx, r·dy) with the signed spacing, along the
    /// plane's axes, as VTK places an image's points.
    pub fn world(&self, v: usize) -> [f64; 3] {
        let (r, c) = self.row_col(v);
        let mut p = [0.0; 3];
        p[self.plane.axes[0]] = self.origin[0] + c as f64 * self.spacing[0];
        p[self.plane.axes[1]] = self.origin[1] + r as f64 * self.spacing[1];
        p[self.plane.normal()] = self.plane.level;
        p
    }

    /// Columns.
    pub fn nx(&self) -> usize {
        self.nx
    }
    /// Rows.
    pub fn ny(&self) -> usize {
        self.ny
    }
    /// Spacing `(dx, dy)` as given (may be negative).
    pub fn spacing(&self) -> [f64; 2] {
        self.spacing
    }
    /// Origin.
    pub fn origin(&self) -> [f64; 2] {
        self.origin
    }
    /// Flat index of (row, column).
    pub fn index(&self, row: usize, col: usize) -> usize {
        row * self.nx + col
    }
    /// (row, column) of a flat index.
    pub fn row_col(&self, v: usize) -> (usize, usize) {
        (v / self.nx, v % self.nx)
    }
    /// Position of a vertex in the plane, with |dx|, |dy| (for operators).
    pub fn position(&self, v: usize) -> [f64; 2] {
        let (r, c) = self.row_col(v);
        [c as f64 * self.spacing[0].abs(), r as f64 * self.spacing[1].abs()]
    }
    /// The `2 (nx−1)(ny−1)` triangles, counter-clockwise in (column, row) coordinates.
    pub fn triangles(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        (0..self.ny - 1).flat_map(move |r| {
            (0..self.nx - 1).flat_map(move |c| {
                let (a, b, d, e) =
                    (self.index(r, c), self.index(r, c + 1), self.index(r + 1, c), self.index(r + 1, c + 1));
                // split along the diagonal a–e: (a, b, e) and (a, e, d)
                [[a, b, e], [a, e, d]]
            })
        })
    }
}

impl Domain for Grid2d {
    fn n_vertices(&self) -> usize {
        self.nx * self.ny
    }

    fn neighbors(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        let (r, c) = self.row_col(v);
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let (r, c) = (r as isize, c as isize);
        // left, right, up, down, then the two along the split diagonal
        [(0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (1, 1)].into_iter().filter_map(move |(dr, dc)| {
            let (rr, cc) = (r + dr, c + dc);
            (rr >= 0 && rr < ny && cc >= 0 && cc < nx).then(|| (rr * nx + cc) as usize)
        })
    }

    fn pairing_rule(&self) -> PairingRule {
        PairingRule::Surface
    }

    fn point(&self, v: usize) -> [f64; 3] {
        let [x, y] = self.position(v);
        [x, y, 0.0]
    }

    fn triangles(&self) -> Vec<[usize; 3]> {
        Grid2d::triangles(self).collect()
    }

    fn diameter(&self) -> f64 {
        let w = (self.nx - 1) as f64 * self.spacing[0].abs();
        let h = (self.ny - 1) as f64 * self.spacing[1].abs();
        w.hypot(h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn six_neighbours_inside_fewer_on_the_boundary() {
        let g = Grid2d::new(4, 3).unwrap();
        let mut n: Vec<usize> = g.neighbors(g.index(1, 1)).collect();
        n.sort();
        // (1,0)=4 (1,2)=6 (0,1)=1 (2,1)=9 (0,0)=0 (2,2)=10
        assert_eq!(n, vec![0, 1, 4, 6, 9, 10]);
        assert_eq!(g.neighbors(0).count(), 3); // right, down, down-right
        assert_eq!(g.neighbors(3).count(), 2); // top-right corner: left, down
                                               // 3 rows × 3 horizontal + 2 × 4 vertical + 2 × 3 diagonal edges
        assert_eq!(g.edges().len(), 9 + 8 + 6);
    }

    #[test]
    fn edges_match_the_triangles() {
        let g = Grid2d::new(5, 4).unwrap();
        let mut from_tri = std::collections::BTreeSet::new();
        for t in g.triangles() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                from_tri.insert((a.min(b), a.max(b)));
            }
        }
        let edges: std::collections::BTreeSet<_> = g.edges().into_iter().collect();
        assert_eq!(edges, from_tri);
        // Euler characteristic of a disk: V − E + F = 1
        let (v, e, f) = (g.n_vertices() as i64, edges.len() as i64, g.triangles().count() as i64);
        assert_eq!(v - e + f, 1);
    }

    #[test]
    fn rejects_degenerate_grids() {
        assert!(Grid2d::new(1, 5).is_err());
        assert!(Grid2d::with_geometry(3, 3, [0.0, 1.0], [0.0, 0.0]).is_err());
        assert!(Grid2d::with_geometry(3, 3, [1.0, f64::NAN], [0.0, 0.0]).is_err());
        let g = Grid2d::with_geometry(3, 2, [0.5, -2.0], [0.0, 0.0]).unwrap();
        assert_eq!(g.diameter(), 1.0f64.hypot(2.0));
        assert_eq!(g.position(5), [1.0, 2.0]);
    }

    #[test]
    fn a_grid_in_the_x_z_plane_places_its_points_along_x_and_z_at_its_level() {
        let g = Grid2d::with_geometry(3, 2, [0.5, -2.0], [1.0, 4.0]).unwrap();
        assert_eq!(g.world(5), [2.0, 2.0, 0.0]);
        let xz = g.clone().in_plane(Plane { axes: [0, 2], level: 7.0 }).unwrap();
        assert_eq!(xz.world(5), [2.0, 7.0, 2.0]);
        assert_ne!(xz, g);
        assert!(g.clone().in_plane(Plane { axes: [2, 0], level: 0.0 }).is_err());
        assert!(g.in_plane(Plane { axes: [1, 2], level: f64::NAN }).is_err());
    }
}
