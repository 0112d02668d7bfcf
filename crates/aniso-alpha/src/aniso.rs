//! Anisotropy: the linear map Q = diag(e) · R of the paper (docs/method.md §2, §4).
//!
//! An [`Anisotropy`] is an orientation R (a proper rotation, rows = the axes of
//! the ellipsoidal ball) and an elongation E = (e₁, e₂, e₃) with e_i > 0 and
//! semi-axis factors λ_i = 1/e_i. The anisotropic distance is
//! d_Q(p, q) = |Q(p − q)| with Q = diag(e₁, e₂, e₃) · R (row i of R scaled by
//! e_i), so the open ellipsoidal ball of "radius" α has its axes along the rows
//! of R and semi-axes α·λ_i. Anisotropic α-shapes of P are Euclidean α-shapes
//! of Q·P ([`Anisotropy::transform`]).
//!
//! # Euler angles
//!
//! R(θ, ψ, φ) = R_z(θ) · R_x(ψ) · R_y(φ) with the standard right-handed
//! (counter-clockwise, active) rotation matrices
//!
//! ```text
//!          | cos θ  −sin θ  0 |           | 1    0       0    |           |  cos φ  0  sin φ |
//! R_z(θ) = | sin θ   cos θ  0 |, R_x(ψ) = | 0  cos ψ  −sin ψ  |, R_y(φ) = |   0     1    0   |
//!          |   0       0    1 |           | 0  sin ψ   cos ψ  |           | −sin φ  0  cos φ |
//! ```
//!
//! so that, as printed in the paper, R's third row is
//! (−sin φ cos ψ, sin ψ, cos φ cos ψ) and does not depend on θ.
//!
//! ```
//! use aniso_alpha::aniso::Anisotropy;
//! // A prolate ellipsoid (k = 1) with its long axis along z, λ₃ = 10.
//! let a = Anisotropy::line([0.0, 0.0, 2.0], 10.0).unwrap();
//! let q = a.transform(&[[0.0, 0.0, 10.0], [1.0, 0.0, 0.0]]);
//! assert!((q[0][2] - 1.0).abs() < 1e-12); // 10 along the axis counts as 1
//! let r = (q[1][0].powi(2) + q[1][1].powi(2) + q[1][2].powi(2)).sqrt();
//! assert!((r - 1.0).abs() < 1e-12); // 1 across counts as 1
//! ```

use std::fmt;

// The linear algebra lives in `geometry`; these names stay importable from
// here for the modules that used them (`detect`, `synth`).
pub(crate) use crate::geometry::{cross, dot, norm, normalize};
pub use crate::geometry::{det3, mat_mul, Mat3};
use crate::geometry::{q_matrix, transform_point, transform_points};

/// Tolerance on orthonormality and on det(R) − 1 of a user-given rotation.
pub const ROTATION_TOLERANCE: f64 = 1e-9;

/// Why an [`Anisotropy`] could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum AnisotropyError {
    /// An elongation factor is NaN, infinite, zero or negative.
    BadElongation {
        /// Which factor (0, 1 or 2).
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A λ parameter is NaN, infinite, zero or negative.
    BadLambda {
        /// The parameter's name (`"lambda2"` or `"lambda3"`).
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// An Euler angle is NaN or infinite.
    BadAngle,
    /// The matrix has a NaN/infinite entry or is not orthonormal:
    /// max |R·Rᵀ − I| exceeds [`ROTATION_TOLERANCE`].
    NotOrthonormal {
        /// max |(R·Rᵀ − I)_ij|.
        error: f64,
    },
    /// The matrix is orthonormal but a reflection (det ≈ −1).
    NotProperRotation {
        /// det(R).
        det: f64,
    },
    /// A direction vector is zero, NaN or infinite.
    BadDirection,
    /// The in-plane direction is (nearly) parallel to the normal.
    ParallelDirections,
}

impl fmt::Display for AnisotropyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadElongation { index, value } => write!(
                f,
                "elongation e{} = {value} must be finite and > 0",
                index + 1
            ),
            Self::BadLambda { name, value } => {
                write!(f, "{name} = {value} must be finite and > 0")
            }
            Self::BadAngle => write!(f, "Euler angles must be finite"),
            Self::NotOrthonormal { error } => write!(
                f,
                "rotation is not orthonormal (max |R·Rᵀ − I| = {error:e} > {ROTATION_TOLERANCE:e})"
            ),
            Self::NotProperRotation { det } => {
                write!(f, "rotation has det {det}, expected +1 (a reflection?)")
            }
            Self::BadDirection => write!(f, "direction must be finite and non-zero"),
            Self::ParallelDirections => {
                write!(f, "in-plane direction is parallel to the normal")
            }
        }
    }
}

