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

/// Adds a point to a centroid's running sum (the first pass of a fit).
#[inline]
fn add_sum(sum: &mut [f64; 3], p: [f64; 3]) {
    for k in 0..3 {
        sum[k] += p[k];
    }
}

/// The centroid of `n` points from their sum (the end of the first pass).
fn centroid(sum: [f64; 3], n: usize) -> [f64; 3] {
    let n = n as f64;
    sum.map(|x| x / n)
}

/// Adds a point to a covariance's running sum about `c` (the second pass),
/// upper triangle only.
#[inline]
fn add_moment(m: &mut Mat3, c: [f64; 3], p: [f64; 3]) {
    let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    for r in 0..3 {
        for s in r..3 {
            m[r][s] += d[r] * d[s];
        }
    }
}

/// The covariance of `n` points from its running sum (divided by `n`,
/// made symmetric).
fn end_moments(mut m: Mat3, n: usize) -> Mat3 {
    let nf = n as f64;
    for r in 0..3 {
        for s in r..3 {
            m[r][s] /= nf;
            m[s][r] = m[r][s];
        }
    }
    m
}

/// Centroid and covariance (divided by `n`) of `n` points given by `get`:
/// the one place the detector forms a second-moment matrix from points.
pub(crate) fn moments(n: usize, get: impl Fn(usize) -> [f64; 3]) -> ([f64; 3], Mat3) {
    let mut sum = [0.0; 3];
    for i in 0..n {
        add_sum(&mut sum, get(i));
    }
    let c = centroid(sum, n);
    let mut m = [[0.0; 3]; 3];
    for i in 0..n {
        add_moment(&mut m, c, get(i));
    }
    (c, end_moments(m, n))
}

fn check(n: usize, needed: usize, get: &impl Fn(usize) -> [f64; 3]) -> Result<(), FitError> {
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

/// A fitted primitive's frame, from the covariance: a line's direction, or
/// a plane's normal and in-plane axes.
#[derive(Debug, Clone, Copy)]
enum Frame {
    Line([f64; 3]),
    Plane([f64; 3], [f64; 3], [f64; 3]),
}

impl Frame {
    /// The frame of covariance `m` (`line`: a line's, else a plane's).
    fn of(m: Mat3, line: bool) -> Result<Frame, FitError> {
        let (vals, vecs) = symmetric_eigen(m);
        if vals[0].is_nan() || vals[0] <= 0.0 {
            return Err(FitError::Degenerate);
        }
        if line {
            return Ok(Frame::Line(canonical_sign(unit(vecs[0]))));
        }
        if vals[1] <= 64.0 * f64::EPSILON * vals[0] {
            return Err(FitError::Degenerate);
        }
        let normal = canonical_sign(unit(vecs[2]));
        let a0 = canonical_sign(unit(vecs[0]));
        Ok(Frame::Plane(normal, a0, cross(normal, a0)))
    }
}

/// The third pass of a fit: the squared residuals and the extents of the
/// projections on the frame's axes (a line: one axis, its direction).
#[derive(Debug, Clone, Copy)]
struct Spread {
    lo: [f64; 2],
    hi: [f64; 2],
    ss: f64,
}

impl Spread {
    fn new() -> Self {
        Spread {
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
            ss: 0.0,
        }
    }

    #[inline]
    fn add(&mut self, frame: &Frame, c: [f64; 3], p: [f64; 3]) {
        match *frame {
            Frame::Line(d) => self.add_line(d, c, p),
            Frame::Plane(normal, a0, a1) => self.add_plane([normal, a0, a1], c, p),
        }
    }

    #[inline]
    fn add_line(&mut self, d: [f64; 3], c: [f64; 3], p: [f64; 3]) {
        let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let t = dot(q, d);
        self.lo[0] = self.lo[0].min(t);
        self.hi[0] = self.hi[0].max(t);
        // The perpendicular part itself, not |q|² − t² (cancellation).
        let r = [q[0] - t * d[0], q[1] - t * d[1], q[2] - t * d[2]];
        self.ss += dot(r, r);
    }

    #[inline]
    fn add_plane(&mut self, [normal, a0, a1]: [[f64; 3]; 3], c: [f64; 3], p: [f64; 3]) {
        let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let h = dot(q, normal);
        self.ss += h * h;
        for (k, a) in [a0, a1].iter().enumerate() {
            let t = dot(q, *a);
            self.lo[k] = self.lo[k].min(t);
            self.hi[k] = self.hi[k].max(t);
        }
    }
}

/// A fitted line or plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fitted {
    /// A line.
    Line(LineFit),
    /// A plane.
    Plane(PlaneFit),
}

