//! What differs between lines and planes in the assembly: the shape of the
//! simplices ([`Shape`], for edges `[u32; 2]` and triangles `[u32; 3]`)
//! says how many points a part needs, when two pieces are one primitive,
//! the volume near a part, which claim radii widening tries, how a part
//! crosses another, whether parts lying apart merge, and what outline a
//! part gets. As CGAL's Shape_detection region types do, each shape
//! carries its own rules and the stages call them.

use super::super::cloud::Cloud;
use super::super::detection::Primitive;
use super::super::fit::LineFit;
use super::super::outline::outline;
use super::super::scan::Face;
use super::embedded;
use super::footprint::Footprint;
use super::same::{joint_line_keeps, same_primitive, Piece};
use super::widen::{CLAIM_RADII, MAX_WIDEN_BACKGROUND};
use super::{merging, Candidate, Draft};
use crate::geometry::{dot, sub};

/// A part's outline polygon (a segment's two ends) and its mesh.
pub(crate) type PartShape = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Relative share of a part's vertices on each side of another part's
/// primitive for that primitive to cross it: 1/5.
const CROSS_SHARE: usize = 5;

/// Along a line, points within this fraction of the line's extent of the
/// crossing point count as on neither side.
const CROSS_LINE_MARGIN: f64 = 0.05;

/// Floor of a plane's side tolerance in a crossing test, relative to the
/// sum of the plane's two extents: with a zero RMS residual (exactly
/// planar points) the points within rounding of the plane still count as
/// on neither side.
const CROSS_PLANE_SLACK: f64 = 1e-9;

/// The volume within distance t of a part, as a function of t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Near {
    /// A slab 2t thick over a plane's area.
    Slab {
        /// The area.
        area: f64,
    },
    /// A tube of radius t along a line's length.
    Tube {
        /// The length.
        length: f64,
    },
}

impl Near {
    /// The volume within distance `t`.
    pub(crate) fn volume(self, t: f64) -> f64 {
        match self {
            Near::Slab { area } => 2.0 * t * area,
            Near::Tube { length } => std::f64::consts::PI * t * t * length,
        }
    }
}

/// The assembly's rules of one shape (module doc).
pub(crate) trait Shape: Face {
    /// The fewest points of a part, for the path filter's nb_c.
    fn min_vertices(nb_c: u32) -> usize;
    /// Whether two candidates (or parts) are one primitive.
    fn same(a: Piece<'_>, b: Piece<'_>, angle_deg: f64, points: &[[f64; 3]]) -> bool;
    /// The volume near the primitive `fit` of a part with the points
    /// `members` and the footprint `foot` of cells of side `cell`.
    fn near(
        fit: &Primitive,
        foot: &Footprint,
        cell: f64,
        members: &[u32],
        points: &[[f64; 3]],
    ) -> Near;
    /// The claim radii that widening tries for a candidate (the first is
    /// its τ; one radius: nothing to try), `rho` the background density.
    fn claim_radii(c: &Candidate, near: Near, rho: f64) -> Vec<f64>;
    /// How many of the points `b` (of another part) lie strictly on each
    /// side of the primitive `fit`; `None` when the question has no answer
    /// (parallel lines).
    fn sides(fit: &Primitive, b: &[u32], points: &[[f64; 3]]) -> Option<(usize, usize)>;
    /// Merges the parts that are one primitive seen in places apart
    /// (docs/method.md §4, step 5); how many pairs that would have merged
    /// stay apart as two faces of a solid. By default they all stay
    /// apart, and none is counted.
    fn merge_apart(
        _parts: &mut Vec<Draft>,
        _cands: &[Candidate],
        _points: &[[f64; 3]],
        _angle_deg: f64,
    ) -> usize {
        0
    }
    /// Drops the parts that lie inside a surface, its sampling rather than
    /// a structure of this shape; how many went. By default none.
    fn reject_in_surface(
        _parts: &mut Vec<Draft>,
        _cands: &[Candidate],
        _cloud: &Cloud<'_>,
    ) -> usize {
        0
    }
    /// A part's outline (or segment) and mesh.
    fn outline(fit: &Primitive, members: &[u32], cell: f64, points: &[[f64; 3]]) -> PartShape;
}

