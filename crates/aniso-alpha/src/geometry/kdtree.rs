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
//! The nearest points of every point of a tree, in this tree or in
//! another, are cheaper a leaf at a time ([`LeafBatch`], the same lists):
//! on mOSD learn 13, 0.72 µs a 16-nearest query against 0.92 one by one,
//! and 0.13 µs against 0.27 for the nearest among a quarter of the points
//! (`examples/knn_time.rs`).
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

use super::{box_d2, box_gap_d2};

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
    /// Whether every coordinate is finite.
    finite: bool,
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

/// A point's key in [`Best`]: its index in the high half, its position
/// in tree order in the low half, so that keys order as indices.
fn index_of(key: u64) -> u32 {
    (key >> 32) as u32
}

/// The position in tree order of a [`Best`] key.
fn position_of(key: u64) -> usize {
    (key & u64::from(u32::MAX)) as usize
}

/// The best `k` points of a nearest query so far, as (squared distance,
/// key), sorted: by distance, then by index.
struct Best {
    items: [(f64, u64); MAX_K],
    len: usize,
    k: usize,
    /// The distance above which no point enters while fewer than `k` are
    /// held: ∞, or a bound known to hold the `k` nearest.
    limit: f64,
}

impl Best {
    fn new(k: usize, limit: f64) -> Self {
        Best {
            items: [(f64::INFINITY, u64::MAX); MAX_K],
            len: 0,
            k,
            limit,
        }
    }

