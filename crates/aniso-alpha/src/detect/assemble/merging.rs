//! Stage 5 of the assembly for planes (docs/method.md §4, "One plane, one
//! part"): planar parts that are the same plane and lie near each other
//! (the panes of one wall's windows, a wall cut in two by an occluder, the
//! ground on both sides of a house) become one part in several pieces, as
//! a plane is for RANSAC and for the labels of CGAL's scans.
//!
//! **What a part is.** Two pieces of one plane are one part when the gap
//! between them is at most the size of the larger one (the longer side of
//! its bounding rectangle on its plane): a gap smaller than a piece reads
//! as a hole in one surface (an occluder's shadow across a wall, a
//! window); a gap larger than both is two surfaces that happen to be
//! coplanar (the flat roofs of two houses at one height, the floors of two
//! buildings), which stay two parts. The gap is the distance between the
//! pieces' bounding boxes. Nor are two pieces one part when a solid stands
//! between them ([`super::crossing`]: a surface rises from their plane
//! between them at least as far as the gap is wide): they are two faces
//! (the arms of a cross, a table top cut in two by a box).
//!
//! Two parts are one plane by the test that merges candidates (parallel,
//! each centroid within τ of the other's plane, or most of the smaller
//! one's points within τ of the larger one's plane) or by the plane fitted
//! to both (it keeps, for each piece, most of what its own plane keeps).
//! A pair is only tested when its normals are within the part angle, each
//! one's plane passes within τ of the other's bounding box, and the gap
//! rule holds; the pairs come from a sweep along x over the boxes grown by
//! their parts' sizes (no pair is looked at whose grown extents along x
//! are apart, which the gap rule excludes), so
//! that a large area with thousands of parallel parts (every roof at one
//! height) costs about one test per neighbouring pair. The pairs are taken
//! largest pieces first, and each is tested as the groups merged so far:
//! pairwise tests alone chain small patches at several heights (floors of
//! two storeys, each a few dozen points) into one plane tilted through all
//! of them. A group keeps its points' moments, so the joint plane of two
//! groups costs O(1), and a test reads the smaller group's points and at
//! most [`JOINT_SAMPLE`] of the larger one's.

use super::super::detection::Primitive;
use super::crossing::Crossings;
use super::moments::Moments;
use super::same::SAME_SHARE;
use super::{Candidate, Draft, Shape};
use crate::geometry::{box_gap, dot, sub, Box3};
use crate::unionfind::UnionFind;

/// The most points of the larger group that the joint plane's test reads
/// (evenly strided): the share it keeps is then known to about 1% (the
/// standard error of a share from 4,096 draws is at most 0.8%).
const JOINT_SAMPLE: usize = 4096;

/// Merges the planar parts that are one plane (module doc); how many
/// pairs of them that are one plane stay apart, a solid between them.
pub(super) fn planes_apart<S: Shape>(
    parts: &mut Vec<Draft>,
    cands: &[Candidate],
    points: &[[f64; 3]],
    angle_deg: f64,
) -> usize {
    if parts.len() < 2 {
        return 0;
    }
    let crossings = Crossings::new(parts, cands, points, angle_deg);
    let pairs = pairs(parts, &crossings.boxes, cands, angle_deg);
    let mut groups = Groups::new(parts, cands, points);
    let mut uf = UnionFind::new(parts.len());
    let (mut merged, mut apart) = (false, 0);
    for (a, b) in pairs {
        let (ra, rb) = (uf.find(a as u32) as usize, uf.find(b as u32) as usize);
        if ra == rb || !groups.one_plane(parts, ra, rb, points, angle_deg) {
            continue;
        }
        if crossings.crossed(parts, points, a, b) {
            apart += 1;
        } else {
            groups.join(&mut uf, a, b, (ra, rb));
            merged = true;
        }
    }
    if merged {
        regroup::<S>(parts, uf.sets(), points);
    }
    apart
}

/// Whether the plane of `fit` passes within `tau` of the box `b`: the
/// signed distances of the box's corners span [−τ, τ].
fn plane_meets_box(fit: &Primitive, tau: f64, b: &Box3) -> bool {
    let Primitive::Plane(f) = fit else {
        return false;
    };
    let (lo, hi) = b;
    let (mut dmin, mut dmax) = (f64::INFINITY, f64::NEG_INFINITY);
    for c in 0..8 {
        let q = [
            if c & 1 == 0 { lo[0] } else { hi[0] },
            if c & 2 == 0 { lo[1] } else { hi[1] },
            if c & 4 == 0 { lo[2] } else { hi[2] },
        ];
        let d = dot(sub(q, f.centroid), f.normal);
        dmin = dmin.min(d);
        dmax = dmax.max(d);
    }
    dmin <= tau && dmax >= -tau
}