impl std::error::Error for AnisotropyError {}

/// Orientation + elongation: Q = diag(e) · R. Built only through validating
/// constructors, so R is always a proper rotation and every e_i finite > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anisotropy {
    rotation: Mat3,
    elongation: [f64; 3],
}

/// R(θ, ψ, φ) = R_z(θ) · R_x(ψ) · R_y(φ) (module docs), computed as the
/// product of the three explicit matrices, `(R_z · R_x) · R_y`, each entry
/// as `fma(a₂, b₂, fma(a₁, b₁, a₀·b₀))`. That is what numpy's
/// `rz @ rx @ ry` computes (its BLAS uses fused multiply-adds), so with the
/// same sin/cos (glibc's, which Rust uses on Linux) the result is bit for
/// bit the R of the project's reference fixtures
/// (`grid_6_aniso.transform.txt`, made with numpy). It matters because the
/// triangulation of a transformed grid depends on the last bit. (Only R is
/// built this way; the point transform itself uses no FMA, see
/// [`Anisotropy::transform`].)
///
/// ```
/// use aniso_alpha::aniso::rotation_from_euler;
/// let r = rotation_from_euler(0.0, 0.0, 0.0);
/// assert_eq!(r, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
/// ```
pub fn rotation_from_euler(theta: f64, psi: f64, phi: f64) -> Mat3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    let (sf, cf) = phi.sin_cos();
    let rz = [[ct, -st, 0.0], [st, ct, 0.0], [0.0, 0.0, 1.0]];
    let rx = [[1.0, 0.0, 0.0], [0.0, cp, -sp], [0.0, sp, cp]];
    let ry = [[cf, 0.0, sf], [0.0, 1.0, 0.0], [-sf, 0.0, cf]];
    let fma_mul = |a: &Mat3, b: &Mat3| -> Mat3 {
        let mut c = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] = a[i][2].mul_add(b[2][j], a[i][1].mul_add(b[1][j], a[i][0] * b[0][j]));
            }
        }
        c
    };
    fma_mul(&fma_mul(&rz, &rx), &ry)
}

/// A proper rotation whose third row is the unit vector `u`: rows
/// (a, b, u) with a = normalize(w × u) for the coordinate axis w least aligned
/// with u, and b = u × a (so a × b = u, det = +1).
pub fn completion_third_row(u: [f64; 3]) -> Mat3 {
    let ax = [u[0].abs(), u[1].abs(), u[2].abs()];
    let w = if ax[0] <= ax[1] && ax[0] <= ax[2] {
        [1.0, 0.0, 0.0]
    } else if ax[1] <= ax[2] {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    // w is at least ~35° away from u, so this never fails for a unit u.
    let a = normalize(cross(w, u)).unwrap_or([1.0, 0.0, 0.0]);
    let b = cross(u, a);
    [a, b, u]
}

/// A proper rotation whose first row is the unit vector `n`: rows (n, a, b)
/// with n × a = b.
pub fn completion_first_row(n: [f64; 3]) -> Mat3 {
    let c = completion_third_row(n); // rows (a, b, n), a × b = n
                                     // (n, a, b): n × a = b holds for a right-handed (a, b, n).
    [n, c[0], c[1]]
}

fn check_rotation(r: &Mat3) -> Result<(), AnisotropyError> {
    if !r.iter().flatten().all(|x| x.is_finite()) {
        return Err(AnisotropyError::NotOrthonormal {
            error: f64::INFINITY,
        });
    }
    let mut err = 0.0f64;
    for i in 0..3 {
        for j in 0..3 {
            let target = if i == j { 1.0 } else { 0.0 };
            err = err.max((dot(r[i], r[j]) - target).abs());
        }
    }
    if err > ROTATION_TOLERANCE {
        return Err(AnisotropyError::NotOrthonormal { error: err });
    }
    let det = det3(r);
    if (det - 1.0).abs() > ROTATION_TOLERANCE {
        return Err(AnisotropyError::NotProperRotation { det });
    }
    Ok(())
}

fn check_elongation(e: &[f64; 3]) -> Result<(), AnisotropyError> {
    for (index, &value) in e.iter().enumerate() {
        if !(value.is_finite() && value > 0.0) {
            return Err(AnisotropyError::BadElongation { index, value });
        }
    }
    Ok(())
}

fn check_lambda(name: &'static str, value: f64) -> Result<(), AnisotropyError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(AnisotropyError::BadLambda { name, value })
    }
}

