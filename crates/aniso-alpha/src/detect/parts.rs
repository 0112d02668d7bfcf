//! Splitting detected structures into their straight or flat primitives,
//! and labelling points (docs/method.md §4, "structures").
//!
//! The union of the filtered α-shapes merges two crossing lines, two planes
//! cutting each other, or the facets of a polyhedral surface into one
//! connected component. These helpers split a set of simplices into
//! *parts* by geometry alone (no triangulation needed):
//!
//! * [`planar_parts`]: triangles grow a region across shared edges while
//!   their unit normal stays within `max_angle_deg` of the region's seed
//!   normal (u ≡ −u);
//! * [`linear_parts`]: edges grow a region across shared vertices while
//!   their direction stays within `max_angle_deg` of the seed's.
//!
//! Seeds are taken in decreasing order of their number of like-oriented
//! neighbours (then by input position), so regions start in the middle of
//! flat or straight pieces, not on the bridging simplices where two pieces
//! meet. The seed's normal/direction is kept for the whole region (no drift
//! along a slowly curving surface). Degenerate simplices (zero area or
//! length) are parts of their own. Whether parts are separate structures
//! (crossing lines/planes) or the facets of one polyhedral surface is the
//! caller's decision.
//!
//! ```
//! use aniso_alpha::detect::parts::planar_parts;
//! // Two unit squares folded at 90° along the edge 1-2.
//! let p = [
//!     [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
//!     [2.0, 0.0, 1.0], [2.0, 1.0, 1.0],
//! ];
//! let t = [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]];
//! assert_eq!(planar_parts(&p, &t, 10.0).unwrap(), vec![0, 0, 1, 1]);
//! ```

use crate::aniso::{cross, dot, normalize};
use crate::detect::filter::{FilterError, Incidence, Simplex};
use std::fmt;

/// Bad input to the part splitters or to [`label_points`].
#[derive(Debug, Clone, PartialEq)]
pub enum PartsError {
    /// A simplex refers to a point that does not exist.
    IndexOutOfRange {
        /// Position of the simplex.
        simplex: usize,
        /// The bad vertex index.
        index: u32,
    },
    /// A point of a simplex has a NaN or infinite coordinate.
    NonFinite {
        /// The point's index.
        index: u32,
    },
    /// The angle tolerance is NaN, negative or above 90°.
    BadAngle(f64),
    /// `ids` does not have one entry per simplex.
    LengthMismatch {
        /// Number of simplices.
        expected: usize,
        /// Number of ids.
        got: usize,
    },
    /// A simplex is bad (repeated vertex, too many simplices).
    Simplex(FilterError),
}

impl fmt::Display for PartsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::IndexOutOfRange { simplex, index } => {
                write!(f, "simplex {simplex} refers to missing point {index}")
            }
            Self::NonFinite { index } => write!(f, "point {index} is not finite"),
            Self::BadAngle(a) => write!(f, "angle tolerance {a}° must be in [0°, 90°]"),
            Self::LengthMismatch { expected, got } => {
                write!(f, "{got} ids for {expected} simplices")
            }
            Self::Simplex(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for PartsError {}

impl From<FilterError> for PartsError {
    fn from(e: FilterError) -> Self {
        Self::Simplex(e)
    }
}

fn check_points<S: Simplex + AsRef<[u32]>>(
    points: &[[f64; 3]],
    simplices: &[S],
) -> Result<(), PartsError> {
    for (si, s) in simplices.iter().enumerate() {
        for &v in s.as_ref() {
            let p = points.get(v as usize).ok_or(PartsError::IndexOutOfRange {
                simplex: si,
                index: v,
            })?;
            if !p.iter().all(|x| x.is_finite()) {
                return Err(PartsError::NonFinite { index: v });
            }
        }
    }
    Ok(())
}

/// Simplices from which [`grow`] computes their axes and supports on the
/// pool's threads: 2^14 (a depth frame's table, a scan's ground).
const PARALLEL_SIMPLICES: usize = 1 << 14;

/// `f(i)` for `i` in `0..n`, in order; on the pool's threads from
/// [`PARALLEL_SIMPLICES`].
fn map_large<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    if n < PARALLEL_SIMPLICES {
        (0..n).map(f).collect()
    } else {
        crate::par::map_ranges(n, || (), |_, i| f(i))
    }
}