/// The size of a planar part: the longer side of its bounding rectangle
/// on its plane.
fn size(fit: &Primitive) -> f64 {
    match fit {
        Primitive::Plane(f) => f.extent[0].max(f.extent[1]),
        _ => 0.0,
    }
}

/// The pairs of parts passing the cheap tests (parallel normals, each
/// plane within its τ of the other's box, the gap at most the larger
/// part's size), largest pieces first.
fn pairs(
    parts: &[Draft],
    boxes: &[Box3],
    cands: &[Candidate],
    angle_deg: f64,
) -> Vec<(usize, usize)> {
    let sizes: Vec<f64> = parts.iter().map(|p| size(&p.fit)).collect();
    let tau = |a: usize| cands[parts[a].cand].tau;
    let cos = angle_deg.to_radians().cos();
    // Sweep along x over each part's box grown by its size: two parts
    // within the gap rule have grown extents that overlap.
    let start = |a: usize| boxes[a].0[0] - sizes[a];
    let end = |a: usize| boxes[a].1[0] + sizes[a];
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by(|&a, &b| start(a).total_cmp(&start(b)).then(a.cmp(&b)));
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for (k, &a) in order.iter().enumerate() {
        for &b in order[k + 1..].iter() {
            if start(b) > end(a) {
                break;
            }
            if box_gap(&boxes[a], &boxes[b]) <= sizes[a].max(sizes[b])
                && parallel_planes(&parts[a].fit, &parts[b].fit, cos)
                && (plane_meets_box(&parts[a].fit, tau(a), &boxes[b])
                    || plane_meets_box(&parts[b].fit, tau(b), &boxes[a]))
            {
                pairs.push((a.min(b), a.max(b)));
            }
        }
    }
    let by_size = |p: &(usize, usize)| {
        let (x, y) = (parts[p.0].members.len(), parts[p.1].members.len());
        (x.max(y), x.min(y))
    };
    pairs.sort_by(|p, q| by_size(q).cmp(&by_size(p)).then(p.cmp(q)));
    pairs
}

/// Whether two primitives are planes within the angle of cosine `cos`.
fn parallel_planes(a: &Primitive, b: &Primitive, cos: f64) -> bool {
    match (a, b) {
        (Primitive::Plane(fa), Primitive::Plane(fb)) => dot(fa.normal, fb.normal).abs() >= cos,
        _ => false,
    }
}

/// The groups merged so far, at each group's root: its parts, the
/// moments of its points, their plane, and its claim radius (its largest
/// piece's).
struct Groups {
    parts: Vec<Vec<usize>>,
    moments: Vec<Moments>,
    fit: Vec<Primitive>,
    tau: Vec<f64>,
}

impl Groups {
    /// Each part alone.
    fn new(parts: &[Draft], cands: &[Candidate], points: &[[f64; 3]]) -> Self {
        Groups {
            parts: (0..parts.len()).map(|p| vec![p]).collect(),
            moments: parts
                .iter()
                .map(|p| Moments::of(&p.members, points))
                .collect(),
            fit: parts.iter().map(|p| p.fit.clone()).collect(),
            tau: parts.iter().map(|p| cands[p.cand].tau).collect(),
        }
    }