    /// The points held, nearest first, as (squared distance, point index).
    fn found(&self) -> impl Iterator<Item = (f64, u32)> + '_ {
        self.items[..self.len]
            .iter()
            .map(|&(d, key)| (d, index_of(key)))
    }

    /// The squared distance above which no point can enter.
    #[inline(always)]
    fn bound(&self) -> f64 {
        if self.len == self.k {
            self.items[self.k - 1].0
        } else {
            self.limit
        }
    }

    /// Inserts `(d, key)` in order when it is among the best `k` so far
    /// (callers skip the distances above [`Self::bound`] first).
    #[inline(always)]
    fn offer(&mut self, d: f64, key: u64) {
        let k = self.k;
        if self.len == k && (d, key) >= self.items[k - 1] {
            return;
        }
        let mut j = if self.len < k { self.len } else { k - 1 };
        while j > 0 && (d, key) < self.items[j - 1] {
            self.items[j] = self.items[j - 1];
            j -= 1;
        }
        self.items[j] = (d, key);
        if self.len < k {
            self.len += 1;
        }
    }
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
        let pts: Vec<[f64; 3]> = ids.iter().map(|&i| points[i as usize]).collect();
        let finite = pts.iter().flatten().all(|x| x.is_finite());
        Self {
            pts,
            ids,
            range,
            bbox,
            finite,
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
        let mut best = Best::new(k, f64::INFINITY);
        self.descend(q, &mut best);
        out.extend(best.found());
    }

    /// The branch-and-bound descent of [`Self::nearest`] into `best`.
    fn descend(&self, q: &[f64; 3], best: &mut Best) {
        let mut stack: [(u32, f64); 64] = [(0, 0.0); 64];
        let mut top = 1usize;
        stack[0] = (0, 0.0);
        while top > 0 {
            top -= 1;
            let (node, bd) = stack[top];
            let node = node as usize;
            if bd > best.bound() {
                continue;
            }
            if self.is_leaf(node) {
                let (s, e) = self.range[node];
                self.scan_leaf(q, s as usize, e as usize, best);
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
    }

    /// Offers the points of tree positions `s..e` (a leaf) to `best`.
    ///
    /// The leaf's distances first (a loop the compiler vectorises), then
    /// the few that may enter: 0.98 → 0.90 µs a query on mOSD learn 5
    /// (`examples/knn_time.rs`). Those are picked by a mask of the
    /// distances within the bound as it stands at the leaf (it only
    /// shrinks) rather than by a branch per point: a 16-nearest query on
    /// mOSD learn 13 takes 0.92 µs against 0.95 alone, 0.72 against 0.79 a
    /// leaf at a time ([`LeafBatch`]). In a tree with a coordinate that is
    /// not finite every point is tried, as a distance may then be NaN and
    /// the bound too.
    #[inline(always)]
    fn scan_leaf(&self, q: &[f64; 3], s: usize, e: usize, best: &mut Best) {
        let mut ds = [0.0f64; LEAF];
        for (d, p) in ds.iter_mut().zip(&self.pts[s..e]) {
            *d = d2(q, p);
        }
        let bound = if self.finite { best.bound() } else { f64::NAN };
        let mut mask = 0u32;
        // Not `d <= bound`: a NaN distance is tried, as a branch per
        // point tries it.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        for (j, &d) in ds[..e - s].iter().enumerate() {
            mask |= u32::from(!(d > bound)) << j;
        }
        while mask != 0 {
            let j = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let d = ds[j];
            if d > best.bound() {
                continue;
            }
            let t = s + j;
            best.offer(d, (u64::from(self.ids[t]) << 32) | t as u64);
        }
    }

    /// The leaf holding tree position `t` (< [`Self::len`]).
    fn leaf_of(&self, t: usize) -> usize {
        let mut node = 0;
        while !self.is_leaf(node) {
            let c = 2 * node + 1;
            node = if t < self.range[c].1 as usize {
                c
            } else {
                c + 1
            };
        }
        node
    }

    /// A [`LeafBatch`] for the nearest queries in this tree of the points
    /// of `from` (this tree itself, or another one).
    pub fn batch<'a>(&'a self, from: &'a KdTree) -> LeafBatch<'a> {
        LeafBatch {
            to: self,
            from,
            start: 0,
            end: 0,
            k: 0,
            found: Vec::new(),
            leaves: Vec::new(),
        }
    }

    /// The leaves whose boxes lie within squared distance `r2` of the box
    /// `b` (per axis, the gap between the boxes), into `out` as (squared
    /// gap, node), nearest first.
    fn leaves_near(&self, b: &([f64; 3], [f64; 3]), r2: f64, out: &mut Vec<(f64, u32)>) {
        out.clear();
        let mut stack: [u32; 64] = [0; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = stack[top] as usize;
            let g = box_gap_d2(b, &self.bbox[node]);
            if g > r2 {
                continue;
            }
            if self.is_leaf(node) {
                out.push((g, node as u32));
            } else {
                stack[top] = (2 * node + 2) as u32;
                stack[top + 1] = (2 * node + 1) as u32;
                top += 2;
            }
        }
        out.sort_unstable_by(|x, y| x.partial_cmp(y).unwrap_or(std::cmp::Ordering::Equal));
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

/// Witnesses of a leaf's 1-nearest queries: its first point's 4 nearest
/// (see [`LeafBatch`]), the nearest of which bounds a point's nearest
/// more tightly than the first point's nearest alone.
const WITNESSES_OF_ONE: usize = 4;

/// The nearest queries of one tree's points in another tree (or in
/// itself), a leaf of the first at a time: [`KdTree::nearest`] of every
/// point of a leaf, kept for the next queries in tree order. Made by
/// [`KdTree::batch`], one per worker.
///
/// Exact, with the lists [`KdTree::nearest`] gives (indices, order and
/// squared distances, bit for bit). The leaf's first point takes the
/// descent, for its `k` nearest (for `k` = 1, its
/// 4 nearest, its answer the first). Those points,
/// the witnesses, are at least `k` distinct points, so for each other
/// point `q` of the leaf the `k`-th smallest of its squared distances to
/// them bounds its `k`-th nearest: its `k` nearest lie in the leaves
/// whose boxes are within that bound. Those leaves are gathered once for
/// the leaf, against the largest bound, nearest first (a node whose box
/// is farther from the leaf's box than that is farther from each of its
/// points, rounding included: per axis the boxes' gap is computed as a
/// point's is, from a face no nearer). Each point then takes the best `k`
/// of their points by (squared distance, index), as the descent does,
/// from the same distances, and stops at the first leaf farther than its
/// `k`-th so far. A tree with a coordinate that is not finite takes the
/// descent for every point.
#[derive(Debug, Clone)]
pub struct LeafBatch<'a> {
    /// The tree searched.
    to: &'a KdTree,
    /// The tree whose points are the queries.
    from: &'a KdTree,
    /// The leaf's range in `from`'s order (empty before the first query).
    start: usize,
    end: usize,
    /// The `k` asked for.
    k: usize,
    /// The leaf's points' nearest, one list after the other.
    found: Vec<(f64, u32)>,
    /// The leaves of `to` near the leaf, as (squared gap, node).
    leaves: Vec<(f64, u32)>,
}

impl LeafBatch<'_> {
    /// The `k` (≤ [`MAX_K`]) nearest points of the searched tree to the
    /// point at position `t` of the query tree's [`KdTree::order`], as
    /// [`KdTree::nearest`] gives them, into `out` (cleared first).
    pub fn nearest(&mut self, t: usize, k: usize, out: &mut Vec<(f64, u32)>) {
        out.clear();
        if t >= self.from.len() {
            return;
        }
        if !(self.start <= t && t < self.end && self.k == k) {
            self.fill(self.from.leaf_of(t), k);
        }
        let each = self.found.len() / (self.end - self.start);
        let at = (t - self.start) * each;
        out.extend_from_slice(&self.found[at..at + each]);
    }

    /// The `k` nearest of every point of `from`'s leaf `leaf`.
    fn fill(&mut self, leaf: usize, k: usize) {
        let (to, from) = (self.to, self.from);
        let (s, e) = from.range[leaf];
        let (s, e) = (s as usize, e as usize);
        (self.start, self.end, self.k) = (s, e, k);
        self.found.clear();
        let kk = k.min(MAX_K).min(to.len());
        if kk == 0 {
            return;
        }
        if !(to.finite && from.finite) {
            let mut out = Vec::new();
            for q in &from.pts[s..e] {
                to.nearest(q, kk, &mut out);
                self.found.extend_from_slice(&out);
            }
            return;
        }
        let seen = if kk == 1 { WITNESSES_OF_ONE } else { kk };
        let mut first = Best::new(seen.min(to.len()), f64::INFINITY);
        to.descend(&from.pts[s], &mut first);
        let witnesses = &first.items[..first.len];
        self.found
            .extend(witnesses[..kk].iter().map(|&(d, key)| (d, index_of(key))));
        if e - s == 1 {
            return;
        }
        // Each other point's bound, and the largest.
        let mut bounds = [0.0f64; LEAF];
        let mut most = 0.0f64;
        for (b, q) in bounds.iter_mut().zip(&from.pts[s + 1..e]) {
            let d = witnesses
                .iter()
                .map(|&(_, key)| d2(q, &to.pts[position_of(key)]));
            *b = if kk == 1 {
                d.fold(f64::INFINITY, f64::min)
            } else {
                d.fold(0.0, f64::max)
            };
            most = most.max(*b);
        }
        to.leaves_near(&from.bbox[leaf], most, &mut self.leaves);
        let mut best = Best::new(kk, 0.0);
        for (&bound, q) in bounds.iter().zip(&from.pts[s + 1..e]) {
            (best.len, best.limit) = (0, bound);
            for &(gap, c) in &self.leaves {
                if gap > best.bound() {
                    break;
                }
                let c = c as usize;
                if box_d2(q, &to.bbox[c]) > best.bound() {
                    continue;
                }
                let (cs, ce) = to.range[c];
                to.scan_leaf(q, cs as usize, ce as usize, &mut best);
            }
            self.found.extend(best.found());
        }
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

    /// A cloud of exact ties: points of an integer grid, a fifth of
    /// them twice.
    fn grid(n: usize) -> Vec<[f64; 3]> {
        let side = (n as f64).cbrt().ceil() as usize;
        let mut pts: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                [
                    (i % side) as f64,
                    (i / side % side) as f64,
                    (i / side / side) as f64,
                ]
            })
            .collect();
        pts.extend_from_within(..n / 5);
        pts
    }

    /// A list with its distances as bits (NaN equal to itself).
    fn bits(list: &[(f64, u32)]) -> Vec<(u64, u32)> {
        list.iter().map(|&(d, i)| (d.to_bits(), i)).collect()
    }

    /// Every point of `from`, in tree order (then every 7th position,
    /// out of order), queried through a [`LeafBatch`] in `to` for each
    /// `k`, against `oracle(to, q, k)`; the first query that differs.
    fn batch_differs(
        from: &KdTree,
        to: &KdTree,
        ks: &[usize],
        oracle: impl Fn(&KdTree, &[f64; 3], usize) -> Vec<(f64, u32)>,
    ) -> Option<(usize, usize)> {
        let mut batch = to.batch(from);
        let mut out = Vec::new();
        let jumps = (0..from.len()).step_by(7).rev();
        for &k in ks {
            for t in (0..from.len()).chain(jumps.clone()) {
                batch.nearest(t, k, &mut out);
                if bits(&out) != bits(&oracle(to, &from.pts[t], k)) {
                    return Some((t, k));
                }
            }
        }
        None
    }

    fn one_by_one(tree: &KdTree, q: &[f64; 3], k: usize) -> Vec<(f64, u32)> {
        let mut out = Vec::new();
        tree.nearest(q, k, &mut out);
        out
    }

    #[test]
    fn batches_give_the_lists_of_nearest() {
        let ks = [1, 2, 5, 16, 64, 80];
        let mut rng = SplitMix64::new(21);
        let uniform: Vec<[f64; 3]> = (0..4000)
            .map(|_| [rng.uniform(), rng.uniform(), 0.01 * rng.uniform()])
            .collect();
        for (name, pts) in [
            ("uniform", uniform),
            ("clustered", cloud(3000, 17)),
            ("grid", grid(2500)),
        ] {
            let all = KdTree::new(&pts, None);
            assert_eq!(batch_differs(&all, &all, &ks, one_by_one), None, "{name}");
            // Between trees of subsets (as the scales' links), both ways,
            // and into trees smaller than k.
            let n = pts.len() as u32;
            let half = KdTree::new(&pts, Some((0..n).filter(|i| i % 2 == 0).collect()));
            let quarter = KdTree::new(&pts, Some((0..n).filter(|i| i % 4 == 1).collect()));
            let few = KdTree::new(&pts, Some((0..n).step_by(97).collect()));
            for (from, to) in [(&half, &quarter), (&quarter, &half), (&all, &few)] {
                assert_eq!(batch_differs(from, to, &ks, one_by_one), None, "{name}");
            }
        }
        // Empty trees, and a tree with a coordinate that is not finite.
        let pts = cloud(500, 23);
        let empty = KdTree::new(&pts, Some(Vec::new()));
        let all = KdTree::new(&pts, None);
        assert_eq!(batch_differs(&all, &empty, &ks, one_by_one), None);
        assert_eq!(batch_differs(&empty, &all, &ks, one_by_one), None);
        let mut odd = pts.clone();
        odd[3] = [f64::NAN, 0.5, 0.5];
        odd[8] = [f64::INFINITY, 0.0, 0.0];
        let odd = KdTree::new(&odd, None);
        assert!(!odd.finite);
        assert_eq!(batch_differs(&odd, &odd, &ks, one_by_one), None);
        assert_eq!(batch_differs(&all, &odd, &ks, one_by_one), None);
    }

    #[test]
    fn a_wrong_batch_oracle_is_caught() {
        // Ties broken by the larger index: caught on the grid's ties.
        let pts = grid(1000);
        let tree = KdTree::new(&pts, None);
        let larger_first = |to: &KdTree, q: &[f64; 3], k: usize| {
            let mut all: Vec<(f64, u32)> = to
                .pts
                .iter()
                .zip(&to.ids)
                .map(|(p, &i)| (d2(q, p), i))
                .collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
            all.truncate(k);
            all
        };
        assert!(batch_differs(&tree, &tree, &[16], larger_first).is_some());
        // Distances summed in another order: caught in their last bits.
        let mut rng = SplitMix64::new(5);
        let pts: Vec<[f64; 3]> = (0..2000)
            .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
            .collect();
        let tree = KdTree::new(&pts, None);
        let other_sum = |to: &KdTree, q: &[f64; 3], k: usize| {
            let mut out = one_by_one(to, q, k);
            for (d, i) in &mut out {
                let p = to.pts[to.ids.iter().position(|j| j == i).unwrap()];
                let (x, y, z) = (q[0] - p[0], q[1] - p[1], q[2] - p[2]);
                *d = x * x + (y * y + z * z);
            }
            out
        };
        assert!(batch_differs(&tree, &tree, &[16], other_sum).is_some());
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
