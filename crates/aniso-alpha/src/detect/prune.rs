//! Exact pruning before triangulating one orientation.
//!
//! A point with no other point within distance `2α` (in the transformed
//! space Q·P, i.e. in the metric d_Q) cannot be a vertex of `F_{k,α,Q}`:
//! the vertices of a simplex of `F_α` lie on a sphere of radius α, so they
//! are pairwise at most `2α` apart. Nor can it lie inside an empty-ball
//! candidate of another simplex: such a ball has radius α and a vertex on
//! its boundary, so every point inside it is within `2α` of that vertex.
//! Dropping such *isolated* points therefore leaves `F_{k,α,Q}` unchanged
//! while the triangulation shrinks to the neighbourhood of the structures
//! (a sparse background is mostly isolated at the scale α).
//!
//! The neighbour search uses a uniform grid of cell side at least `2α`,
//! stored as flat arrays (a counting sort of the points into cells, no hash
//! map); each point looks at its own and the 26 adjacent cells. Across the
//! orientations of one run, [`CandidatePairs`] finds the pairs within
//! `2α·λ_max` once, and each orientation only tests those under its Q.

/// Marks the points that have another point within distance `radius`
/// (inclusive). Points are `[f64; 3]` in the metric of interest.
pub fn non_isolated(points: &[[f64; 3]], radius: f64) -> Vec<bool> {
    let n = points.len();
    let mut keep = vec![false; n];
    if n < 2 || radius.is_nan() || radius < 0.0 {
        return keep;
    }
    if !radius.is_finite() {
        return vec![true; n];
    }
    let r2 = radius * radius;
    let grid = Grid::new(points, radius);
    for (i, p) in points.iter().enumerate() {
        if keep[i] {
            continue;
        }
        grid.for_near(points, p, |j| {
            if j as usize == i {
                return true;
            }
            let q = &points[j as usize];
            let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
            if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r2 {
                keep[i] = true;
                keep[j as usize] = true;
                return false;
            }
            true
        });
    }
    keep
}

/// A uniform grid over a point set, stored as a counting sort of the
/// points into cells (CSR): cell side at least `radius` (so points within
/// `radius` are in adjacent cells), enlarged until there are at most about
/// 4n cells (a larger side only costs distance checks).
struct Grid {
    lo: [f64; 3],
    side: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    sorted: Vec<u32>,
}

impl Grid {
    fn new(points: &[[f64; 3]], radius: f64) -> Grid {
        let n = points.len();
        let (lo, hi) = crate::geometry::bounding_box(points);
        let mut side = radius.max(f64::MIN_POSITIVE);
        let cells_for = |side: f64| -> [usize; 3] {
            [0, 1, 2].map(|k| (((hi[k] - lo[k]) / side).floor() as usize).saturating_add(1))
        };
        let budget = 4 * n + 64;
        loop {
            let d = cells_for(side);
            let total = d[0].saturating_mul(d[1]).saturating_mul(d[2]);
            if total <= budget {
                break;
            }
            side *= ((total as f64) / (budget as f64)).cbrt().max(1.01);
        }
        let dims = cells_for(side);
        let mut g = Grid {
            lo,
            side,
            dims,
            start: Vec::new(),
            sorted: Vec::new(),
        };
        let total = dims[0] * dims[1] * dims[2];
        let mut start = vec![0u32; total + 1];
        let cell: Vec<u32> = points
            .iter()
            .map(|p| g.index(g.cell_of(p)) as u32)
            .collect();
        for &c in &cell {
            start[c as usize + 1] += 1;
        }
        for i in 0..total {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut sorted = vec![0u32; n];
        for (i, &c) in cell.iter().enumerate() {
            sorted[fill[c as usize] as usize] = i as u32;
            fill[c as usize] += 1;
        }
        g.start = start;
        g.sorted = sorted;
        g
    }

    fn cell_of(&self, p: &[f64; 3]) -> [usize; 3] {
        [0, 1, 2].map(|k| (((p[k] - self.lo[k]) / self.side) as usize).min(self.dims[k] - 1))
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[0] * self.dims[1] + c[1]) * self.dims[2] + c[2]
    }

    /// Calls `f` on every point of the 27 cells around `p` until it
    /// returns false.
    fn for_near(&self, _points: &[[f64; 3]], p: &[f64; 3], mut f: impl FnMut(u32) -> bool) {
        let c = self.cell_of(p);
        let range = |k: usize| c[k].saturating_sub(1)..=(c[k] + 1).min(self.dims[k] - 1);
        for x in range(0) {
            for y in range(1) {
                for z in range(2) {
                    let ci = self.index([x, y, z]);
                    for &j in &self.sorted[self.start[ci] as usize..self.start[ci + 1] as usize] {
                        if !f(j) {
                            return;
                        }
                    }
                }
            }
        }
    }
}

