//! The local shape of a point cloud: for every point, a principal component
//! analysis of its neighbourhood at the scale where it looks most planar
//! (k = 2) or most linear (k = 1). This is what the parameters and the
//! orientation set are estimated from (see [`super::estimate`] and
//! [`super::modes`]).
//!
//! **Scales.** A neighbourhood is the [`NEIGHBOURS`] nearest points of a
//! subsample: scale 0 uses every point, scale j keeps one point in 4^j
//! (chosen by a hash of its rank in the order of positions, so the
//! subsample has no grid pattern of its own and does not depend on the
//! order the points are listed in). On a surface, 4× fewer points make the same number of
//! neighbours reach 2× farther, so the scales double the radius: a noisy
//! wall or a thick pole, which looks like a blob at the sampling scale,
//! looks like a plane or a line a few scales up. Scales stop at
//! [`MAX_SCALES`] or when the subsample is too small.
//!
//! **Choosing the scale.** With σ₁ ≥ σ₂ ≥ σ₃ the principal standard
//! deviations of the neighbourhood, the dimensionality features of Demantké
//! et al. (2011) are a₁ = (σ₁ − σ₂)/σ₁ (linear), a₂ = (σ₂ − σ₃)/σ₁
//! (planar) and a₃ = σ₃/σ₁ (scattered). Each point keeps the scale that
//! maximises a₂ when planes are sought and a₁ when lines are (the smallest
//! such scale on ties).
//!
//! ```
//! use aniso_alpha::detect::local::local_shapes;
//! use aniso_alpha::detect::StructureKind;
//! // A 20 × 20 grid on the plane z = 0.
//! let pts: Vec<[f64; 3]> = (0..400).map(|i| [(i % 20) as f64, (i / 20) as f64, 0.0]).collect();
//! let shapes = local_shapes(&pts, StructureKind::Planes);
//! assert!(shapes.iter().all(|s| s.normal[2].abs() > 0.99 && s.planarity() > 0.5));
//! assert!(shapes.iter().all(|s| (s.spacing - 1.0).abs() < 1e-6));
//! // On a grid the nearest neighbour across (45° or more away from the
//! // nearest one) is as near: the row gap is the spacing.
//! assert!(shapes.iter().all(|s| (s.row_gap - 1.0).abs() < 1e-6));
//! ```

use super::StructureKind;
use crate::geometry::kdtree::{KdTree, LeafBatch};
use crate::geometry::{cross, dot, sub};
use crate::rng::mix;

/// Neighbours per neighbourhood: the usual choice for PCA normals (CGAL's
/// examples use 12–24, PCL's 10–30): enough for a stable covariance of 3
/// coordinates, few enough to stay local.
pub const NEIGHBOURS: usize = 16;

/// Number of scales at most (radii 1, 2, 4, 8, 16 and 32 times the
/// sampling scale, on a surface).
pub const MAX_SCALES: usize = 6;

/// A score at which a point stops looking at larger scales: 0.8 is the
/// planarity of a clean plane sampled irregularly (σ₂/σ₁ ≈ 0.8–0.9, σ₃ ≈ 0)
/// and the linearity of a line with points a little off it.
pub const GOOD: f32 = 0.8;

/// Score (planarity or linearity) from which a point is structure-like: the
/// midpoint of the features' range [0, 1].
pub const SCORE_MIN: f32 = 0.5;

/// The local shape of the cloud around one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalShape {
    /// Unit normal of the local plane (the smallest principal axis).
    pub normal: [f32; 3],
    /// Unit direction of the local line (the largest principal axis).
    pub direction: [f32; 3],
    /// Principal standard deviations σ₁ ≥ σ₂ ≥ σ₃ of the neighbourhood.
    pub sigma: [f32; 3],
    /// The chosen scale (0 = every point).
    pub scale: u8,
    /// Distance to the nearest other point with other coordinates (∞ when
    /// there is none).
    pub spacing: f32,
    /// Distance to the nearest neighbour at least 45° away from the
    /// direction of the nearest one (either way): on a scan line, the
    /// gap to the next line; on an isotropic sampling, about the spacing.
    /// Where the neighbourhood at scale 0 is a line, the direction is the
    /// line's and a neighbour across it nearer than the nearest along it
    /// is skipped (a twin line, as a zigzag scanner's forward and backward
    /// lines near the swath's edges). The farthest of the neighbours when
    /// none is (the gap is at least that); ∞ when there is no neighbour.
    pub row_gap: f32,
}

