//! Double-double arithmetic (a value as the unevaluated sum `hi + lo` of two doubles, about
//! 32 significant digits) for the factored form's iteration, every operation inlined.
//!
//! faer's `fx128` (the `qd` crate) computes the same sums and products, but out of line: its
//! operations are not marked for inlining across crates, and its exact product calls the
//! `fma` function, a library call on any build without the FMA target feature (the default
//! x86-64 target). On a series of 3·10⁶ samples those calls were 40 % of the run (perf:
//! `add_estimate` 10 %, `sub_estimate` 10 %, `fma` 14 %, division 6 %). Here the product's
//! rounding error comes from the processor's fused multiply-add, found at run time and issued
//! inline, or where there is none from Dekker's splitting, in plain multiplications and
//! additions; the sum is Knuth's branch-free two-sum: the same results on every x86-64 and
//! aarch64 processor, with or without FMA, and no call in the loops. faer's sparse kernels still need
//! `fx128`: [`to_fx128`] and [`from_fx128`] convert at that border.
//!
//! The operations are those of Bailey's QD library in its "sloppy" form (as `qd`'s `+`, `−`,
//! `×`): the sum `a + b` with a relative error of about `2⁻¹⁰⁴` unless `a ≈ −b`, where its
//! error is bounded by `2⁻¹⁰⁴ (|a| + |b|)`; the product with a relative error below `2⁻¹⁰²`.
//! Values must stay below about `2⁹⁹⁶` in magnitude (the splitting's overflow): the iteration
//! works on unit-scaled fields.

use std::cmp::Ordering;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// A double-double number `hi + lo`, `|lo| ≤ ulp(hi) / 2`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Dd {
    pub hi: f64,
    pub lo: f64,
}

/// `2²⁷ + 1`: Dekker's splitting constant for doubles.
const SPLITTER: f64 = 134_217_729.0;

/// `s + e = a + b` exactly, for `|a| ≥ |b|` (or `a` zero).
#[inline(always)]
fn quick_two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    Dd { hi: s, lo: b - (s - a) }
}

/// `s + e = a + b` exactly (Knuth; no branch).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd { hi: s, lo: (a - (s - bb)) + (b - bb) }
}

/// `a = hi + lo` with both halves of 26 bits.
#[inline(always)]
fn split(a: f64) -> (f64, f64) {
    let t = SPLITTER * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

/// `p + e = a · b` exactly: the fused multiply-add's `a·b − p` where the processor has one
/// ([`fused`]), else Dekker's splitting. Both give the exact error term (below the splitting's
/// overflow, about `2⁹⁹⁶`, and above the subnormals), so the same bits either way.
#[inline(always)]
fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    if let Some(lo) = fused::error(a, b, p) {
        return Dd { hi: p, lo };
    }
    dekker(a, b, p)
}

/// Dekker's exact product's error term `a·b − p`, in plain multiplications and additions.
#[inline(always)]
fn dekker(a: f64, b: f64, p: f64) -> Dd {
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    Dd { hi: p, lo: ((ah * bh - p) + ah * bl + al * bh) + al * bl }
}

/// The fused multiply-add, found at run time: the default x86-64 target has none, so
/// `f64::mul_add` there is a library call (the reason this module splits instead), while every
/// x86-64 processor since 2013 executes `vfmsub213sd`. Its exact error term costs one
/// instruction where the splitting costs ten dependent ones (a series of 3·10⁶ samples in
/// double-double: solve 16.6 → 13.9 s, docs/performance.md §3).
mod fused {
    /// `a·b − p` rounded once, if the processor fuses.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn error(a: f64, b: f64, p: f64) -> Option<f64> {
        if !std::arch::is_x86_feature_detected!("fma") {
            return None;
        }
        let mut r = a;
        // SAFETY: executed only where the processor reports FMA; registers only, no memory.
        unsafe {
            std::arch::asm!(
                "vfmsub213sd {r}, {b}, {p}",
                r = inout(xmm_reg) r,
                b = in(xmm_reg) b,
                p = in(xmm_reg) p,
                options(pure, nomem, nostack, preserves_flags)
            );
        }
        Some(r)
    }

    /// `a·b − p` rounded once (FMA is in every aarch64 processor's base set).
    #[cfg(target_arch = "aarch64")]
    #[inline(always)]
    pub(super) fn error(a: f64, b: f64, p: f64) -> Option<f64> {
        Some(a.mul_add(b, -p))
    }

    /// No fused multiply-add known on this architecture: Dekker's splitting.
    #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
    #[inline(always)]
    pub(super) fn error(_: f64, _: f64, _: f64) -> Option<f64> {
        None
    }
}

impl Dd {
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    /// The nearest double.
    #[inline(always)]
    #[must_use]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// The square root (one Newton step from the double one).
    #[must_use]
    pub fn sqrt(self) -> Dd {
        if self.hi <= 0.0 {
            return Dd { hi: self.hi.sqrt(), lo: 0.0 };
        }
        let r = self.hi.sqrt();
        let residual = self - two_prod(r, r);
        quick_two_sum(r, residual.hi / (2.0 * r))
    }
}

impl From<f64> for Dd {
    #[inline(always)]
    fn from(hi: f64) -> Dd {
        Dd { hi, lo: 0.0 }
    }
}

impl Add for Dd {
    type Output = Dd;
    #[inline(always)]
    fn add(self, rhs: Dd) -> Dd {
        let s = two_sum(self.hi, rhs.hi);
        quick_two_sum(s.hi, s.lo + (self.lo + rhs.lo))
    }
}