/// The pairs of points within a Euclidean distance, found once and then
/// tested under many linear maps: since `|Q·d| ≥ |d| / λ_max` for
/// `Q = diag(e)·R` with `min(e) = 1/λ_max`, every pair within `2α` in a
/// Q-metric is within `2α·λ_max` in Euclidean distance.
#[derive(Debug, Clone)]
pub struct CandidatePairs {
    /// Pairs `(i, j)`, `i < j`.
    pairs: Vec<[u32; 2]>,
    n: usize,
}

impl CandidatePairs {
    /// All pairs within `radius` (inclusive), or `None` if there are more
    /// than `max_pairs` of them.
    pub fn new(points: &[[f64; 3]], radius: f64, max_pairs: usize) -> Option<CandidatePairs> {
        let n = points.len();
        let mut pairs = Vec::new();
        if n >= 2 && radius.is_finite() && radius >= 0.0 {
            let r2 = radius * radius;
            let grid = Grid::new(points, radius);
            for (i, p) in points.iter().enumerate() {
                let mut over = false;
                grid.for_near(points, p, |j| {
                    if j as usize > i {
                        let q = &points[j as usize];
                        let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
                        if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r2 {
                            pairs.push([i as u32, j]);
                            over = pairs.len() > max_pairs;
                        }
                    }
                    !over
                });
                if over {
                    return None;
                }
            }
        }
        Some(CandidatePairs { pairs, n })
    }

    /// [`non_isolated`] in the metric `|Q·(p − q)|` (Q given by its rows),
    /// restricted to the candidate pairs: exact as long as every pair
    /// within `radius` under Q is a candidate.
    pub fn non_isolated_under(
        &self,
        points: &[[f64; 3]],
        q: &[[f64; 3]; 3],
        radius: f64,
    ) -> Vec<bool> {
        self.core_under(points, q, radius, 1)
    }