impl Anisotropy {
    /// Explicit rotation rows and elongation. R must be orthonormal with
    /// det +1 within [`ROTATION_TOLERANCE`]; it is stored as given (not
    /// re-orthogonalised), so the fixture transforms reproduce bit for bit.
    ///
    /// ```
    /// use aniso_alpha::aniso::{Anisotropy, AnisotropyError};
    /// let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// assert!(Anisotropy::from_matrix_rows(id, [1.0, 0.25, 0.125]).is_ok());
    /// let mirror = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]];
    /// assert!(matches!(
    ///     Anisotropy::from_matrix_rows(mirror, [1.0; 3]),
    ///     Err(AnisotropyError::NotProperRotation { .. })
    /// ));
    /// ```
    pub fn from_matrix_rows(rotation: Mat3, elongation: [f64; 3]) -> Result<Self, AnisotropyError> {
        check_elongation(&elongation)?;
        check_rotation(&rotation)?;
        Ok(Self {
            rotation,
            elongation,
        })
    }

    /// R = R(θ, ψ, φ) ([`rotation_from_euler`]) with elongation `e`.
    ///
    /// ```
    /// use aniso_alpha::aniso::Anisotropy;
    /// let a = Anisotropy::from_euler(0.3, -0.2, 0.5, [1.0, 0.25, 0.125]).unwrap();
    /// assert!((a.rotation()[2][1] - (-0.2f64).sin()).abs() < 1e-15);
    /// ```
    pub fn from_euler(
        theta: f64,
        psi: f64,
        phi: f64,
        elongation: [f64; 3],
    ) -> Result<Self, AnisotropyError> {
        if !(theta.is_finite() && psi.is_finite() && phi.is_finite()) {
            return Err(AnisotropyError::BadAngle);
        }
        Self::from_matrix_rows(rotation_from_euler(theta, psi, phi), elongation)
    }

    /// The identity: Q = I, ellipsoidal balls are balls.
    pub fn euclidean() -> Self {
        Self {
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            elongation: [1.0; 3],
        }
    }

    /// Linear structures (k = 1): E = (1, 1, 1/λ₃), R's third row the unit
    /// `direction` (the long axis, semi-axis α·λ₃), the first two rows an
    /// orthonormal completion ([`completion_third_row`]) with det R = +1.
    pub fn line(direction: [f64; 3], lambda3: f64) -> Result<Self, AnisotropyError> {
        check_lambda("lambda3", lambda3)?;
        let u = normalize(direction).ok_or(AnisotropyError::BadDirection)?;
        Self::from_matrix_rows(completion_third_row(u), [1.0, 1.0, 1.0 / lambda3])
    }