impl AddAssign for Dd {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Dd) {
        *self = *self + rhs;
    }
}

impl SubAssign for Dd {
    #[inline(always)]
    fn sub_assign(&mut self, rhs: Dd) {
        *self = *self - rhs;
    }
}

impl Neg for Dd {
    type Output = Dd;
    #[inline(always)]
    fn neg(self) -> Dd {
        Dd { hi: -self.hi, lo: -self.lo }
    }
}

impl Sub for Dd {
    type Output = Dd;
    #[inline(always)]
    fn sub(self, rhs: Dd) -> Dd {
        self + (-rhs)
    }
}

impl Mul for Dd {
    type Output = Dd;
    #[inline(always)]
    fn mul(self, rhs: Dd) -> Dd {
        let p = two_prod(self.hi, rhs.hi);
        quick_two_sum(p.hi, p.lo + (self.hi * rhs.lo + self.lo * rhs.hi))
    }
}

impl Div for Dd {
    type Output = Dd;
    /// Long division: two quotient digits and a correction.
    #[inline]
    fn div(self, rhs: Dd) -> Dd {
        let q1 = self.hi / rhs.hi;
        let r = self - rhs * Dd::from(q1);
        let q2 = r.hi / rhs.hi;
        let r = r - rhs * Dd::from(q2);
        let q3 = r.hi / rhs.hi;
        quick_two_sum(q1, q2) + Dd::from(q3)
    }
}

impl PartialOrd for Dd {
    /// By the high parts, then the low ones (the representation is normalised).
    #[inline]
    fn partial_cmp(&self, other: &Dd) -> Option<Ordering> {
        match self.hi.partial_cmp(&other.hi)? {
            Ordering::Equal => self.lo.partial_cmp(&other.lo),
            o => Some(o),
        }
    }
}

/// `v` as faer's double-double type.
#[must_use]
pub fn to_fx128(v: Dd) -> faer::fx128 {
    faer::fx128 { 0: v.hi, 1: v.lo }
}

/// faer's double-double value as a [`Dd`].
#[must_use]
pub fn from_fx128(v: faer::fx128) -> Dd {
    Dd { hi: v.0, lo: v.1 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_and_products_keep_about_32_digits_where_doubles_keep_16() {
        // (1 + 2⁻⁶⁰)² = 1 + 2⁻⁵⁹ + 2⁻¹²⁰: a double loses the 2⁻⁵⁹, the double-double keeps it
        let a = Dd::from(1.0) + Dd::from(2f64.powi(-60));
        assert_eq!(a.hi, 1.0);
        assert_eq!(a.lo, 2f64.powi(-60));
        let sq = a * a;
        assert_eq!(sq.hi, 1.0);
        assert_eq!(sq.lo, 2f64.powi(-59));
        // cancellation: (1 + 2⁻⁶⁰) − 1 is exact
        assert_eq!((a - Dd::from(1.0)).to_f64(), 2f64.powi(-60));
        // the exact product of two doubles: 3·(1/3 rounded) differs from 1 by the rounding
        let third = 1.0f64 / 3.0;
        let p = Dd::from(3.0) * Dd::from(third);
        assert_eq!(p.hi + p.lo, 3.0 * third);
        assert_eq!(p.lo, (3.0f64).mul_add(third, -(3.0 * third)));
        // every product of two random doubles: its error term is the fused one
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..10_000 {
            let (x, y) = (next() * 1e3, next() * 1e-3);
            let p = two_prod(x, y);
            assert_eq!(p.lo, x.mul_add(y, -p.hi), "{x} × {y}");
            // the splitting, run on every processor, gives the fused bits
            assert_eq!(dekker(x, y, p.hi), p, "{x} × {y}");
            // the sum's error term: hi + lo − x − y vanishes to double-double precision
            let s = two_sum(x, y);
            assert_eq!(s.hi, x + y);
            let rest = (s - Dd::from(x) - Dd::from(y)).to_f64();
            assert!(rest.abs() <= 1e-30 * (x.abs() + y.abs()), "{x} + {y}: {rest:e}");
        }
    }

    #[test]
    fn division_and_square_root_invert_the_product_to_about_32_digits() {
        let a = Dd::from(2.0) + Dd::from(2f64.powi(-70));
        let b = Dd::from(3.0);
        let q = a / b;
        let back = q * b - a;
        assert!(back.to_f64().abs() <= 1e-31 * a.to_f64(), "{back:?}");
        let r = Dd::from(2.0).sqrt();
        let err = (r * r - Dd::from(2.0)).to_f64().abs();
        assert!(err <= 1e-31, "√2² − 2 = {err:e}");
        assert!(Dd::from(1.0) < Dd::from(1.0) + Dd::from(1e-20));
        assert!(Dd::from(-1.0) < Dd::ZERO);
    }

    #[test]
    fn the_values_match_faer_s_double_double_to_its_precision() {
        let xs = [0.1, -7.25, 1e-9, 3.0e5, -2.0 / 3.0];
        for &x in &xs {
            for &y in &xs {
                let (a, b) = (Dd::from(x) + Dd::from(y * 1e-17), Dd::from(y));
                let (fa, fb) = (to_fx128(a), to_fx128(b));
                for (ours, theirs) in [(a + b, fa + fb), (a - b, fa - fb), (a * b, fa * fb), (a / b, fa / fb)] {
                    let diff = (ours - from_fx128(theirs)).to_f64().abs();
                    assert!(diff <= 1e-30 * ours.to_f64().abs().max(1e-300), "{x}, {y}: {ours:?} vs {theirs:?}");
                }
            }
        }
    }
}
