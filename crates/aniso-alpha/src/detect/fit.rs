//! Least-squares lines and planes (total least squares via the covariance
//! matrix), with a self-contained symmetric 3×3 eigensolver (cyclic Jacobi).
//!
//! For points p_1 … p_n with centroid c and covariance
//! C = (1/n) Σ (p_i − c)(p_i − c)ᵀ with eigenvalues λ₁ ≥ λ₂ ≥ λ₃:
//!
//! * the best line (least sum of squared distances) passes through c along
//!   the eigenvector of λ₁; its RMS residual (root mean squared distance to
//!   the line) is √(λ₂ + λ₃);
//! * the best plane passes through c with normal the eigenvector of λ₃; its
//!   RMS residual is √λ₃; its in-plane principal axes are those of λ₁, λ₂.
//!
//! Extents: a line's is the length of the interval of projections on its
//! direction; a plane's are the side lengths of the bounding rectangle of
//! the projections on its two in-plane principal axes (largest first).
//!
//! Residuals and extents are computed from the points, not from the
//! eigenvalues. Directions and normals are unit vectors with their largest
//! component (in absolute value; the first on ties) positive, so the output
//! is deterministic.
//!
//! ```
//! use aniso_alpha::detect::fit::{fit_line, fit_plane};
//! let line = fit_line(&[[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [3.0, 3.0, 0.0]]).unwrap();
//! let s = 0.5f64.sqrt();
//! assert!((line.direction[0] - s).abs() < 1e-12 && (line.direction[1] - s).abs() < 1e-12);
//! assert!((line.extent - 18f64.sqrt()).abs() < 1e-12);
//! assert!(line.rms_residual < 1e-12);
//!
//! let square = [[0.0, 0.0, 5.0], [2.0, 0.0, 5.0], [0.0, 1.0, 5.0], [2.0, 1.0, 5.0]];
//! let plane = fit_plane(&square).unwrap();
//! assert_eq!(plane.normal, [0.0, 0.0, 1.0]);
//! assert!((plane.extent[0] - 2.0).abs() < 1e-12 && (plane.extent[1] - 1.0).abs() < 1e-12);
//! ```

// Small fixed-size matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::aniso::{cross, dot, Mat3};
use std::fmt;

/// A fitted line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineFit {
    /// Centroid of the points (a point on the line).
    pub centroid: [f64; 3],
    /// Unit direction (largest component positive).
    pub direction: [f64; 3],
    /// Root mean squared distance of the points to the line.
    pub rms_residual: f64,
    /// Length of the interval of the points' projections on the line.
    pub extent: f64,
}

/// A fitted plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFit {
    /// Centroid of the points (a point on the plane).
    pub centroid: [f64; 3],
    /// Unit normal (largest component positive).
    pub normal: [f64; 3],
    /// In-plane principal axes: `axes[0]` of the largest variance,
    /// `axes[1] = normal × axes[0]`.
    pub axes: [[f64; 3]; 2],
    /// Root mean squared distance of the points to the plane.
    pub rms_residual: f64,
    /// Side lengths of the bounding rectangle of the projected points along
    /// `axes[0]` and `axes[1]`.
    pub extent: [f64; 2],
}

/// Why a fit failed.
#[derive(Debug, Clone, PartialEq)]
pub enum FitError {
    /// Not enough points (2 for a line, 3 for a plane).
    TooFewPoints {
        /// Points needed.
        needed: usize,
        /// Points given.
        got: usize,
    },
    /// Point `index` has a NaN or infinite coordinate.
    NonFinite {
        /// Position of the point (in `points`, or in `indices` for the
        /// subset variants).
        index: usize,
    },
    /// An index of a subset is out of range.
    IndexOutOfRange {
        /// The index.
        index: u32,
    },
    /// The points do not determine the primitive: all equal (line), or all
    /// on one line (plane: λ₂ ≤ 64·ε·λ₁).
    Degenerate,
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooFewPoints { needed, got } => {
                write!(f, "need at least {needed} points to fit, got {got}")
            }
            Self::NonFinite { index } => write!(f, "point {index} is not finite"),
            Self::IndexOutOfRange { index } => write!(f, "point index {index} out of range"),
            Self::Degenerate => write!(f, "degenerate point set"),
        }
    }
}

