//! The moments of a set of points (count, centroid, scatter matrix), which
//! join in O(1): the fits of groups of parts or candidates while they are
//! merged (stage 5's groups of parts, stage 3's groups of candidates).

// Small fixed-size matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use super::super::detection::Primitive;
use super::super::fit::{symmetric_eigen, LineFit, PlaneFit};
use crate::geometry::{cross, dot, sub};

/// The moments of a set of points: their number, centroid and scatter
/// matrix Σ (p − c)(p − c)ᵀ.
#[derive(Debug, Clone, Copy)]
pub(super) struct Moments {
    /// The number of points.
    pub(super) n: f64,
    /// Their centroid.
    pub(super) centroid: [f64; 3],
    /// Σ (p − c)(p − c)ᵀ.
    scatter: [[f64; 3]; 3],
}

impl Moments {
    /// The moments of `members`.
    pub(super) fn of(members: &[u32], points: &[[f64; 3]]) -> Self {
        let n = members.len() as f64;
        let mut c = [0.0; 3];
        for &v in members {
            let p = points[v as usize];
            (0..3).for_each(|k| c[k] += p[k]);
        }
        c = c.map(|x| x / n);
        let mut s = [[0.0; 3]; 3];
        for &v in members {
            let d = sub(points[v as usize], c);
            for r in 0..3 {
                for q in 0..3 {
                    s[r][q] += d[r] * d[q];
                }
            }
        }
        Moments {
            n,
            centroid: c,
            scatter: s,
        }
    }

    /// The moments of the union of two disjoint sets (the parallel-axis
    /// rule: no cancellation, whatever the coordinates' magnitude).
    pub(super) fn join(&self, o: &Moments) -> Moments {
        let n = self.n + o.n;
        let d = sub(o.centroid, self.centroid);
        let w = self.n * o.n / n;
        let mut s = [[0.0; 3]; 3];
        for r in 0..3 {
            for q in 0..3 {
                s[r][q] = self.scatter[r][q] + o.scatter[r][q] + w * d[r] * d[q];
            }
        }
        Moments {
            n,
            centroid: [0, 1, 2].map(|k| self.centroid[k] + d[k] * o.n / n),
            scatter: s,
        }
    }

    /// The least-squares plane of the points (its extent left at zero:
    /// only the plane itself is asked for while merging).
    pub(super) fn plane(&self) -> Primitive {
        let cov = self.scatter.map(|row| row.map(|x| x / self.n));
        let (vals, vecs) = symmetric_eigen(cov);
        if !(vals[0] > 0.0 && vals[1] > 64.0 * f64::EPSILON * vals[0]) {
            return Primitive::None;
        }
        let unit = |u: [f64; 3]| {
            let l = dot(u, u).sqrt();
            u.map(|x| x / l)
        };
        let normal = unit(vecs[2]);
        let a0 = unit(vecs[0]);
        Primitive::Plane(PlaneFit {
            centroid: self.centroid,
            normal,
            axes: [a0, cross(normal, a0)],
            rms_residual: vals[2].max(0.0).sqrt(),
            extent: [0.0; 2],
        })
    }

    /// The least-squares line of the points (its extent left at zero: only
    /// the line itself is asked for while merging).
    pub(super) fn line(&self) -> Primitive {
        let cov = self.scatter.map(|row| row.map(|x| x / self.n));
        let (vals, vecs) = symmetric_eigen(cov);
        // No spread (one point) or NaN: no line.
        if vals[0].is_nan() || vals[0] <= 0.0 {
            return Primitive::None;
        }
        let l = dot(vecs[0], vecs[0]).sqrt();
        Primitive::Line(LineFit {
            centroid: self.centroid,
            direction: vecs[0].map(|x| x / l),
            rms_residual: (vals[1] + vals[2]).max(0.0).sqrt(),
            extent: 0.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::fit::{fit_line, fit_plane};

    #[test]
    fn joined_moments_fit_as_the_points_together() {
        // Two halves of a tilted plane and of a line, far from the origin:
        // the joined moments give the fits of all the points.
        let plane: Vec<[f64; 3]> = (0..60)
            .map(|k| {
                let (x, y) = (f64::from(k % 10), f64::from(k / 10));
                [
                    1e6 + x,
                    2e6 + y,
                    0.3 * x - 0.1 * y + 0.01 * f64::from(k % 3),
                ]
            })
            .collect();
        let ids: Vec<u32> = (0..60).collect();
        let joined = Moments::of(&ids[..25], &plane).join(&Moments::of(&ids[25..], &plane));
        let (Primitive::Plane(p), Ok(q)) = (joined.plane(), fit_plane(&plane)) else {
            panic!("no plane");
        };
        assert!(dot(p.normal, q.normal).abs() > 1.0 - 1e-9);
        assert!((p.rms_residual - q.rms_residual).abs() < 1e-9);
        let line: Vec<[f64; 3]> = (0..30)
            .map(|k| {
                let t = f64::from(k);
                [5e5 + t, 2.0 * t + 0.02 * f64::from(k % 2), -t]
            })
            .collect();
        let joined = Moments::of(&ids[..7], &line).join(&Moments::of(&ids[7..30], &line));
        let (Primitive::Line(p), Ok(q)) = (joined.line(), fit_line(&line)) else {
            panic!("no line");
        };
        assert!(dot(p.direction, q.direction).abs() > 1.0 - 1e-9);
        assert!((p.rms_residual - q.rms_residual).abs() < 1e-9);
    }
}