impl LocalShape {
    /// a₂ = (σ₂ − σ₃)/σ₁: 1 on a clean plane, 0 on a line or a blob.
    pub fn planarity(&self) -> f32 {
        let [s1, s2, s3] = self.sigma;
        if s1 > 0.0 {
            (s2 - s3) / s1
        } else {
            0.0
        }
    }

    /// a₁ = (σ₁ − σ₂)/σ₁: 1 on a clean line, 0 on a plane or a blob.
    pub fn linearity(&self) -> f32 {
        let [s1, s2, _] = self.sigma;
        if s1 > 0.0 {
            (s1 - s2) / s1
        } else {
            0.0
        }
    }

    /// The spread across the local structure: σ₃ for a plane (its noise),
    /// √(σ₂² + σ₃²) for a line (its radius of scatter).
    pub fn spread(&self, kind: StructureKind) -> f32 {
        let [_, s2, s3] = self.sigma;
        match kind {
            StructureKind::Planes => s3,
            StructureKind::Lines => (s2 * s2 + s3 * s3).sqrt(),
        }
    }

    /// The feature the scale was chosen by: planarity (k = 2) or linearity
    /// (k = 1).
    pub fn score(&self, kind: StructureKind) -> f32 {
        match kind {
            StructureKind::Planes => self.planarity(),
            StructureKind::Lines => self.linearity(),
        }
    }

    /// The local axis of the structure kind: the normal (k = 2) or the
    /// direction (k = 1).
    pub fn axis(&self, kind: StructureKind) -> [f32; 3] {
        match kind {
            StructureKind::Planes => self.normal,
            StructureKind::Lines => self.direction,
        }
    }
}

/// The points' indices in the order of their positions: by x, then y, then
/// z (ties, which are copies of one position, by index). It does not
/// depend on the order the points were given in, nor on a shift or a
/// positive scaling of the coordinates, so neither do the subsamples drawn
/// along it.
fn position_order(points: &[[f64; 3]]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    crate::par::sort_unstable_by(&mut order, |&a, &b| {
        let (p, q) = (&points[a as usize], &points[b as usize]);
        p[0].total_cmp(&q[0])
            .then(p[1].total_cmp(&q[1]))
            .then(p[2].total_cmp(&q[2]))
            .then(a.cmp(&b))
    });
    order
}

/// The indices kept at scale `j` (ascending): one point in 4^j, the point
/// of rank r in [`position_order`] kept when `mix(r)` is a multiple of 4^j.
fn subsample(order: &[u32], j: usize) -> Vec<u32> {
    let keep = 1u64 << (2 * j);
    let mut ids: Vec<u32> = order
        .iter()
        .enumerate()
        .filter(|&(r, _)| mix(r as u64) % keep == 0)
        .map(|(_, &i)| i)
        .collect();
    ids.sort_unstable();
    ids
}

