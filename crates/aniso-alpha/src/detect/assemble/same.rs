//! Whether two candidates or parts are one primitive: the test that merges
//! candidates sharing claimed points (docs/method.md §4, step 3), and for
//! planes lying apart the joint plane's test (step 5).

use super::super::detection::Primitive;
use super::super::fit::{fit_line, fit_plane_indices};
use super::Candidate;
use crate::geometry::{dot, sub};

/// Share of a piece's points that must lie within τ of the other's
/// primitive (or of the joint one) for the two to be one.
const SAME_SHARE: f64 = 0.8;

/// What the same-primitive tests look at of a candidate or a part: its
/// primitive, its claim radius τ and its points.
#[derive(Clone, Copy)]
pub(crate) struct Piece<'a> {
    pub(super) fit: &'a Primitive,
    pub(super) tau: f64,
    pub(super) seeds: &'a [u32],
}

impl Candidate {
    /// The candidate as a [`Piece`].
    pub(super) fn piece(&self) -> Piece<'_> {
        Piece {
            fit: &self.fit,
            tau: self.tau,
            seeds: &self.seeds,
        }
    }
}

/// Whether two pieces are one primitive: their planes (lines) are within
/// the part angle of each other, and either each one's centroid lies
/// within τ of the other's primitive or most of the smaller one's points
/// ([`SAME_SHARE`]) lie within τ of the larger one's primitive. (The
/// second test catches a strip along the edge of a plane, found by
/// another mode: it fits a plane tilted across the strip, whose offset at
/// the other's centroid says nothing.)
pub(super) fn same_primitive(a: Piece, b: Piece, angle_deg: f64, points: &[[f64; 3]]) -> bool {
    let cos = angle_deg.to_radians().cos();
    let parallel = match (a.fit, b.fit) {
        (Primitive::Plane(fa), Primitive::Plane(fb)) => dot(fa.normal, fb.normal).abs() >= cos,
        (Primitive::Line(fa), Primitive::Line(fb)) => dot(fa.direction, fb.direction).abs() >= cos,
        _ => false,
    };
    if !parallel {
        return false;
    }
    let centroid = |f: &Primitive| match f {
        Primitive::Plane(p) => p.centroid,
        Primitive::Line(l) => l.centroid,
        Primitive::None => [f64::NAN; 3],
    };
    if a.fit.distance(&centroid(b.fit)) <= a.tau && b.fit.distance(&centroid(a.fit)) <= b.tau {
        return true;
    }
    let (big, small) = if a.seeds.len() >= b.seeds.len() {
        (a, b)
    } else {
        (b, a)
    };
    let near = small
        .seeds
        .iter()
        .filter(|&&v| big.fit.distance(&points[v as usize]) <= big.tau)
        .count();
    near as f64 >= SAME_SHARE * small.seeds.len() as f64
}

/// Whether two pieces of a noisy line are one line: the line fitted to
/// both keeps most of each one's points ([`SAME_SHARE`]) within the larger
/// claim radius. Their own fits can be tens of degrees apart (three
/// points jittered by σ ≈ α over two steps); lines crossing at an angle,
/// or the two legs of a polyline, leave one piece's far points outside
/// the joint line.
pub(super) fn joint_line_keeps(a: Piece, b: Piece, points: &[[f64; 3]]) -> bool {
    let joint: Vec<[f64; 3]> = a
        .seeds
        .iter()
        .chain(b.seeds)
        .map(|&v| points[v as usize])
        .collect();
    let Ok(f) = fit_line(&joint) else {
        return false;
    };
    let tau = a.tau.max(b.tau);
    let within = |seeds: &[u32]| {
        seeds
            .iter()
            .filter(|&&v| {
                let w = sub(points[v as usize], f.centroid);
                let t = dot(w, f.direction);
                (dot(w, w) - t * t).max(0.0).sqrt() <= tau
            })
            .count() as f64
            >= SAME_SHARE * seeds.len() as f64
    };
    within(a.seeds) && within(b.seeds)
}