impl std::error::Error for FitError {}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi
/// rotations: returns eigenvalues in descending order and the matching unit
/// eigenvectors as the rows of the second matrix (an orthonormal basis).
/// Only the upper triangle of `m` is read.
///
/// ```
/// use aniso_alpha::detect::fit::symmetric_eigen;
/// let (vals, vecs) = symmetric_eigen([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]]);
/// assert!((vals[0] - 5.0).abs() < 1e-12 && (vals[1] - 3.0).abs() < 1e-12 && (vals[2] - 1.0).abs() < 1e-12);
/// assert!((vecs[0][2].abs() - 1.0).abs() < 1e-12);
/// ```
pub fn symmetric_eigen(m: Mat3) -> ([f64; 3], Mat3) {
    let mut a = [
        [m[0][0], m[0][1], m[0][2]],
        [m[0][1], m[1][1], m[1][2]],
        [m[0][2], m[1][2], m[2][2]],
    ];
    // v's columns are the eigenvectors.
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..64 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off == 0.0 || !off.is_finite() {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            // For huge theta, t ≈ 1/(2θ); theta*theta may overflow to inf,
            // giving t = 0, which is the right limit.
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with J the rotation in the (p, q) plane.
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            a[p][q] = 0.0;
            a[q][p] = 0.0;
            for row in v.iter_mut() {
                let vkp = row[p];
                let vkq = row[q];
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    let vals = [
        a[order[0]][order[0]],
        a[order[1]][order[1]],
        a[order[2]][order[2]],
    ];
    let col = |j: usize| [v[0][j], v[1][j], v[2][j]];
    (vals, [col(order[0]), col(order[1]), col(order[2])])
}

/// Flips `u` so that its largest |component| (first on ties) is positive.
fn canonical_sign(u: [f64; 3]) -> [f64; 3] {
    let mut k = 0;
    for i in 1..3 {
        if u[i].abs() > u[k].abs() {
            k = i;
        }
    }
    if u[k] < 0.0 {
        [-u[0], -u[1], -u[2]]
    } else {
        u
    }
}

fn unit(u: [f64; 3]) -> [f64; 3] {
    let n = dot(u, u).sqrt();
    [u[0] / n, u[1] / n, u[2] / n]
}

/// Centroid and covariance (divided by `n`) of `n` points given by `get`:
/// the one place the detector forms a second-moment matrix from points.
pub(crate) fn moments(n: usize, get: impl Fn(usize) -> [f64; 3]) -> ([f64; 3], Mat3) {
    let nf = n as f64;
    let mut c = [0.0; 3];
    for i in 0..n {
        let p = get(i);
        for k in 0..3 {
            c[k] += p[k];
        }
    }
    c = c.map(|x| x / nf);
    let mut m = [[0.0; 3]; 3];
    for i in 0..n {
        let p = get(i);
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        for r in 0..3 {
            for s in r..3 {
                m[r][s] += d[r] * d[s];
            }
        }
    }
    for r in 0..3 {
        for s in r..3 {
            m[r][s] /= nf;
            m[s][r] = m[r][s];
        }
    }
    (c, m)
}

fn check(n: usize, needed: usize, get: &dyn Fn(usize) -> [f64; 3]) -> Result<(), FitError> {
    if n < needed {
        return Err(FitError::TooFewPoints { needed, got: n });
    }
    for i in 0..n {
        if !get(i).iter().all(|x| x.is_finite()) {
            return Err(FitError::NonFinite { index: i });
        }
    }
    Ok(())
}

fn line_impl(n: usize, get: &dyn Fn(usize) -> [f64; 3]) -> Result<LineFit, FitError> {
    check(n, 2, get)?;
    let (c, m) = moments(n, get);
    let (vals, vecs) = symmetric_eigen(m);
    if vals[0].is_nan() || vals[0] <= 0.0 {
        return Err(FitError::Degenerate);
    }
    let d = canonical_sign(unit(vecs[0]));
    let (mut lo, mut hi, mut ss) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
    for i in 0..n {
        let p = get(i);
        let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let t = dot(q, d);
        lo = lo.min(t);
        hi = hi.max(t);
        // The perpendicular part itself, not |q|² − t² (cancellation).
        let r = [q[0] - t * d[0], q[1] - t * d[1], q[2] - t * d[2]];
        ss += dot(r, r);
    }
    Ok(LineFit {
        centroid: c,
        direction: d,
        rms_residual: (ss / n as f64).sqrt(),
        extent: hi - lo,
    })
}

fn plane_impl(n: usize, get: &dyn Fn(usize) -> [f64; 3]) -> Result<PlaneFit, FitError> {
    check(n, 3, get)?;
    let (c, m) = moments(n, get);
    let (vals, vecs) = symmetric_eigen(m);
    if vals[0].is_nan() || vals[0] <= 0.0 || vals[1] <= 64.0 * f64::EPSILON * vals[0] {
        return Err(FitError::Degenerate);
    }
    let normal = canonical_sign(unit(vecs[2]));
    let a0 = canonical_sign(unit(vecs[0]));
    let a1 = cross(normal, a0);
    let (mut lo, mut hi, mut ss) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2], 0.0);
    for i in 0..n {
        let p = get(i);
        let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let h = dot(q, normal);
        ss += h * h;
        for (k, a) in [a0, a1].iter().enumerate() {
            let t = dot(q, *a);
            lo[k] = lo[k].min(t);
            hi[k] = hi[k].max(t);
        }
    }
    Ok(PlaneFit {
        centroid: c,
        normal,
        axes: [a0, a1],
        rms_residual: (ss / n as f64).sqrt(),
        extent: [hi[0] - lo[0], hi[1] - lo[1]],
    })
}

