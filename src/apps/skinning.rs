//! Skinning: pose a mesh from per-handle weights and per-handle affine transforms.
//!
//! Two blends are offered ([`Skinning`]):
//! - linear blend skinning (LBS): `p' = Σ_h w_h (A_h p + t_h)`. It is cheap and exact for
//!   affine handles, but blending rotations linearly collapses volume where weights are mixed
//!   (the "candy wrapper" of a twisted bar).
//! - dual-quaternion skinning (DQS, Kavan, Collins, Žára & O'Sullivan 2007, "Skinning with dual
//!   quaternions"): each handle's rigid part becomes a unit dual quaternion; these are blended
//!   with the antipodality fix, normalised and applied. Blends of rotations stay rotations, so
//!   a twist preserves the cross-section. Only the rotation part of a handle's linear map is
//!   used (its nearest rotation, the polar factor); scale or shear is dropped with a warning,
//!   and a reflection is an input error.
//!
//! Transforms come from `pose.json` (SPEC.md, "Formats"), read by [`parse_pose`].
mod pose;
mod rotation;

use crate::error::{Error, Result};
pub use pose::{parse_pose, Transform};
use rotation::{blend_apply, det, fro, is_singular, polar_rotation, quat_from_rotation, sub3, DualQuat};

/// How the handles' transforms are blended at a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Skinning {
    /// Linear blend skinning: the weighted sum of the transformed positions.
    Lbs,
    /// Dual-quaternion skinning: the normalised weighted sum of the handles' rigid motions.
    Dqs,
}

named_enum!(Skinning, "skinning", [(Skinning::Lbs, "lbs"), (Skinning::Dqs, "dqs")]);

/// A linear part farther than this from its rotation part (`|A − R|_F / |R|_F`) has scale or
/// shear.
const NOT_ROTATION: f64 = 1e-6;

/// Weights whose sum at a vertex differs from 1 by more than this get a warning in LBS.
const WEIGHT_SUM: f64 = 1e-6;

/// Posed positions: `weights[h][v]` is the weight of handle `h` at vertex `v`, `transforms[h]`
/// the transform of handle `h`. Returns the positions and warnings.
///
/// Handles are named `handle 0`, `handle 1`, … in messages; [`skin_named`] takes their names.
pub fn skin(
    rest: &[[f64; 3]],
    weights: &[Vec<f64>],
    transforms: &[Transform],
    method: Skinning,
) -> Result<(Vec<[f64; 3]>, Vec<String>)> {
    let names: Vec<String> = (0..transforms.len()).map(|h| format!("handle {h}")).collect();
    skin_named(rest, weights, transforms, &names, method)
}

