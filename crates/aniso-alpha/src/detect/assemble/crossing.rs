//! A solid between two pieces of one plane (docs/method.md §4 step 5,
//! "What a part is"): the test that keeps two faces apart where the
//! merging of planes apart ([`super::merging`]) would join them.
//!
//! Two coplanar pieces with a gap between them are one surface with a
//! hole (a window, an occluder's shadow, a façade's recess or porch) or
//! two faces with a solid standing between them (the arms of a cross, a
//! box that cuts a table top in two, a tower between two flat roofs). What
//! tells them apart is what rises from their plane in the gap, and how
//! far. The pieces are two faces when a planar part C, not parallel to
//! them,
//! * has the two pieces on the two sides of its plane, and they do not
//!   reach across it: the gap's width across C (how near each piece comes
//!   to C's plane from its own side, summed) exceeds τ. The ground along a
//!   wall's foot has both stretches on one side; a piece bent round C's
//!   edge (an L-shaped face seen past an occluder) reaches across;
//! * meets their plane there: one of its points lies within τ of the
//!   plane, inside the pieces' joint bounding box (a part's points lie on
//!   its plane, so such a point lies where the two planes meet; the front
//!   of a truck standing before a wall, its shadow's cause, does not);
//! * rises from the plane at least as far as the gap is wide (its
//!   farthest point from the plane against the width). A solid is as deep
//!   as it is wide or deeper; a step shallower than it is wide, the recess
//!   or the porch of a façade (CGAL's building scan: the central section
//!   between the wings of its 56 m façade, across a 16 m gap), leaves one
//!   surface with a hole, as the gap rule reads it.
//!
//! From the geometry alone (no scanner position) a recess and a
//! protrusion are mirror images; the comparison of depth and width is
//! what the scene itself offers.
//!
//! *Cost:* the parts are sorted by the lower x of their boxes, so a test
//! reads the parts whose boxes may meet the pair's (a binary search, then
//! a scan bounded by the widest box), and the points of those that pass
//! the cheap tests; the ⌊√n⌋ widest parts are set apart and read by every
//! test, so that one part spanning the whole cloud (the ground) does not
//! widen every scan to all n parts. It runs only for the pairs that are
//! one plane by the merging's test.

use super::super::detection::Primitive;
use super::{Candidate, Draft};
use crate::geometry::{bounding_box_of, box_d2, box_gap, dot, sub, Box3};

/// The parts' boxes, claim radii and an index of the boxes along x.
pub(super) struct Crossings {
    /// Per part, the bounding box of its members.
    pub(super) boxes: Vec<Box3>,
    /// Per part, its candidate's claim radius τ.
    tau: Vec<f64>,
    /// The parts by the lower x of their box, less the widest.
    order: Vec<usize>,
    /// The lower x of each box, in `order`.
    lo_x: Vec<f64>,
    /// The widest box along x in `order`.
    width_x: f64,
    /// The ⌊√n⌋ parts widest along x (the ground of a survey spans it
    /// all): read by every test, so that the others' scan is bounded by
    /// the widest of the rest, not by the ground.
    wide: Vec<usize>,
    /// Cosine of the part angle: parts closer to parallel never cross.
    cos: f64,
}

impl Crossings {
    /// The index over `parts` (their members among `points`).
    pub(super) fn new(
        parts: &[Draft],
        cands: &[Candidate],
        points: &[[f64; 3]],
        angle_deg: f64,
    ) -> Self {
        let boxes: Vec<Box3> = parts
            .iter()
            .map(|p| bounding_box_of(points, &p.members))
            .collect();
        let width = |a: usize| boxes[a].1[0] - boxes[a].0[0];
        let mut order: Vec<usize> = (0..parts.len()).collect();
        order.sort_by(|&a, &b| width(b).total_cmp(&width(a)).then(a.cmp(&b)));
        let wide = order.drain(..parts.len().isqrt()).collect();
        order.sort_by(|&a, &b| boxes[a].0[0].total_cmp(&boxes[b].0[0]).then(a.cmp(&b)));
        Crossings {
            tau: parts.iter().map(|p| cands[p.cand].tau).collect(),
            lo_x: order.iter().map(|&a| boxes[a].0[0]).collect(),
            width_x: order.iter().map(|&a| width(a)).fold(0.0, f64::max),
            wide,
            boxes,
            order,
            cos: angle_deg.to_radians().cos(),
        }
    }

