//! Circumsphere constructions for tetrahedra, triangles and edges.
//!
//! These are floating-point constructions (not exact), computed relative to
//! the first vertex for accuracy.

use super::{cross, dot, sub, Point3};

/// Squared circumradius of the tetrahedron `abcd` and the circumcentre's
/// offset from `a`. Returns infinite values for a flat tetrahedron.
#[inline]
pub fn tet_circum_offset(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> (Point3, f64) {
    let u = sub(*b, *a);
    let v = sub(*c, *a);
    let w = sub(*d, *a);
    let uu = dot(u, u);
    let vv = dot(v, v);
    let ww = dot(w, w);
    let vw = cross(v, w);
    let wu = cross(w, u);
    let uv = cross(u, v);
    let det = dot(u, vw);
    let s = 0.5 / det;
    let o = [
        (uu * vw[0] + vv * wu[0] + ww * uv[0]) * s,
        (uu * vw[1] + vv * wu[1] + ww * uv[1]) * s,
        (uu * vw[2] + vv * wu[2] + ww * uv[2]) * s,
    ];
    (o, dot(o, o))
}

/// Circumcentre and circumradius of a tetrahedron.
///
/// ```
/// use aniso_alpha::geometry::circum::tet_circumsphere;
/// let (c, r) = tet_circumsphere(&[0.0, 0.0, 0.0], &[2.0, 0.0, 0.0], &[0.0, 2.0, 0.0], &[0.0, 0.0, 2.0]);
/// assert!((c[0] - 1.0).abs() < 1e-15 && (r - 3f64.sqrt()).abs() < 1e-15);
/// ```
pub fn tet_circumsphere(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> (Point3, f64) {
    let (o, r2) = tet_circum_offset(a, b, c, d);
    ([a[0] + o[0], a[1] + o[1], a[2] + o[2]], r2.sqrt())
}

/// Squared circumradius of the triangle `abc` (radius of its smallest
/// circumsphere) and the circumcentre's offset from `a`.
#[inline]
pub fn tri_circum_offset(a: &Point3, b: &Point3, c: &Point3) -> (Point3, f64) {
    let u = sub(*b, *a);
    let v = sub(*c, *a);
    let n = cross(u, v);
    let nn = dot(n, n);
    let uu = dot(u, u);
    let vv = dot(v, v);
    // o = (|u|² (v × n) + |v|² (n × u)) / (2 |n|²)
    let vn = cross(v, n);
    let nu = cross(n, u);
    let s = 0.5 / nn;
    let o = [
        (uu * vn[0] + vv * nu[0]) * s,
        (uu * vn[1] + vv * nu[1]) * s,
        (uu * vn[2] + vv * nu[2]) * s,
    ];
    (o, dot(o, o))
}

/// Circumcentre and circumradius of a triangle (its smallest circumsphere).
///
/// ```
/// use aniso_alpha::geometry::circum::tri_circumsphere;
/// let (c, r) = tri_circumsphere(&[0.0, 0.0, 0.0], &[2.0, 0.0, 0.0], &[0.0, 2.0, 0.0]);
/// assert_eq!(c, [1.0, 1.0, 0.0]);
/// assert!((r - 2f64.sqrt()).abs() < 1e-15);
/// ```
pub fn tri_circumsphere(a: &Point3, b: &Point3, c: &Point3) -> (Point3, f64) {
    let (o, r2) = tri_circum_offset(a, b, c);
    ([a[0] + o[0], a[1] + o[1], a[2] + o[2]], r2.sqrt())
}

/// Midpoint and half-length of an edge (its smallest circumsphere).
///
/// ```
/// use aniso_alpha::geometry::circum::edge_circumsphere;
/// assert_eq!(edge_circumsphere(&[0.0, 0.0, 0.0], &[0.0, 0.0, 2.0]), ([0.0, 0.0, 1.0], 1.0));
/// ```
pub fn edge_circumsphere(a: &Point3, b: &Point3) -> (Point3, f64) {
    let d = sub(*b, *a);
    (
        [a[0] + 0.5 * d[0], a[1] + 0.5 * d[1], a[2] + 0.5 * d[2]],
        0.5 * dot(d, d).sqrt(),
    )
}
