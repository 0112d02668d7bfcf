//! Orientation sets A (docs/method.md §4): the paper's "box" sampler and a
//! near-uniform Fibonacci sampler.
//!
//! Every orientation is a proper rotation R (rows = ellipsoid axes). For
//! k = 1 the long axis is R's **third** row; for k = 2 the short axis (the
//! plane's normal) is R's **first** row (see [`crate::aniso`]).
//!
//! # Box sampler (the paper's, the reference)
//!
//! Grid the surface of the box [−1, 1] × [−1, 1] × [0, 1] minus its bottom
//! face: x, y ∈ linspace(−1, 1, ⌈2/m1⌉ + 1), z ∈ linspace(0, 1, ⌈1/m1⌉ + 1),
//! each face edge to edge. Each sample M gives u = M/|M|, ψ = asin(u_y),
//! φ = atan2(−u_x, u_z), so R(0, ψ, φ)'s third row is u. Repeated
//! directions (box edges, u vs −u on the z = 0 rim) are dropped. For k = 1
//! A = {R(0, ψ, φ)}; for k = 2 A = {R(θ_j, ψ, φ)}, θ_j = −π/2 + j·π/m2,
//! j = 1..m2.
//!
//! Measured worst angular gaps (max over 20,000 random axes of the angle to
//! the nearest sampled axis, u ≡ −u; tests `box_gap`, `fibonacci_gap`):
//!
//! | sampler | axes | long-axis gap (k = 1) | normal gap (k = 2) |
//! |---|---:|---:|---:|
//! | box m1 = 0.3 (m2 = 12 for k = 2) | 162 (1,944) | 11.2° | 7.2° |
//! | Fibonacci 5° | 826 | 4.0° | 4.0° |
//! | Fibonacci 10° | 207 | 7.6° | 7.6° |
//! | Fibonacci 15° | 92 | 12.2° | 12.2° |
//!
//! (The k = 2 box normals are the first rows of R(θ_j, ψ, φ): 1,944 normals
//! spread over the half sphere, hence the smaller gap.)
//!
//! Compared on the synthetic scenes of [`crate::synth`] with the
//! brute-force pipelines of `tests/*_pipeline_bruteforce.rs` (mean per-point
//! F1; lines: seeds 1–3, planes: planes + polyhedron scenes, seeds 1–2):
//!
//! | sampler | orientations k = 1 / k = 2 | lines 0.01 | lines 0.02 | planes 0.01 | planes 0.1 |
//! |---|---:|---:|---:|---:|---:|
//! | box m1 = 0.3, m2 = 12 | 162 / 1,944 | 0.896 (15/15 lines) | 0.608 | 0.967 | 0.794 |
//! | Fibonacci 10° | 207 / 3,726 | 0.895 (14/15) | 0.611 | 0.968 | 0.790 |
//! | Fibonacci 14° / 15° | 106 / 1,104 | 0.917 (15/15) | 0.730 | 0.968 | 0.802 |
//!
//! (Column headers: background points per α-ellipsoid.) Fewer orientations
//! let fewer background chains into the union, so a coarser near-uniform
//! set is as good or better on these scenes at about half the cost; a finer
//! one buys nothing here.
//!
//! # Fibonacci sampler
//!
//! n = ⌈2π / step²⌉ (step in radians: each axis owns about step² of the
//! half sphere's 2π steradians) axes on the upper half sphere,
//! z_i = 1 − (i + ½)/n, azimuth i·(golden angle): equal-area spacing. For
//! k = 1 each axis is the long axis (third row, completed by
//! [`crate::aniso::completion_third_row`]). For k = 2 each axis is a normal
//! (first row); unless λ₂ = λ₃ the in-plane axes are also turned about the
//! normal by θ = t·π/m_θ, t = 0..m_θ − 1, m_θ = ⌈180°/step⌉ (the ellipsoid is
//! symmetric under a half turn). When λ₂ = λ₃ the ellipsoid is symmetric
//! about its short axis and one rotation per normal suffices.
//!
//! ```
//! use aniso_alpha::detect::orientations::{box_directions, orientations, Sampler};
//! use aniso_alpha::detect::StructureKind;
//! assert_eq!(box_directions(0.3).unwrap().len(), 162);
//! let a = orientations(StructureKind::Planes, &Sampler::Box { m1: 0.3, m2: 12 }, false).unwrap();
//! assert_eq!(a.len(), 1944);
//! ```

use crate::aniso::{completion_first_row, completion_third_row, rotation_from_euler, Mat3};
use crate::detect::StructureKind;
use std::f64::consts::PI;
use std::fmt;

