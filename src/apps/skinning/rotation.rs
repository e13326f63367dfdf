//! The rotation and dual-quaternion arithmetic of dual-quaternion skinning: determinants, the
//! nearest rotation (polar factor), quaternions, and the blend of unit dual quaternions.

use crate::domain::vec3::{cross, dot};

/// A linear part whose determinant is at most this, relative to the cube of its mean
/// singular-value scale (`|A|_F / √3`), is singular.
pub(super) const SINGULAR_DET: f64 = 1e-12;
/// A 3×3 matrix, row-major.
pub(super) type Mat3 = [[f64; 3]; 3];

/// A quaternion `(w, x, y, z)`.
pub(super) type Quat = [f64; 4];

pub(super) fn det(a: &Mat3) -> f64 {
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

/// The cofactor matrix, `det(a) a⁻ᵀ`.
pub(super) fn cofactor(a: &Mat3) -> Mat3 {
    let c = |r0: usize, r1: usize, c0: usize, c1: usize| a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0];
    [
        [c(1, 2, 1, 2), -c(1, 2, 0, 2), c(1, 2, 0, 1)],
        [-c(0, 2, 1, 2), c(0, 2, 0, 2), -c(0, 2, 0, 1)],
        [c(0, 1, 1, 2), -c(0, 1, 0, 2), c(0, 1, 0, 1)],
    ]
}

/// Frobenius norm.
pub(super) fn fro(a: &Mat3) -> f64 {
    a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
}

pub(super) fn sub3(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] - b[i][j]))
}

/// Whether `|det a|` is negligible against the cube of `a`'s scale.
pub(super) fn is_singular(a: &Mat3) -> bool {
    let scale = fro(a) / 3f64.sqrt();
    let d = det(a).abs();
    !(scale.is_finite() && d.is_finite()) || scale == 0.0 || d <= SINGULAR_DET * scale * scale * scale
}

/// The orthogonal polar factor of a nonsingular `a` (its nearest orthogonal matrix; a rotation
/// when `det a > 0`), by Newton's iteration `X ← (γX + X⁻ᵀ/γ)/2` with Higham's scaling `γ`
/// while far from convergence. `None` if `a` is singular or the iteration fails.
pub(super) fn polar_rotation(a: &Mat3) -> Option<Mat3> {
    let mut x = *a;
    let mut scaled = true;
    for _ in 0..100 {
        let cof = cofactor(&x);
        let d = x[0][0] * cof[0][0] + x[0][1] * cof[0][1] + x[0][2] * cof[0][2];
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        let inv_t = cof.map(|r| r.map(|c| c / d));
        let gamma = if scaled { (fro(&inv_t) / fro(&x)).sqrt() } else { 1.0 };
        let next: Mat3 =
            std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (gamma * x[i][j] + inv_t[i][j] / gamma)));
        let change = fro(&sub3(&next, &x));
        x = next;
        if change < 1e-2 {
            scaled = false;
        }
        if change <= 1e-14 {
            return Some(x);
        }
    }
    None
}

/// The unit quaternion of a rotation matrix (Shepperd's method: divide by the largest of
/// `4w², 4x², 4y², 4z²`, so it is accurate for every angle, 180° included).
pub(super) fn quat_from_rotation(r: &Mat3) -> Quat {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let q = if tr >= r[0][0] && tr >= r[1][1] && tr >= r[2][2] {
        let w = 0.5 * (1.0 + tr).sqrt();
        let f = 0.25 / w;
        [w, (r[2][1] - r[1][2]) * f, (r[0][2] - r[2][0]) * f, (r[1][0] - r[0][1]) * f]
    } else if r[0][0] >= r[1][1] && r[0][0] >= r[2][2] {
        let x = 0.5 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
        let f = 0.25 / x;
        [(r[2][1] - r[1][2]) * f, x, (r[0][1] + r[1][0]) * f, (r[0][2] + r[2][0]) * f]
    } else if r[1][1] >= r[2][2] {
        let y = 0.5 * (1.0 - r[0][0] + r[1][1] - r[2][2]).sqrt();
        let f = 0.25 / y;
        [(r[0][2] - r[2][0]) * f, (r[0][1] + r[1][0]) * f, y, (r[1][2] + r[2][1]) * f]
    } else {
        let z = 0.5 * (1.0 - r[0][0] - r[1][1] + r[2][2]).sqrt();
        let f = 0.25 / z;
        [(r[1][0] - r[0][1]) * f, (r[0][2] + r[2][0]) * f, (r[1][2] + r[2][1]) * f, z]
    };
    let l = dot4(&q, &q).sqrt();
    q.map(|c| c / l)
}