    /// The points of group `r`, every `stride`-th (by position in the
    /// group's parts, in order).
    fn points_of<'a>(
        &'a self,
        parts: &'a [Draft],
        r: usize,
        stride: usize,
    ) -> impl Iterator<Item = u32> + 'a {
        self.parts[r]
            .iter()
            .flat_map(move |&p| parts[p].members.iter().copied())
            .step_by(stride.max(1))
    }

    /// Whether the groups at roots `a` and `b` are one plane (module doc).
    fn one_plane(
        &self,
        parts: &[Draft],
        a: usize,
        b: usize,
        points: &[[f64; 3]],
        angle_deg: f64,
    ) -> bool {
        let cos = angle_deg.to_radians().cos();
        if !parallel_planes(&self.fit[a], &self.fit[b], cos) {
            return false;
        }
        let (ma, mb) = (&self.moments[a], &self.moments[b]);
        if self.fit[a].distance(&mb.centroid) <= self.tau[a]
            && self.fit[b].distance(&ma.centroid) <= self.tau[b]
        {
            return true;
        }
        let (big, small) = if ma.n >= mb.n { (a, b) } else { (b, a) };
        let near = self
            .points_of(parts, small, 1)
            .filter(|&v| self.fit[big].distance(&points[v as usize]) <= self.tau[big])
            .count();
        if near as f64 >= SAME_SHARE * self.moments[small].n {
            return true;
        }
        self.joint_keeps(parts, a, b, points, cos)
    }

    /// Whether the plane fitted to both groups is parallel to each and
    /// keeps, of each group's points, at least [`SAME_SHARE`] of those its
    /// own plane keeps within its τ (the larger group read on a sample of
    /// at most [`JOINT_SAMPLE`] points). Two pieces of one wall fitted
    /// apart can tilt by a degree or so each (noise, a slight bow of the
    /// wall), so that either one's plane, carried over the gap, misses the
    /// other by more than τ; the joint plane passes through both. Two
    /// distinct parallel planes (a façade and a wall set back from it by
    /// more than τ) leave about half of each piece outside the joint
    /// plane, which lies between them.
    fn joint_keeps(
        &self,
        parts: &[Draft],
        a: usize,
        b: usize,
        points: &[[f64; 3]],
        cos: f64,
    ) -> bool {
        let joint = self.moments[a].join(&self.moments[b]).plane();
        if !(parallel_planes(&joint, &self.fit[a], cos)
            && parallel_planes(&joint, &self.fit[b], cos))
        {
            return false;
        }
        let tau = self.tau[a].max(self.tau[b]);
        [a, b].iter().all(|&r| {
            let stride = (self.moments[r].n as usize).div_ceil(JOINT_SAMPLE);
            let (mut own, mut kept) = (0usize, 0usize);
            for v in self.points_of(parts, r, stride) {
                let q = &points[v as usize];
                own += usize::from(self.fit[r].distance(q) <= self.tau[r]);
                kept += usize::from(joint.distance(q) <= tau);
            }
            own > 0 && kept as f64 >= SAME_SHARE * own as f64
        })
    }

    /// Joins the groups of parts `a` and `b`, at roots `ra` and `rb`.
    fn join(&mut self, uf: &mut UnionFind, a: usize, b: usize, (ra, rb): (usize, usize)) {
        uf.union_min_root(a as u32, b as u32);
        let root = uf.find(a as u32) as usize;
        let other = if root == ra { rb } else { ra };
        let big = if self.moments[other].n > self.moments[root].n {
            other
        } else {
            root
        };
        let moved = std::mem::take(&mut self.parts[other]);
        self.parts[root].extend(moved);
        self.moments[root] = self.moments[root].join(&self.moments[other]);
        self.tau[root] = self.tau[big];
        self.fit[root] = self.moments[root].plane();
    }
}

