//! A static 3D kd-tree for the nearest-neighbour queries of the detection's
//! local analysis: k nearest points (k ≤ [`MAX_K`], no allocation per query)
//! every point within a radius (through a callback), and every point in
//! an oriented box ([`OrientedBox`]).
//!
//! Flat storage: the points are copied once in tree order (leaves of at
//! most [`LEAF`] consecutive points), nodes are an implicit balanced binary
//! tree over that order (node `i` has children `2i + 1`, `2i + 2`; its
//! range is split at the median along the widest axis of its bounding
//! box), and each node keeps its box for pruning. Building is O(n log n)
//! (`select_nth_unstable` per level), queries are the usual
//! branch-and-bound descent, nearer child first.
//!
//! Written here rather than taken from `kiddo` (5.x): on the 100k-point
//! building scan, 16-nearest queries took 3.5 µs each through kiddo's
//! allocating `nearest_n` and 0.9 µs here (same run); the detection
//! makes several such queries per point. `examples/knn_time.rs` times
//! them on a file.
//!
//! Ties in distance are broken by the smaller point index, so results do
//! not depend on the tree layout.
//!
//! ```
//! use aniso_alpha::geometry::kdtree::KdTree;
//! let pts: Vec<[f64; 3]> = (0..100).map(|i| [i as f64, 0.0, 0.0]).collect();
//! let tree = KdTree::new(&pts, None);
//! let mut out = Vec::new();
//! tree.nearest(&[10.2, 0.0, 0.0], 3, &mut out);
//! assert_eq!(out.iter().map(|x| x.1).collect::<Vec<_>>(), vec![10, 11, 9]);
//! let mut near = Vec::new();
//! tree.within(&[50.0, 0.0, 0.0], 1.5, |i| near.push(i));
//! near.sort_unstable();
//! assert_eq!(near, vec![49, 50, 51]);
//! ```

/// Largest k of a k-nearest query.
pub const MAX_K: usize = 64;

/// Points per leaf at most: 12. Timed with `examples/knn_time.rs` (16
/// nearest of every point, in tree order) on two train scans: mOSD learn
/// 5 0.90 µs a query at 12 points a leaf, 0.82 at 24, 0.83 at 32; AHN
/// 2386_9702 1.04, 0.94, 0.93 µs. Kept at 12: the layout of the tree is
/// the order in which radius queries report their points, and the mean
/// shift of the modes sums them in that order, so another leaf size moves
/// the modes' axes in their last bits (and the scan's orientations with
/// them) for 1% of a run's time.
pub const LEAF: usize = 12;

/// A static kd-tree over a set of points (or a subset of them).
#[derive(Debug, Clone)]
pub struct KdTree {
    /// Points in tree order.
    pts: Vec<[f64; 3]>,
    /// Their indices in the caller's numbering.
    ids: Vec<u32>,
    /// Per node: its range `[start, end)` in tree order.
    range: Vec<(u32, u32)>,
    /// Per node: its bounding box (min, max).
    bbox: Vec<([f64; 3], [f64; 3])>,
}

fn d2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let (x, y, z) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    x * x + y * y + z * z
}

/// Squared distance from `q` to the box's farthest corner.
fn far_d2(q: &[f64; 3], b: &([f64; 3], [f64; 3])) -> f64 {
    let mut s = 0.0;
    for k in 0..3 {
        let d = (q[k] - b.0[k]).abs().max((b.1[k] - q[k]).abs());
        s += d * d;
    }
    s
}

/// Squared distance from `q` to the box, per axis the larger of the two
/// differences or zero inside: no branch to mispredict in the nearest
/// queries' descent (16-nearest 0.90 → 0.88 µs a query on mOSD learn 5,
/// 1.04 → 1.00 on the AHN train tile).
fn box_d2(q: &[f64; 3], b: &([f64; 3], [f64; 3])) -> f64 {
    let mut s = 0.0;
    for k in 0..3 {
        let d = (b.0[k] - q[k]).max(q[k] - b.1[k]).max(0.0);
        s += d * d;
    }
    s
}