/// How far the dot product of two unit axes held in f32 may be from that
/// of the f64 axes: each component is rounded by at most 2^-24 of itself,
/// so the products' sum moves by at most 2·2^-24 ≈ 1.2e-7 (plus the f64
/// sum's rounding). 2^-16 leaves a factor of 100.
const AXIS_MARGIN: f64 = 1.0 / 65536.0;

/// Region growing over unique simplices with axis `axis[s]` (None =
/// degenerate), returning a part id per input simplex.
fn grow<S: Simplex>(
    simplices: &[S],
    axes: impl Fn(&S) -> Option<[f64; 3]> + Sync,
    max_angle_deg: f64,
) -> Result<Vec<u32>, PartsError> {
    if !(0.0..=90.0).contains(&max_angle_deg) {
        return Err(PartsError::BadAngle(max_angle_deg));
    }
    let inc = Incidence::new(simplices)?;
    let n = inc.n;
    // Each unique simplex's axis, NaN where it has none (alike to none).
    let exact = |u: usize| axes(&simplices[inc.input_of(u) as usize]).unwrap_or([f64::NAN; 3]);
    // Held in f32, 12 bytes a simplex: a filter in front of the f64 test,
    // which decides alone (the f64 axes recomputed) where the two could
    // differ ([`AXIS_MARGIN`]); NaN stays NaN.
    let axis: Vec<[f32; 3]> = map_large(n, |u| exact(u).map(|x| x as f32));
    let cos_tol = max_angle_deg.to_radians().cos();
    let alike = |a: usize, b: usize| {
        let d = dot(axis[a].map(f64::from), axis[b].map(f64::from)).abs();
        if (d - cos_tol).abs() > AXIS_MARGIN {
            d >= cos_tol
        } else {
            dot(exact(a), exact(b)).abs() >= cos_tol
        }
    };
    // Like-oriented neighbour counts (through faces).
    let support: Vec<u32> = map_large(n, |s| {
        let mut sup = 0u32;
        for &f in inc.faces_of(s) {
            for &t in inc.face(f as usize) {
                if t as usize != s && alike(s, t as usize) {
                    sup += 1;
                }
            }
        }
        sup
    });
    // Best supported first; ties by input position, which is unique.
    let mut order: Vec<u32> = (0..n as u32).collect();
    crate::par::sort_unstable_by(&mut order, |&a, &b| {
        support[b as usize]
            .cmp(&support[a as usize])
            .then(inc.input_of(a as usize).cmp(&inc.input_of(b as usize)))
    });
    let mut part = vec![u32::MAX; n];
    let mut next = 0u32;
    let mut stack = Vec::new();
    for &seed in &order {
        if part[seed as usize] != u32::MAX {
            continue;
        }
        let id = next;
        next += 1;
        part[seed as usize] = id;
        if axis[seed as usize].iter().any(|x| x.is_nan()) {
            continue;
        }
        stack.push(seed);
        while let Some(s) = stack.pop() {
            for &f in inc.faces_of(s as usize) {
                for &t in inc.face(f as usize) {
                    if part[t as usize] == u32::MAX && alike(seed as usize, t as usize) {
                        part[t as usize] = id;
                        stack.push(t);
                    }
                }
            }
        }
    }
    Ok(inc.per_input(|u| part[u as usize]))
}

