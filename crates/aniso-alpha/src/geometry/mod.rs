//! Geometry: exact predicates (with the symbolic perturbation that settles
//! ties), floating-point constructions (circumspheres), and the small
//! linear algebra the crate shares (vector helpers, [`Mat3`], the exact
//! transform `Q·p`).
//!
//! Nothing here knows about triangulation topology.

pub mod circum;
pub mod kdtree;
mod linear;
pub mod predicates;
mod wide;

pub(crate) use linear::cross_permanent;
pub use linear::{
    add, cross, det3, dot, mat_mul, norm, normalize, q_matrix, scale, sub, transform_point,
    transform_points, Mat3,
};
pub use predicates::{Point3, Sign};

/// The axis-aligned bounding box `(lo, hi)` of `points`; for an empty slice
/// `lo` is `+∞` and `hi` is `−∞` on every axis.
///
/// ```
/// use aniso_alpha::geometry::bounding_box;
/// let (lo, hi) = bounding_box(&[[1.0, 5.0, -2.0], [3.0, 4.0, 0.0]]);
/// assert_eq!((lo, hi), ([1.0, 4.0, -2.0], [3.0, 5.0, 0.0]));
/// ```
pub fn bounding_box(points: &[Point3]) -> (Point3, Point3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// [`bounding_box`] of the points `ids` of `points`, without gathering
/// them.
pub(crate) fn bounding_box_of(points: &[Point3], ids: &[u32]) -> (Point3, Point3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in ids {
        let p = points[i as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}