pub(super) fn dot4(a: &Quat, b: &Quat) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// Hamilton product `a b`.
pub(super) fn qmul(a: &Quat, b: &Quat) -> Quat {
    let (av, bv) = ([a[1], a[2], a[3]], [b[1], b[2], b[3]]);
    let c = cross(av, bv);
    [
        a[0] * b[0] - dot(av, bv),
        a[0] * bv[0] + b[0] * av[0] + c[0],
        a[0] * bv[1] + b[0] * av[1] + c[1],
        a[0] * bv[2] + b[0] * av[2] + c[2],
    ]
}

/// `q p q*` for a unit quaternion `q`.
pub(super) fn rotate(q: &Quat, p: [f64; 3]) -> [f64; 3] {
    let u = [q[1], q[2], q[3]];
    let uxp = cross(u, p);
    let uuxp = cross(u, uxp);
    std::array::from_fn(|k| p[k] + 2.0 * (q[0] * uxp[k] + uuxp[k]))
}

/// A unit dual quaternion `real + ε dual`: the rigid motion `p ↦ R p + t` with
/// `real` the quaternion of `R` and `dual = ½ (0, t) real`.
#[derive(Clone, Copy, Debug)]
pub(super) struct DualQuat {
    pub(super) real: Quat,
    pub(super) dual: Quat,
}

impl DualQuat {
    pub(super) fn new(real: Quat, t: [f64; 3]) -> Self {
        let d = qmul(&[0.0, t[0], t[1], t[2]], &real);
        DualQuat { real, dual: d.map(|c| 0.5 * c) }
    }
}

/// Blends the dual quaternions with weights `w` (antipodality fix against the handle of
/// largest weight), normalises and applies the result to `p`. `None` where the blended real
/// part vanishes.
pub(super) fn blend_apply(dqs: &[DualQuat], w: &[f64], p: [f64; 3]) -> Option<[f64; 3]> {
    let pivot = (0..w.len()).fold(None, |best: Option<usize>, h| match best {
        Some(b) if w[b] >= w[h] => Some(b),
        _ => Some(h),
    })?;
    let pivot = dqs[pivot].real;
    let (mut real, mut dual) = ([0.0; 4], [0.0; 4]);
    for (dq, &wh) in dqs.iter().zip(w) {
        if wh == 0.0 {
            continue;
        }
        let s = if dot4(&dq.real, &pivot) < 0.0 { -wh } else { wh };
        for k in 0..4 {
            real[k] += s * dq.real[k];
            dual[k] += s * dq.dual[k];
        }
    }
    let l = dot4(&real, &real).sqrt();
    if !l.is_finite() || l <= 1e-12 {
        return None;
    }
    let (r, d) = (real.map(|c| c / l), dual.map(|c| c / l));
    // translation 2 (d r*).vec, which ignores the part of d not orthogonal to r (the blend
    // is not exactly a unit dual quaternion)
    let (rv, dv) = ([r[1], r[2], r[3]], [d[1], d[2], d[3]]);
    let c = cross(rv, dv);
    let q = rotate(&r, p);
    Some(std::array::from_fn(|k| q[k] + 2.0 * (r[0] * dv[k] - d[0] * rv[k] + c[k])))
}