/// Smallest accepted box spacing m1 (keeps the sample count below ~10⁵).
pub const MIN_M1: f64 = 0.01;
/// Largest accepted orientation set (72 MB of rotations; a detection runs
/// one triangulation per orientation). Checked before anything is
/// allocated: `--m2 100000000` once asked for 1.17 TB.
pub const MAX_ORIENTATIONS: usize = 1_000_000;
/// Smallest accepted Fibonacci step in degrees.
pub const MIN_STEP_DEGREES: f64 = 0.5;
/// Two unit vectors closer than this (max coordinate difference) are one
/// direction.
pub const SAME_DIRECTION_TOLERANCE: f64 = 1e-12;

/// How to sample the orientation set A.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sampler {
    /// The paper's box sampler: grid spacing `m1` on the box faces, `m2`
    /// in-plane angles for k = 2 (m1 = 0.3, m2 = 12 in the paper).
    Box {
        /// Grid spacing on the faces of [−1, 1]² × [0, 1].
        m1: f64,
        /// Number of angles θ_j for k = 2 (ignored for k = 1).
        m2: u32,
    },
    /// Near-uniform axes on the half sphere with the given angular step.
    Fibonacci {
        /// Angular step in degrees.
        step_degrees: f64,
    },
}

impl Default for Sampler {
    /// The paper's setting: `Box { m1: 0.3, m2: 12 }`.
    fn default() -> Self {
        Sampler::Box { m1: 0.3, m2: 12 }
    }
}

/// A bad sampler parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum OrientationError {
    /// m1 is NaN, infinite or below [`MIN_M1`].
    BadM1(f64),
    /// m2 is zero (k = 2 needs at least one θ).
    BadM2(u32),
    /// The step is NaN, infinite, below [`MIN_STEP_DEGREES`] or above 180°.
    BadStep(f64),
    /// The set would hold more than [`MAX_ORIENTATIONS`] orientations.
    TooMany {
        /// Axes sampled.
        axes: usize,
        /// Rotations about each axis (m2, or the Fibonacci m_θ).
        per_axis: usize,
    },
}

impl fmt::Display for OrientationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadM1(m) => write!(f, "m1 = {m} must be finite and ≥ {MIN_M1}"),
            Self::BadM2(m) => write!(f, "m2 = {m} must be ≥ 1"),
            Self::BadStep(s) => write!(
                f,
                "angular step = {s}° must be finite, ≥ {MIN_STEP_DEGREES}° and ≤ 180°"
            ),
            Self::TooMany { axes, per_axis } => write!(
                f,
                "{axes} axes × {per_axis} rotations = {} orientations, more than the limit of \
                 {MAX_ORIENTATIONS}",
                (*axes as u128) * (*per_axis as u128)
            ),
        }
    }
}

impl std::error::Error for OrientationError {}

/// `n ≥ 2` evenly spaced values from `a` to `b`: (a·(n−1−i) + b·i)/(n−1).
/// Both ends are exact, and linspace(−1, 1, n) is exactly symmetric
/// (value n−1−i = −value i), so antipodal rim samples normalise to exactly
/// opposite unit vectors.
fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    let d = (n - 1) as f64;
    (0..n)
        .map(|i| (a * (n - 1 - i) as f64 + b * i as f64) / d)
        .collect()
}

/// The Euler angles (ψ, φ) with R(0, ψ, φ)'s third row = the unit vector
/// `u`: ψ = asin(u_y), φ = atan2(−u_x, u_z).
pub fn euler_of_direction(u: [f64; 3]) -> (f64, f64) {
    (u[1].clamp(-1.0, 1.0).asin(), (-u[0]).atan2(u[2]))
}

