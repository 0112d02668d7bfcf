//! Stage 5 of the assembly for planes (docs/method.md §4, "One plane, one
//! part"): planar parts that are the same plane but lie apart (the panes
//! of one wall's windows, a wall cut in two by an occluder, the ground on
//! both sides of a house) become one part in several pieces, as a plane is
//! for RANSAC and for the labels of CGAL's scans.
//!
//! Two parts are one plane by the test that merges candidates
//! ([`same_primitive`]) or by the plane fitted to both
//! ([`joint_plane_keeps`]). A pair is only tested when its normals are
//! within the part angle and each one's plane passes within τ of the
//! other's bounding box (O(1); no point of a part whose box the plane
//! misses can be within τ of it). The pairs are taken largest pieces
//! first, and each is tested as the groups merged so far (their members
//! and their joint fit): pairwise tests alone chain small patches at
//! several heights (floors of two storeys, 40 m apart, each a few dozen
//! points) into one plane tilted through all of them.

use super::super::detection::Primitive;
use super::same::{joint_plane_keeps, same_primitive, Piece};
use super::{Candidate, Draft, Shape};
use crate::geometry::{dot, sub};
use crate::unionfind::UnionFind;

/// Merges the planar parts that are one plane (module doc).
pub(super) fn planes_apart<S: Shape>(
    parts: &mut Vec<Draft>,
    cands: &[Candidate],
    points: &[[f64; 3]],
    angle_deg: f64,
) {
    if parts.len() < 2 {
        return;
    }
    let pairs = pairs(parts, cands, points, angle_deg);
    let mut groups = Groups::new(parts, cands);
    let mut uf = UnionFind::new(parts.len());
    let mut merged = false;
    for (a, b) in pairs {
        merged |= groups.join::<S>(&mut uf, a, b, points, angle_deg);
    }
    if merged {
        regroup(parts, uf.sets(), groups);
    }
}

/// The pairs of parts passing the O(1) tests (parallel normals, each
/// plane within its τ of the other's box), largest pieces first.
fn pairs(
    parts: &[Draft],
    cands: &[Candidate],
    points: &[[f64; 3]],
    angle_deg: f64,
) -> Vec<(usize, usize)> {
    let boxes: Vec<([f64; 3], [f64; 3])> = parts
        .iter()
        .map(|p| {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &v in &p.members {
                let q = points[v as usize];
                for k in 0..3 {
                    lo[k] = lo[k].min(q[k]);
                    hi[k] = hi[k].max(q[k]);
                }
            }
            (lo, hi)
        })
        .collect();
    // Whether the plane of part `a` passes within its τ of part `b`'s
    // box: the signed distances of the box's corners span [−τ, τ].
    let near = |a: usize, b: usize| -> bool {
        let Primitive::Plane(f) = &parts[a].fit else {
            return false;
        };
        let tau = cands[parts[a].cand].tau;
        let (lo, hi) = boxes[b];
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
    };
    let cos = angle_deg.to_radians().cos();
    let parallel = |a: usize, b: usize| parallel_planes(&parts[a].fit, &parts[b].fit, cos);
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for a in 0..parts.len() {
        for b in a + 1..parts.len() {
            if parallel(a, b) && (near(a, b) || near(b, a)) {
                pairs.push((a, b));
            }
        }
    }
    let size = |p: &(usize, usize)| {
        let (x, y) = (parts[p.0].members.len(), parts[p.1].members.len());
        (x.max(y), x.min(y))
    };
    pairs.sort_by(|p, q| size(q).cmp(&size(p)).then(p.cmp(q)));
    pairs
}

/// Whether two primitives are planes within the angle of cosine `cos`.
fn parallel_planes(a: &Primitive, b: &Primitive, cos: f64) -> bool {
    match (a, b) {
        (Primitive::Plane(fa), Primitive::Plane(fb)) => dot(fa.normal, fb.normal).abs() >= cos,
        _ => false,
    }
}

/// The groups merged so far, at each group's root: its members (sorted),
/// their fit, and its claim radius (its largest piece's).
struct Groups {
    members: Vec<Vec<u32>>,
    fit: Vec<Primitive>,
    tau: Vec<f64>,
}