/// The parts after merging: per set of the union-find (`sets`, at their
/// roots), the part alone, or one part of the group's members (sorted)
/// and their fit, the largest piece's candidate (its claim radius and
/// cell), the others' as its pieces, and the smallest NFA.
fn regroup<S: Shape>(parts: &mut Vec<Draft>, sets: Vec<Vec<u32>>, points: &[[f64; 3]]) {
    let mut old: Vec<Option<Draft>> = parts.drain(..).map(Some).collect();
    for set in sets {
        let group: Vec<Draft> = set.iter().filter_map(|&p| old[p as usize].take()).collect();
        if group.len() < 2 {
            parts.extend(group);
            continue;
        }
        let cand = group
            .iter()
            .max_by(|x, y| {
                x.members
                    .len()
                    .cmp(&y.members.len())
                    .then(y.members[0].cmp(&x.members[0]))
            })
            .map_or(group[0].cand, |p| p.cand);
        let log10_nfa = group
            .iter()
            .map(|p| p.log10_nfa)
            .fold(f64::INFINITY, f64::min);
        let mut members: Vec<u32> = group
            .iter()
            .flat_map(|p| p.members.iter().copied())
            .collect();
        members.sort_unstable();
        let fit = S::fit(points, &members);
        if matches!(fit, Primitive::None) {
            // Not reached (each piece has a plane); the pieces stay.
            parts.extend(group);
            continue;
        }
        let pieces: Vec<usize> = group
            .iter()
            .flat_map(|p| std::iter::once(p.cand).chain(p.pieces.iter().copied()))
            .filter(|&c| c != cand)
            .collect();
        parts.push(Draft {
            members,
            fit,
            cand,
            pieces,
            log10_nfa,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::same::same_primitive;
    use super::*;
    use crate::detect::fit::fit_plane_indices;
    use crate::rng::SplitMix64;

    /// A part of the grid points of [x0, x0 + 0.5·(nx − 1)] × [0, 4] (step
    /// 0.5) on z = `z`, its candidate at index `cand` (τ 0.05).
    fn patch(
        pts: &mut Vec<[f64; 3]>,
        (x0, nx): (f64, usize),
        z: f64,
        cand: usize,
    ) -> (Draft, Candidate) {
        let start = pts.len() as u32;
        for i in 0..nx {
            for j in 0..9 {
                pts.push([x0 + 0.5 * i as f64, 0.5 * j as f64, z]);
            }
        }
        let members: Vec<u32> = (start..pts.len() as u32).collect();
        let fit = Primitive::Plane(fit_plane_indices(pts, &members).unwrap());
        Draft::with_candidate(pts, members, fit, cand, (0.05, 1.0))
    }

    #[test]
    fn pieces_of_one_plane_merge_across_a_gap_smaller_than_them_and_not_farther() {
        // Patches 4 × 4 on z = 0 at x = 0, 6 and 30 (gaps of 2, then 20),
        // the middle one the largest (5 × 4); one on z = 1 beside the
        // first (parallel, a step up).
        let mut pts = Vec::new();
        let (mut parts, mut cands) = (Vec::new(), Vec::new());
        let at = [
            ((0.0, 9), 0.0),
            ((6.0, 11), 0.0),
            ((30.0, 9), 0.0),
            ((-6.0, 9), 1.0),
        ];
        for (k, (x, z)) in at.into_iter().enumerate() {
            let (d, c) = patch(&mut pts, x, z, k);
            parts.push(d);
            cands.push(c);
        }
        planes_apart::<[u32; 3]>(&mut parts, &cands, &pts, 10.0);
        assert_eq!(parts.len(), 3);
        // The group's members, sorted; the largest piece lends its
        // candidate; the other is its piece.
        assert_eq!(parts[0].members, (0..81 + 99).collect::<Vec<u32>>());
        assert_eq!(parts[0].cand, 1);
        assert_eq!(parts[0].pieces, [0]);
        assert_eq!(parts[0].log10_nfa, -1.0);
        assert!(parts[0].fit.rms() < 1e-9);
        // The far patch (20 away, five times its size) and the step stay.
        assert_eq!(parts[1].cand, 2);
        assert_eq!(parts[2].cand, 3);
    }

    /// Half-width of the uniform jitter across the test pieces; τ is
    /// twice it.
    const NOISE: f64 = 0.03;
    const TAU: f64 = 0.06;

    /// A part of the points on z = `height(x)` over [xa, xb] × [ya, yb],
    /// on a grid of step 0.25, jittered across by ±[`NOISE`], its
    /// candidate at index `cand` (τ = [`TAU`]).
    fn jittered(
        out: &mut Vec<[f64; 3]>,
        rng: &mut SplitMix64,
        (xa, xb): (f64, f64),
        (ya, yb): (f64, f64),
        height: impl Fn(f64) -> f64,
        cand: usize,
    ) -> (Draft, Candidate) {
        let start = out.len() as u32;
        let (nx, ny) = (((xb - xa) / 0.25) as usize, ((yb - ya) / 0.25) as usize);
        for i in 0..=nx {
            for j in 0..=ny {
                let (x, y) = (xa + 0.25 * i as f64, ya + 0.25 * j as f64);
                out.push([x, y, height(x) + NOISE * (2.0 * rng.uniform() - 1.0)]);
            }
        }
        let members: Vec<u32> = (start..out.len() as u32).collect();
        let fit = Primitive::Plane(fit_plane_indices(out, &members).unwrap());
        Draft::with_candidate(out, members, fit, cand, (TAU, 1.0))
    }

    /// The parts left of `pieces` after merging at the part angle `angle`.
    fn merged(pts: &[[f64; 3]], pieces: Vec<(Draft, Candidate)>, angle: f64) -> usize {
        let (mut parts, cands): (Vec<Draft>, Vec<Candidate>) = pieces.into_iter().unzip();
        planes_apart::<[u32; 3]>(&mut parts, &cands, pts, angle);
        parts.len()
    }

    #[test]
    fn a_wall_bowed_across_a_gap_is_one_plane_for_the_joint_fit() {
        // Two pieces of one wall, 10 m apart, each tilted 0.34° the other
        // way (a bow of 3 cm at their far ends): either piece's own plane,
        // carried over the gap, misses the other by 6–18 cm, twice τ, so
        // the test that merges candidates says "two planes"; the plane
        // fitted to both keeps them.
        let mut rng = SplitMix64::new(7);
        let mut pts = Vec::new();
        let a = jittered(
            &mut pts,
            &mut rng,
            (0.0, 10.0),
            (0.0, 10.0),
            |x| 0.006 * (x - 5.0),
            0,
        );
        let b = jittered(
            &mut pts,
            &mut rng,
            (20.0, 30.0),
            (0.0, 10.0),
            |x| -0.006 * (x - 25.0),
            1,
        );
        assert!(!same_primitive(a.1.piece(), b.1.piece(), 10.0, &pts));
        assert_eq!(merged(&pts, vec![a, b], 10.0), 1);
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
        let a = jittered(&mut pts, &mut rng, (0.0, 0.25), (0.0, 0.25), |_| 0.0, 0);
        let b = jittered(&mut pts, &mut rng, (10.0, 10.25), (0.0, 0.25), |_| 2.5, 1);
        let (parts, cands): (Vec<Draft>, Vec<Candidate>) = vec![a, b].into_iter().unzip();
        let groups = Groups::new(&parts, &cands, &pts);
        let cos = |deg: f64| deg.to_radians().cos();
        assert!(!groups.joint_keeps(&parts, 0, 1, &pts, cos(10.0)));
        assert!(groups.joint_keeps(&parts, 0, 1, &pts, cos(90.0)));
    }

    #[test]
    fn a_wall_set_back_by_five_tau_beside_another_stays_apart() {
        // A façade and a wall 30 cm behind it, side by side: the joint
        // plane lies between them and keeps about half of each.
        let mut rng = SplitMix64::new(8);
        let mut pts = Vec::new();
        let a = jittered(&mut pts, &mut rng, (0.0, 10.0), (0.0, 10.0), |_| 0.0, 0);
        let b = jittered(&mut pts, &mut rng, (0.0, 10.0), (12.0, 22.0), |_| 0.3, 1);
        assert_eq!(merged(&pts, vec![a.clone(), b.clone()], 10.0), 2);
        // The same two pieces in one plane are one.
        let mut flat = pts.clone();
        for &v in &b.0.members {
            flat[v as usize][2] -= 0.3;
        }
        let fb = Primitive::Plane(fit_plane_indices(&flat, &b.0.members).unwrap());
        let b = Draft::with_candidate(&flat, b.0.members.clone(), fb, 1, (TAU, 1.0));
        assert_eq!(merged(&flat, vec![a, b], 10.0), 1);
    }

    #[test]
    fn thousands_of_coplanar_roofs_apart_stay_apart_and_cost_a_sweep() {
        // 2,500 flat roofs 4 m across on a 10 m grid, all at one height:
        // each is farther from the next than its own size, so none merge;
        // the sweep looks at the neighbours along x only (a pairwise pass
        // would test three million pairs).
        let mut pts = Vec::new();
        let mut pieces = Vec::new();
        for i in 0..50 {
            for j in 0..50 {
                let start = pts.len() as u32;
                for a in 0..5 {
                    for b in 0..5 {
                        pts.push([10.0 * i as f64 + a as f64, 10.0 * j as f64 + b as f64, 0.0]);
                    }
                }
                let members: Vec<u32> = (start..pts.len() as u32).collect();
                let fit = Primitive::Plane(fit_plane_indices(&pts, &members).unwrap());
                let k = pieces.len();
                pieces.push(Draft::with_candidate(&pts, members, fit, k, (0.05, 1.0)));
            }
        }
        let (parts, cands): (Vec<Draft>, Vec<Candidate>) = pieces.into_iter().unzip();
        let boxes: Vec<Box3> = parts
            .iter()
            .map(|p| crate::geometry::bounding_box_of(&pts, &p.members))
            .collect();
        assert!(pairs(&parts, &boxes, &cands, 10.0).is_empty());
        let mut parts = parts;
        planes_apart::<[u32; 3]>(&mut parts, &cands, &pts, 10.0);
        assert_eq!(parts.len(), 2500);
    }
}