/// Whether the primitive `fit` (of part A) passes through the interior of
/// part B (its points `b`): B has at least 1/[`CROSS_SHARE`] of its points
/// strictly on each side ([`Shape::sides`]).
pub(super) fn crosses<S: Shape>(fit: &Primitive, b: &[u32], points: &[[f64; 3]]) -> bool {
    b.len() >= 4
        && S::sides(fit, b, points)
            .is_some_and(|(pos, neg)| usize::min(pos, neg) * CROSS_SHARE >= b.len())
}

/// The side of a signed offset `d` beyond `tol`: 1 above, 2 below, 0 on.
fn side(d: f64, tol: f64) -> u8 {
    if d > tol {
        1
    } else if d < -tol {
        2
    } else {
        0
    }
}

/// The counts of sides 1 and 2 among `offsets`.
fn count_sides(offsets: impl Iterator<Item = u8>) -> (usize, usize) {
    offsets.fold((0, 0), |(p, n), s| match s {
        1 => (p + 1, n),
        2 => (p, n + 1),
        _ => (p, n),
    })
}

/// The extreme positions of `members` along the line `f`.
pub(super) fn span(f: &LineFit, members: &[u32], points: &[[f64; 3]]) -> (f64, f64) {
    let (mut t0, mut t1) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in members {
        let t = dot(sub(points[v as usize], f.centroid), f.direction);
        t0 = t0.min(t);
        t1 = t1.max(t);
    }
    (t0, t1)
}

/// Lines: edges.
impl Shape for [u32; 2] {
    /// A path of nb_c edges has nb_c + 1 points.
    fn min_vertices(nb_c: u32) -> usize {
        nb_c as usize + 1
    }

    /// A line inside a surface is the surface's sampling
    /// ([`embedded::reject_lines`]).
    fn reject_in_surface(parts: &mut Vec<Draft>, cands: &[Candidate], cloud: &Cloud<'_>) -> usize {
        embedded::reject_lines(parts, cands, cloud)
    }

    /// Pieces of one noisy line are one ([`joint_line_keeps`]), and so are
    /// lines that pass [`same_primitive`].
    fn same(a: Piece<'_>, b: Piece<'_>, angle_deg: f64, points: &[[f64; 3]]) -> bool {
        joint_line_keeps(a, b, points) || same_primitive(a, b, angle_deg, points)
    }

    /// A tube along the span of the members (a line's footprint is one row
    /// of cells, and its growth by one cell marks the rows beside it too:
    /// its cells would triple the length).
    fn near(
        fit: &Primitive,
        _foot: &Footprint,
        _cell: f64,
        members: &[u32],
        points: &[[f64; 3]],
    ) -> Near {
        let length = match fit {
            Primitive::Line(f) => {
                let (t0, t1) = span(f, members, points);
                (t1 - t0).max(0.0)
            }
            _ => 0.0,
        };
        Near::Tube { length }
    }

    /// The radii of [`CLAIM_RADII`] whose tube holds at most
    /// [`MAX_WIDEN_BACKGROUND`] expected background points.
    fn claim_radii(c: &Candidate, near: Near, rho: f64) -> Vec<f64> {
        CLAIM_RADII
            .iter()
            .enumerate()
            .take_while(|&(i, &f)| i == 0 || rho * near.volume(f * c.tau) <= MAX_WIDEN_BACKGROUND)
            .map(|(_, &f)| f * c.tau)
            .collect()
    }

    /// The two sides of the point of B's line closest to A's line, along
    /// B's direction (points within [`CROSS_LINE_MARGIN`] of B's extent of
    /// it on neither).
    fn sides(fit: &Primitive, b: &[u32], points: &[[f64; 3]]) -> Option<(usize, usize)> {
        let Primitive::Line(la) = fit else {
            return None;
        };
        let bv: Vec<[f64; 3]> = b.iter().map(|&v| points[v as usize]).collect();
        let lb = super::super::fit::fit_line(&bv).ok()?;
        let w = sub(lb.centroid, la.centroid);
        let (u, v) = (la.direction, lb.direction);
        let (a_, b_, c_) = (dot(u, u), dot(u, v), dot(v, v));
        let (d_, e_) = (dot(u, w), dot(v, w));
        let den = a_ * c_ - b_ * b_;
        if den.abs() < 1e-12 {
            return None; // parallel: no crossing
        }
        let t = (b_ * d_ - a_ * e_) / den; // parameter along B
        let tol = CROSS_LINE_MARGIN * lb.extent.max(1e-12);
        Some(count_sides(
            bv.iter()
                .map(|p| side(dot(sub(*p, lb.centroid), v) - t, tol)),
        ))
    }