impl Groups {
    /// Each part alone.
    fn new(parts: &[Draft], cands: &[Candidate]) -> Self {
        Groups {
            members: parts.iter().map(|p| p.members.clone()).collect(),
            fit: parts.iter().map(|p| p.fit.clone()).collect(),
            tau: parts.iter().map(|p| cands[p.cand].tau).collect(),
        }
    }

    /// The group at root `r` as a piece.
    fn piece(&self, r: usize) -> Piece<'_> {
        Piece {
            fit: &self.fit[r],
            tau: self.tau[r],
            seeds: &self.members[r],
        }
    }

    /// Joins the groups of parts `a` and `b` if they are one plane; whether
    /// they were joined.
    fn join<S: Shape>(
        &mut self,
        uf: &mut UnionFind,
        a: usize,
        b: usize,
        points: &[[f64; 3]],
        angle_deg: f64,
    ) -> bool {
        let (ra, rb) = (uf.find(a as u32) as usize, uf.find(b as u32) as usize);
        if ra == rb {
            return false;
        }
        let cos = angle_deg.to_radians().cos();
        let one = parallel_planes(&self.fit[ra], &self.fit[rb], cos)
            && (same_primitive(self.piece(ra), self.piece(rb), angle_deg, points)
                || joint_plane_keeps(self.piece(ra), self.piece(rb), angle_deg, points));
        if !one {
            return false;
        }
        uf.union_min_root(a as u32, b as u32);
        let root = uf.find(a as u32) as usize;
        let other = if root == ra { rb } else { ra };
        let mut m = std::mem::take(&mut self.members[other]);
        let big = if m.len() > self.members[root].len() {
            other
        } else {
            root
        };
        m.extend_from_slice(&self.members[root]);
        m.sort_unstable();
        self.tau[root] = self.tau[big];
        self.fit[root] = S::fit(points, &m);
        self.members[root] = m;
        true
    }
}

/// The parts after merging: per set of the union-find (`sets`, at their
/// roots), the part alone, or one part of the group's members and fit,
/// the largest piece's candidate (its claim radius and cell), the others'
/// as its pieces, and the smallest NFA.
fn regroup(parts: &mut Vec<Draft>, sets: Vec<Vec<u32>>, mut groups: Groups) {
    let mut old: Vec<Option<Draft>> = parts.drain(..).map(Some).collect();
    for (root, set) in sets.into_iter().enumerate() {
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
        let members = std::mem::take(&mut groups.members[root]);
        let fit = std::mem::replace(&mut groups.fit[root], Primitive::None);
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
    use super::*;
    use crate::detect::fit::fit_plane_indices;

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
    fn pieces_of_one_plane_merge_and_a_parallel_plane_stays() {
        // Three patches on z = 0 with gaps of 6 and 15 between them (the
        // middle one the largest, 11 × 9 points), and one on z = 1
        // (parallel, a step up).
        let mut pts = Vec::new();
        let (mut parts, mut cands) = (Vec::new(), Vec::new());
        let at = [
            ((0.0, 9), 0.0),
            ((10.0, 11), 0.0),
            ((30.0, 9), 0.0),
            ((40.0, 9), 1.0),
        ];
        for (k, (x, z)) in at.into_iter().enumerate() {
            let (d, c) = patch(&mut pts, x, z, k);
            parts.push(d);
            cands.push(c);
        }
        planes_apart::<[u32; 3]>(&mut parts, &cands, &pts, 10.0);
        assert_eq!(parts.len(), 2);
        // The group's members, sorted; the largest piece lends its
        // candidate; the others are its pieces.
        assert_eq!(parts[0].members, (0..81 + 99 + 81).collect::<Vec<u32>>());
        assert_eq!(parts[0].cand, 1);
        assert_eq!(parts[0].pieces, [0, 2]);
        assert_eq!(parts[0].log10_nfa, -2.0);
        assert_eq!(parts[1].cand, 3);
        assert!(parts[0].fit.rms() < 1e-9);
    }
}