/// [`skin`] with the handles' names for the messages (`names[h]` names handle `h`).
///
/// The weights are meant to be normalised (sum 1 at every vertex); they are not renormalised.
/// LBS is evaluated as `p + Σ_h w_h (A_h p + t_h − p)`, which equals `Σ_h w_h (A_h p + t_h)`
/// for a partition of unity and reproduces the rest pose exactly under identity transforms;
/// where the weights do not sum to 1 (a warning says so) the missing weight keeps the vertex
/// at rest. DQS normalises the blended dual quaternion, so it does not depend on the sum.
///
/// Errors ([`Error::input`]): a weight vector count other than the transform count (or name
/// count), a weight vector whose length is not the vertex count, a non-finite weight, rest
/// position or transform entry; in DQS a singular or reflecting (det < 0) linear part, or a
/// vertex whose blended rotation vanishes (weights summing to about 0).
pub fn skin_named<S: AsRef<str>>(
    rest: &[[f64; 3]],
    weights: &[Vec<f64>],
    transforms: &[Transform],
    names: &[S],
    method: Skinning,
) -> Result<(Vec<[f64; 3]>, Vec<String>)> {
    let n = rest.len();
    if weights.len() != transforms.len() {
        return Err(Error::input(format!(
            "skinning: {} weight functions but {} transforms (one of each per handle)",
            weights.len(),
            transforms.len()
        )));
    }
    if names.len() != transforms.len() {
        return Err(Error::input(format!(
            "skinning: {} handle names but {} transforms",
            names.len(),
            transforms.len()
        )));
    }
    let name = |h: usize| names[h].as_ref();
    for (h, w) in weights.iter().enumerate() {
        if w.len() != n {
            return Err(Error::input(format!(
                "skinning: the weights of `{}` have {} values for {n} vertices",
                name(h),
                w.len()
            )));
        }
        if let Some(v) = w.iter().position(|x| !x.is_finite()) {
            return Err(Error::input(format!("skinning: the weight of `{}` at vertex {v} is {}", name(h), w[v])));
        }
    }
    check_transforms(transforms, names, Skinning::Lbs)?;
    if let Some(v) = rest.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
        return Err(Error::input(format!("skinning: rest position of vertex {v} is not finite: {:?}", rest[v])));
    }
    let mut warnings = Vec::new();
    let positions = match method {
        Skinning::Lbs => {
            let mut off = 0;
            let mut first = None;
            let out = (0..n)
                .map(|v| {
                    let p = rest[v];
                    let mut q = p;
                    let mut sum = 0.0;
                    for (w, t) in weights.iter().zip(transforms) {
                        let w = w[v];
                        sum += w;
                        if w != 0.0 {
                            let tp = t.apply(p);
                            for k in 0..3 {
                                q[k] += w * (tp[k] - p[k]);
                            }
                        }
                    }
                    if (sum - 1.0).abs() > WEIGHT_SUM {
                        off += 1;
                        first.get_or_insert((v, sum));
                    }
                    q
                })
                .collect();
            if let Some((v, sum)) = first {
                warnings.push(format!(
                    "the weights do not sum to 1 at {off} vertices (first: vertex {v}, sum {sum}); \
                     linear blend skinning leaves the missing weight at rest"
                ));
            }
            out
        }
        Skinning::Dqs => {
            let (dqs, dq_warnings) = dual_quaternions(transforms, names)?;
            warnings.extend(dq_warnings);
            let mut out = Vec::with_capacity(n);
            let mut wv = vec![0.0; transforms.len()];
            for v in 0..n {
                for (x, w) in wv.iter_mut().zip(weights) {
                    *x = w[v];
                }
                let p = blend_apply(&dqs, &wv, rest[v]).ok_or_else(|| {
                    Error::input(format!(
                        "skinning: the blended rotation vanishes at vertex {v} (its weights sum to about 0)"
                    ))
                })?;
                out.push(p);
            }
            out
        }
    };
    Ok((positions, warnings))
}

/// Checks the transforms alone, for the method: finite entries; for dual quaternions also a
/// non-singular, non-reflecting linear part. Returns the warnings (scale or shear dropped by
/// dual quaternions). [`skin_named`] runs the same checks; a caller that wants to blame the pose
/// file and not the weights for them runs this first.
///
/// # Errors
/// [`Error::input`] naming the transform.
pub fn check_transforms<S: AsRef<str>>(transforms: &[Transform], names: &[S], method: Skinning) -> Result<Vec<String>> {
    for (h, t) in transforms.iter().enumerate() {
        if t.0.iter().flatten().any(|x| !x.is_finite()) {
            let name = names.get(h).map_or("?", |n| n.as_ref());
            return Err(Error::input(format!("skinning: the transform of `{name}` has a non-finite entry")));
        }
    }
    match method {
        Skinning::Lbs => Ok(Vec::new()),
        Skinning::Dqs => dual_quaternions(transforms, names).map(|(_, w)| w),
    }
}

/// The unit dual quaternion of each transform's rotation part and translation, with a warning
/// per transform whose scale or shear is dropped.
fn dual_quaternions<S: AsRef<str>>(transforms: &[Transform], names: &[S]) -> Result<(Vec<DualQuat>, Vec<String>)> {
    let name = |h: usize| names.get(h).map_or("?", |n| n.as_ref());
    let mut dqs = Vec::with_capacity(transforms.len());
    let mut warnings = Vec::new();
    for (h, t) in transforms.iter().enumerate() {
        let a = t.linear();
        let d = det(&a);
        if is_singular(&a) {
            return Err(Error::input(format!(
                "skinning: the transform of `{}` has a singular linear part (determinant {d:e}); \
                 dual quaternions need a rotation",
                name(h)
            )));
        }
        if d < 0.0 {
            return Err(Error::input(format!(
                "skinning: the transform of `{}` is a reflection (determinant {d}); dual quaternions \
                 represent rotations only",
                name(h)
            )));
        }
        let r = polar_rotation(&a).ok_or_else(|| {
            Error::input(format!("skinning: the rotation part of `{}` could not be computed", name(h)))
        })?;
        if fro(&sub3(&a, &r)) > NOT_ROTATION * fro(&r) {
            warnings
                .push(format!("dual quaternions use the rotation part of `{}`; its scale/shear is dropped", name(h)));
        }
        dqs.push(DualQuat::new(quat_from_rotation(&r), t.translation()));
    }
    Ok((dqs, warnings))
}