    /// Whether a solid stands between the planar parts `a` and `b`: a
    /// planar part crosses their gap and rises from their plane at least
    /// as far as the gap is wide (module doc).
    pub(super) fn crossed(&self, parts: &[Draft], points: &[[f64; 3]], a: usize, b: usize) -> bool {
        let (Primitive::Plane(pa), Primitive::Plane(pb)) = (&parts[a].fit, &parts[b].fit) else {
            return false;
        };
        let (ba, bb) = (&self.boxes[a], &self.boxes[b]);
        let joint: Box3 = (
            std::array::from_fn(|k| ba.0[k].min(bb.0[k])),
            std::array::from_fn(|k| ba.1[k].max(bb.1[k])),
        );
        let tau = self.tau[a].max(self.tau[b]);
        let start = self
            .lo_x
            .partition_point(|&x| x < joint.0[0] - self.width_x);
        let meeting = (start..self.order.len())
            .take_while(|&k| self.lo_x[k] <= joint.1[0])
            .map(|k| self.order[k])
            .chain(self.wide.iter().copied())
            .filter(|&c| c != a && c != b && box_gap(&self.boxes[c], &joint) == 0.0);
        for c in meeting {
            let Primitive::Plane(pc) = &parts[c].fit else {
                continue;
            };
            if dot(pc.normal, pa.normal).abs() >= self.cos {
                continue;
            }
            let side_a = dot(sub(pa.centroid, pc.centroid), pc.normal);
            let side_b = dot(sub(pb.centroid, pc.centroid), pc.normal);
            if side_a * side_b >= 0.0 || side_a.abs().min(side_b.abs()) <= self.tau[c] {
                continue;
            }
            // C's points: whether one meets the plane of `a` within the
            // joint box, and how far C rises from that plane.
            let (mut meets, mut rise) = (false, 0.0f64);
            for &v in &parts[c].members {
                let q = &points[v as usize];
                let d = parts[a].fit.distance(q);
                rise = rise.max(d);
                meets |= d <= tau && box_d2(q, &joint).sqrt() <= tau;
            }
            if !meets {
                continue;
            }
            // The gap's width across C: how near each piece comes to C's
            // plane from its own side (negative where it reaches across);
            // read only for a C that meets the plane (the pieces may be
            // the ground's, of many points).
            let near = |p: usize, side: f64| {
                parts[p]
                    .members
                    .iter()
                    .map(|&v| dot(sub(points[v as usize], pc.centroid), pc.normal) * side.signum())
                    .fold(f64::INFINITY, f64::min)
            };
            let width = near(a, side_a) + near(b, side_b);
            if width > tau && rise >= width {
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::fit::fit_plane_indices;

    /// A grid of points on the rectangle p0 + s·u + r·w (s, r in [0, 1])
    /// at about `step`, appended to `pts`, as a part (candidate `cand`, τ
    /// `tau`).
    fn rect(
        pts: &mut Vec<[f64; 3]>,
        p0: [f64; 3],
        u: [f64; 3],
        w: [f64; 3],
        (step, cand, tau): (f64, usize, f64),
    ) -> (Draft, Candidate) {
        let n = |v: [f64; 3]| ((dot(v, v).sqrt() / step) as usize).max(1);
        let (nu, nw) = (n(u), n(w));
        let start = pts.len() as u32;
        for i in 0..=nu {
            for j in 0..=nw {
                let (s, r) = (i as f64 / nu as f64, j as f64 / nw as f64);
                pts.push(std::array::from_fn(|k| p0[k] + s * u[k] + r * w[k]));
            }
        }
        let members: Vec<u32> = (start..pts.len() as u32).collect();
        let fit = Primitive::Plane(fit_plane_indices(pts, &members).unwrap());
        Draft::with_candidate(pts, members, fit, cand, (tau, step))
    }

    /// Two stretches of a wall (the plane y = 0, x in [0, 1] and [1.5,
    /// 2.5], z in [0, 1]) and a third part from `between`: whether it
    /// crosses their gap.
    fn crossed_with(p0: [f64; 3], u: [f64; 3], w: [f64; 3]) -> bool {
        let mut pts = Vec::new();
        let (x, z) = ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        let (parts, cands): (Vec<Draft>, Vec<Candidate>) = [
            rect(&mut pts, [0.0; 3], x, z, (0.02, 0, 0.005)),
            rect(&mut pts, [1.5, 0.0, 0.0], x, z, (0.02, 1, 0.005)),
            rect(&mut pts, p0, u, w, (0.02, 2, 0.005)),
        ]
        .into_iter()
        .unzip();
        Crossings::new(&parts, &cands, &pts, 10.0).crossed(&parts, &pts, 0, 1)
    }

    #[test]
    fn a_solid_s_side_between_two_faces_crosses_their_gap() {
        // The side of a solid standing on the wall between the stretches
        // (the gap is 0.5 wide): the plane x = 1.2, from the wall (y = 0)
        // out to y = 0.6, deeper than the gap is wide.
        assert!(crossed_with(
            [1.2, 0.0, 0.0],
            [0.0, 0.6, 0.0],
            [0.0, 0.0, 1.0]
        ));
        // The same on the wall's other side (a recess as deep).
        assert!(crossed_with(
            [1.2, -0.6, 0.0],
            [0.0, 0.6, 0.0],
            [0.0, 0.0, 1.0]
        ));
    }

    #[test]
    fn a_step_shallower_than_the_gap_is_wide_is_a_hole() {
        // A porch or a recess 0.3 deep across the 0.5 gap: one wall.
        assert!(!crossed_with(
            [1.2, 0.0, 0.0],
            [0.0, 0.3, 0.0],
            [0.0, 0.0, 1.0]
        ));
        assert!(!crossed_with(
            [1.2, -0.3, 0.0],
            [0.0, 0.3, 0.0],
            [0.0, 0.0, 1.0]
        ));
    }

    #[test]
    fn an_occluder_in_front_the_ground_along_the_foot_and_a_pane_do_not() {
        // The same side standing half a metre before the wall: a shadow's
        // cause, not a solid on the wall.
        assert!(!crossed_with(
            [1.2, 0.5, 0.0],
            [0.0, 0.6, 0.0],
            [0.0, 0.0, 1.0]
        ));
        // The ground along the wall's foot meets the wall's plane in the
        // gap, but both stretches lie on one side of it.
        assert!(!crossed_with(
            [-0.5, -1.0, 0.0],
            [3.5, 0.0, 0.0],
            [0.0, 1.0, 0.0]
        ));
        // A pane set back in the gap, parallel to the wall.
        assert!(!crossed_with(
            [1.0, -0.2, 0.0],
            [0.5, 0.0, 0.0],
            [0.0, 0.0, 1.0]
        ));
    }

    #[test]
    fn each_gap_of_a_long_wall_is_crossed_by_its_own_pillar() {
        // A thousand stretches of a wall along x, a pillar's side in each
        // gap (1.2 deep, the gap 1 wide): the index finds each pair's
        // pillar among 2,000 parts.
        let mut pts = Vec::new();
        let (mut parts, mut cands) = (Vec::new(), Vec::new());
        for k in 0..1000 {
            let x0 = 2.0 * k as f64;
            for (p0, u) in [
                ([x0, 0.0, 0.0], [1.0, 0.0, 0.0]),
                ([x0 + 1.5, 0.0, 0.0], [0.0, 1.2, 0.0]),
            ] {
                let (d, c) = rect(&mut pts, p0, u, [0.0, 0.0, 1.0], (0.1, parts.len(), 0.01));
                parts.push(d);
                cands.push(c);
            }
        }
        // The ground under the whole wall, the widest part: both stretches
        // of each pair lie on one side of it.
        let (d, g) = rect(
            &mut pts,
            [-1.0, -1.0, 0.0],
            [2001.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            (0.5, parts.len(), 0.01),
        );
        parts.push(d);
        cands.push(g);
        let c = Crossings::new(&parts, &cands, &pts, 10.0);
        assert!(c.wide.contains(&2000));
        assert!((0..999).all(|k| c.crossed(&parts, &pts, 2 * k, 2 * k + 2)));
        // Without the pillars (the ground kept), no gap is crossed.
        let walls: Vec<Draft> = parts.iter().step_by(2).cloned().collect();
        let wall_cands: Vec<Candidate> = cands.iter().step_by(2).cloned().collect();
        let parts = walls
            .into_iter()
            .enumerate()
            .map(|(k, mut d)| {
                d.cand = k;
                d
            })
            .collect::<Vec<_>>();
        let c = Crossings::new(&parts, &wall_cands, &pts, 10.0);
        assert!((0..999).all(|k| !c.crossed(&parts, &pts, k, k + 1)));
    }
}