/// The box sampler's directions (module docs), repeats dropped, sorted
/// lexicographically. Rim directions (z = 0) are canonicalised to x > 0, or
/// x = 0 and y > 0.
///
/// ```
/// use aniso_alpha::detect::orientations::box_directions;
/// let d = box_directions(1.0).unwrap(); // x, y ∈ {−1, 0, 1}, z ∈ {0, 1}
/// assert_eq!(d.len(), 9 + 4); // top 3×3, rim 8 samples → 4 axes
/// ```
pub fn box_directions(m1: f64) -> Result<Vec<[f64; 3]>, OrientationError> {
    if !(m1.is_finite() && m1 >= MIN_M1) {
        return Err(OrientationError::BadM1(m1));
    }
    let nxy = (2.0 / m1).ceil() as usize + 1;
    let nz = (1.0 / m1).ceil() as usize + 1;
    let xy = linspace(-1.0, 1.0, nxy);
    let z = linspace(0.0, 1.0, nz);
    let mut samples: Vec<[f64; 3]> = Vec::with_capacity(nxy * nxy + 4 * nxy * nz);
    for &x in &xy {
        for &y in &xy {
            samples.push([x, y, 1.0]);
        }
    }
    for &s in &[-1.0, 1.0] {
        for &t in &xy {
            for &zz in &z {
                samples.push([s, t, zz]);
                samples.push([t, s, zz]);
            }
        }
    }
    let mut dirs: Vec<[f64; 3]> = samples
        .into_iter()
        .map(|m| {
            let n = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
            let mut u = [m[0] / n, m[1] / n, m[2] / n];
            if m[2] == 0.0 && (u[0] < 0.0 || (u[0] == 0.0 && u[1] < 0.0)) {
                u = [-u[0], -u[1], 0.0];
            }
            u
        })
        .collect();
    sort_dedup(&mut dirs);
    Ok(dirs)
}

fn sort_dedup(dirs: &mut Vec<[f64; 3]>) {
    dirs.sort_by(|a, b| {
        a[0].total_cmp(&b[0])
            .then(a[1].total_cmp(&b[1]))
            .then(a[2].total_cmp(&b[2]))
    });
    // Near-equal vectors need not be adjacent after a lexicographic sort,
    // so compare each one with every kept vector whose x is within the
    // tolerance (a window at the end of the sorted kept list).
    let tol = SAME_DIRECTION_TOLERANCE;
    let mut kept: Vec<[f64; 3]> = Vec::with_capacity(dirs.len());
    for &u in dirs.iter() {
        let dup = kept
            .iter()
            .rev()
            .take_while(|k| k[0] >= u[0] - tol)
            .any(|k| (0..3).all(|c| (k[c] - u[c]).abs() <= tol));
        if !dup {
            kept.push(u);
        }
    }
    *dirs = kept;
}