    /// Planar structures (k = 2): E = (1, 1/λ₂, 1/λ₃); R's first row the unit
    /// `normal` (short axis, semi-axis α), the second row `in_plane_dir`
    /// orthogonalised against the normal (semi-axis α·λ₂), the third their
    /// cross product (semi-axis α·λ₃).
    ///
    /// ```
    /// use aniso_alpha::aniso::Anisotropy;
    /// let a = Anisotropy::plane([0.0, 0.0, 1.0], [1.0, 0.0, 0.3], 4.0, 8.0).unwrap();
    /// let r = a.rotation();
    /// assert_eq!(r[0], [0.0, 0.0, 1.0]);
    /// assert_eq!(r[1], [1.0, 0.0, 0.0]);
    /// assert_eq!(r[2], [0.0, 1.0, 0.0]);
    /// assert_eq!(a.elongation(), [1.0, 0.25, 0.125]);
    /// ```
    pub fn plane(
        normal: [f64; 3],
        in_plane_dir: [f64; 3],
        lambda2: f64,
        lambda3: f64,
    ) -> Result<Self, AnisotropyError> {
        check_lambda("lambda2", lambda2)?;
        check_lambda("lambda3", lambda3)?;
        let n = normalize(normal).ok_or(AnisotropyError::BadDirection)?;
        let d = normalize(in_plane_dir).ok_or(AnisotropyError::BadDirection)?;
        let c = dot(d, n);
        if c.abs() > 1.0 - 1e-12 {
            return Err(AnisotropyError::ParallelDirections);
        }
        let t = [d[0] - c * n[0], d[1] - c * n[1], d[2] - c * n[2]];
        let t = normalize(t).ok_or(AnisotropyError::ParallelDirections)?;
        let b = cross(n, t);
        Self::from_matrix_rows([n, t, b], [1.0, 1.0 / lambda2, 1.0 / lambda3])
    }

    /// A copy with another rotation (validated as in [`Self::from_matrix_rows`]).
    pub fn with_rotation(&self, rotation: Mat3) -> Result<Self, AnisotropyError> {
        Self::from_matrix_rows(rotation, self.elongation)
    }

    /// R (rows = ellipsoid axes).
    pub fn rotation(&self) -> Mat3 {
        self.rotation
    }

    /// E = (e₁, e₂, e₃).
    pub fn elongation(&self) -> [f64; 3] {
        self.elongation
    }

    /// λ_i = 1/e_i: the ellipsoid's semi-axes for α = 1.
    pub fn lambdas(&self) -> [f64; 3] {
        [
            1.0 / self.elongation[0],
            1.0 / self.elongation[1],
            1.0 / self.elongation[2],
        ]
    }

    /// Q = diag(e) · R: Q_ij = e_i · R_ij (one rounding per entry, see
    /// [`q_matrix`]).
    pub fn q(&self) -> Mat3 {
        q_matrix(&self.rotation, &self.elongation)
    }

    /// Q·p for one point: q_i = (Q_i1·x + Q_i2·y) + Q_i3·z, each operation
    /// rounded to f64 in exactly that order, no fused multiply-add (this is
    /// the convention of the CGAL fixtures, reproduced bit for bit).
    pub fn transform_point(&self, p: [f64; 3]) -> [f64; 3] {
        transform_point(&self.q(), p)
    }

    /// Q·p for every point (see [`Self::transform_point`]).
    pub fn transform(&self, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
        transform_points(&self.q(), points)
    }