/// The fit of `n` points with centroid `c`, frame and spread.
fn fitted(c: [f64; 3], frame: Frame, spread: &Spread, n: usize) -> Fitted {
    let rms_residual = (spread.ss / n as f64).sqrt();
    match frame {
        Frame::Line(direction) => Fitted::Line(LineFit {
            centroid: c,
            direction,
            rms_residual,
            extent: spread.hi[0] - spread.lo[0],
        }),
        Frame::Plane(normal, a0, a1) => Fitted::Plane(PlaneFit {
            centroid: c,
            normal,
            axes: [a0, a1],
            rms_residual,
            extent: [spread.hi[0] - spread.lo[0], spread.hi[1] - spread.lo[1]],
        }),
    }
}

/// The fit of the `n` points `get(0..n)`: generic over `get`, so that the
/// passes over the points inline it rather than make a `dyn` call per
/// point (the assembly refits tens of thousands of points per candidate:
/// mOSD learn 8's candidates stage, 2 threads, 76.5 → 72.4 ms).
fn fit_impl(n: usize, line: bool, get: &impl Fn(usize) -> [f64; 3]) -> Result<Fitted, FitError> {
    check(n, if line { 2 } else { 3 }, get)?;
    let (c, m) = moments(n, get);
    let frame = Frame::of(m, line)?;
    let mut spread = Spread::new();
    // One loop per kind: the frame is matched once, not per point.
    match frame {
        Frame::Line(d) => (0..n).for_each(|i| spread.add_line(d, c, get(i))),
        Frame::Plane(nm, a0, a1) => (0..n).for_each(|i| spread.add_plane([nm, a0, a1], c, get(i))),
    }
    Ok(fitted(c, frame, &spread, n))
}

fn line_impl(n: usize, get: &impl Fn(usize) -> [f64; 3]) -> Result<LineFit, FitError> {
    match fit_impl(n, true, get)? {
        Fitted::Line(f) => Ok(f),
        Fitted::Plane(_) => unreachable!("a line's frame is a line"),
    }
}

fn plane_impl(n: usize, get: &impl Fn(usize) -> [f64; 3]) -> Result<PlaneFit, FitError> {
    match fit_impl(n, false, get)? {
        Fitted::Plane(f) => Ok(f),
        Fitted::Line(_) => unreachable!("a plane's frame is a plane"),
    }
}

/// A line or plane fitted over points streamed to it in input order, in
/// the three passes [`fit_line`] and [`fit_plane`] make (the centroid's
/// sums, the covariance about it, then the residuals and extents along the
/// fitted axes): the same arithmetic in the same order, so the same fit
/// bit for bit as of the points gathered in that order, without holding
/// them. Feed every point to [`Self::add_sum`], then [`Self::end_sums`];
/// again to [`Self::add_moment`], then [`Self::end_moments`]; again to
/// [`Self::add_residual`], then [`Self::finish`].
///
/// ```
/// use aniso_alpha::detect::fit::{fit_plane, Fitted, PassFit};
/// let pts = [[0.0, 0.0, 1.0], [2.0, 0.0, 1.1], [0.0, 1.0, 0.9], [2.0, 1.0, 1.0]];
/// let mut f = PassFit::new(false);
/// pts.iter().for_each(|&p| f.add_sum(p));
/// f.end_sums();
/// pts.iter().for_each(|&p| f.add_moment(p));
/// f.end_moments();
/// pts.iter().for_each(|&p| f.add_residual(p));
/// assert_eq!(f.finish(), Ok(Fitted::Plane(fit_plane(&pts).unwrap())));
/// ```
#[derive(Debug, Clone)]
pub struct PassFit {
    line: bool,
    n: usize,
    finite: bool,
    c: [f64; 3],
    m: Mat3,
    frame: Option<Result<Frame, FitError>>,
    spread: Spread,
}