/// n = ⌈2π/step²⌉ near-uniform unit axes on the upper half sphere (z > 0),
/// see the module docs.
///
/// ```
/// use aniso_alpha::detect::orientations::fibonacci_directions;
/// let d = fibonacci_directions(10.0).unwrap();
/// assert_eq!(d.len(), 207);
/// assert!(d.iter().all(|u| u[2] > 0.0));
/// ```
pub fn fibonacci_directions(step_degrees: f64) -> Result<Vec<[f64; 3]>, OrientationError> {
    if !(step_degrees.is_finite() && (MIN_STEP_DEGREES..=180.0).contains(&step_degrees)) {
        return Err(OrientationError::BadStep(step_degrees));
    }
    let step = step_degrees.to_radians();
    let n = ((2.0 * PI) / (step * step)).ceil().max(1.0) as usize;
    let golden = PI * (3.0 - 5f64.sqrt());
    Ok((0..n)
        .map(|i| {
            let z = 1.0 - (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let a = golden * i as f64;
            [r * a.cos(), r * a.sin(), z]
        })
        .collect())
}

/// The orientation set A for structures of `kind` (module docs).
///
/// `lambda2_eq_lambda3` only matters for the Fibonacci sampler with k = 2:
/// then one rotation per normal is enough. The box sampler is the paper's
/// reference and always yields the full R(θ_j, ψ, φ) set.
pub fn orientations(
    kind: StructureKind,
    sampler: &Sampler,
    lambda2_eq_lambda3: bool,
) -> Result<Vec<Mat3>, OrientationError> {
    match *sampler {
        Sampler::Box { m1, m2 } => {
            let dirs = box_directions(m1)?;
            let angles: Vec<(f64, f64)> = dirs.iter().map(|&u| euler_of_direction(u)).collect();
            match kind {
                StructureKind::Lines => Ok(angles
                    .iter()
                    .map(|&(psi, phi)| rotation_from_euler(0.0, psi, phi))
                    .collect()),
                StructureKind::Planes => {
                    if m2 == 0 {
                        return Err(OrientationError::BadM2(m2));
                    }
                    too_many(angles.len(), m2 as usize)?;
                    let mut out = Vec::with_capacity(angles.len() * m2 as usize);
                    for &(psi, phi) in &angles {
                        for j in 1..=m2 {
                            let theta = -PI / 2.0 + j as f64 * PI / m2 as f64;
                            out.push(rotation_from_euler(theta, psi, phi));
                        }
                    }
                    Ok(out)
                }
            }
        }
        Sampler::Fibonacci { step_degrees } => {
            let dirs = fibonacci_directions(step_degrees)?;
            match kind {
                StructureKind::Lines => Ok(dirs.iter().map(|&u| completion_third_row(u)).collect()),
                StructureKind::Planes => {
                    let m_theta = if lambda2_eq_lambda3 {
                        1
                    } else {
                        (180.0 / step_degrees).ceil().max(1.0) as usize
                    };
                    too_many(dirs.len(), m_theta)?;
                    let mut out = Vec::with_capacity(dirs.len() * m_theta);
                    for &n in &dirs {
                        let [n, a, b] = completion_first_row(n); // n × a = b
                        for t in 0..m_theta {
                            let (s, c) = (t as f64 * PI / m_theta as f64).sin_cos();
                            let r2 = [
                                c * a[0] + s * b[0],
                                c * a[1] + s * b[1],
                                c * a[2] + s * b[2],
                            ];
                            let r3 = [
                                c * b[0] - s * a[0],
                                c * b[1] - s * a[1],
                                c * b[2] - s * a[2],
                            ];
                            out.push([n, r2, r3]);
                        }
                    }
                    Ok(out)
                }
            }
        }
    }
}

/// [`OrientationError::TooMany`] when `axes × per_axis` exceeds
/// [`MAX_ORIENTATIONS`].
fn too_many(axes: usize, per_axis: usize) -> Result<(), OrientationError> {
    if axes
        .checked_mul(per_axis)
        .is_none_or(|n| n > MAX_ORIENTATIONS)
    {
        Err(OrientationError::TooMany { axes, per_axis })
    } else {
        Ok(())
    }
}

/// Axial angular gap: the largest, over `probes`, of the angle (radians)
/// between a probe axis and its nearest axis in `axes` (u and −u are the
/// same axis). Brute force, O(|probes|·|axes|). Returns π/2 if `axes` is
/// empty.
pub fn max_axial_gap(axes: &[[f64; 3]], probes: &[[f64; 3]]) -> f64 {
    let mut worst = 0.0f64;
    for p in probes {
        let best = axes
            .iter()
            .map(|a| (a[0] * p[0] + a[1] * p[1] + a[2] * p[2]).abs())
            .fold(0.0f64, f64::max);
        worst = worst.max(best.min(1.0).acos());
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aniso::det3;
    use crate::synth::Rng;

    fn assert_proper(r: &Mat3) {
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                let t = if i == j { 1.0 } else { 0.0 };
                assert!((d - t).abs() < 1e-12, "{r:?}");
            }
        }
        assert!((det3(r) - 1.0).abs() < 1e-12, "{r:?}");
    }

    fn probes(n: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut rng = Rng::new(seed);
        (0..n).map(|_| rng.unit_vector()).collect()
    }

    #[test]
    fn box_counts() {
        let d = box_directions(0.3).unwrap();
        assert_eq!(d.len(), 162);
        for u in &d {
            assert!((u[0] * u[0] + u[1] * u[1] + u[2] * u[2] - 1.0).abs() < 1e-15);
            assert!(u[2] >= 0.0);
        }
        // No two axes are the same (u ≡ −u).
        for i in 0..d.len() {
            for j in 0..i {
                let c = (d[i][0] * d[j][0] + d[i][1] * d[j][1] + d[i][2] * d[j][2]).abs();
                assert!(c < 1.0 - 1e-9, "{:?} {:?}", d[i], d[j]);
            }
        }
        // Counts for other spacings: top n², sides 4(n − 1)(nz − 1), rim
        // 4(n − 1) samples → 2(n − 1) axes.
        for m1 in [1.0, 0.5, 0.25, 0.2, 0.1] {
            let n = (2.0f64 / m1).ceil() as usize + 1;
            let nz = (1.0f64 / m1).ceil() as usize + 1;
            let want = n * n + 4 * (n - 1) * (nz - 2) + 2 * (n - 1);
            assert_eq!(box_directions(m1).unwrap().len(), want, "m1 = {m1}");
        }
        assert!(box_directions(0.0).is_err());
        assert!(box_directions(f64::NAN).is_err());
    }

    #[test]
    fn box_rotations() {
        let s = Sampler::Box { m1: 0.3, m2: 12 };
        let dirs = box_directions(0.3).unwrap();
        let a1 = orientations(StructureKind::Lines, &s, false).unwrap();
        assert_eq!(a1.len(), 162);
        for (r, u) in a1.iter().zip(&dirs) {
            assert_proper(r);
            for c in 0..3 {
                assert!((r[2][c] - u[c]).abs() < 1e-15, "{r:?} {u:?}");
            }
        }
        let a2 = orientations(StructureKind::Planes, &s, true).unwrap();
        assert_eq!(a2.len(), 1944);
        for (i, r) in a2.iter().enumerate() {
            assert_proper(r);
            let u = dirs[i / 12];
            for c in 0..3 {
                assert!((r[2][c] - u[c]).abs() < 1e-15);
            }
        }
        // θ_12 = π/2 and θ_0 = −π/2 would be the same axes: j starts at 1.
        let r = &a2[11];
        let q = rotation_from_euler(
            PI / 2.0,
            euler_of_direction(dirs[0]).0,
            euler_of_direction(dirs[0]).1,
        );
        assert_eq!(r, &q);
        assert!(matches!(
            orientations(
                StructureKind::Planes,
                &Sampler::Box { m1: 0.3, m2: 0 },
                false
            ),
            Err(OrientationError::BadM2(0))
        ));
    }

    #[test]
    fn fibonacci_rotations() {
        let s = Sampler::Fibonacci { step_degrees: 10.0 };
        let dirs = fibonacci_directions(10.0).unwrap();
        let a1 = orientations(StructureKind::Lines, &s, false).unwrap();
        assert_eq!(a1.len(), dirs.len());
        for (r, u) in a1.iter().zip(&dirs) {
            assert_proper(r);
            assert_eq!(&r[2], u);
        }
        let a2 = orientations(StructureKind::Planes, &s, true).unwrap();
        assert_eq!(a2.len(), dirs.len());
        let a3 = orientations(StructureKind::Planes, &s, false).unwrap();
        assert_eq!(a3.len(), dirs.len() * 18);
        for (i, r) in a3.iter().enumerate() {
            assert_proper(r);
            assert_eq!(r[0], dirs[i / 18]);
        }
        // The in-plane axes of one normal are spread over half a turn.
        let t1 =
            (a3[0][1][0] * a3[1][1][0] + a3[0][1][1] * a3[1][1][1] + a3[0][1][2] * a3[1][1][2])
                .acos();
        assert!((t1 - 10f64.to_radians()).abs() < 1e-9);
        for bad in [0.0, -1.0, f64::NAN, 181.0] {
            assert!(fibonacci_directions(bad).is_err());
        }
    }

    #[test]
    fn box_gap() {
        let p = probes(20_000, 0x5eed_0001);
        let dirs = box_directions(0.3).unwrap();
        let g1 = max_axial_gap(&dirs, &p).to_degrees();
        let a2 = orientations(StructureKind::Planes, &Sampler::default(), false).unwrap();
        let normals: Vec<[f64; 3]> = a2.iter().map(|r| r[0]).collect();
        let g2 = max_axial_gap(&normals, &p).to_degrees();
        eprintln!("box m1=0.3: long-axis gap {g1:.2}°, k=2 normal gap {g2:.2}°");
        assert!(g1 > 10.0 && g1 < 12.0, "{g1}");
        assert!(g2 < 8.0, "{g2}");
    }

    #[test]
    fn fibonacci_gap() {
        let p = probes(20_000, 0x5eed_0002);
        for (step, lo, hi) in [(10.0, 6.5, 8.5), (15.0, 9.0, 13.0), (5.0, 3.0, 4.5)] {
            let dirs = fibonacci_directions(step).unwrap();
            let g = max_axial_gap(&dirs, &p).to_degrees();
            eprintln!("fibonacci {step}°: {} axes, gap {g:.2}°", dirs.len());
            assert!(g > lo && g < hi, "step {step}: gap {g}");
        }
    }

    #[test]
    fn huge_sets_are_refused_before_allocation() {
        let e = orientations(
            StructureKind::Planes,
            &Sampler::Box {
                m1: 0.3,
                m2: 100_000_000,
            },
            false,
        )
        .unwrap_err();
        assert_eq!(
            e,
            OrientationError::TooMany {
                axes: 162,
                per_axis: 100_000_000
            }
        );
        assert!(e.to_string().contains("16200000000 orientations"), "{e}");
        let ok = orientations(
            StructureKind::Planes,
            &Sampler::Box { m1: 0.3, m2: 6000 },
            false,
        );
        assert_eq!(ok.unwrap().len(), 162 * 6000);
        assert!(orientations(
            StructureKind::Planes,
            &Sampler::Fibonacci {
                step_degrees: MIN_STEP_DEGREES
            },
            false
        )
        .is_err());
    }
}
