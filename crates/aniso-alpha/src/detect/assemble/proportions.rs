//! Stage 5b of the assembly (docs/method.md §4, "Proportions"): a part
//! must have its shape's proportions at the scale of the ellipsoid that
//! found it, or it goes.
//!
//! The scan resolves a structure at the scale of its ellipsoid: half
//! thickness α (the candidate's claim radius τ before any widening) and
//! reach c = α·λ (the footprint cell), so a long diameter of 2c.
//!
//! * **A plane is two-dimensional at that scale**: its width (the second
//!   in-plane extent) holds at least as many of its spacings as the
//!   ellipsoid's long diameter does in the estimate's rule (2·C_REACH = 4:
//!   the reach α·λ is C_REACH spacings). Its spacing is the side of the
//!   area per member, √(A/n): A the cells that hold a member, of side the
//!   spacing of the members' bounding rectangle √(L·W/n) (so that pieces
//!   of one plane apart do not count the gap between them). A wire, a
//!   pole's side, a crossbar or the row of points where a scanner's beam
//!   grazes an edge, one to three rows of points across, is not a plane:
//!   the scan cannot tell its second direction from noise (the line run
//!   finds it when it is a line). In the members' spacings, not in c: in
//!   the paper's sparse scenes the significance test may choose a reach
//!   larger than a small plane's own spacing.
//! * **A line is one-dimensional at that scale**: its thickness is at
//!   most its length over the elongation λ = c/τ of the ellipsoid (with
//!   a widened claim radius τ, a smaller λ): a part
//!   less elongated than the ellipsoid that found it is a blob, a patch
//!   of a surface or a clump of clutter.
//!
//! Widths and thicknesses are uniform-equivalent: √12 times the standard
//! deviation of the members across (the full width of a uniform strip;
//! the bounding box would follow a single stray member). A plane's rows
//! across are √(W² + s²)/s for a width W and spacing s: r rows of points
//! s apart have W = s·√(r² − 1), and each row stands for a band s wide.
//! No constant: the sizes are the ellipsoid's own.
//!
//! The stage runs with the data's orientations (real scans:
//! `Regime::checks_proportions`); with a sampler the paper's smallest
//! faces, about four rows across, are the significance test's to judge.

use super::super::detection::Primitive;
use super::super::fit::{moments, PlaneFit};
use super::super::local::any_orthogonal;
use super::shape::span;
use super::{Candidate, Draft};
use crate::aniso::Mat3;
use crate::geometry::{cross, dot, floor_i64, sub};
use std::collections::HashSet;

/// Rows of points a plane holds across, at least: the long diameter of
/// the ellipsoid in the data's spacings (2·`C_REACH`, the estimate's reach
/// rule: α·λ = C_REACH·d).
const ROWS_ACROSS: f64 = 2.0 * super::super::estimate::C_REACH;

/// √12: the full width of a uniform distribution over its standard
/// deviation.
const UNIFORM_WIDTH: f64 = 3.464_101_615_137_754_5;

/// Drops the parts without their shape's proportions (module doc); how
/// many went.
pub(super) fn reject(parts: &mut Vec<Draft>, cands: &[Candidate], points: &[[f64; 3]]) -> usize {
    let before = parts.len();
    parts.retain(|p| {
        let c = &cands[p.cand];
        proportioned(&p.fit, &p.members, c.tau, c.cell, points)
    });
    before - parts.len()
}

/// Whether a part with the primitive `fit` and the points `members`,
/// found by an ellipsoid of reach `cell` with claim radius `tau`, has the
/// proportions of its shape (module doc).
pub(super) fn proportioned(
    fit: &Primitive,
    members: &[u32],
    tau: f64,
    cell: f64,
    points: &[[f64; 3]],
) -> bool {
    match fit {
        Primitive::Plane(f) => {
            let n = members.len().max(1) as f64;
            let c = covariance(members, points);
            let length = UNIFORM_WIDTH * quadratic(c, f.axes[0], f.axes[0]).max(0.0).sqrt();
            let width = UNIFORM_WIDTH * quadratic(c, f.axes[1], f.axes[1]).max(0.0).sqrt();
            if width.is_nan() || width <= 0.0 {
                return false;
            }
            let rough = (length * width / n).sqrt();
            let spacing = (covered_area(members, points, f, rough) / n).sqrt();
            let rows = width.hypot(spacing) / spacing;
            rows >= ROWS_ACROSS || rows.is_nan()
        }
        Primitive::Line(f) => {
            let (t0, t1) = span(f, members, points);
            let thickness =
                UNIFORM_WIDTH * largest_rms_across(covariance(members, points), f.direction);
            let elongation = cell / tau;
            let excess = thickness * elongation - (t1 - t0);
            excess <= 0.0 || excess.is_nan()
        }
        Primitive::None => true,
    }
}

