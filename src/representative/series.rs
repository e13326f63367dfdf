//! u on a series: the 1D Morse-Smale complex's separatrices are the intervals between
//! consecutive kept extrema: u is linear in x on each of them, between the kept input values
//! (the harmonic solution with those Dirichlet values), and strictly monotone from each end
//! of the series to the nearest kept extremum.
//! (The test `series_u_is_linear_between_the_kept_extrema` shows it on five samples.)

use crate::domain::{Domain, Series};
use crate::error::{Error, Result};
use crate::topology::{KeptSet, Role};

/// Builds u on a series from the kept set: linear in x between consecutive kept extrema,
/// strictly monotone from each free end to the nearest kept extremum (the end takes the
/// extreme input value of its stretch, or a typical slope if the data gives none), then
/// made strictly monotone in floating point by one pass each way.
///
/// # Errors
/// Infeasible (exit 3) if two consecutive kept extrema have values so close that double
/// precision has fewer distinct numbers between them than there are samples between them.
pub fn series_representative(series: &Series, h: &[f64], kept: &KeptSet) -> Result<Vec<f64>> {
    let x = series.x();
    let n = x.len();
    assert_eq!(h.len(), n);
    let anchors: Vec<(usize, Role)> = kept.kept.iter().map(|k| (k.index, k.role)).collect();
    let mut u = h.to_vec();
    if anchors.is_empty() {
        return Err(Error::Representative { path: None, message: "no kept extremum".into() });
    }
    let (lo, hi) = crate::domain::value_range(h);
    let slope = (hi - lo) / series.diameter();
    // free ends: the end opposite in type to the nearest kept extremum, inside [lo, hi]
    let end_value = |stretch: &[f64], anchor: f64, role: Role, fallback: f64| {
        end_value(stretch, anchor, role, fallback).clamp(lo, hi)
    };
    let (first, first_role) = anchors[0];
    if first > 0 {
        let end = end_value(&h[..=first], h[first], first_role, slope * (x[first] - x[0]));
        let end = with_room(h[first], end, first);
        linear(&mut u, x, 0, first, end, h[first]);
    }
    let (last, last_role) = anchors[anchors.len() - 1];
    if last + 1 < n {
        let end = end_value(&h[last..], h[last], last_role, slope * (x[n - 1] - x[last]));
        let end = with_room(h[last], end, n - 1 - last);
        linear(&mut u, x, last, n - 1, h[last], end);
    }
    for w in anchors.windows(2) {
        let (a, b) = (w[0].0, w[1].0);
        let missing = b - a - 1;
        if (floats_between(h[a], h[b]) as u128) < missing as u128 {
            return Err(Error::infeasible(format!(
                "kept extrema {a} (value {:e}) and {b} (value {:e}) are too close: double precision has fewer than the {missing} distinct values a strictly monotone path between them needs",
                h[a], h[b]
            )));
        }
        linear(&mut u, x, a, b, h[a], h[b]);
    }
    strictify(&mut u, &anchors);
    Ok(u)
}

fn end_value(stretch: &[f64], anchor: f64, role: Role, fallback: f64) -> f64 {
    let fallback = if fallback > 0.0 { fallback } else { 1.0 };
    if role == Role::Min {
        let m = stretch.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        if m > anchor {
            m
        } else {
            anchor + fallback
        }
    } else {
        let m = stretch.iter().cloned().fold(f64::INFINITY, f64::min);
        if m < anchor {
            m
        } else {
            anchor - fallback
        }
    }
}

/// The free end's value moved away from the anchor, if needed, so that at least `4 (len + 2)`
/// doubles lie between them: room for a strictly monotone stretch of `len` edges.
fn with_room(anchor: f64, end: f64, len: usize) -> f64 {
    let gap = (end - anchor).abs();
    let top = anchor.abs().max(end.abs()) + gap;
    let ulp = top.next_up() - top;
    let need = 4.0 * (len as f64 + 2.0) * ulp;
    if gap >= need {
        end
    } else {
        anchor + (end - anchor).signum() * need
    }
}

/// u linear in x on [a, b] from ua to ub (endpoints set exactly).
fn linear(u: &mut [f64], x: &[f64], a: usize, b: usize, ua: f64, ub: f64) {
    let len = x[b] - x[a];
    for i in a..=b {
        let t = (x[i] - x[a]) / len;
        u[i] = ua + (ub - ua) * t;
    }
    u[a] = ua;
    u[b] = ub;
}

