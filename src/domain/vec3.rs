//! Small 3-vector helpers shared by the mesh code, the operators, the geodesic distance and
//! the mesh pictures.

/// `a − b`.
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a · b`.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `|a|`.
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|` (a zero vector stays zero).
pub fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    if l > 0.0 {
        a.map(|x| x / l)
    } else {
        a
    }
}

/// `6 ×` the signed volume of the tetrahedron `(a, b, c, d)`: positive when `d` lies on the
/// side of the triangle `(a, b, c)` that its normal `(b − a) × (c − a)` points to.
pub(crate) fn signed_volume6(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    dot(cross(sub(b, a), sub(c, a)), sub(d, a))
}
