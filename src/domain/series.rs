//! A 1D series: samples `0..n` on a path, with optional strictly increasing coordinates.

use super::{Domain, PairingRule};
use crate::error::{Error, Result};

/// A path of `n ≥ 2` samples with coordinates `x` (times, dates as days, or `0..n`).
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    x: Vec<f64>,
}

impl Series {
    /// Unit spacing: `x = 0, 1, …, n − 1`.
    ///
    /// # Panics
    /// If `n < 2` (a contract violation; readers reject such input first).
    pub fn uniform(n: usize) -> Self {
        assert!(n >= 2, "a series needs at least 2 samples");
        Series { x: (0..n).map(|i| i as f64).collect() }
    }

    /// Series with the given coordinates.
    ///
    /// # Errors
    /// Fewer than 2 samples, a non-finite coordinate, or coordinates that do not strictly
    /// increase (the message names the first offending sample).
    pub fn with_coordinates(x: Vec<f64>) -> Result<Self> {
        if x.len() < 2 {
            return Err(Error::input(format!("a series needs at least 2 samples, found {}", x.len())));
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(format!("x coordinate of sample {i} is not finite")));
        }
        if let Some(i) = (1..x.len()).find(|&i| x[i] <= x[i - 1]) {
            return Err(Error::input(format!(
                "x coordinates must strictly increase: sample {i} (x = {}) does not exceed sample {} (x = {})",
                x[i],
                i - 1,
                x[i - 1]
            )));
        }
        Ok(Series { x })
    }

    /// Coordinates of the samples.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// Interval lengths `h_i = x_{i+1} − x_i` (`n − 1` of them, all > 0).
    pub fn spacings(&self) -> Vec<f64> {
        self.x.windows(2).map(|w| w[1] - w[0]).collect()
    }
}

impl Domain for Series {
    fn n_vertices(&self) -> usize {
        self.x.len()
    }

    fn neighbors(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        let n = self.x.len();
        let left = v.checked_sub(1);
        let right = if v + 1 < n { Some(v + 1) } else { None };
        left.into_iter().chain(right)
    }

    fn pairing_rule(&self) -> PairingRule {
        PairingRule::Path
    }

    fn point(&self, v: usize) -> [f64; 3] {
        [self.x[v], 0.0, 0.0]
    }

    fn diameter(&self) -> f64 {
        self.x[self.x.len() - 1] - self.x[0]
    }

    fn edges(&self) -> Vec<(usize, usize)> {
        (0..self.x.len() - 1).map(|i| (i, i + 1)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_non_increasing_coordinates() {
        let e = Series::with_coordinates(vec![0.0, 1.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("sample 2"), "{e}");
        assert!(Series::with_coordinates(vec![0.0]).is_err());
        assert!(Series::with_coordinates(vec![0.0, f64::NAN]).is_err());
    }

    #[test]
    fn neighbours_and_edges() {
        let s = Series::with_coordinates(vec![0.0, 2.0, 3.0]).unwrap();
        assert_eq!(s.neighbors(1).collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(s.neighbors(2).collect::<Vec<_>>(), vec![1]);
        assert_eq!(s.edges(), vec![(0, 1), (1, 2)]);
        assert_eq!(s.spacings(), vec![2.0, 1.0]);
        assert_eq!(s.diameter(), 3.0);
    }
}