/// Eigen-decomposition of a symmetric 3×3 matrix in closed form (the
/// trigonometric solution of the characteristic cubic, then eigenvectors
/// as cross products of rows of A − λI): eigenvalues descending, matching
/// unit eigenvectors as rows. About ten times cheaper than the Jacobi
/// iteration of [`super::fit::symmetric_eigen`], and accurate to about
/// 1e-8 of the largest eigenvalue, plenty for local normals; where two
/// eigenvalues are nearly equal their eigenvectors are arbitrary in their
/// plane (as they are for any method).
pub fn eigen_sym3(a: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let p1 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    let q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    let p2 = (a[0][0] - q).powi(2) + (a[1][1] - q).powi(2) + (a[2][2] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    if !(p.is_finite() && p > 1e-300) {
        // A multiple of the identity (or not finite): any basis.
        return ([q; 3], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    }
    let mut b = a;
    for i in 0..3 {
        b[i][i] -= q;
        for j in 0..3 {
            b[i][j] /= p;
        }
    }
    let det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1])
        - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0])
        + b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
    let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    let l1 = q + 2.0 * p * phi.cos();
    let l3 = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    let l2 = 3.0 * q - l1 - l3;
    // Eigenvector of λ: the largest cross product of two rows of A − λI.
    let vector = |l: f64| -> Option<[f64; 3]> {
        let r = [
            [a[0][0] - l, a[0][1], a[0][2]],
            [a[0][1], a[1][1] - l, a[1][2]],
            [a[0][2], a[1][2], a[2][2] - l],
        ];
        let mut best = [0.0; 3];
        let mut bn = -1.0;
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            let c = cross(r[i], r[j]);
            let n = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
            if n > bn {
                bn = n;
                best = c;
            }
        }
        let n = bn.sqrt();
        (n > 0.0).then(|| best.map(|x| x / n))
    };
    // The better separated end first; the other is made orthogonal to it
    // (its own cross products are unreliable when its eigenvalue is close
    // to the middle one).
    let orthogonal_to = |u: [f64; 3], v: [f64; 3]| -> [f64; 3] {
        let d = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let w = [v[0] - d * u[0], v[1] - d * u[1], v[2] - d * u[2]];
        let n = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        if n > 1e-6 {
            w.map(|x| x / n)
        } else {
            any_orthogonal(u)
        }
    };
    let (v1, v3) = if l1 - l2 >= l2 - l3 {
        let v1 = vector(l1).unwrap_or([1.0, 0.0, 0.0]);
        (
            v1,
            orthogonal_to(v1, vector(l3).unwrap_or_else(|| any_orthogonal(v1))),
        )
    } else {
        let v3 = vector(l3).unwrap_or([0.0, 0.0, 1.0]);
        (
            orthogonal_to(v3, vector(l1).unwrap_or_else(|| any_orthogonal(v3))),
            v3,
        )
    };
    let v2 = cross(v3, v1);
    ([l1, l2, l3], [v1, v2, v3])
}