impl PassFit {
    /// A fit of a line (`line`) or a plane, before any point.
    pub fn new(line: bool) -> Self {
        PassFit {
            line,
            n: 0,
            finite: true,
            c: [0.0; 3],
            m: [[0.0; 3]; 3],
            frame: None,
            spread: Spread::new(),
        }
    }

    /// The first pass: one point.
    #[inline]
    pub fn add_sum(&mut self, p: [f64; 3]) {
        self.n += 1;
        self.finite &= p.iter().all(|x| x.is_finite());
        add_sum(&mut self.c, p);
    }

    /// Ends the first pass (the centroid).
    pub fn end_sums(&mut self) {
        self.c = centroid(self.c, self.n);
    }

    /// The second pass: one point.
    #[inline]
    pub fn add_moment(&mut self, p: [f64; 3]) {
        add_moment(&mut self.m, self.c, p);
    }

    /// Ends the second pass (the frame, or why there is none).
    pub fn end_moments(&mut self) {
        let needed = if self.line { 2 } else { 3 };
        self.frame = Some(if self.n < needed {
            Err(FitError::TooFewPoints {
                needed,
                got: self.n,
            })
        } else if !self.finite {
            Err(FitError::NonFinite { index: 0 })
        } else {
            Frame::of(end_moments(self.m, self.n), self.line)
        });
    }

    /// The third pass: one point.
    #[inline]
    pub fn add_residual(&mut self, p: [f64; 3]) {
        if let Some(Ok(frame)) = &self.frame {
            self.spread.add(frame, self.c, p);
        }
    }

    /// The fit, after the three passes.
    ///
    /// # Errors
    /// As [`fit_line`] or [`fit_plane`] (a non-finite point is reported at
    /// index 0); [`FitError::Degenerate`] when a pass was not ended.
    pub fn finish(&self) -> Result<Fitted, FitError> {
        match &self.frame {
            Some(Ok(frame)) => Ok(fitted(self.c, *frame, &self.spread, self.n)),
            Some(Err(e)) => Err(e.clone()),
            None => Err(FitError::Degenerate),
        }
    }
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

    /// A [`PassFit`] fed `pts` in three passes.
    fn passes(pts: &[[f64; 3]], line: bool) -> Result<Fitted, FitError> {
        let mut f = PassFit::new(line);
        pts.iter().for_each(|&p| f.add_sum(p));
        f.end_sums();
        pts.iter().for_each(|&p| f.add_moment(p));
        f.end_moments();
        pts.iter().for_each(|&p| f.add_residual(p));
        f.finish()
    }

    #[test]
    fn a_fit_in_passes_is_the_fit_of_the_gathered_points_bit_for_bit() {
        let mut rng = Rng::new(5);
        for case in 0..500 {
            let n = case % 9;
            let mut pts: Vec<[f64; 3]> = (0..n * 7)
                .map(|_| {
                    [
                        rng.range(-1e3, 1e3),
                        rng.range(-5.0, 5.0),
                        rng.range(0.0, 1e-3),
                    ]
                })
                .collect();
            match case % 5 {
                // All on one line (a degenerate plane), all one point.
                1 => pts.iter_mut().for_each(|p| *p = [p[0], 2.0 * p[0], 1.0]),
                2 => pts.iter_mut().for_each(|p| *p = [3.0, 4.0, 5.0]),
                _ => {}
            }
            let plane = passes(&pts, false);
            match fit_plane(&pts) {
                Ok(f) => assert_eq!(plane, Ok(Fitted::Plane(f)), "case {case}"),
                Err(e) => assert!(plane.is_err(), "case {case}: {e}"),
            }
            let line = passes(&pts, true);
            match fit_line(&pts) {
                Ok(f) => assert_eq!(line, Ok(Fitted::Line(f)), "case {case}"),
                Err(e) => assert!(line.is_err(), "case {case}: {e}"),
            }
        }
        // A non-finite point, and a pass not ended, are errors.
        let bad = [[0.0, 0.0, 0.0], [1.0, 0.0, f64::NAN], [0.0, 1.0, 0.0]];
        assert!(passes(&bad, false).is_err());
        assert_eq!(PassFit::new(false).finish(), Err(FitError::Degenerate));
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