    /// The `k`-core of the graph joining the points within `radius` under
    /// Q (restricted to the candidate pairs): the largest set in which every
    /// point has at least `k` neighbours. For `radius = 2α` it is exact for
    /// `F_{k,α,Q}`: the vertices of a k-simplex of `F_α` are pairwise within
    /// 2α, so together they have degree ≥ k and survive the peeling; and a
    /// point inside an empty-ball candidate of a simplex of the core is
    /// within 2α of its k + 1 vertices, so it is never peeled either. `k = 1`
    /// drops the isolated points; `k = 2` (planes) also drops isolated
    /// pairs and chains of background points. (The detector uses `k = 1`:
    /// with `k = 2` a clean plane is often left alone, and a nearly flat
    /// set triangulates into slivers that cost more than the points saved.)
    pub fn core_under(
        &self,
        points: &[[f64; 3]],
        q: &[[f64; 3]; 3],
        radius: f64,
        k: u32,
    ) -> Vec<bool> {
        let n = self.n;
        let r2 = radius * radius;
        let mut close: Vec<[u32; 2]> = Vec::new();
        let mut deg = vec![0u32; n];
        for &[i, j] in &self.pairs {
            let (a, b) = (&points[i as usize], &points[j as usize]);
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            let mut s = 0.0;
            for row in q {
                let x = row[0] * d[0] + row[1] * d[1] + row[2] * d[2];
                s += x * x;
            }
            if s <= r2 {
                close.push([i, j]);
                deg[i as usize] += 1;
                deg[j as usize] += 1;
            }
        }
        if k <= 1 {
            return deg.iter().map(|&d| d >= 1).collect();
        }
        // Adjacency (CSR) of the close pairs, then peel.
        let mut start = vec![0u32; n + 1];
        for &[i, j] in &close {
            start[i as usize + 1] += 1;
            start[j as usize + 1] += 1;
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut adj = vec![0u32; close.len() * 2];
        for &[i, j] in &close {
            adj[fill[i as usize] as usize] = j;
            fill[i as usize] += 1;
            adj[fill[j as usize] as usize] = i;
            fill[j as usize] += 1;
        }
        let mut removed = vec![false; n];
        let mut stack: Vec<u32> = (0..n as u32).filter(|&v| deg[v as usize] < k).collect();
        for &v in &stack {
            removed[v as usize] = true;
        }
        while let Some(v) = stack.pop() {
            for &w in &adj[start[v as usize] as usize..start[v as usize + 1] as usize] {
                let w = w as usize;
                if !removed[w] {
                    deg[w] -= 1;
                    if deg[w] < k {
                        removed[w] = true;
                        stack.push(w as u32);
                    }
                }
            }
        }
        removed.iter().map(|&r| !r).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn a_far_point_is_isolated() {
        let p = [[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [10.0, 0.0, 0.0]];
        assert_eq!(non_isolated(&p, 2.0), vec![true, true, false]);
        // The radius is inclusive.
        assert_eq!(non_isolated(&p, 1.5), vec![true, true, false]);
        assert_eq!(non_isolated(&p, 1.4), vec![false; 3]);
    }

    #[test]
    fn matches_brute_force() {
        let mut rng = SplitMix64::new(11);
        let mut rnd = || rng.uniform();
        for round in 0..50 {
            let n = 1 + round * 7;
            let scale = [1.0, 10.0, 100.0][round % 3];
            let pts: Vec<[f64; 3]> = (0..n)
                .map(|_| [rnd() * scale, rnd() * scale, rnd() * 0.1 * scale])
                .collect();
            for radius in [0.0, 0.5, 1.0, 3.0] {
                let fast = non_isolated(&pts, radius);
                for i in 0..n {
                    let brute = (0..n).any(|j| {
                        j != i && {
                            let d: f64 = (0..3).map(|k| (pts[i][k] - pts[j][k]).powi(2)).sum();
                            d <= radius * radius
                        }
                    });
                    assert_eq!(fast[i], brute, "n {n} radius {radius} point {i}");
                }
            }
        }
    }

    #[test]
    fn candidate_pairs_under_a_map_match_brute_force() {
        let mut rng = SplitMix64::new(3);
        let mut rnd = || rng.uniform();
        for round in 0..20 {
            let pts: Vec<[f64; 3]> = (0..200)
                .map(|_| [rnd() * 60.0, rnd() * 60.0, rnd() * 60.0])
                .collect();
            let (t, p, f) = (rnd() * 6.0, rnd() * 3.0 - 1.5, rnd() * 6.0);
            let r = crate::aniso::rotation_from_euler(t, p, f);
            let e = [1.0, 0.25, 0.125];
            let q = [0, 1, 2].map(|i| r[i].map(|x| x * e[i]));
            let radius = 1.0 + round as f64 * 0.3;
            let cand = CandidatePairs::new(&pts, radius * 8.0 * (1.0 + 1e-9), usize::MAX).unwrap();
            let fast = cand.non_isolated_under(&pts, &q, radius);
            for i in 0..pts.len() {
                let brute = (0..pts.len()).any(|j| {
                    j != i && {
                        let d = [0, 1, 2].map(|k| pts[i][k] - pts[j][k]);
                        let s: f64 = q
                            .iter()
                            .map(|row| (row[0] * d[0] + row[1] * d[1] + row[2] * d[2]).powi(2))
                            .sum();
                        s <= radius * radius
                    }
                });
                assert_eq!(fast[i], brute, "round {round} point {i}");
            }
        }
        assert!(CandidatePairs::new(&[[0.0; 3]; 10], 1.0, 5).is_none());
    }

    #[test]
    fn two_core_peels_pairs_and_chains_but_keeps_triangles() {
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        // A triangle (0, 1, 2), a pair (3, 4), a chain 5-6-7 hanging off
        // nothing, and a point 8 near the triangle's corner 0 only.
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [10.0, 0.0, 0.0],
            [11.0, 0.0, 0.0],
            [20.0, 0.0, 0.0],
            [21.0, 0.0, 0.0],
            [22.0, 0.0, 0.0],
            [-1.0, -0.5, 0.0],
        ];
        let c = CandidatePairs::new(&pts, 1.5, usize::MAX).unwrap();
        assert_eq!(
            c.core_under(&pts, &id, 1.5, 2),
            vec![true, true, true, false, false, false, false, false, false]
        );
        assert_eq!(
            c.core_under(&pts, &id, 1.5, 1),
            vec![true, true, true, true, true, true, true, true, true]
        );
    }

    #[test]
    fn exact_distance_is_inclusive_and_duplicates_count() {
        assert_eq!(
            non_isolated(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], 2.0),
            vec![true, true]
        );
        assert_eq!(
            non_isolated(&[[5.0, 5.0, 5.0], [5.0, 5.0, 5.0], [9.0, 9.0, 9.0]], 0.0),
            vec![true, true, false]
        );
    }
}