    /// d_Q(p, q) = |Q(p − q)|.
    pub fn distance(&self, p: [f64; 3], q: [f64; 3]) -> f64 {
        norm(self.transform_point([p[0] - q[0], p[1] - q[1], p[2] - q[2]]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn is_proper(r: &Mat3) -> bool {
        check_rotation(r).is_ok()
    }

    #[test]
    fn euler_matches_product_of_axis_rotations() {
        let (t, p, f): (f64, f64, f64) = (0.3, -0.2, 0.5);
        let rz = [
            [t.cos(), -t.sin(), 0.0],
            [t.sin(), t.cos(), 0.0],
            [0.0, 0.0, 1.0],
        ];
        let rx = [
            [1.0, 0.0, 0.0],
            [0.0, p.cos(), -p.sin()],
            [0.0, p.sin(), p.cos()],
        ];
        let ry = [
            [f.cos(), 0.0, f.sin()],
            [0.0, 1.0, 0.0],
            [-f.sin(), 0.0, f.cos()],
        ];
        let prod = mat_mul(&mat_mul(&rz, &rx), &ry);
        let r = rotation_from_euler(t, p, f);
        for i in 0..3 {
            for j in 0..3 {
                assert!((prod[i][j] - r[i][j]).abs() < 1e-15, "{i}{j}");
            }
        }
        assert!(is_proper(&r));
        // Against the fixture's R (grid_6_aniso.transform.txt).
        let fixture = [
            [
                0.8665341013181509,
                -0.28962947762551555,
                0.40648913508618606,
            ],
            [0.16835030129256742, 0.9362933635841992, 0.308241647677416],
            [
                -0.4698689469495153,
                -0.19866933079506122,
                0.8600893382050473,
            ],
        ];
        for i in 0..3 {
            for j in 0..3 {
                assert!((fixture[i][j] - r[i][j]).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn line_and_plane_frames() {
        for dir in [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.0, -3.0, 0.0],
            [1.0, 2.0, -3.0],
            [1e-300, 1e-300, 0.0],
            [1e300, -1e300, 1e300],
        ] {
            let a = Anisotropy::line(dir, 10.0).unwrap();
            let r = a.rotation();
            assert!(is_proper(&r));
            let u = normalize(dir).unwrap();
            assert_eq!(r[2], u);
            assert_eq!(a.elongation(), [1.0, 1.0, 0.1]);
        }
        let a = Anisotropy::plane([1.0, 1.0, 0.0], [0.0, 1.0, 1.0], 4.0, 8.0).unwrap();
        let r = a.rotation();
        assert!(is_proper(&r));
        let s = 0.5f64.sqrt();
        assert!((r[0][0] - s).abs() < 1e-15 && (r[0][1] - s).abs() < 1e-15);
        assert!(dot(r[1], [0.0, 1.0, 1.0]) > 0.0);
        assert!(dot(r[0], r[1]).abs() < 1e-15);
        assert_eq!(a.lambdas(), [1.0, 4.0, 8.0]);
    }

    #[test]
    fn errors() {
        let id = Anisotropy::euclidean().rotation();
        for (i, bad) in [0.0, -1.0, f64::NAN, f64::INFINITY].into_iter().enumerate() {
            let mut e = [1.0; 3];
            e[i % 3] = bad;
            assert!(matches!(
                Anisotropy::from_matrix_rows(id, e),
                Err(AnisotropyError::BadElongation { .. })
            ));
        }
        let mut r = id;
        r[0][0] = 1.0 + 1e-8;
        assert!(matches!(
            Anisotropy::from_matrix_rows(r, [1.0; 3]),
            Err(AnisotropyError::NotOrthonormal { .. })
        ));
        r[0][0] = 1.0 + 1e-11;
        assert!(Anisotropy::from_matrix_rows(r, [1.0; 3]).is_ok());
        r[0][0] = f64::NAN;
        assert!(Anisotropy::from_matrix_rows(r, [1.0; 3]).is_err());
        let swap = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(matches!(
            Anisotropy::from_matrix_rows(swap, [1.0; 3]),
            Err(AnisotropyError::NotProperRotation { .. })
        ));
        assert_eq!(
            Anisotropy::line([0.0; 3], 2.0),
            Err(AnisotropyError::BadDirection)
        );
        assert!(matches!(
            Anisotropy::line([0.0, 0.0, 1.0], 0.0),
            Err(AnisotropyError::BadLambda { .. })
        ));
        assert_eq!(
            Anisotropy::plane([0.0, 0.0, 1.0], [0.0, 0.0, -2.0], 4.0, 8.0),
            Err(AnisotropyError::ParallelDirections)
        );
        assert_eq!(
            Anisotropy::from_euler(f64::NAN, 0.0, 0.0, [1.0; 3]),
            Err(AnisotropyError::BadAngle)
        );
        assert!(!AnisotropyError::BadAngle.to_string().is_empty());
    }

    #[test]
    fn distance_is_ellipsoidal() {
        let a = Anisotropy::plane([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 4.0, 8.0).unwrap();
        let o = [1.0, 2.0, 3.0];
        assert!((a.distance(o, [1.0, 2.0, 4.0]) - 1.0).abs() < 1e-15);
        assert!((a.distance(o, [5.0, 2.0, 3.0]) - 1.0).abs() < 1e-15);
        assert!((a.distance(o, [1.0, 10.0, 3.0]) - 1.0).abs() < 1e-15);
        let e = Anisotropy::euclidean();
        assert_eq!(e.transform(&[o]), vec![o]);
    }
}