#[cfg(test)]
mod tests {
    use super::rotation::*;
    use super::*;

    /// xorshift64*, uniform in [0, 1).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn sym(&mut self) -> f64 {
            2.0 * self.next() - 1.0
        }
    }

    fn rotation_from_quat(q: &Quat) -> Mat3 {
        let [w, x, y, z] = *q;
        [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
            [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
            [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
        ]
    }

    fn axis_angle(axis: [f64; 3], degrees: f64) -> Mat3 {
        let a = crate::domain::vec3::unit(axis);
        let h = 0.5 * degrees.to_radians();
        rotation_from_quat(&[h.cos(), h.sin() * a[0], h.sin() * a[1], h.sin() * a[2]])
    }

    fn random_rotation(rng: &mut Rng) -> Mat3 {
        let q = [rng.sym(), rng.sym(), rng.sym(), rng.sym()];
        let l = dot4(&q, &q).sqrt();
        rotation_from_quat(&q.map(|c| c / l))
    }

    fn transform(a: &Mat3, t: [f64; 3]) -> Transform {
        Transform(std::array::from_fn(|i| [a[i][0], a[i][1], a[i][2], t[i]]))
    }

    /// Rotation by `r` about the line through `c`: `p ↦ R (p − c) + c`.
    fn about(r: &Mat3, c: [f64; 3]) -> Transform {
        let rc = transform(r, [0.0; 3]).apply(c);
        transform(r, std::array::from_fn(|k| c[k] - rc[k]))
    }

    fn random_points(rng: &mut Rng, n: usize) -> Vec<[f64; 3]> {
        (0..n).map(|_| [3.0 * rng.sym(), 3.0 * rng.sym(), 3.0 * rng.sym()]).collect()
    }

    /// `handles` weight functions, normalised per vertex.
    fn random_weights(rng: &mut Rng, handles: usize, n: usize) -> Vec<Vec<f64>> {
        let mut w: Vec<Vec<f64>> = (0..handles).map(|_| (0..n).map(|_| rng.next()).collect()).collect();
        for v in 0..n {
            let s: f64 = w.iter().map(|wh| wh[v]).sum();
            for wh in &mut w {
                wh[v] /= s;
            }
        }
        w
    }

    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        crate::domain::vec3::norm(crate::domain::vec3::sub(a, b))
    }

    fn input_message(e: Error) -> String {
        assert_eq!(e.exit_code(), 3, "{e}");
        match e {
            Error::Input { message, .. } => message,
            other => panic!("expected an input error, got {other}"),
        }
    }

    #[test]
    fn identity_pose_reproduces_the_rest_pose() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        let rest = random_points(&mut rng, 500);
        let w = random_weights(&mut rng, 4, rest.len());
        let t = vec![Transform::identity(); 4];
        let (lbs, warn) = skin(&rest, &w, &t, Skinning::Lbs).unwrap();
        assert!(warn.is_empty(), "{warn:?}");
        assert_eq!(lbs, rest);
        let (dqs, warn) = skin(&rest, &w, &t, Skinning::Dqs).unwrap();
        assert!(warn.is_empty(), "{warn:?}");
        for (p, q) in rest.iter().zip(&dqs) {
            assert!(dist(*p, *q) <= 1e-12, "{p:?} -> {q:?}");
        }
    }

    #[test]
    fn a_single_full_weight_handle_applies_its_rigid_transform() {
        let mut rng = Rng(42);
        let rest = random_points(&mut rng, 200);
        for _ in 0..20 {
            let r = random_rotation(&mut rng);
            let target = transform(&r, [5.0 * rng.sym(), 5.0 * rng.sym(), 5.0 * rng.sym()]);
            // the other handle has weight 0 everywhere and a wild transform
            let other = transform(&axis_angle([1.0, 2.0, 3.0], 77.0), [9.0, -4.0, 1.0]);
            let w = vec![vec![0.0; rest.len()], vec![1.0; rest.len()]];
            for method in [Skinning::Lbs, Skinning::Dqs] {
                let (posed, warn) = skin(&rest, &w, &[other, target], method).unwrap();
                assert!(warn.is_empty(), "{warn:?}");
                for (p, q) in rest.iter().zip(&posed) {
                    let e = target.apply(*p);
                    assert!(dist(*q, e) <= 1e-12, "{method:?}: {q:?} vs {e:?}");
                }
            }
        }
    }

    #[test]
    fn candy_wrapper_lbs_collapses_and_dqs_keeps_the_cross_section() {
        // a bar along x from −1 to 1 around the axis y = 1, z = −2; the right end is twisted
        // 170° about the bar's axis, weights blend linearly along the bar
        let c = [0.0, 1.0, -2.0];
        let radius = 0.3;
        let mut rest = Vec::new();
        for i in 0..=20 {
            let x = -1.0 + 0.1 * i as f64;
            for k in 0..16 {
                let a = std::f64::consts::TAU * k as f64 / 16.0;
                rest.push([x, c[1] + radius * a.cos(), c[2] + radius * a.sin()]);
            }
        }
        let right: Vec<f64> = rest.iter().map(|p| (p[0] + 1.0) / 2.0).collect();
        let w = vec![right.iter().map(|r| 1.0 - r).collect(), right];
        let t = [Transform::identity(), about(&axis_angle([1.0, 0.0, 0.0], 170.0), c)];
        let r = |p: [f64; 3]| ((p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt();
        let middle = |p: &[f64; 3]| p[0].abs() < 1e-9;

        let (lbs, _) = skin(&rest, &w, &t, Skinning::Lbs).unwrap();
        let mut mid = 0;
        for (p, q) in rest.iter().zip(&lbs) {
            if middle(p) {
                mid += 1;
                assert!(r(*q) < 0.2 * radius, "LBS kept the middle radius: {}", r(*q));
            }
        }
        assert_eq!(mid, 16);

        let (dqs, warn) = skin(&rest, &w, &t, Skinning::Dqs).unwrap();
        assert!(warn.is_empty(), "{warn:?}");
        for (p, q) in rest.iter().zip(&dqs) {
            assert!((r(*q) - radius).abs() <= 1e-9, "DQS radius {} at {p:?}", r(*q));
            assert!((q[0] - p[0]).abs() <= 1e-9, "DQS moved along the bar: {p:?} -> {q:?}");
        }
        // the middle turns by half the twist
        for (p, q) in rest.iter().zip(&dqs).filter(|(p, _)| middle(p)) {
            let e = about(&axis_angle([1.0, 0.0, 0.0], 85.0), c).apply(*p);
            assert!(dist(*q, e) <= 1e-9, "{q:?} vs {e:?}");
        }
    }

    #[test]
    fn antipodal_quaternions_blend_like_identical_ones() {
        let mut rng = Rng(7);
        for _ in 0..20 {
            let r1 = quat_from_rotation(&random_rotation(&mut rng));
            let r2 = quat_from_rotation(&random_rotation(&mut rng));
            let t1 = [rng.sym(), rng.sym(), rng.sym()];
            let t2 = [rng.sym(), rng.sym(), rng.sym()];
            let a = DualQuat::new(r1, t1);
            let b = DualQuat::new(r2, t2);
            let neg = |d: DualQuat| DualQuat { real: d.real.map(|c| -c), dual: d.dual.map(|c| -c) };
            let p = [rng.sym(), rng.sym(), rng.sym()];
            for w in [[0.5, 0.5, 0.0], [0.3, 0.7, 0.0], [0.2, 0.5, 0.3]] {
                // the same rotation given twice, once with each sign
                let same = blend_apply(&[a, a, b], &w, p).unwrap();
                for set in [[a, neg(a), b], [neg(a), a, b], [neg(a), neg(a), neg(b)], [a, neg(a), neg(b)]] {
                    let got = blend_apply(&set, &w, p).unwrap();
                    assert!(dist(got, same) <= 1e-12, "{got:?} vs {same:?} (weights {w:?})");
                }
            }
        }
    }

    #[test]
    fn blending_takes_the_short_arc() {
        // identity and 200° about z, half each: the short way is −80°, not +100°
        let rest = vec![[1.0, 0.0, 0.5]];
        let w = vec![vec![0.5], vec![0.5]];
        let t = [Transform::identity(), transform(&axis_angle([0.0, 0.0, 1.0], 200.0), [0.0; 3])];
        let (q, _) = skin(&rest, &w, &t, Skinning::Dqs).unwrap();
        let e = transform(&axis_angle([0.0, 0.0, 1.0], -80.0), [0.0; 3]).apply(rest[0]);
        assert!(dist(q[0], e) <= 1e-12, "{:?} vs {e:?}", q[0]);
    }

    #[test]
    fn the_pivot_is_the_heaviest_handle() {
        // 0°, 120° and 240° about z weighted 0.1, 0.8, 0.1: symmetric about 120° when every
        // quaternion is taken in the hemisphere of the 120° one (with the 0° one as pivot, the
        // 240° one would flip and pull the blend to about 96°)
        let rest = vec![[1.0, 0.0, 0.5], [0.0, -2.0, 1.0]];
        let w = vec![vec![0.1; 2], vec![0.8; 2], vec![0.1; 2]];
        let z = |deg: f64| transform(&axis_angle([0.0, 0.0, 1.0], deg), [0.0; 3]);
        let (q, _) = skin(&rest, &w, &[z(0.0), z(120.0), z(240.0)], Skinning::Dqs).unwrap();
        for (p, q) in rest.iter().zip(&q) {
            let e = z(120.0).apply(*p);
            assert!(dist(*q, e) <= 1e-12, "{q:?} vs {e:?}");
        }
    }

    #[test]
    fn a_scaled_transform_in_dqs_warns_once_and_uses_its_rotation() {
        let mut rng = Rng(99);
        let rest = random_points(&mut rng, 50);
        let r = axis_angle([1.0, -1.0, 2.0], 40.0);
        // A = R S with S symmetric positive definite: the rotation part is R
        let s = [[2.0, 0.3, 0.0], [0.3, 1.0, 0.1], [0.0, 0.1, 0.5]];
        let a: Mat3 = std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| r[i][k] * s[k][j]).sum()));
        let tr = [1.0, 2.0, 3.0];
        let w = vec![vec![1.0; rest.len()], vec![0.0; rest.len()]];
        let t = [transform(&a, tr), Transform::identity()];
        let (posed, warn) = skin_named(&rest, &w, &t, &["arm", "leg"], Skinning::Dqs).unwrap();
        assert_eq!(
            warn,
            vec!["dual quaternions use the rotation part of `arm`; its scale/shear is dropped".to_string()]
        );
        for (p, q) in rest.iter().zip(&posed) {
            let e = transform(&r, tr).apply(*p);
            assert!(dist(*q, e) <= 1e-12, "{q:?} vs {e:?}");
        }
        // LBS applies the affine map as it is, without a warning
        let (posed, warn) = skin(&rest, &w, &t, Skinning::Lbs).unwrap();
        assert!(warn.is_empty(), "{warn:?}");
        for (p, q) in rest.iter().zip(&posed) {
            assert!(dist(*q, t[0].apply(*p)) <= 1e-12);
        }
        // a uniform scale warns too; a rotation with rounding noise does not
        let t2 = [transform(&r.map(|row| row.map(|x| 1.001 * x)), tr), transform(&r, tr)];
        let (_, warn) = skin(&rest, &w, &t2, Skinning::Dqs).unwrap();
        assert_eq!(warn.len(), 1);
        assert!(warn[0].contains("`handle 0`"), "{warn:?}");
    }

    #[test]
    fn polar_rotation_and_quaternions_are_accurate() {
        let mut rng = Rng(5);
        for _ in 0..50 {
            let r = random_rotation(&mut rng);
            // symmetric positive definite stretch, condition up to ~100
            let b: Mat3 = std::array::from_fn(|_| std::array::from_fn(|_| rng.sym()));
            let s: Mat3 = std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    (0..3).map(|k| b[k][i] * b[k][j]).sum::<f64>() + if i == j { 0.01 } else { 0.0 }
                })
            });
            let a: Mat3 = std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| r[i][k] * s[k][j]).sum()));
            let got = polar_rotation(&a).unwrap();
            assert!(fro(&sub3(&got, &r)) <= 1e-10, "{got:?} vs {r:?}");
        }
        // quaternions of rotations near and at 180°, about every axis direction
        for deg in [0.0, 1e-6, 90.0, 179.999_999, 180.0, 270.0] {
            for axis in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, -2.0, 0.5]] {
                let m = axis_angle(axis, deg);
                let q = quat_from_rotation(&m);
                assert!(fro(&sub3(&rotation_from_quat(&q), &m)) <= 1e-14, "{deg}° about {axis:?}");
            }
        }
    }

    #[test]
    fn unnormalised_lbs_weights_warn_and_keep_the_rest() {
        let rest = vec![[1.0, 2.0, 3.0], [0.0, 0.0, 1.0]];
        let w = vec![vec![0.5, 1.0]];
        let t = [transform(&axis_angle([0.0, 0.0, 1.0], 0.0), [2.0, 0.0, 0.0])];
        let (posed, warn) = skin(&rest, &w, &t, Skinning::Lbs).unwrap();
        assert_eq!(posed, vec![[2.0, 2.0, 3.0], [2.0, 0.0, 1.0]]);
        assert_eq!(warn.len(), 1);
        assert!(warn[0].contains("at 1 vertices (first: vertex 0, sum 0.5)"), "{warn:?}");
    }

    #[test]
    fn skinning_input_errors() {
        let rest = vec![[0.0; 3]; 3];
        let id = Transform::identity();
        let lbs = Skinning::Lbs;
        let m = input_message(skin(&rest, &[vec![1.0; 3]], &[id, id], lbs).unwrap_err());
        assert!(m.contains("1 weight functions but 2 transforms"), "{m}");
        let m = input_message(skin(&rest, &[vec![1.0; 3], vec![0.0; 2]], &[id, id], lbs).unwrap_err());
        assert!(m.contains("`handle 1` have 2 values for 3 vertices"), "{m}");
        let m = input_message(skin(&rest, &[vec![1.0, f64::NAN, 1.0]], &[id], lbs).unwrap_err());
        assert!(m.contains("at vertex 1 is NaN"), "{m}");
        let m = input_message(skin(&rest, &[vec![1.0, f64::INFINITY, 1.0]], &[id], Skinning::Dqs).unwrap_err());
        assert!(m.contains("at vertex 1 is inf"), "{m}");
        let mut bad = id;
        bad.0[1][3] = f64::NAN;
        let m = input_message(skin(&rest, &[vec![1.0; 3]], &[bad], lbs).unwrap_err());
        assert!(m.contains("non-finite"), "{m}");
        let m = input_message(skin_named(&rest, &[vec![1.0; 3]], &[id], &["a", "b"], lbs).unwrap_err());
        assert!(m.contains("2 handle names but 1 transforms"), "{m}");
        // a reflection is fine for LBS, an error for DQS
        let mirror = Transform([[-1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]);
        let rest = vec![[1.0, 2.0, 3.0]];
        assert_eq!(skin(&rest, &[vec![1.0]], &[mirror], lbs).unwrap().0, vec![[-1.0, 2.0, 3.0]]);
        let m = input_message(skin_named(&rest, &[vec![1.0]], &[mirror], &["tail"], Skinning::Dqs).unwrap_err());
        assert!(m.contains("`tail` is a reflection"), "{m}");
        let flat = Transform([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]);
        let m = input_message(skin(&rest, &[vec![1.0]], &[flat], Skinning::Dqs).unwrap_err());
        assert!(m.contains("singular"), "{m}");
        // weights summing to 0 leave no rotation to normalise
        let m = input_message(skin(&rest, &[vec![0.0]], &[id], Skinning::Dqs).unwrap_err());
        assert!(m.contains("vanishes at vertex 0"), "{m}");
    }

    #[test]
    fn transform_apply_and_identity() {
        let t = Transform([[0.0, -1.0, 0.0, 1.0], [1.0, 0.0, 0.0, 2.0], [0.0, 0.0, 2.0, 3.0]]);
        assert_eq!(t.apply([1.0, 2.0, 3.0]), [-1.0, 3.0, 9.0]);
        assert_eq!(Transform::identity().apply([1.5, -2.0, 7.0]), [1.5, -2.0, 7.0]);
    }

    #[test]
    fn parse_pose_reads_transforms_in_file_order() {
        let text = r#"{
            "comment": {"ignored": [1, 2]},
            "transforms": {
                "tail": [[1, 0, 0, 0.5], [0, 1, 0, -1], [0, 0, 1, 2e1]],
                "head": [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]],
                "arm": [[2, 0, 0, 0], [0, 2, 0, 0], [0, 0, 2, 0]]
            }
        }"#;
        let pose = parse_pose(text).unwrap();
        let names: Vec<&str> = pose.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["tail", "head", "arm"]);
        assert_eq!(pose[0].1, Transform([[1.0, 0.0, 0.0, 0.5], [0.0, 1.0, 0.0, -1.0], [0.0, 0.0, 1.0, 20.0]]));
        assert_eq!(pose[1].1, Transform([[0.0, -1.0, 0.0, 1.0], [1.0, 0.0, 0.0, 2.0], [0.0, 0.0, 1.0, 3.0]]));
        assert_eq!(pose[2].1.apply([1.0, 1.0, 1.0]), [2.0, 2.0, 2.0]);
    }

    #[test]
    fn parse_pose_errors() {
        let row = "[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]";
        let cases: Vec<(String, &str)> = vec![
            ("{\"transforms\": {".into(), "invalid pose JSON"),
            ("[1, 2]".into(), "invalid pose JSON"),
            ("{\"transforms\": [1, 2]}".into(), "invalid pose JSON"),
            ("{\"pose\": {}}".into(), "no \"transforms\""),
            ("{\"transforms\": null}".into(), "no \"transforms\""),
            ("{\"transforms\": {}}".into(), "is empty"),
            (format!("{{\"transforms\": {{\"a\": [{row}], \"a\": [{row}]}}}}"), "`a` is given twice"),
            (format!("{{\"transforms\": {{\"a\": [{row}]}}, \"transforms\": {{}}}}"), "invalid pose JSON"),
            ("{\"transforms\": {\"a\": 3}}".into(), "`a` must be a 3x4 matrix"),
            ("{\"transforms\": {\"a\": [[1, 0, 0, 0], [0, 1, 0, 0]]}}".into(), "got 2 rows"),
            ("{\"transforms\": {\"a\": [[1, 0, 0, 0], [0, 1, 0], [0, 0, 1, 0]]}}".into(), "row 2 has 3 entries"),
            ("{\"transforms\": {\"a\": [[1, 0, 0, 0], 5, [0, 0, 1, 0]]}}".into(), "row 2 is 5"),
            (format!("{{\"transforms\": {{\"a\": [{row}, [0, 0, 0, 1], [0, 0, 0, 1]]}}}}"), "got 5 rows"),
            (
                "{\"transforms\": {\"a\": [[1, 0, 0, 0], [0, 1, \"x\", 0], [0, 0, 1, 0]]}}".into(),
                "column 3 is not a number",
            ),
            (
                "{\"transforms\": {\"a\": [[1, 0, 0, null], [0, 1, 0, 0], [0, 0, 1, 0]]}}".into(),
                "column 4 is not a number",
            ),
            // serde_json refuses numbers that overflow f64
            ("{\"transforms\": {\"a\": [[1e400, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}}".into(), "invalid pose JSON"),
            (format!("{{\"transforms\": {{\"a\": [{row}, [0, 0, 1, 1]]}}}}"), "not [0,0,0,1]"),
            (format!("{{\"transforms\": {{\"a\": [{row}, [0, 0, 0, 2]]}}}}"), "not [0,0,0,1]"),
            (
                "{\"transforms\": {\"a\": [[1, 2, 3, 0], [2, 4, 6, 0], [0, 0, 1, 0]]}}".into(),
                "`a` has a singular linear part",
            ),
            ("{\"transforms\": {\"a\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1e-20, 0]]}}".into(), "singular"),
        ];
        for (text, expect) in cases {
            let m = input_message(parse_pose(&text).unwrap_err());
            assert!(m.contains(expect), "{text}: {m}");
        }
        // the caller attaches the file
        let e = parse_pose("{}").unwrap_err().in_file("pose.json");
        assert!(e.to_string().starts_with("pose.json: pose JSON has no \"transforms\""), "{e}");
        // tiny but uniform scales are not singular
        assert!(parse_pose("{\"transforms\": {\"a\": [[1e-6, 0, 0, 0], [0, 1e-6, 0, 0], [0, 0, 1e-6, 0]]}}").is_ok());
    }
}