/// Number of doubles strictly between a and b.
fn floats_between(a: f64, b: f64) -> u64 {
    // monotone map of doubles to integers; −0 and +0 share one key
    let key = |x: f64| {
        let bits = (if x == 0.0 { 0.0 } else { x }).to_bits();
        if bits >> 63 == 1 {
            (!bits) + 1
        } else {
            bits | (1 << 63)
        }
    };
    let (ka, kb) = (key(a), key(b));
    ka.abs_diff(kb).saturating_sub(1)
}

/// Rounding in `linear` can create ties on long, nearly flat stretches: push each stretch to
/// strict monotonicity with one pass towards each of its fixed ends.
fn strictify(u: &mut [f64], anchors: &[(usize, Role)]) {
    let n = u.len();
    let mut stretches: Vec<(usize, usize)> = anchors.windows(2).map(|w| (w[0].0, w[1].0)).collect();
    if anchors[0].0 > 0 {
        stretches.push((0, anchors[0].0));
    }
    if anchors[anchors.len() - 1].0 + 1 < n {
        stretches.push((anchors[anchors.len() - 1].0, n - 1));
    }
    for (a, b) in stretches {
        let up = u[b] > u[a];
        let step = |v: f64, toward_up: bool| {
            if toward_up {
                v.next_up()
            } else {
                v.next_down()
            }
        };
        for i in a + 1..b {
            let bound = step(u[i - 1], up);
            if (up && u[i] < bound) || (!up && u[i] > bound) {
                u[i] = bound;
            }
        }
        for i in (a + 1..b).rev() {
            let bound = step(u[i + 1], !up);
            if (up && u[i] > bound) || (!up && u[i] < bound) {
                u[i] = bound;
            }
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn series_u_is_linear_between_the_kept_extrema() {
        use crate::topology::{select, Selection};
        let h = [0.0, 2.0, 1.0, 3.0, 2.5];
        let s = Series::uniform(5);
        let kept = select(&s, &h, &Selection::Explicit { minima: vec![0], maxima: vec![3] }).unwrap();
        let u = series_representative(&s, &h, &kept).unwrap();
        assert_eq!(u[..4], [0.0, 1.0, 2.0, 3.0]);
        assert!(u[4] < 3.0); // free end below the kept maximum
    }

    use super::*;
    use crate::topology::{select, Selection};

    #[test]
    fn counts_doubles() {
        assert_eq!(floats_between(1.0, 1.0f64.next_up()), 0);
        assert_eq!(floats_between(1.0, 1.0f64.next_up().next_up()), 1);
        assert_eq!(floats_between((-0.0f64).next_down(), 0.0f64.next_up()), 1); // just zero
    }

    #[test]
    fn too_close_kept_values_are_infeasible() {
        let a = 1.0;
        let b = a + 2.0 * f64::EPSILON; // one double strictly between
        let h = [a, 0.5 * (a + b), a, a, b];
        let s = Series::uniform(5);
        let kept = select(&s, &h, &Selection::Explicit { minima: vec![0], maxima: vec![4] });
        // vertex 0 must be a minimum of the input: it is (SoS), vertex 4 the global maximum
        let kept = kept.unwrap();
        let e = series_representative(&s, &h, &kept).unwrap_err();
        assert_eq!(e.exit_code(), 3, "{e}");
    }

    #[test]
    fn free_ends_get_room_for_a_strict_stretch() {
        // the left end is only two doubles above the kept minimum at 4 (review finding)
        let e = f64::EPSILON;
        let h = [1.0 + 2.0 * e, 1.0 + e, 1.0 + e, 1.0 + e, 1.0, 5.0, 0.0];
        let s = Series::uniform(7);
        let kept = select(&s, &h, &Selection::Relative(0.05)).unwrap();
        assert_eq!((kept.minima(), kept.maxima()), (vec![4, 6], vec![5]));
        let u = series_representative(&s, &h, &kept).unwrap();
        assert!(u[..5].windows(2).all(|w| w[0] > w[1]), "{u:?}");
    }

    #[test]
    fn tight_but_representable_stretch_becomes_strict() {
        let a = 1.0;
        let b = a + 4.0 * f64::EPSILON; // three doubles between: exactly enough for 3 samples
        let h = [a, a, a, a, b];
        let s = Series::uniform(5);
        let kept = select(&s, &h, &Selection::Explicit { minima: vec![0], maxima: vec![4] }).unwrap();
        let u = series_representative(&s, &h, &kept).unwrap();
        assert!(u.windows(2).all(|w| w[0] < w[1]), "{u:?}");
    }
}