/// Splits triangles into planar parts (module docs); returns a part id per
/// input triangle (ids in order of creation: the best-supported part is 0).
pub fn planar_parts(
    points: &[[f64; 3]],
    triangles: &[[u32; 3]],
    max_angle_deg: f64,
) -> Result<Vec<u32>, PartsError> {
    check_points(points, triangles)?;
    grow(
        triangles,
        |t| {
            let [a, b, c] = t.map(|v| points[v as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            normalize(cross(u, v))
        },
        max_angle_deg,
    )
}

/// Splits edges into straight parts (module docs); returns a part id per
/// input edge.
///
/// ```
/// use aniso_alpha::detect::parts::linear_parts;
/// // Two lines crossing at point 2.
/// let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0],
///          [2.0, 1.0, 0.0], [2.0, -1.0, 0.0]];
/// let e = [[0, 1], [1, 2], [2, 3], [4, 2], [2, 5]];
/// assert_eq!(linear_parts(&p, &e, 10.0).unwrap(), vec![0, 0, 0, 1, 1]);
/// ```
pub fn linear_parts(
    points: &[[f64; 3]],
    edges: &[[u32; 2]],
    max_angle_deg: f64,
) -> Result<Vec<u32>, PartsError> {
    check_points(points, edges)?;
    grow(
        edges,
        |e| {
            let [a, b] = e.map(|v| points[v as usize]);
            normalize([b[0] - a[0], b[1] - a[1], b[2] - a[2]])
        },
        max_angle_deg,
    )
}

/// Labels points from labelled simplices: each of the `n_points` points
/// gets the id (`ids[s]`) of the largest group (most simplices) among the
/// simplices containing it (smallest id on ties), or −1 if none does. This
/// is docs/method.md §4's "the id of the largest structure that contains it, or
/// background".
///
/// ```
/// use aniso_alpha::detect::parts::label_points;
/// let edges = [[0, 1], [1, 2], [2, 3], [3, 5]];
/// let ids = [7, 7, 7, 2];
/// assert_eq!(label_points(6, &edges, &ids).unwrap(), vec![7, 7, 7, 7, -1, 2]);
/// ```
pub fn label_points<S: Simplex + AsRef<[u32]>>(
    n_points: usize,
    simplices: &[S],
    ids: &[u32],
) -> Result<Vec<i64>, PartsError> {
    if ids.len() != simplices.len() {
        return Err(PartsError::LengthMismatch {
            expected: simplices.len(),
            got: ids.len(),
        });
    }
    let n_ids = ids.iter().map(|&i| i as usize + 1).max().unwrap_or(0);
    let mut size = vec![0usize; n_ids];
    for &i in ids {
        size[i as usize] += 1;
    }
    let mut label = vec![-1i64; n_points];
    let mut best = vec![0usize; n_points];
    for (si, (s, &id)) in simplices.iter().zip(ids).enumerate() {
        for &v in s.as_ref() {
            let (l, b) = match (label.get_mut(v as usize), best.get_mut(v as usize)) {
                (Some(l), Some(b)) => (l, b),
                _ => {
                    return Err(PartsError::IndexOutOfRange {
                        simplex: si,
                        index: v,
                    })
                }
            };
            let sz = size[id as usize];
            if sz > *b || (sz == *b && i64::from(id) < *l) {
                *b = sz;
                *l = i64::from(id);
            }
        }
    }
    Ok(label)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::Rng;

    /// Grid triangles of an nx × ny patch spanned by vectors u, v from o.
    fn patch(
        pts: &mut Vec<[f64; 3]>,
        o: [f64; 3],
        u: [f64; 3],
        v: [f64; 3],
        nx: u32,
        ny: u32,
    ) -> Vec<[u32; 3]> {
        let base = pts.len() as u32;
        for j in 0..=ny {
            for i in 0..=nx {
                let (a, b) = (i as f64, j as f64);
                pts.push([
                    o[0] + a * u[0] + b * v[0],
                    o[1] + a * u[1] + b * v[1],
                    o[2] + a * u[2] + b * v[2],
                ]);
            }
        }
        let id = |i: u32, j: u32| base + i + j * (nx + 1);
        let mut t = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        t
    }

    #[test]
    fn hinges_at_the_tolerance_follow_the_f64_axes() {
        // Two triangles on the edge (0,0,0)-(0,1,0), folded by angles
        // within 1e-6 rad of the 10° tolerance: the f32 axes cannot tell
        // these apart, the f64 test decides each one.
        let tol = 10f64.to_radians();
        let mut both = [false, false];
        for k in -50..=50 {
            let theta = tol + f64::from(k) * 2e-8;
            let p = [
                [0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [-1.0, 0.5, 0.0],
                [theta.cos(), 0.5, theta.sin()],
            ];
            let t = [[0, 1, 2], [0, 1, 3]];
            let normal = |t: [u32; 3]| {
                let [a, b, c] = t.map(|v| p[v as usize]);
                normalize(cross(
                    [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                    [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
                ))
                .unwrap()
            };
            let want = dot(normal(t[0]), normal(t[1])).abs() >= tol.cos();
            let parts = planar_parts(&p, &t, 10.0).unwrap();
            assert_eq!(parts[0] == parts[1], want, "k = {k}");
            both[usize::from(want)] = true;
        }
        assert_eq!(both, [true, true]);
    }

    #[test]
    fn crossing_planes_split_and_fold() {
        // Plane z = 0 and plane x = 2 cutting through it, joined by a
        // bridging triangle.
        let mut p = Vec::new();
        let mut t = patch(&mut p, [0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 4, 4);
        let t2 = patch(
            &mut p,
            [2.0, 0.0, -2.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            4,
            4,
        );
        let n1 = t.len();
        t.extend(t2);
        // A bridge from (1,1,0) to the edge (2,0,−1)-(2,1,−1) of the x = 2
        // plane, normal (1,0,1)/√2: 45° from both planes.
        t.push([6, 30, 31]);
        assert_eq!(n1, 32);
        let parts = planar_parts(&p, &t, 10.0).unwrap();
        assert!(parts[..n1].iter().all(|&x| x == parts[0]));
        assert!(parts[n1..2 * n1].iter().all(|&x| x == parts[n1]));
        assert_ne!(parts[0], parts[n1]);
        assert_eq!(
            parts
                .iter()
                .collect::<std::collections::BTreeSet<_>>()
                .len(),
            3
        );
        // Noisy normals within the tolerance stay together.
        let mut rng = Rng::new(3);
        let noisy: Vec<[f64; 3]> = p
            .iter()
            .map(|q| {
                [
                    q[0] + 0.01 * rng.gaussian(),
                    q[1] + 0.01 * rng.gaussian(),
                    q[2] + 0.01 * rng.gaussian(),
                ]
            })
            .collect();
        let parts = planar_parts(&noisy, &t, 10.0).unwrap();
        assert!(parts[..n1].iter().all(|&x| x == parts[0]));
        assert!(parts[n1..2 * n1].iter().all(|&x| x == parts[n1]));
    }

    #[test]
    fn degenerate_and_errors() {
        let p = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        // Collinear triangle 0-1-2 is its own part.
        let parts = planar_parts(&p, &[[0, 1, 3], [0, 1, 2]], 10.0).unwrap();
        assert_ne!(parts[0], parts[1]);
        assert_eq!(
            planar_parts(&p, &[[0, 1, 9]], 10.0),
            Err(PartsError::IndexOutOfRange {
                simplex: 0,
                index: 9
            })
        );
        assert_eq!(
            planar_parts(&p, &[[0, 1, 3]], -1.0),
            Err(PartsError::BadAngle(-1.0))
        );
        assert!(matches!(
            linear_parts(&p, &[[1, 1]], 5.0),
            Err(PartsError::Simplex(FilterError::RepeatedVertex {
                index: 0
            }))
        ));
        let bad = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]];
        assert_eq!(
            linear_parts(&bad, &[[0, 1]], 5.0),
            Err(PartsError::NonFinite { index: 0 })
        );
        assert!(label_points(2, &[[0, 1]], &[]).is_err());
        assert!(label_points(1, &[[0, 1]], &[0]).is_err());
        // Duplicates get the same part.
        let parts = linear_parts(&p, &[[0, 1], [1, 0], [1, 2]], 5.0).unwrap();
        assert_eq!(parts, vec![0, 0, 0]);
    }

    #[test]
    fn labels_prefer_larger_groups() {
        // Point 2 is in group 0 (3 edges) and group 1 (1 edge).
        let e = [[0, 1], [1, 2], [2, 3], [2, 4]];
        assert_eq!(
            label_points(6, &e, &[0, 0, 0, 1]).unwrap(),
            vec![0, 0, 0, 0, 1, -1]
        );
        // Ties: smaller id.
        assert_eq!(
            label_points(3, &[[0, 1], [1, 2]], &[5, 3]).unwrap(),
            vec![5, 3, 3]
        );
    }
}
