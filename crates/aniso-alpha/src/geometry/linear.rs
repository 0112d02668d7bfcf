//! Small linear algebra on `[f64; 3]`: the vector helpers, the one 3×3
//! matrix type [`Mat3`], and the exact point transform `Q·p` of the
//! anisotropic method.
//!
//! Every function here is plain `f64` arithmetic, evaluated in the order
//! its doc gives and never fused (Rust contracts `a * b + c` into a fused
//! multiply-add only through `mul_add`, which nothing here calls), so the
//! results are the same bit for bit on every machine.

use super::Point3;

/// A 3×3 matrix stored as rows.
pub type Mat3 = [[f64; 3]; 3];

/// `a − b`.
#[inline]
pub fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a + b`.
#[inline]
pub fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `s · a`.
#[inline]
pub fn scale(s: f64, a: Point3) -> Point3 {
    [s * a[0], s * a[1], s * a[2]]
}

/// The dot product `(a₀b₀ + a₁b₁) + a₂b₂`.
#[inline]
pub fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product `a × b`.
#[inline]
pub fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The permanent of [`cross`]: `|a₁b₂| + |a₂b₁|` and so on per component,
/// the size of the products each component of `a × b` subtracts, which
/// bounds its rounding error (the error bounds of `alpha::exact` and
/// `detect::faces`).
#[inline]
pub(crate) fn cross_permanent(a: Point3, b: Point3) -> Point3 {
    [
        (a[1] * b[2]).abs() + (a[2] * b[1]).abs(),
        (a[2] * b[0]).abs() + (a[0] * b[2]).abs(),
        (a[0] * b[1]).abs() + (a[1] * b[0]).abs(),
    ]
}

/// The Euclidean norm `|a|`.
#[inline]
pub fn norm(a: Point3) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`, or `None` if `a` is zero or not finite. Scaled first, so
/// that huge or tiny vectors neither overflow nor underflow.
///
/// ```
/// use aniso_alpha::geometry::normalize;
/// assert_eq!(normalize([0.0, 3e300, 4e300]), Some([0.0, 0.6, 0.8]));
/// assert_eq!(normalize([0.0; 3]), None);
/// ```
pub fn normalize(a: Point3) -> Option<Point3> {
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let m = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 {
        return None;
    }
    let b = [a[0] / m, a[1] / m, a[2] / m];
    let n = norm(b);
    Some([b[0] / n, b[1] / n, b[2] / n])
}

/// Matrix product a · b, each entry `(a_i0·b_0j + a_i1·b_1j) + a_i2·b_2j`.
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}

/// Determinant of a 3×3 matrix (cofactor expansion along the first row).
pub fn det3(m: &Mat3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// `Q = diag(e)·R`: row `i` of the rotation `r` scaled by `e[i]`
/// (`Q_ij = e_i·R_ij`, one rounding each).
///
/// ```
/// use aniso_alpha::geometry::q_matrix;
/// let r = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
/// assert_eq!(q_matrix(&r, &[2.0, 1.0, 0.5]), [[0.0, 2.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.5]]);
/// ```
pub fn q_matrix(rotation: &Mat3, elongation: &[f64; 3]) -> Mat3 {
    std::array::from_fn(|i| rotation[i].map(|x| elongation[i] * x))
}

/// `Q·p`: `q_i = (Q_i0·x + Q_i1·y) + Q_i2·z`, each operation rounded to
/// `f64` in exactly that order, no fused multiply-add (numpy's and the CGAL
/// fixtures' convention, reproduced bit for bit: the triangulation of a
/// transformed grid depends on the last bit).
///
/// ```
/// use aniso_alpha::geometry::transform_point;
/// let q = [[2.0, 0.0, 0.0], [0.0, 1.0, 1.0], [0.0, 0.0, 0.5]];
/// assert_eq!(transform_point(&q, [1.0, 2.0, 4.0]), [2.0, 6.0, 2.0]);
/// ```
#[inline]
pub fn transform_point(q: &Mat3, p: Point3) -> Point3 {
    let mut out = [0.0; 3];
    for (o, row) in out.iter_mut().zip(q.iter()) {
        let a = row[0] * p[0];
        let b = row[1] * p[1];
        let s = a + b;
        let c = row[2] * p[2];
        *o = s + c;
    }
    out
}

/// [`transform_point`] for every point.
pub fn transform_points(q: &Mat3, points: &[Point3]) -> Vec<Point3> {
    points.iter().map(|&p| transform_point(q, p)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vector_identities() {
        let a = [1.0, -2.0, 3.0];
        let b = [0.5, 4.0, -1.0];
        let c = cross(a, b);
        assert_eq!(dot(c, a), 0.0);
        assert_eq!(dot(c, b), 0.0);
        assert_eq!(cross(b, a), scale(-1.0, c));
        assert_eq!(add(sub(a, b), b), a);
        assert_eq!(norm([3.0, 4.0, 12.0]), 13.0);
        let m = [a, b, c];
        // det[a; b; a × b] = |a × b|².
        assert_eq!(det3(&m), dot(c, c));
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(mat_mul(&m, &id), m);
        assert_eq!(mat_mul(&id, &m), m);
    }

    /// The transform rounds `(Q_i0·x + Q_i1·y) + Q_i2·z` in that order: on
    /// values where the order matters, the result is the one that order
    /// gives, not the exact one nor another order's.
    #[test]
    fn transform_rounds_in_the_stated_order() {
        let q = [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]];
        let p = [1e16, 1.0, -1e16];
        // (1e16 + 1) rounds to 1e16, then + (−1e16) = 0; other orders
        // give 1.
        assert_eq!(transform_point(&q, p), [0.0, 0.0, 0.0]);
        let q = q_matrix(&q, &[1.0, 3.0, 1.0]);
        assert_eq!(q[1], [3.0, 3.0, 3.0]);
        assert_eq!(transform_points(&q, &[[1.0; 3]]), vec![[3.0, 9.0, 0.0]]);
    }
}
