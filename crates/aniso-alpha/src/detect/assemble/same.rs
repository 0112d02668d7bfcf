//! Whether two candidates or parts are one primitive: the test that merges
//! candidates sharing claimed points (docs/method.md §4, step 3), and for
//! planes lying apart the joint plane's test (step 5).

use super::super::detection::Primitive;
use super::super::fit::fit_line;
use super::Candidate;
use crate::geometry::{dot, sub};

/// Share of a piece's points that must lie within τ of the other's
/// primitive (or of the joint one) for the two to be one.
pub(super) const SAME_SHARE: f64 = 0.8;

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
    let (big, small) = big_and_small(a, b);
    mostly_within(small, big, points)
}

/// The piece with more seeds (`a` on a tie), then the other.
fn big_and_small<'a>(a: Piece<'a>, b: Piece<'a>) -> (Piece<'a>, Piece<'a>) {
    if a.seeds.len() >= b.seeds.len() {
        (a, b)
    } else {
        (b, a)
    }
}

/// Whether most of `small`'s seeds ([`SAME_SHARE`]) lie within `big`'s
/// claim radius of `big`'s primitive.
pub(super) fn mostly_within(small: Piece, big: Piece, points: &[[f64; 3]]) -> bool {
    let near = small
        .seeds
        .iter()
        .filter(|&&v| big.fit.distance(&points[v as usize]) <= big.tau)
        .count();
    near as f64 >= SAME_SHARE * small.seeds.len() as f64
}

/// Of two pieces that are one primitive, the one the other absorbs: the
/// smaller one (fewer seeds) when its claim radius is the wider and most
/// of its points ([`SAME_SHARE`]) lie within the larger one's radius of
/// the larger one's primitive: a piece found at a coarser scale (a mode
/// whose own spacing and noise are inflated, as the blended normals along
/// an edge) on points of a finer one. `Some(true)` when it is `a`.
pub(super) fn absorbed(a: Piece, b: Piece, points: &[[f64; 3]]) -> Option<bool> {
    let (big, small) = big_and_small(a, b);
    let a_is_small = a.seeds.len() < b.seeds.len();
    (small.tau > big.tau && mostly_within(small, big, points)).then_some(a_is_small)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::fit::fit_line_indices;

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
