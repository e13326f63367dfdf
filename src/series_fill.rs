//! Filling the missing (NaN) samples of a series: linearly in x between the known samples
//! around each gap, and with the nearest known value at an end, as the harmonic fill of a grid
//! does (the Laplacian on a path is the second difference; Neumann at a free end).
//!
//! Filled samples are data the user did not give, so none may become a kept extremum, whose
//! value the certificate pins bit for bit. Inside the series that holds by itself: a linear
//! fill lies between its two known neighbours, a gap between equal values is a plateau whose
//! first and last members (where the (value, index) order puts its extremum) are known, and
//! ties from rounding give extrema of persistence 0, which are never kept. At an end the fill
//! would be a plateau whose extremum is the outermost, filled, sample; so the filled end
//! samples step away from the known end value by one unit in the last place per sample, on the
//! side of the known neighbours, which leaves the known sample the extremum and the filled end
//! a free end.

use crate::error::{Error, Result};

/// Fills the NaN samples of `values` over the coordinates `x` (strictly increasing): linearly
/// inside, the nearest known value stepped away by one ulp per sample at the ends (see the
/// module documentation). Returns the mask of filled samples.
///
/// # Errors
/// Every sample is missing; `x` and `values` differ in length.
pub fn fill_missing_series(x: &[f64], values: &mut [f64]) -> Result<Vec<bool>> {
    if x.len() != values.len() {
        return Err(Error::input(format!("{} x values for {} samples", x.len(), values.len())));
    }
    let mask: Vec<bool> = values.iter().map(|v| v.is_nan()).collect();
    let known: Vec<usize> = (0..values.len()).filter(|&i| !mask[i]).collect();
    let (Some(&first), Some(&last)) = (known.first(), known.last()) else {
        return Err(Error::input("every sample is missing (NaN): nothing to fill from"));
    };
    for pair in known.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let (va, vb) = (values[a], values[b]);
        let (lo, hi) = (va.min(vb), va.max(vb));
        for i in a + 1..b {
            let t = (x[i] - x[a]) / (x[b] - x[a]);
            values[i] = (va + (vb - va) * t).clamp(lo, hi);
        }
    }
    let n = values.len();
    fill_end(values, first, (0..first).rev(), first + 1..n);
    fill_end(values, last, last + 1..n, (0..last).rev());
    Ok(mask)
}

/// Fills the samples `outward` from the known end sample `end` with its value stepped one ulp
/// per sample towards the side where the first different value `inward` lies.
fn fill_end(
    values: &mut [f64],
    end: usize,
    outward: impl Iterator<Item = usize>,
    mut inward: impl Iterator<Item = usize>,
) {
    let v = values[end];
    let up = match inward.find(|&i| values[i] != v) {
        Some(i) => values[i] > v,
        None => true, // a constant series: refused later, whichever way
    };
    let mut w = v;
    for i in outward {
        let next = if up { w.next_up() } else { w.next_down() };
        w = if next.is_finite() { next } else { w };
        values[i] = w;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAN: f64 = f64::NAN;

    #[test]
    fn linear_in_x_inside() {
        let x = [0.0, 1.0, 3.0, 4.0, 10.0];
        let mut v = [2.0, NAN, NAN, 6.0, 0.0];
        let mask = fill_missing_series(&x, &mut v).unwrap();
        assert_eq!(mask, [false, true, true, false, false]);
        assert_eq!(v, [2.0, 3.0, 5.0, 6.0, 0.0], "linear in x, not in the index");
    }

    #[test]
    fn ends_take_the_nearest_value_and_leave_the_extremum_on_known_samples() {
        let x: Vec<f64> = (0..7).map(f64::from).collect();
        // rising after the gap: the filled start steps up, so sample 2 is the minimum
        let mut v = [NAN, NAN, 3.0, 5.0, 4.0, NAN, NAN];
        fill_missing_series(&x, &mut v).unwrap();
        assert_eq!(v[1], 3.0f64.next_up());
        assert_eq!(v[0], 3.0f64.next_up().next_up());
        assert!(v[0] > v[1] && v[1] > v[2], "{v:?}");
        // 5 then 4 before the end gap: the filled end steps up, so 4 at sample 4 is a minimum
        assert_eq!(v[5], 4.0f64.next_up());
        assert!(v[4] < v[5] && v[5] < v[6], "{v:?}");
        // every filled sample is within an ulp per step of the nearest known value
        assert!((v[0] - 3.0).abs() < 1e-14 && (v[6] - 4.0).abs() < 1e-14);
        // 5 then 1 after the start gap: the filled start steps down, so 5 at sample 1 is a maximum
        let mut w = [NAN, 5.0, 1.0];
        fill_missing_series(&x[..3], &mut w).unwrap();
        assert_eq!(w[0], 5.0f64.next_down());
    }

    #[test]
    fn plateaus_and_errors() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let mut v = [5.0, 3.0, NAN, 3.0, 5.0];
        fill_missing_series(&x, &mut v).unwrap();
        assert_eq!(v[2], 3.0, "a gap between equal values is a plateau");
        let mut none = [NAN; 3];
        assert!(fill_missing_series(&x[..3], &mut none).unwrap_err().to_string().contains("every sample"));
        let mut one = [NAN, 2.0, NAN];
        assert_eq!(fill_missing_series(&x[..3], &mut one).unwrap(), [true, false, true]);
        assert!(fill_missing_series(&x[..2], &mut [1.0, 2.0, 3.0]).is_err());
    }
}