/// The area the members cover on their plane `f`: the cells of side
/// `cell` that hold a member. Pieces of one plane apart cover their own
/// areas, not the gap between them.
fn covered_area(members: &[u32], points: &[[f64; 3]], f: &PlaneFit, cell: f64) -> f64 {
    let cells: HashSet<(i64, i64)> = members
        .iter()
        .map(|&v| {
            let d = sub(points[v as usize], f.centroid);
            (
                floor_i64(dot(d, f.axes[0]) / cell),
                floor_i64(dot(d, f.axes[1]) / cell),
            )
        })
        .collect();
    cells.len() as f64 * cell * cell
}

/// The covariance of the members (divided by their number), from
/// [`moments`].
fn covariance(members: &[u32], points: &[[f64; 3]]) -> Mat3 {
    moments(members.len(), |k| points[members[k] as usize]).1
}

/// uᵀ·C·w.
fn quadratic(c: Mat3, u: [f64; 3], w: [f64; 3]) -> f64 {
    dot(u, [dot(c[0], w), dot(c[1], w), dot(c[2], w)])
}

/// The largest root mean square spread across the unit `direction` of
/// points of covariance `c`: the square root of the larger eigenvalue of
/// their 2×2 covariance across it.
fn largest_rms_across(c: Mat3, direction: [f64; 3]) -> f64 {
    let u = any_orthogonal(direction);
    let w = cross(direction, u);
    let (a, b, d) = (quadratic(c, u, u), quadratic(c, u, w), quadratic(c, w, w));
    let half_trace = 0.5 * (a + d);
    let det = a * d - b * b;
    (half_trace + (half_trace * half_trace - det).max(0.0).sqrt())
        .max(0.0)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::super::super::fit::{fit_line_indices, fit_plane_indices};
    use super::*;

    /// A grid of `nx` × `ny` points 1 apart in the plane z = 0.
    fn grid(nx: usize, ny: usize) -> Vec<[f64; 3]> {
        (0..nx * ny)
            .map(|i| [(i % nx) as f64, (i / nx) as f64, 0.0])
            .collect()
    }

    fn all(n: usize) -> Vec<u32> {
        (0..n as u32).collect()
    }

    #[test]
    fn a_plane_must_be_as_many_spacings_wide_as_its_ellipsoid_is_long() {
        // Points 1 apart: spacing 1, width √12·σ of r rows = √(r² − 1),
        // r rows across.
        for (rows, plane) in [(2, false), (3, false), (4, true), (5, true), (12, true)] {
            let pts = grid(60, rows);
            let ids = all(pts.len());
            let f = Primitive::Plane(fit_plane_indices(&pts, &ids).expect("a plane"));
            assert_eq!(
                proportioned(&f, &ids, 0.125, 1.0, &pts),
                plane,
                "{rows} rows"
            );
        }
        // Two 10 × 10 squares 100 apart along x: a plane in two pieces,
        // whose gap is not area.
        let mut pts = grid(10, 10);
        pts.extend(grid(10, 10).iter().map(|p| [p[0] + 100.0, p[1], p[2]]));
        let ids = all(pts.len());
        let f = Primitive::Plane(fit_plane_indices(&pts, &ids).expect("a plane"));
        assert!(proportioned(&f, &ids, 0.125, 1.0, &pts));
        // A strip two points wide, 0.05 apart, sampled at 0.1 along it:
        // spacing 0.07, width 0.05.
        let strip: Vec<[f64; 3]> = (0..400)
            .map(|i| [0.1 * (i / 2) as f64, 0.05 * (i % 2) as f64, 0.0])
            .collect();
        let ids = all(strip.len());
        let f = Primitive::Plane(fit_plane_indices(&strip, &ids).expect("a plane"));
        assert!(!proportioned(&f, &ids, 0.05, 0.5, &strip));
    }

    #[test]
    fn a_line_must_be_as_elongated_as_its_ellipsoid() {
        // 30 points 1 apart along x, alternating ±0.2 in y: thickness
        // √12·0.2 = 0.69, length 29.
        let pts: Vec<[f64; 3]> = (0..30)
            .map(|i| [i as f64, if i % 2 == 0 { 0.2 } else { -0.2 }, 0.0])
            .collect();
        let ids = all(pts.len());
        let f = Primitive::Line(fit_line_indices(&pts, &ids).expect("a line"));
        // λ = 8: 0.69·8 = 5.5 ≤ 29.
        assert!(proportioned(&f, &ids, 0.5, 4.0, &pts));
        // As elongated as the ellipsoid? λ = 50: 0.69·50 = 34.6 > 29.
        assert!(!proportioned(&f, &ids, 0.1, 5.0, &pts));
        // A square patch (a blob) is no line at the ellipsoid's λ = 4.
        let patch = grid(8, 8);
        let ids = all(patch.len());
        let f = Primitive::Line(fit_line_indices(&patch, &ids).expect("a line"));
        assert!(!proportioned(&f, &ids, 0.5, 2.0, &patch));
    }
}