    /// The segment between the members' extreme projections.
    fn outline(fit: &Primitive, members: &[u32], _cell: f64, points: &[[f64; 3]]) -> PartShape {
        let Primitive::Line(f) = fit else {
            return (Vec::new(), Vec::new());
        };
        let (t0, t1) = span(f, members, points);
        let at = |t: f64| [0, 1, 2].map(|k| f.centroid[k] + t * f.direction[k]);
        (vec![at(t0), at(t1)], Vec::new())
    }
}

/// Planes: triangles.
impl Shape for [u32; 3] {
    /// Half nb_c (a strip of nb_c triangles has about nb_c/2 + 2
    /// points), at least 4.
    fn min_vertices(nb_c: u32) -> usize {
        (nb_c as usize / 2).max(4)
    }

    fn same(a: Piece<'_>, b: Piece<'_>, angle_deg: f64, points: &[[f64; 3]]) -> bool {
        same_primitive(a, b, angle_deg, points)
    }

    /// A slab over the footprint's area: its cells, which the members
    /// cover grown by one (generous: the region the scan could have found
    /// the plane in).
    fn near(
        _fit: &Primitive,
        foot: &Footprint,
        cell: f64,
        _members: &[u32],
        _points: &[[f64; 3]],
    ) -> Near {
        Near::Slab {
            area: foot.count() as f64 * cell * cell,
        }
    }

    /// Every radius of [`CLAIM_RADII`], unless the candidate's RMS is under
    /// τ/3: a Gaussian spread keeps 99% of its points within τ then, and a
    /// wider slab has nothing to gain.
    fn claim_radii(c: &Candidate, _near: Near, _rho: f64) -> Vec<f64> {
        if 3.0 * c.fit.rms() < c.tau {
            return vec![c.tau];
        }
        CLAIM_RADII.iter().map(|&f| f * c.tau).collect()
    }

    /// The two sides of A's plane, beyond 3·RMS.
    fn sides(fit: &Primitive, b: &[u32], points: &[[f64; 3]]) -> Option<(usize, usize)> {
        let Primitive::Plane(pf) = fit else {
            return None;
        };
        let tol = 3.0 * pf.rms_residual + CROSS_PLANE_SLACK * (pf.extent[0] + pf.extent[1]);
        Some(count_sides(b.iter().map(|&v| {
            side(dot(sub(points[v as usize], pf.centroid), pf.normal), tol)
        })))
    }

    /// One plane, one part: planar parts that are the same plane but lie
    /// apart merge ([`merging::planes_apart`]).
    fn merge_apart(
        parts: &mut Vec<Draft>,
        cands: &[Candidate],
        points: &[[f64; 3]],
        angle_deg: f64,
    ) -> usize {
        merging::planes_apart::<Self>(parts, cands, points, angle_deg)
    }