fn subset<'a>(
    points: &'a [[f64; 3]],
    indices: &'a [u32],
) -> Result<impl Fn(usize) -> [f64; 3] + 'a, FitError> {
    if let Some(&index) = indices.iter().find(|&&i| i as usize >= points.len()) {
        return Err(FitError::IndexOutOfRange { index });
    }
    Ok(move |i: usize| points[indices[i] as usize])
}

/// Least-squares line through `points` (at least 2, not all equal).
pub fn fit_line(points: &[[f64; 3]]) -> Result<LineFit, FitError> {
    line_impl(points.len(), &|i| points[i])
}

/// Least-squares plane through `points` (at least 3, not all on a line).
pub fn fit_plane(points: &[[f64; 3]]) -> Result<PlaneFit, FitError> {
    plane_impl(points.len(), &|i| points[i])
}

/// [`fit_line`] of `points[indices[..]]`, without copying.
pub fn fit_line_indices(points: &[[f64; 3]], indices: &[u32]) -> Result<LineFit, FitError> {
    let get = subset(points, indices)?;
    line_impl(indices.len(), &get)
}

/// [`fit_plane`] of `points[indices[..]]`, without copying.
///
/// ```
/// use aniso_alpha::detect::fit::fit_plane_indices;
/// let pts = [[0.0, 0.0, 1.0], [9.0, 9.0, 9.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
/// let p = fit_plane_indices(&pts, &[0, 2, 3]).unwrap();
/// assert_eq!(p.normal, [0.0, 0.0, 1.0]);
/// ```
pub fn fit_plane_indices(points: &[[f64; 3]], indices: &[u32]) -> Result<PlaneFit, FitError> {
    let get = subset(points, indices)?;
    plane_impl(indices.len(), &get)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::Rng;

    fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
        (dot(a, b).abs() / (dot(a, a) * dot(b, b)).sqrt())
            .min(1.0)
            .acos()
    }

    #[test]
    fn eigen_random_symmetric() {
        let mut rng = Rng::new(11);
        for case in 0..2000 {
            let mut m = [[0.0; 3]; 3];
            for r in 0..3 {
                for s in r..3 {
                    m[r][s] = rng.range(-10.0, 10.0);
                    m[s][r] = m[r][s];
                }
            }
            if case % 3 == 0 {
                // Repeated eigenvalues: Q diag(a, a, b) Qᵀ.
                let u = rng.unit_vector();
                for r in 0..3 {
                    for s in 0..3 {
                        m[r][s] = 2.0 * f64::from(u8::from(r == s)) + 3.0 * u[r] * u[s];
                    }
                }
            }
            let (vals, vecs) = symmetric_eigen(m);
            assert!(vals[0] >= vals[1] && vals[1] >= vals[2]);
            for i in 0..3 {
                for j in 0..3 {
                    let d = dot(vecs[i], vecs[j]);
                    let t = if i == j { 1.0 } else { 0.0 };
                    assert!((d - t).abs() < 1e-12, "case {case}");
                }
                for r in 0..3 {
                    let mv = dot(m[r], vecs[i]);
                    assert!(
                        (mv - vals[i] * vecs[i][r]).abs() < 1e-11,
                        "case {case}: {m:?}"
                    );
                }
            }
            let trace = m[0][0] + m[1][1] + m[2][2];
            assert!((vals.iter().sum::<f64>() - trace).abs() < 1e-11);
        }
        let (vals, _) = symmetric_eigen([[0.0; 3]; 3]);
        assert_eq!(vals, [0.0; 3]);
    }

    #[test]
    fn exact_line() {
        let d = unit([2.0, -1.0, 3.0]);
        let p0 = [1.0, 2.0, 3.0];
        let ts = [-4.0, 0.0, 1.5, 2.0, 7.0];
        let pts: Vec<[f64; 3]> = ts
            .iter()
            .map(|&t| [p0[0] + t * d[0], p0[1] + t * d[1], p0[2] + t * d[2]])
            .collect();
        let f = fit_line(&pts).unwrap();
        assert!(angle(f.direction, d) < 1e-12);
        assert_eq!(f.direction, canonical_sign(f.direction));
        assert!(f.direction[2] > 0.0);
        assert!((f.extent - 11.0).abs() < 1e-12);
        assert!(f.rms_residual < 1e-12);
        let tm = ts.iter().sum::<f64>() / 5.0;
        for k in 0..3 {
            assert!((f.centroid[k] - (p0[k] + tm * d[k])).abs() < 1e-12);
        }
    }

    #[test]
    fn noisy_line() {
        let mut rng = Rng::new(12);
        let d = unit([1.0, 1.0, 0.2]);
        let sigma = 0.05;
        let pts: Vec<[f64; 3]> = (0..2000)
            .map(|i| {
                let t = i as f64 * 0.01;
                [
                    t * d[0] + sigma * rng.gaussian(),
                    t * d[1] + sigma * rng.gaussian(),
                    t * d[2] + sigma * rng.gaussian(),
                ]
            })
            .collect();
        let f = fit_line(&pts).unwrap();
        assert!(angle(f.direction, d) < 2e-3, "{}", angle(f.direction, d));
        // Two perpendicular noise dimensions: rms ≈ σ√2.
        let want = sigma * 2f64.sqrt();
        assert!(
            (f.rms_residual - want).abs() < 0.05 * want,
            "{}",
            f.rms_residual
        );
        assert!((f.extent - 19.99).abs() < 0.5);
    }

    fn rect_points(n: [f64; 3], a: [f64; 3], w: f64, h: f64, step: f64) -> Vec<[f64; 3]> {
        let b = cross(n, a);
        let o = [3.0, -2.0, 1.0];
        let mut pts = Vec::new();
        let (nu, nv) = ((w / step).round() as usize, (h / step).round() as usize);
        for i in 0..=nu {
            for j in 0..=nv {
                let (u, v) = (i as f64 * step, j as f64 * step);
                pts.push([
                    o[0] + u * a[0] + v * b[0],
                    o[1] + u * a[1] + v * b[1],
                    o[2] + u * a[2] + v * b[2],
                ]);
            }
        }
        pts
    }

    #[test]
    fn exact_plane() {
        let n = unit([1.0, 2.0, 2.0]);
        let a = unit(cross(n, [0.0, 0.0, 1.0]));
        let pts = rect_points(n, a, 10.0, 4.0, 0.5);
        let f = fit_plane(&pts).unwrap();
        assert!(angle(f.normal, n) < 1e-12);
        assert!(angle(f.axes[0], a) < 1e-9);
        assert!(f.rms_residual < 1e-12);
        assert!((f.extent[0] - 10.0).abs() < 1e-9, "{:?}", f.extent);
        assert!((f.extent[1] - 4.0).abs() < 1e-9, "{:?}", f.extent);
        assert!(dot(f.normal, f.axes[0]).abs() < 1e-12);
        assert!((dot(cross(f.normal, f.axes[0]), f.axes[1]) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn noisy_plane() {
        let mut rng = Rng::new(13);
        let n = unit([0.0, -1.0, 1.0]);
        let a = unit([1.0, 0.0, 0.0]);
        let sigma = 0.02;
        let pts: Vec<[f64; 3]> = rect_points(n, a, 20.0, 10.0, 0.25)
            .into_iter()
            .map(|p| {
                let e = sigma * rng.gaussian();
                [p[0] + e * n[0], p[1] + e * n[1], p[2] + e * n[2]]
            })
            .collect();
        let f = fit_plane(&pts).unwrap();
        assert!(angle(f.normal, n) < 1e-3);
        assert!(
            (f.rms_residual - sigma).abs() < 0.05 * sigma,
            "{}",
            f.rms_residual
        );
        assert!((f.extent[0] - 20.0).abs() < 0.01 && (f.extent[1] - 10.0).abs() < 0.01);
    }

    #[test]
    fn errors() {
        assert_eq!(
            fit_line(&[[0.0; 3]]),
            Err(FitError::TooFewPoints { needed: 2, got: 1 })
        );
        assert_eq!(fit_line(&[[1.0; 3]; 4]), Err(FitError::Degenerate));
        assert_eq!(
            fit_plane(&[[0.0; 3], [1.0, 0.0, 0.0]]),
            Err(FitError::TooFewPoints { needed: 3, got: 2 })
        );
        let collinear = [
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [2.0, 4.0, 6.0],
            [0.3, 0.6, 0.9],
        ];
        assert_eq!(fit_plane(&collinear), Err(FitError::Degenerate));
        assert!(fit_line(&collinear).is_ok());
        assert_eq!(
            fit_line(&[[0.0; 3], [f64::NAN, 0.0, 0.0]]),
            Err(FitError::NonFinite { index: 1 })
        );
        assert_eq!(
            fit_line_indices(&[[0.0; 3], [1.0; 3]], &[0, 2]),
            Err(FitError::IndexOutOfRange { index: 2 })
        );
        let f = fit_line_indices(&[[0.0; 3], [5.0; 3], [1.0; 3]], &[0, 2]).unwrap();
        assert!((f.extent - 3f64.sqrt()).abs() < 1e-12);
    }
}
