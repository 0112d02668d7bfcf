//! Geometry: exact predicates (with the symbolic perturbation that settles
//! ties) and floating-point constructions (circumspheres).
//!
//! Nothing here knows about triangulation topology.

pub mod circum;
pub mod kdtree;
pub mod predicates;

pub use predicates::Point3;

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