    /// The plane's 2D α-shape of the members at the candidate's cell.
    fn outline(fit: &Primitive, members: &[u32], cell: f64, points: &[[f64; 3]]) -> PartShape {
        let Primitive::Plane(f) = fit else {
            return (Vec::new(), Vec::new());
        };
        let o = outline(points, members, f, cell);
        (o.polygon, o.triangles)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::fit::{fit_line_indices, fit_plane_indices};

    type Lines = [u32; 2];
    type Planes = [u32; 3];

    #[test]
    fn a_line_through_the_middle_of_another_crosses_it() {
        // B: ten points along x from 0 to 9; A: a line along y through
        // x = 4.5 crosses it; one through x = 9.5 (past its end) does not,
        // nor one through x = 8.8 (B's last point is within the margin of
        // 5% of B's extent, all the others on one side).
        let mut pts: Vec<[f64; 3]> = (0..10).map(|i| [i as f64, 0.0, 0.0]).collect();
        let b: Vec<u32> = (0..10).collect();
        let mut cross_at = |x: f64| {
            let a0 = pts.len() as u32;
            pts.extend([[x, -1.0, 0.0], [x, 1.0, 0.0], [x, 2.0, 0.0]]);
            let fit = Primitive::Line(fit_line_indices(&pts, &[a0, a0 + 1, a0 + 2]).unwrap());
            crosses::<Lines>(&fit, &b, &pts)
        };
        assert!(cross_at(4.5));
        assert!(!cross_at(9.5));
        assert!(!cross_at(8.8));
        // Parallel lines never cross; too few points never do.
        let par = Primitive::Line(fit_line_indices(&pts, &[0, 9]).unwrap());
        assert_eq!(Lines::sides(&par, &b, &pts), None);
        assert!(!crosses::<Lines>(&par, &b[..3], &pts));
    }

    #[test]
    fn a_plane_cutting_through_another_crosses_it() {
        // B: a 5 × 5 grid on z = 0; A: the plane x = 2 cuts it in the
        // middle, x = 3.9 leaves one column of five (a fifth) beyond it.
        let mut pts: Vec<[f64; 3]> = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                pts.push([i as f64, j as f64, 0.0]);
            }
        }
        let b: Vec<u32> = (0..25).collect();
        let mut wall = |x: f64| {
            let a0 = pts.len() as u32;
            pts.extend([[x, 0.0, -1.0], [x, 4.0, -1.0], [x, 0.0, 1.0], [x, 4.0, 1.0]]);
            let ids: Vec<u32> = (a0..a0 + 4).collect();
            Primitive::Plane(fit_plane_indices(&pts, &ids).unwrap())
        };
        let middle = wall(2.0);
        let edge = wall(3.5);
        let past = wall(4.5);
        assert!(crosses::<Planes>(&middle, &b, &pts));
        // One column of five beyond x = 3.5: a fifth, still a crossing.
        assert!(crosses::<Planes>(&edge, &b, &pts));
        assert_eq!(
            Planes::sides(&past, &b, &pts).map(|(p, n)| p.min(n)),
            Some(0)
        );
        assert!(!crosses::<Planes>(&past, &b, &pts));
        // A plane's own points are all on it.
        let own = Primitive::Plane(fit_plane_indices(&pts, &b).unwrap());
        assert_eq!(Planes::sides(&own, &b, &pts), Some((0, 0)));
    }

    #[test]
    fn near_volumes_are_a_tube_along_a_line_and_a_slab_over_cells() {
        let pts: Vec<[f64; 3]> = (0..11).map(|i| [i as f64, 0.0, 0.0]).collect();
        let ids: Vec<u32> = (0..11).collect();
        let line = Primitive::Line(fit_line_indices(&pts, &ids).unwrap());
        let foot = Footprint::new(&line, &pts, &ids, 1.0).unwrap();
        let tube = Lines::near(&line, &foot, 1.0, &ids, &pts);
        assert!((tube.volume(0.5) - std::f64::consts::PI * 0.25 * 10.0).abs() < 1e-9);
        let slab = Planes::near(&line, &foot, 1.0, &ids, &pts);
        assert_eq!(slab.volume(0.5), foot.count() as f64);
    }

    #[test]
    fn outlines_are_segments_for_lines() {
        let pts = [[1.0, 1.0, 1.0], [3.0, 1.0, 1.0], [2.0, 1.0, 1.0]];
        let line = Primitive::Line(fit_line_indices(&pts, &[0, 1, 2]).unwrap());
        let (seg, mesh) = Lines::outline(&line, &[0, 1, 2], 1.0, &pts);
        assert!(mesh.is_empty());
        let mut xs: Vec<f64> = seg.iter().map(|p| p[0]).collect();
        xs.sort_by(f64::total_cmp);
        assert!((xs[0] - 1.0).abs() < 1e-12 && (xs[1] - 3.0).abs() < 1e-12);
        assert_eq!(
            Planes::outline(&line, &[0, 1, 2], 1.0, &pts),
            (vec![], vec![])
        );
        assert_eq!(Lines::min_vertices(4), 5);
        assert_eq!(Planes::min_vertices(20), 10);
        assert_eq!(Planes::min_vertices(4), 4);
    }
}