/// Whether two parallel planar pieces that lie apart are one plane seen
/// in two places: the plane fitted to both keeps, for each piece, at least
/// [`SAME_SHARE`] of the points its own plane keeps within τ. Two pieces
/// of one wall fitted apart can tilt by a degree or so each (noise, a
/// slight bow of the wall), so that either one's plane, carried over the
/// gap, misses the other by more than τ; the joint plane passes through
/// both. Two distinct parallel planes (a façade and a wall set back from
/// it by more than τ) leave about half of each piece outside the joint
/// plane, which lies between them.
pub(super) fn joint_plane_keeps(a: Piece, b: Piece, angle_deg: f64, points: &[[f64; 3]]) -> bool {
    let joint: Vec<u32> = a.seeds.iter().chain(b.seeds).copied().collect();
    let Ok(f) = fit_plane_indices(points, &joint) else {
        return false;
    };
    // The joint plane must be parallel to both pieces: two small patches
    // at different heights (the floors of two storeys) are both kept by
    // the plane tilted through them.
    let cos = angle_deg.to_radians().cos();
    let parallel = |p: &Piece| match p.fit {
        Primitive::Plane(q) => dot(q.normal, f.normal).abs() >= cos,
        _ => false,
    };
    if !(parallel(&a) && parallel(&b)) {
        return false;
    }
    let joint_fit = Primitive::Plane(f);
    let tau = a.tau.max(b.tau);
    [a, b].iter().all(|p| {
        let (mut own, mut kept) = (0usize, 0usize);
        for &v in p.seeds {
            let q = &points[v as usize];
            own += usize::from(p.fit.distance(q) <= p.tau);
            kept += usize::from(joint_fit.distance(q) <= tau);
        }
        own > 0 && kept as f64 >= SAME_SHARE * own as f64
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::fit::fit_line_indices;
    use crate::rng::SplitMix64;

    /// Half-width of the uniform jitter across the test pieces; τ is
    /// twice it.
    const NOISE: f64 = 0.03;
    const TAU: f64 = 0.06;

    /// Points on z = `height(x)` over [xa, xb] × [ya, yb], on a grid of
    /// step 0.25, jittered across by ±[`NOISE`]: their ids.
    fn piece(
        out: &mut Vec<[f64; 3]>,
        rng: &mut SplitMix64,
        (xa, xb): (f64, f64),
        (ya, yb): (f64, f64),
        height: impl Fn(f64) -> f64,
    ) -> Vec<u32> {
        let start = out.len() as u32;
        let (nx, ny) = (((xb - xa) / 0.25) as usize, ((yb - ya) / 0.25) as usize);
        for i in 0..=nx {
            for j in 0..=ny {
                let (x, y) = (xa + 0.25 * i as f64, ya + 0.25 * j as f64);
                out.push([x, y, height(x) + NOISE * (2.0 * rng.uniform() - 1.0)]);
            }
        }
        (start..out.len() as u32).collect()
    }

    fn fit(points: &[[f64; 3]], ids: &[u32]) -> Primitive {
        Primitive::Plane(fit_plane_indices(points, ids).unwrap())
    }

    /// A piece's plane, claim radius [`TAU`] and points.
    fn as_piece<'a>(fit: &'a Primitive, seeds: &'a [u32]) -> Piece<'a> {
        Piece {
            fit,
            tau: TAU,
            seeds,
        }
    }

    #[test]
    fn a_wall_bowed_across_a_gap_is_one_plane_for_the_joint_fit_only() {
        // Two pieces of one wall, 10 m apart, each tilted 0.34° the other
        // way (a bow of 3 cm at their far ends): either piece's own plane,
        // carried over the gap, misses the other by 6–18 cm, twice τ, so
        // the test that merges candidates says "two planes"; the plane
        // fitted to both keeps them.
        let mut rng = SplitMix64::new(7);
        let mut pts = Vec::new();
        let a = piece(&mut pts, &mut rng, (0.0, 10.0), (0.0, 10.0), |x| {
            0.006 * (x - 5.0)
        });
        let b = piece(&mut pts, &mut rng, (20.0, 30.0), (0.0, 10.0), |x| {
            -0.006 * (x - 25.0)
        });
        let (fa, fb) = (fit(&pts, &a), fit(&pts, &b));
        let (pa, pb) = (as_piece(&fa, &a), as_piece(&fb, &b));
        assert!(!same_primitive(pa, pb, 10.0, &pts));
        assert!(joint_plane_keeps(pa, pb, 10.0, &pts));
        assert!(joint_plane_keeps(pb, pa, 10.0, &pts));
    }

    #[test]
    fn two_small_patches_at_two_heights_are_not_one_plane() {
        // Two flat patches a quarter metre across, 10 m apart and 2.5 m
        // apart in height (the floors of two storeys): the plane fitted to
        // both tilts 14° and keeps each within τ, so only its angle to the
        // patches tells them apart. Without the angle test (90°) they would
        // be one plane.
        let mut rng = SplitMix64::new(9);
        let mut pts = Vec::new();
        let a = piece(&mut pts, &mut rng, (0.0, 0.25), (0.0, 0.25), |_| 0.0);
        let b = piece(&mut pts, &mut rng, (10.0, 10.25), (0.0, 0.25), |_| 2.5);
        let (fa, fb) = (fit(&pts, &a), fit(&pts, &b));
        let (pa, pb) = (as_piece(&fa, &a), as_piece(&fb, &b));
        assert!(!joint_plane_keeps(pa, pb, 10.0, &pts));
        assert!(joint_plane_keeps(pa, pb, 90.0, &pts));
    }

    #[test]
    fn a_wall_set_back_by_five_tau_beside_another_stays_apart() {
        // A façade and a wall 30 cm behind it, side by side: the joint
        // plane lies between them and keeps about half of each.
        let mut rng = SplitMix64::new(8);
        let mut pts = Vec::new();
        let a = piece(&mut pts, &mut rng, (0.0, 10.0), (0.0, 10.0), |_| 0.0);
        let b = piece(&mut pts, &mut rng, (0.0, 10.0), (12.0, 22.0), |_| 0.3);
        let (fa, fb) = (fit(&pts, &a), fit(&pts, &b));
        let (pa, pb) = (as_piece(&fa, &a), as_piece(&fb, &b));
        assert!(!same_primitive(pa, pb, 10.0, &pts));
        assert!(!joint_plane_keeps(pa, pb, 10.0, &pts));
        // The same two pieces in one plane are one.
        let mut flat = pts.clone();
        for &v in &b {
            flat[v as usize][2] -= 0.3;
        }
        let fb = fit(&flat, &b);
        assert!(joint_plane_keeps(pa, as_piece(&fb, &b), 10.0, &flat));
    }

    #[test]
    fn pieces_of_a_noisy_line_are_one_line_and_crossing_lines_are_not() {
        // Two runs of four points along the x axis, 2 apart, zigzagging by
        // ±0.03 (τ = 0.1) in opposite phases, so that their own fits tilt
        // 0.7° either way; then a run along a line at 30° from the first
        // one's end.
        let zig = |x0: f64, s: f64| -> Vec<[f64; 3]> {
            (0..4)
                .map(|i| {
                    [
                        x0 + i as f64,
                        s * 0.03 * if i % 2 == 0 { 1.0 } else { -1.0 },
                        0.0,
                    ]
                })
                .collect()
        };
        let mut pts = zig(0.0, 1.0);
        pts.extend(zig(5.0, -1.0));
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        pts.extend((1..5).map(|i| [3.0 + i as f64 * c, i as f64 * s, 0.0]));
        let ids: Vec<Vec<u32>> = (0..3).map(|k| (4 * k..4 * k + 4).collect()).collect();
        let fits: Vec<Primitive> = ids
            .iter()
            .map(|s| Primitive::Line(fit_line_indices(&pts, s).unwrap()))
            .collect();
        let piece = |k: usize| Piece {
            fit: &fits[k],
            tau: 0.1,
            seeds: &ids[k],
        };
        assert!(joint_line_keeps(piece(0), piece(1), &pts));
        assert!(!joint_line_keeps(piece(0), piece(2), &pts));
        // Within the part angle and each other's claim radius too.
        assert!(same_primitive(piece(0), piece(1), 10.0, &pts));
        assert!(!same_primitive(piece(0), piece(2), 10.0, &pts));
    }
}