/// Points from which [`KdTree::new`] splits a level's nodes on the
/// pool's threads: 2^15. Smaller trees (a tile's, a subsample's) are
/// built while other threads build theirs.
pub const PARALLEL_POINTS: usize = 1 << 15;

/// The nodes' ranges of a tree of `n` points: node `i`'s children are
/// `2i + 1` and `2i + 2`, a range holding more than [`LEAF`] points is
/// cut at its middle, and an absent child is `(0, 0)`.
fn shape(n: usize) -> Vec<(u32, u32)> {
    let mut range: Vec<(u32, u32)> = vec![(0, n as u32)];
    let mut node = 0;
    while node < range.len() {
        let (s, e) = range[node];
        if (e - s) as usize > LEAF && ((s, e) != (0, 0) || node == 0) {
            let mid = s + (e - s) / 2;
            range.resize((2 * node + 1).max(range.len()), (0, 0));
            range.push((s, mid));
            range.push((mid, e));
        }
        node += 1;
    }
    range
}

/// Each node's bounding box, with its points split at their median
/// along the box's widest axis when they are more than [`LEAF`] (the
/// smaller index first among equal coordinates).
fn split_node(points: &[[f64; 3]], slice: &mut [u32]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in slice.iter() {
        let p = points[i as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if slice.len() > LEAF {
        let axis = (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        let mid = slice.len() / 2;
        slice.select_nth_unstable_by(mid, |&a, &b| {
            points[a as usize][axis]
                .total_cmp(&points[b as usize][axis])
                .then(a.cmp(&b))
        });
    }
    (lo, hi)
}

/// [`split_node`] of each node of a level, on the pool's threads when
/// `parallel`.
#[allow(clippy::type_complexity)]
fn split_level(
    points: &[[f64; 3]],
    level: Vec<(usize, &mut [u32])>,
    parallel: bool,
) -> Vec<(usize, ([f64; 3], [f64; 3]))> {
    #[cfg(feature = "parallel")]
    if parallel {
        use rayon::prelude::*;
        return level
            .into_par_iter()
            .map(|(node, slice)| (node, split_node(points, slice)))
            .collect();
    }
    let _ = parallel;
    level
        .into_iter()
        .map(|(node, slice)| (node, split_node(points, slice)))
        .collect()
}

impl KdTree {
    /// A tree over `points[ids[..]]` (every point when `ids` is `None`).
    ///
    /// The tree's shape follows from the number of points alone, so the
    /// nodes of one level, whose ranges are disjoint, are split at once:
    /// on the pool's threads from [`PARALLEL_POINTS`] points. Each node's
    /// split is the same as one node after the other would make it.
    pub fn new(points: &[[f64; 3]], ids: Option<Vec<u32>>) -> Self {
        let ids = ids.unwrap_or_else(|| (0..points.len() as u32).collect());
        let parallel = ids.len() >= PARALLEL_POINTS;
        Self::build(points, ids, parallel)
    }

    /// [`Self::new`], its levels on the pool's threads when `parallel`.
    fn build(points: &[[f64; 3]], mut ids: Vec<u32>, parallel: bool) -> Self {
        let range = shape(ids.len());
        let mut bbox: Vec<([f64; 3], [f64; 3])> =
            vec![([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]); range.len()];
        let mut first = 0usize;
        while first < range.len() {
            // The level's nodes: first..=2·first (the root's level is 0..1).
            let end = (2 * first + 1).min(range.len());
            let mut rest: &mut [u32] = &mut ids;
            let mut at = 0u32;
            let mut level: Vec<(usize, &mut [u32])> = Vec::new();
            for (node, &(s, e)) in range.iter().enumerate().take(end).skip(first) {
                if (s, e) == (0, 0) && node != 0 {
                    continue;
                }
                let (_, tail) = rest.split_at_mut((s - at) as usize);
                let (mine, tail) = tail.split_at_mut((e - s) as usize);
                rest = tail;
                at = e;
                level.push((node, mine));
            }
            let boxes = split_level(points, level, parallel);
            for (node, b) in boxes {
                bbox[node] = b;
            }
            first = end;
        }
        let pts = ids.iter().map(|&i| points[i as usize]).collect();
        Self {
            pts,
            ids,
            range,
            bbox,
        }
    }

    /// Number of points in the tree.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether the tree holds no point.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The indices of the tree's points in tree order: points close in
    /// this order are close in space, so queries made in it reuse the
    /// same nodes from the cache.
    pub fn order(&self) -> &[u32] {
        &self.ids
    }

    fn is_leaf(&self, node: usize) -> bool {
        let c = 2 * node + 1;
        c >= self.range.len() || self.range[c] == (0, 0)
    }

    /// The `k` (≤ [`MAX_K`]) nearest points to `q`, nearest first, as
    /// (squared distance, point index), into `out` (cleared first). Fewer
    /// when the tree holds fewer points.
    pub fn nearest(&self, q: &[f64; 3], k: usize, out: &mut Vec<(f64, u32)>) {
        out.clear();
        let k = k.min(MAX_K).min(self.ids.len());
        if k == 0 {
            return;
        }
        // A sorted array of the best k so far.
        let mut best = [(f64::INFINITY, u32::MAX); MAX_K];
        let mut len = 0usize;
        let mut stack: [(u32, f64); 64] = [(0, 0.0); 64];
        let mut top = 1usize;
        stack[0] = (0, 0.0);
        while top > 0 {
            top -= 1;
            let (node, bd) = stack[top];
            let node = node as usize;
            if len == k && bd > best[k - 1].0 {
                continue;
            }
            if self.is_leaf(node) {
                let (s, e) = self.range[node];
                let (s, e) = (s as usize, e as usize);
                // The leaf's distances first (a loop the compiler
                // vectorises), then the few that may enter: 0.98 → 0.90 µs
                // a query on mOSD learn 5 (`examples/knn_time.rs`).
                let mut ds = [0.0f64; LEAF];
                for (d, p) in ds.iter_mut().zip(&self.pts[s..e]) {
                    *d = d2(q, p);
                }
                for t in s..e {
                    let d = ds[t - s];
                    if len == k && d > best[k - 1].0 {
                        continue;
                    }
                    let id = self.ids[t];
                    if len == k && (d, id) >= best[k - 1] {
                        continue;
                    }
                    // Insert in order.
                    let mut j = if len < k { len } else { k - 1 };
                    while j > 0 && (d, id) < best[j - 1] {
                        best[j] = best[j - 1];
                        j -= 1;
                    }
                    best[j] = (d, id);
                    if len < k {
                        len += 1;
                    }
                }
            } else {
                let (a, b) = (2 * node + 1, 2 * node + 2);
                let (da, db) = (box_d2(q, &self.bbox[a]), box_d2(q, &self.bbox[b]));
                // Push the farther child first so the nearer is visited
                // first.
                let (first, second) = if da <= db {
                    ((b, db), (a, da))
                } else {
                    ((a, da), (b, db))
                };
                for (c, d) in [first, second] {
                    if top < stack.len() {
                        stack[top] = (c as u32, d);
                        top += 1;
                    }
                }
            }
        }
        out.extend_from_slice(&best[..len]);
    }

    /// Calls `f` with the index of every point within distance `r` of `q`
    /// (inclusive), in tree order.
    pub fn within(&self, q: &[f64; 3], r: f64, mut f: impl FnMut(u32)) {
        self.any_within(q, r, |i| {
            f(i);
            false
        });
    }

    /// The number of points within distance `r` of `q` (inclusive): the
    /// count of [`within`](Self::within)'s calls, without visiting the
    /// points of a node whose box lies inside the ball.
    ///
    /// Exact: a point of a box is no farther from `q`, per axis and in
    /// floating point, than the box's farther face (subtraction, squaring
    /// and addition round monotonically, and both sums add the axes in
    /// the same order), so a box whose farthest corner is within `r`
    /// holds only points within `r`.
    pub fn count_within(&self, q: &[f64; 3], r: f64) -> usize {
        if self.ids.is_empty() {
            return 0;
        }
        let r2 = r * r;
        let mut count = 0usize;
        let mut stack: [u32; 64] = [0; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = stack[top] as usize;
            let b = &self.bbox[node];
            if box_d2(q, b) > r2 {
                continue;
            }
            let (s, e) = self.range[node];
            if far_d2(q, b) <= r2 {
                count += (e - s) as usize;
            } else if self.is_leaf(node) {
                count += self.pts[s as usize..e as usize]
                    .iter()
                    .filter(|p| d2(q, p) <= r2)
                    .count();
            } else {
                stack[top] = (2 * node + 1) as u32;
                stack[top + 1] = (2 * node + 2) as u32;
                top += 2;
            }
        }
        count
    }

    /// Whether `stop` returns `true` for a point within distance `r` of
    /// `q` (inclusive): [`within`](Self::within)'s points, in tree order,
    /// until the first for which it does.
    pub fn any_within(&self, q: &[f64; 3], r: f64, mut stop: impl FnMut(u32) -> bool) -> bool {
        if self.ids.is_empty() {
            return false;
        }
        let r2 = r * r;
        let mut stack: [u32; 64] = [0; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = stack[top] as usize;
            if box_d2(q, &self.bbox[node]) > r2 {
                continue;
            }
            if self.is_leaf(node) {
                let (s, e) = self.range[node];
                for t in s as usize..e as usize {
                    if d2(q, &self.pts[t]) <= r2 && stop(self.ids[t]) {
                        return true;
                    }
                }
            } else {
                stack[top] = (2 * node + 1) as u32;
                stack[top + 1] = (2 * node + 2) as u32;
                top += 2;
            }
        }
        false
    }

    /// Calls `f(index, point)` for every point inside the oriented box
    /// `b` (and perhaps a few within its padding, [`OrientedBox::new`]),
    /// in tree order. A node is skipped when an axis of the box or of the
    /// node separates them (six of the fifteen separating axes: never a
    /// node that meets the box, sometimes one that does not).
    pub fn within_box(&self, b: &OrientedBox, mut f: impl FnMut(u32, &[f64; 3])) {
        if self.ids.is_empty() {
            return;
        }
        let mut stack: [u32; 64] = [0; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = stack[top] as usize;
            if b.separated(&self.bbox[node]) {
                continue;
            }
            if self.is_leaf(node) {
                let (s, e) = self.range[node];
                for t in s as usize..e as usize {
                    let p = &self.pts[t];
                    if b.holds(p) {
                        f(self.ids[t], p);
                    }
                }
            } else {
                stack[top] = (2 * node + 1) as u32;
                stack[top + 1] = (2 * node + 2) as u32;
                top += 2;
            }
        }
    }
}

/// A box with its own orthonormal axes, for [`KdTree::within_box`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedBox {
    centre: [f64; 3],
    axes: [[f64; 3]; 3],
    /// Half extents along `axes`, padded.
    half: [f64; 3],
    /// Per world axis: the half extent of the box's projection on it.
    reach: [f64; 3],
}

impl OrientedBox {
    /// The box of centre `centre`, orthonormal `axes` and half extents
    /// `half`, each padded by a millionth of the largest one and by a
    /// relative 10⁻¹² of the coordinates' magnitude: the rounding of the
    /// dot products that place a point must not leave out a point on the
    /// box's faces (callers test their points exactly).
    pub fn new(centre: [f64; 3], axes: [[f64; 3]; 3], half: [f64; 3]) -> Self {
        let size = half.iter().fold(0.0f64, |m, &h| m.max(h));
        let magnitude = centre.iter().fold(size, |m, &c| m.max(c.abs()));
        let pad = 1e-6 * size + 1e-12 * magnitude;
        let half = half.map(|h| h + pad);
        let reach = [0, 1, 2].map(|j| (0..3).map(|k| axes[k][j].abs() * half[k]).sum());
        OrientedBox {
            centre,
            axes,
            half,
            reach,
        }
    }

    /// Whether the point lies in the (padded) box.
    pub fn holds(&self, p: &[f64; 3]) -> bool {
        let w = [
            p[0] - self.centre[0],
            p[1] - self.centre[1],
            p[2] - self.centre[2],
        ];
        (0..3).all(|k| {
            let a = &self.axes[k];
            (w[0] * a[0] + w[1] * a[1] + w[2] * a[2]).abs() <= self.half[k]
        })
    }

    /// Whether an axis of the box or of the axis-aligned box `(lo, hi)`
    /// separates them.
    fn separated(&self, (lo, hi): &([f64; 3], [f64; 3])) -> bool {
        let m = [0, 1, 2].map(|j| 0.5 * (lo[j] + hi[j]) - self.centre[j]);
        let e = [0, 1, 2].map(|j| 0.5 * (hi[j] - lo[j]));
        if (0..3).any(|j| m[j].abs() > e[j] + self.reach[j]) {
            return true;
        }
        (0..3).any(|k| {
            let a = &self.axes[k];
            let along = m[0] * a[0] + m[1] * a[1] + m[2] * a[2];
            let spread = e[0] * a[0].abs() + e[1] * a[1].abs() + e[2] * a[2].abs();
            along.abs() > self.half[k] + spread
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn cloud(n: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(seed);
        let mut r = move || rng.uniform();
        // Clustered and duplicated points as well as uniform ones.
        (0..n)
            .map(|i| match i % 4 {
                0 => [r(), r(), r()],
                1 => [0.5 + 1e-3 * r(), 0.5, 0.5 + 1e-3 * r()],
                2 => [0.25, 0.25, 0.25],
                _ => [r(), 0.0, (r() * 8.0).round() / 8.0],
            })
            .collect()
    }

    fn brute(pts: &[[f64; 3]], q: &[f64; 3]) -> Vec<(f64, u32)> {
        let mut all: Vec<(f64, u32)> = pts
            .iter()
            .enumerate()
            .map(|(i, p)| (d2(p, q), i as u32))
            .collect();
        all.sort_by(|a, b| a.partial_cmp(b).unwrap());
        all
    }

    #[test]
    fn nearest_and_within_match_brute_force() {
        let pts = cloud(3000, 5);
        let tree = KdTree::new(&pts, None);
        let mut out = Vec::new();
        for (qi, q) in pts.iter().enumerate().step_by(37) {
            let all = brute(&pts, q);
            for k in [1, 5, 16, 64] {
                tree.nearest(q, k, &mut out);
                assert_eq!(out, all[..k].to_vec(), "query {qi} k {k}");
            }
            for r in [0.0, 1e-3, 0.05, 0.3] {
                let mut got = Vec::new();
                tree.within(q, r, |i| got.push(i));
                got.sort_unstable();
                let mut want: Vec<u32> = all.iter().filter(|x| x.0 <= r * r).map(|x| x.1).collect();
                want.sort_unstable();
                assert_eq!(got, want, "query {qi} r {r}");
                assert_eq!(
                    tree.count_within(q, r),
                    want.len(),
                    "count: query {qi} r {r}"
                );
                // The first point `any_within` stops at is `within`'s
                // first of those the predicate accepts.
                let odd = |i: u32| i % 2 == 1;
                let mut seen = Vec::new();
                let found = tree.any_within(q, r, |i| {
                    seen.push(i);
                    odd(i)
                });
                assert_eq!(found, want.iter().any(|&i| odd(i)), "any: query {qi} r {r}");
                let mut order = Vec::new();
                tree.within(q, r, |i| order.push(i));
                assert_eq!(seen[..], order[..seen.len()], "any: query {qi} r {r}");
            }
        }
    }

    #[test]
    fn within_box_matches_brute_force() {
        let pts = cloud(3000, 11);
        let tree = KdTree::new(&pts, None);
        let mut rng = SplitMix64::new(4);
        for trial in 0..60 {
            // A random rotation (Gram–Schmidt of random vectors) and box.
            let mut r = || rng.uniform() - 0.5;
            let a0 = crate::geometry::normalize([r(), r(), r()]).unwrap();
            let v = [r(), r(), r()];
            let t = crate::geometry::dot(v, a0);
            let a1 =
                crate::geometry::normalize([v[0] - t * a0[0], v[1] - t * a0[1], v[2] - t * a0[2]])
                    .unwrap();
            let a2 = crate::geometry::cross(a0, a1);
            let centre = [0.5 + r(), 0.5 + r(), 0.5 + r()];
            let half = [
                0.3 * r().abs(),
                0.2 * r().abs(),
                if trial % 3 == 0 { 0.0 } else { 0.1 * r().abs() },
            ];
            let b = OrientedBox::new(centre, [a0, a1, a2], half);
            let mut got: Vec<u32> = Vec::new();
            tree.within_box(&b, |i, p| {
                assert_eq!(p, &pts[i as usize]);
                got.push(i);
            });
            got.sort_unstable();
            let want: Vec<u32> = (0..pts.len() as u32)
                .filter(|&i| b.holds(&pts[i as usize]))
                .collect();
            assert_eq!(got, want, "trial {trial}");
            // Every point strictly inside the unpadded box is held.
            for p in &pts {
                let w = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
                let inside = [a0, a1, a2]
                    .iter()
                    .zip(half)
                    .all(|(a, h)| crate::geometry::dot(w, *a).abs() <= h);
                assert!(!inside || b.holds(p));
            }
        }
        // The oracle can fail: a box moved by its own width holds others.
        let b = OrientedBox::new(
            [0.5; 3],
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            [0.1; 3],
        );
        let moved = OrientedBox::new(
            [0.7, 0.5, 0.5],
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            [0.1; 3],
        );
        let mut got = Vec::new();
        tree.within_box(&b, |i, _| got.push(i));
        assert!(!got.is_empty() && got.iter().any(|&i| !moved.holds(&pts[i as usize])));
    }

    #[test]
    fn a_tree_built_in_parallel_is_the_one_built_in_sequence() {
        let pts = cloud(PARALLEL_POINTS + 5000, 13);
        let serial = KdTree::build(&pts, (0..pts.len() as u32).collect(), false);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        let parallel = pool.install(|| KdTree::new(&pts, None));
        assert_eq!(serial.ids, parallel.ids);
        assert_eq!(serial.range, parallel.range);
        assert_eq!(serial.bbox, parallel.bbox);
        // Every node holds what its box says, and splits at its median.
        for (node, &(s, e)) in serial.range.iter().enumerate() {
            let (lo, hi) = serial.bbox[node];
            for p in &serial.pts[s as usize..e as usize] {
                assert!((0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k]));
            }
        }
        // (The comparison can fail: another leaf order differs.)
        let mut other = serial.ids.clone();
        other.swap(0, 1);
        assert_ne!(other, parallel.ids);
    }

    #[test]
    fn subsets_and_small_trees() {
        let pts = cloud(500, 9);
        let ids: Vec<u32> = (0..500).filter(|i| i % 3 == 0).collect();
        let tree = KdTree::new(&pts, Some(ids.clone()));
        assert_eq!(tree.len(), ids.len());
        let mut out = Vec::new();
        tree.nearest(&[0.3, 0.3, 0.3], 10, &mut out);
        let sub: Vec<[f64; 3]> = ids.iter().map(|&i| pts[i as usize]).collect();
        let want: Vec<(f64, u32)> = brute(&sub, &[0.3, 0.3, 0.3])[..10]
            .iter()
            .map(|&(d, i)| (d, ids[i as usize]))
            .collect();
        assert_eq!(out, want);
        // Empty and one-point trees.
        let empty = KdTree::new(&pts, Some(Vec::new()));
        empty.nearest(&[0.0; 3], 3, &mut out);
        assert!(out.is_empty());
        let one = KdTree::new(&pts, Some(vec![7]));
        one.nearest(&[0.0; 3], 3, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].1, 7);
    }

    #[test]
    fn a_wrong_oracle_is_caught() {
        // The brute-force comparison fails when the tree answer is
        // perturbed: the oracle is not vacuous.
        let pts = cloud(200, 3);
        let tree = KdTree::new(&pts, None);
        let mut out = Vec::new();
        tree.nearest(&pts[0], 4, &mut out);
        let mut wrong = out.clone();
        wrong.swap(1, 2);
        assert_ne!(wrong, brute(&pts, &pts[0])[..4].to_vec());
    }
}