/// A unit vector orthogonal to the unit vector `u`.
pub(crate) fn any_orthogonal(u: [f64; 3]) -> [f64; 3] {
    let t = if u[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let c = cross(u, t);
    let n = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    c.map(|x| x / n)
}

/// Principal standard deviations (descending), axes (rows, matching) and
/// centroid of the points `ids`.
fn pca(points: &[[f64; 3]], ids: &[(f64, u32)]) -> ([f64; 3], [[f64; 3]; 3], [f64; 3]) {
    let (c, m) = super::fit::moments(ids.len(), |k| points[ids[k].1 as usize]);
    let (vals, vecs) = eigen_sym3(m);
    (vals.map(|v| v.max(0.0).sqrt()), vecs, c)
}

fn to_f32(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// `f(batch, neighbours, t)` for each position `t` of `from`'s
/// [`KdTree::order`], in parallel with the `parallel` feature: `batch` is
/// a [`LeafBatch`] of `to`'s points nearest to `from`'s, made by `batch`,
/// and `neighbours` a buffer, one of each per worker's range of
/// positions. Collected in tree order.
fn in_tree_order<T: Send, B>(
    from: &KdTree,
    batch: impl Fn() -> B + Sync,
    f: impl Fn(&mut B, &mut Vec<(f64, u32)>, usize) -> T + Sync,
) -> Vec<T> {
    crate::par::map_ranges(
        from.len(),
        || (batch(), Vec::new()),
        |(b, nb), t| f(b, nb, t),
    )
}

/// [`in_tree_order`] for the queries of `from`'s points in `to`, put back
/// in the order of `ids` (`from`'s points, ascending): each query then
/// starts in the cache where the last one ended.
fn in_input_order<T: Send + Copy>(
    from: &KdTree,
    to: &KdTree,
    ids: &[u32],
    f: impl Fn(&mut LeafBatch, &mut Vec<(f64, u32)>, usize) -> T + Sync,
) -> Vec<T> {
    let found = in_tree_order(from, || to.batch(from), f);
    put_back(found, from.order(), |i| ids.binary_search(&i).ok())
}

/// `found[t]`, the result for the point `order[t]`, moved to the slot
/// `slot(order[t])` (none: dropped). `order` is a permutation of the slots,
/// so every slot is written once.
fn put_back<T: Copy>(found: Vec<T>, order: &[u32], slot: impl Fn(u32) -> Option<usize>) -> Vec<T> {
    let Some(&fill) = found.first() else {
        return found;
    };
    let mut out = vec![fill; found.len()];
    for (&i, x) in order.iter().zip(found) {
        if let Some(at) = slot(i) {
            out[at] = x;
        }
    }
    out
}

/// The shape of the neighbourhood `nb` (at least 3 points).
fn shape_of(points: &[[f64; 3]], nb: &[(f64, u32)], scale: usize, spacing: f32) -> LocalShape {
    let (sigma, axes, _) = pca(points, nb);
    shape_from(sigma, axes, scale, spacing)
}

/// The shape of principal deviations `sigma` along `axes`.
fn shape_from(sigma: [f64; 3], axes: [[f64; 3]; 3], scale: usize, spacing: f32) -> LocalShape {
    LocalShape {
        normal: to_f32(axes[2]),
        direction: to_f32(axes[0]),
        sigma: to_f32(sigma),
        scale: scale as u8,
        spacing,
        row_gap: f32::INFINITY,
    }
}

/// The row gap of `q` among its neighbours `nb` (squared distances,
/// ascending; see [`LocalShape::row_gap`]), across `line` (unit) when the
/// neighbourhood is a line, else across the direction of the nearest
/// neighbour.
fn row_gap(points: &[[f64; 3]], q: &[f64; 3], nb: &[(f64, u32)], line: Option<[f64; 3]>) -> f32 {
    let offset = |j: u32| sub(points[j as usize], *q);
    let mut rest = nb.iter().filter(|&&(d, _)| d > 0.0);
    let Some(&(d0, first)) = rest.clone().next() else {
        return f32::INFINITY;
    };
    let farthest = nb[nb.len() - 1].0;
    // |cos| ≤ cos 45° ⟺ 2·(u·v)² ≤ |u|²·|v|².
    let across = |u: [f64; 3], uu: f64, d: f64, j: u32| {
        let uv = dot(u, offset(j));
        2.0 * uv * uv <= uu * d
    };
    let gap = match line {
        None => {
            let u = offset(first);
            rest.find(|&&(d, j)| across(u, d0, d, j))
                .map_or(farthest, |&(d, _)| d)
        }
        // The nearest neighbour along the line is its spacing; a point
        // across it but nearer than that lies on a twin line (a zigzag
        // scanner's forward and backward lines nearly meet near the
        // swath's edges), and the gap to bridge is to the next pair.
        Some(u) => {
            let along = rest
                .clone()
                .find(|&&(d, j)| !across(u, 1.0, d, j))
                .map_or(0.0, |&(d, _)| d);
            rest.find(|&&(d, j)| d > along && across(u, 1.0, d, j))
                .map_or(farthest, |&(d, _)| d)
        }
    };
    gap.sqrt() as f32
}

/// The shape of the neighbourhood `nb` of `q` at scale 0, with its
/// spacing and row gap.
fn finest_shape(points: &[[f64; 3]], q: &[f64; 3], nb: &[(f64, u32)]) -> LocalShape {
    let spacing = nb
        .iter()
        .map(|&(d, _)| d)
        .find(|&d| d > 0.0)
        .map_or(f32::INFINITY, |d| d.sqrt() as f32);
    if nb.len() >= 3 {
        let shape = shape_of(points, nb, 0, spacing);
        // A neighbourhood that is a line (linearity at least the features'
        // midpoint) lies on a scan line: its gap is measured across it.
        let line = (shape.linearity() >= SCORE_MIN).then(|| shape.direction.map(f64::from));
        LocalShape {
            row_gap: row_gap(points, q, nb, line),
            ..shape
        }
    } else {
        let gap = row_gap(points, q, nb, None);
        LocalShape {
            normal: [0.0, 0.0, 1.0],
            direction: [1.0, 0.0, 0.0],
            sigma: [0.0; 3],
            scale: 0,
            spacing,
            row_gap: gap,
        }
    }
}

/// The local shape of every point (see the module doc). Deterministic;
/// runs on the current rayon pool with the `parallel` feature.
///
/// Cost: the neighbourhoods of scale j ≥ 1 are analysed at the points of
/// the scale-j subsample only (n/4^j of them), and a point that needs
/// them takes those of its nearest subsample point: about 1.4 n
/// 16-nearest queries in all, however many scales there are. A point whose
/// score at scale 0 already reaches [`GOOD`] looks no further.
pub fn local_shapes(points: &[[f64; 3]], kind: StructureKind) -> Vec<LocalShape> {
    local_shapes_by(points, false, |best| best(kind, false))
}

/// The line shape of every point ([`local_shapes`] for lines), and whether
/// it lies on a surface ([`on_surface`]), from one pass: the
/// neighbourhoods, their analyses and the links between scales do not
/// depend on the kind, only the scale each point keeps does.
///
/// The plane shape a point is judged by here keeps a coarser scale only
/// where the point lies in that neighbourhood's plane (within
/// [`C_NOISE`](super::estimate::C_NOISE) times its spread across it): a
/// coarse neighbourhood is taken from the nearest point of a subsample
/// (1 in 4^j), which beside a sparse structure lies on the dense surface
/// around it. A pole's point 3 m above the ground otherwise took the
/// ground's shape at the coarsest scale (planarity 0.95 against its own
/// linearity 0.84), and the whole pole was left out as a surface.
pub fn line_shapes_on_surfaces(points: &[[f64; 3]]) -> Vec<(LocalShape, bool)> {
    local_shapes_by(points, true, |best| {
        let line = best(StructureKind::Lines, false);
        (line, on_surface(&line, &best(StructureKind::Planes, true)))
    })
}

/// Whether a point whose line and plane shapes are `line` and `plane` lies
/// on a surface, for lines: its neighbourhood, at the scale where it looks
/// most planar, is planar (planarity ≥ [`SCORE_MIN`]) and at least as
/// planar as it is linear at the scale where it looks most linear. The
/// local "direction" of a wall's or the ground's point is any direction in
/// its plane: left among the line directions, such points fill every cone,
/// so that no mode of the true lines' directions stands out (a simulated
/// street of 895k points: 0 modes), or their weakly linear coarse
/// neighbourhoods (linearity ≈ 0.55, planarity ≈ 0.85) make lines of their
/// own. A pole or a cable is more linear than planar at its best scales
/// (linearity 0.78–0.93, planarity 0.3–0.7 on that street).
pub fn on_surface(line: &LocalShape, plane: &LocalShape) -> bool {
    plane.planarity() >= SCORE_MIN && plane.planarity() >= line.linearity()
}

/// Whether `q` lies in the plane of the neighbourhood of shape `s` and
/// centroid `centre`: within [`C_NOISE`](super::estimate::C_NOISE) times
/// its spread across the plane (σ₃).
fn in_plane_of(s: &LocalShape, centre: [f64; 3], q: &[f64; 3]) -> bool {
    let off = dot(sub(*q, centre), s.normal.map(f64::from)).abs();
    off <= super::estimate::C_NOISE * f64::from(s.sigma[2])
}

/// The best shape of a kind for one point, as [`local_shapes_by`] hands it
/// to its `pick`: `best(kind, in_plane)`, where `in_plane` keeps only the
/// coarser plane shapes whose plane holds the point ([`in_plane_of`]).
type Best<'a> = &'a mut dyn FnMut(StructureKind, bool) -> LocalShape;

/// The multi-scale analysis of [`local_shapes`], each point's result made by
/// `pick` from the best shape of a kind (the finest shape, or the first of
/// the coarser ones to reach [`GOOD`], else the highest scoring). With
/// `centres`, the coarse neighbourhoods' centroids are kept, for
/// `best(kind, true)`.
fn local_shapes_by<T: Copy + Send>(
    points: &[[f64; 3]],
    centres: bool,
    pick: impl Fn(Best<'_>) -> T + Sync,
) -> Vec<T> {
    // Nested subsamples (mix(r) % 4^j == 0 implies the same for j − 1).
    let by_position = position_order(points);
    let mut samples: Vec<Vec<u32>> = vec![Vec::new()];
    let mut trees: Vec<KdTree> = vec![KdTree::new(points, None)];
    for j in 1..MAX_SCALES {
        let ids = subsample(&by_position, j);
        if ids.len() < 4 * NEIGHBOURS {
            break;
        }
        trees.push(KdTree::new(points, Some(ids.clone())));
        samples.push(ids);
    }
    drop(by_position);
    let scales = trees.len();
    // Shapes of the subsample points at their own scale (and the centroids
    // of their neighbourhoods), and the link from each point of subsample
    // j − 1 to its nearest point of subsample j.
    let mut coarse: Vec<Vec<LocalShape>> = vec![Vec::new()];
    let mut centre: Vec<Vec<[f64; 3]>> = vec![Vec::new()];
    let mut up: Vec<Vec<u32>> = vec![Vec::new(), Vec::new()];
    for j in 1..scales {
        let ids = &samples[j];
        let tree = &trees[j];
        let analysed = in_input_order(tree, tree, ids, |batch, nb, t| {
            batch.nearest(t, NEIGHBOURS, nb);
            let (sigma, axes, c) = pca(points, nb);
            (shape_from(sigma, axes, j, f32::INFINITY), c)
        });
        coarse.push(analysed.iter().map(|a| a.0).collect());
        centre.push(if centres {
            analysed.iter().map(|a| a.1).collect()
        } else {
            Vec::new()
        });
        drop(analysed);
        if j >= 2 {
            let below = &samples[j - 1];
            up.push(in_input_order(
                &trees[j - 1],
                tree,
                below,
                |batch, nb, t| {
                    batch.nearest(t, 1, nb);
                    ids.binary_search(&nb[0].1).unwrap_or(0) as u32
                },
            ));
        }
    }
    // The points in tree order (each query then starts where the last one
    // ended, in the cache), the results put back in input order; with each,
    // its nearest point of subsample 1 when it needs the coarser scales.
    let batches = || {
        (
            trees[0].batch(&trees[0]),
            trees.get(1).map(|t| t.batch(&trees[0])),
        )
    };
    let order = trees[0].order();
    let per_point = in_tree_order(&trees[0], batches, |(own, coarser), nb, t| {
        own.nearest(t, NEIGHBOURS, nb);
        let q = &points[order[t] as usize];
        let finest = finest_shape(points, q, nb);
        let mut nearest_coarse: Option<usize> = None;
        let mut best_of = |kind: StructureKind, in_plane: bool| {
            let mut best = finest;
            let mut score = best.score(kind);
            let Some(coarser) = coarser.as_mut().filter(|_| score < GOOD) else {
                return best;
            };
            let mut at = *nearest_coarse.get_or_insert_with(|| {
                coarser.nearest(t, 1, nb);
                samples[1].binary_search(&nb[0].1).unwrap_or(0)
            });
            for j in 1..scales {
                if j >= 2 {
                    at = up[j][at] as usize;
                }
                let c = coarse[j][at];
                if in_plane && !in_plane_of(&c, centre[j][at], q) {
                    continue;
                }
                let s = c.score(kind);
                if s > score {
                    score = s;
                    best = LocalShape {
                        spacing: best.spacing,
                        row_gap: best.row_gap,
                        ..c
                    };
                }
                if s >= GOOD {
                    break;
                }
            }
            best
        };
        pick(&mut best_of)
    });
    put_back(per_point, order, |i| Some(i as usize))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random stream in [0, 1).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut i = seed;
        move || {
            i += 1;
            crate::rng::unit(mix(i))
        }
    }

    #[test]
    fn closed_form_eigen_agrees_with_jacobi() {
        let mut r = uniform(3);
        for t in 0..2000 {
            // Random symmetric matrices, including near-degenerate spectra.
            let mut m = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in i..3 {
                    m[i][j] = r() - 0.5;
                    m[j][i] = m[i][j];
                }
            }
            if t % 3 == 0 {
                // Thin planes' and lines' covariances: repeated and tiny
                // eigenvalues.
                m = match t % 9 {
                    0 => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1e-6]],
                    3 => [[1e-6, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 1.0]],
                    _ => [[0.5, 0.5, 0.0], [0.5, 0.5, 0.0], [0.0, 0.0, 0.25]],
                };
            }
            let (lv, lx) = eigen_sym3(m);
            let (jv, _) = super::super::fit::symmetric_eigen(m);
            for k in 0..3 {
                assert!((lv[k] - jv[k]).abs() < 1e-9, "{t}: {lv:?} vs {jv:?}");
            }
            // A·v = λ·v for the well-separated ends; an orthonormal basis.
            for i in 0..3 {
                for j in 0..3 {
                    let d: f64 = (0..3).map(|c| lx[i][c] * lx[j][c]).sum();
                    assert!((d - f64::from(u8::from(i == j))).abs() < 1e-9, "{t}: basis");
                }
            }
            for k in [0, 2] {
                let v = lx[k];
                let sep = if k == 0 { lv[0] - lv[1] } else { lv[1] - lv[2] };
                if sep < 1e-3 {
                    continue;
                }
                for i in 0..3 {
                    let av = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
                    assert!((av - lv[k] * v[i]).abs() < 1e-7, "{t} {k}");
                }
            }
        }
    }

    #[test]
    fn noisy_plane_is_planar_at_a_larger_scale() {
        // A plane sampled at spacing 1 with noise of 2 spacings across it:
        // a blob at 16 neighbours, a plane a few scales up.
        let mut r = uniform(7);
        let mut gauss = move || {
            let (u, v) = (r().max(1e-300), r());
            (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
        };
        let pts: Vec<[f64; 3]> = (0..40_000)
            .map(|i| [(i % 200) as f64, (i / 200) as f64, 2.0 * gauss()])
            .collect();
        let shapes = local_shapes(&pts, StructureKind::Planes);
        let good = shapes
            .iter()
            .filter(|s| s.normal[2].abs() > 0.95 && s.scale >= 2)
            .count();
        assert!(good > 30_000, "{good} of 40000 points see the plane");
        let mut spread: Vec<f32> = shapes.iter().map(|s| s.sigma[2]).collect();
        spread.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let median = spread[spread.len() / 2];
        assert!((1.5..2.5).contains(&median), "noise estimate {median}");
    }

    #[test]
    fn row_gap_is_the_distance_between_scan_lines() {
        // Lines 1.5 apart, points 0.3 apart along them: the nearest
        // neighbour is on the line, the row gap is the next line.
        let pts: Vec<[f64; 3]> = (0..8)
            .flat_map(|j| (0..40).map(move |i| [0.3 * i as f64, 1.5 * j as f64, 0.0]))
            .collect();
        let shapes = local_shapes(&pts, StructureKind::Planes);
        for (p, s) in pts.iter().zip(&shapes) {
            assert!((s.spacing - 0.3).abs() < 1e-5);
            if p[0] > 3.0 && p[0] < 9.0 {
                assert!((s.row_gap - 1.5).abs() < 1e-5, "{p:?}: {}", s.row_gap);
            }
        }
        // Lines farther apart than the neighbourhood reaches: the gap is at
        // least its farthest neighbour (8 steps along the line).
        let pts: Vec<[f64; 3]> = (0..3)
            .flat_map(|j| (0..60).map(move |i| [0.3 * i as f64, 10.0 * j as f64, 0.0]))
            .collect();
        let shapes = local_shapes(&pts, StructureKind::Planes);
        assert!(
            (shapes[30].row_gap - 2.4).abs() < 1e-5,
            "{}",
            shapes[30].row_gap
        );
    }

    #[test]
    fn a_twin_line_does_not_hide_the_gap_to_the_next_pair() {
        // Scan lines in pairs (a zigzag scanner's forward and backward
        // lines near the swath's edges): 0.05 apart, the pairs 1.2 apart,
        // 0.3 between points along a line. The nearest neighbour is on the
        // twin line, across; the gap to bridge is to the next pair, not
        // the spacing along the line (0.3, what the nearest neighbour's
        // direction gave).
        let pts: Vec<[f64; 3]> = (0..6)
            .flat_map(|j| {
                (0..40).flat_map(move |i| {
                    let (x, y) = (0.3 * i as f64, 1.2 * j as f64);
                    [[x, y, 0.0], [x + 0.02, y + 0.05, 0.0]]
                })
            })
            .collect();
        let shapes = local_shapes(&pts, StructureKind::Planes);
        for (p, s) in pts.iter().zip(&shapes) {
            if p[0] > 3.0 && p[0] < 9.0 && p[1] > 2.0 && p[1] < 5.0 {
                assert!(s.row_gap > 1.0, "{p:?}: {}", s.row_gap);
            }
        }
    }

    #[test]
    fn line_direction_and_duplicates() {
        let mut pts: Vec<[f64; 3]> = (0..300).map(|i| [0.5 * i as f64, 0.0, 0.0]).collect();
        pts.extend_from_within(0..10); // exact duplicates
        let shapes = local_shapes(&pts, StructureKind::Lines);
        for s in &shapes {
            assert!(s.direction[0].abs() > 0.99);
            assert!(s.linearity() > 0.9);
            assert!((s.spacing - 0.5).abs() < 1e-6, "{}", s.spacing);
        }
    }

    #[test]
    fn a_pole_on_the_ground_is_not_a_surface() {
        // A 30 × 30 m ground on a 10 cm grid (1 cm of noise) and a pole
        // 7 m tall, 12 cm in radius (3 cm of noise), seen from one side as
        // a voxelized mapping scan sees it: 4 points across its half every
        // 10 cm.
        // Its points lie far fewer than the ground's, so the coarser
        // scales' neighbourhoods nearest to them are the ground's.
        let mut r = uniform(11);
        let mut pts: Vec<[f64; 3]> = Vec::new();
        for i in 0..300 {
            for j in 0..300 {
                pts.push([0.1 * i as f64, 0.1 * j as f64, 0.01 * (r() - 0.5)]);
            }
        }
        let first_pole = pts.len();
        for k in 0..70 {
            for a in 0..4 {
                let t = std::f64::consts::PI * (a as f64 + 0.5 * (k % 2) as f64) / 4.0;
                let e = 0.03 * (r() - 0.5);
                pts.push([
                    15.0 + (0.12 + e) * t.cos(),
                    15.0 - (0.12 + e) * t.sin(),
                    0.1 * k as f64 + 0.05,
                ]);
            }
        }
        let both = line_shapes_on_surfaces(&pts);
        let high = |i: &usize| pts[*i][2] > 0.5;
        let pole: Vec<usize> = (first_pole..pts.len()).filter(high).collect();
        let surface = pole.iter().filter(|&&i| both[i].1).count();
        assert!(
            surface * 10 <= pole.len(),
            "{surface} of {} pole points on a surface",
            pole.len()
        );
        // The ground stays a surface.
        let ground = (0..first_pole).filter(|&i| both[i].1).count();
        assert!(
            ground * 100 >= first_pole * 99,
            "{ground} of {first_pole} ground points"
        );
        // The same line shapes, and the plane shapes free to take any
        // coarser neighbourhood, would put the pole on the ground's
        // surface: what the test is about.
        let planes = local_shapes(&pts, StructureKind::Planes);
        let free = pole
            .iter()
            .filter(|&&i| on_surface(&both[i].0, &planes[i]))
            .count();
        assert!(
            free * 2 >= pole.len(),
            "{free} of {} with any coarser plane",
            pole.len()
        );
        // The line shapes are local_shapes' for lines.
        let lines = local_shapes(&pts, StructureKind::Lines);
        assert!(lines.iter().zip(&both).all(|(l, b)| *l == b.0));
    }
}
