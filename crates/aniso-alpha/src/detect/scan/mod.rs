//! The orientation scan (paper §4.3, first step): for every orientation of
//! the set, `F_{k,α,Q}` of the points it looks at, path-filtered, and the
//! union of them all.
//!
//! One [`Job`] is an orientation with its anisotropy, its α and the points
//! it looks at: every point (the paper's samplers), or the points whose
//! local axis agrees with a mode of the data (the data orientation set, see
//! [`super::estimate`]). For each job: Q = diag(E)·R, transform the points,
//! drop the points isolated at distance 2α (exact, [`super::prune`]),
//! triangulate, select `F_{k,α,Q}` ([`super::faces`]: the same membership
//! as [`crate::alpha::AlphaComplex`], computed for one α), map back to
//! input indices and apply the path filter with `nb_c`.
//!
//! **Tiles** (method doc §8). `F_{k,α,Q}` is local: a simplex of it has an
//! empty ellipsoid of "radius" α through its vertices, which lies within
//! 2α·λ_max (Euclidean) of each vertex, and whether that ellipsoid is empty
//! depends only on the points there. So a job's points can be cut into
//! tiles (a grid of cubes of side `tile` over the original coordinates),
//! each triangulated with the points of its halo (those within
//! 2α·λ_max·(1 + 10⁻⁹) of the cube), and each tile keeps the simplices
//! whose smallest input index lies in its cube: the union is exactly the
//! job's `F_{k,α,Q}` (tested against the untiled result). Tiles bound the
//! memory of one triangulation and are independent tasks (in parallel here,
//! or spread over machines). A job of many points is always cut so
//! ([`tile_grid`], tiles of about [`TILE_POINTS`] points): the same faces,
//! one triangulation's memory bounded, its tiles on the pool's threads at
//! once.
//!
//! The path filter is not local (a path can cross tiles): it runs on the
//! job's gathered simplices. The union is a set, sorted; each simplex keeps
//! the smallest group (mode) id of the jobs that found it. The result does
//! not depend on the thread count. The path filter and its thresholds
//! (measured from the background for lines under the significance test)
//! are in `path_filter`.

mod path_filter;

pub(crate) use path_filter::{filter_job, ChanceScale, ScanFilter, LINE_SCAN_MIN};

use super::detection::Primitive;
use super::faces::{edges_at, edges_at_levels, triangles_at};
use super::filter::{FilterError, Simplex};
use super::fit::{fit_line_indices, fit_plane_indices};
use super::parts::{linear_parts, planar_parts, PartsError};
use super::prune::{non_isolated, CandidatePairs};
use crate::aniso::Anisotropy;
use crate::delaunay::{DelaunayError, Triangulation};
use crate::geometry::floor_i64;

/// Relative inflation of the pruning and halo radii, so that rounding in
/// the two ways of computing a distance never drops a point at exactly 2α.
pub(crate) const RADIUS_SLACK: f64 = 1e-9;

/// A simplex kind the detector works with: edges (k = 1) or triangles
/// (k = 2).
pub(crate) trait Face: Simplex + AsRef<[u32]> + Send + Sync + 'static {
    /// The simplex dimension.
    const K: usize;
    /// `F_{k,α}` of a triangulation.
    fn at(tri: &Triangulation, alpha: f64) -> Vec<Self>;
    /// `F_{k,α}` of a triangulation at each α of `alphas`.
    fn at_levels(tri: &Triangulation, alphas: &[f64]) -> Vec<Vec<Self>> {
        alphas.iter().map(|&a| Self::at(tri, a)).collect()
    }
    /// The simplex of the given vertices, sorted.
    fn sorted(v: impl Iterator<Item = u32>) -> Self;
    /// Straight or flat parts of a set of simplices.
    fn parts(points: &[[f64; 3]], s: &[Self], angle: f64) -> Result<Vec<u32>, PartsError>;
    /// Least-squares line or plane of points.
    fn fit(points: &[[f64; 3]], vertices: &[u32]) -> Primitive;
}

impl Face for [u32; 2] {
    const K: usize = 1;
    fn at(tri: &Triangulation, alpha: f64) -> Vec<Self> {
        edges_at(tri, alpha)
    }
    fn at_levels(tri: &Triangulation, alphas: &[f64]) -> Vec<Vec<Self>> {
        edges_at_levels(tri, alphas)
    }
    fn sorted(mut v: impl Iterator<Item = u32>) -> Self {
        let mut s = [v.next().unwrap_or(0), v.next().unwrap_or(0)];
        s.sort_unstable();
        s
    }
    fn parts(points: &[[f64; 3]], s: &[Self], angle: f64) -> Result<Vec<u32>, PartsError> {
        linear_parts(points, s, angle)
    }
    fn fit(points: &[[f64; 3]], vertices: &[u32]) -> Primitive {
        fit_line_indices(points, vertices).map_or(Primitive::None, Primitive::Line)
    }
}

impl Face for [u32; 3] {
    const K: usize = 2;
    fn at(tri: &Triangulation, alpha: f64) -> Vec<Self> {
        triangles_at(tri, alpha)
    }
    fn sorted(mut v: impl Iterator<Item = u32>) -> Self {
        let mut s = [
            v.next().unwrap_or(0),
            v.next().unwrap_or(0),
            v.next().unwrap_or(0),
        ];
        s.sort_unstable();
        s
    }
    fn parts(points: &[[f64; 3]], s: &[Self], angle: f64) -> Result<Vec<u32>, PartsError> {
        planar_parts(points, s, angle)
    }
    fn fit(points: &[[f64; 3]], vertices: &[u32]) -> Primitive {
        fit_plane_indices(points, vertices).map_or(Primitive::None, Primitive::Plane)
    }
}

/// One orientation of the scan with what it looks at.
#[derive(Debug, Clone)]
pub(crate) struct Job<'p> {
    /// Q = diag(E)·R.
    pub anisotropy: Anisotropy,
    /// The α of this orientation.
    pub alpha: f64,
    /// The points it looks at (ascending input indices), or every point.
    pub ids: Option<&'p [u32]>,
    /// The group (mode) it belongs to: the union keeps, per simplex, the
    /// smallest group that found it.
    pub group: u32,
}

/// What one job produced.
#[derive(Debug, Clone, Default)]
pub(crate) struct JobResult<S> {
    /// Filtered simplices, sorted.
    pub faces: Vec<S>,
    /// Points triangulated (after pruning), over its tiles.
    pub triangulated: usize,
    /// Simplices of `F_{k,α,Q}` before the path filter.
    pub raw: usize,
}

/// Why a job failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ScanError {
    /// The triangulation refused the transformed points (out of range).
    Triangulation(DelaunayError),
    /// An internal invariant of the filter broke.
    Filter(FilterError),
}

/// How the points of a job are pruned before triangulating.
pub(crate) enum Pruning<'c> {
    /// Not at all.
    Off,
    /// With a grid of the transformed points.
    Grid,
    /// With candidate pairs found once for all jobs over every point.
    Pairs(&'c CandidatePairs),
}

/// Four sentinel points around a box, farther than 2α from every point in
/// it (the distance from any point of the box to a sentinel is at least
/// (√3/2)·`ext` > 2α), so that a flat or straight set becomes
/// 3-dimensional without changing `F_α`. Not farther than needed: far
/// sentinels make slivers, which the exact arithmetic pays for.
fn sentinels(lo: [f64; 3], hi: [f64; 3], alpha: f64) -> [[f64; 3]; 4] {
    let ext = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max) + 4.0 * alpha + 1.0;
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ]
    .map(|s| [c[0] + ext * s[0], c[1] + ext * s[1], c[2] + ext * s[2]])
}

/// `F_{k,α,Q}` of the transformed points `q` (which are the input points
/// `map[..]`), as sorted input-index simplices. Points at positions ≥
/// `owned_below` of `map` are halo points: a simplex is kept only when its
/// smallest vertex (in input numbering) is owned.
pub(crate) fn faces_of<S: Face>(
    q: Vec<[f64; 3]>,
    map: &[u32],
    alpha: f64,
    owned: &dyn Fn(u32) -> bool,
) -> Result<Vec<S>, ScanError> {
    Ok(faces_at::<S>(q, map, &[alpha], owned)?
        .pop()
        .unwrap_or_default())
}

/// [`faces_of`] at each α of `alphas` from one triangulation (the
/// Delaunay tetrahedralization of Q·P does not depend on α; the points
/// kept by a pruning at the largest α give every smaller α's faces too,
/// since a point isolated at 2α is a vertex of no face at α).
pub(crate) fn faces_at<S: Face>(
    mut q: Vec<[f64; 3]>,
    map: &[u32],
    alphas: &[f64],
    owned: &dyn Fn(u32) -> bool,
) -> Result<Vec<Vec<S>>, ScanError> {
    if q.len() < 2 {
        return Ok(vec![Vec::new(); alphas.len()]);
    }
    let n_real = q.len() as u32;
    let mut tri = Triangulation::new(&q).map_err(ScanError::Triangulation)?;
    if tri.dimension() < 3 {
        let (lo, hi) = crate::geometry::bounding_box(&q);
        let top = alphas.iter().copied().fold(0.0, f64::max);
        q.extend(sentinels(lo, hi, top));
        tri = Triangulation::new(&q).map_err(ScanError::Triangulation)?;
    }
    Ok(S::at_levels(&tri, alphas)
        .into_iter()
        .map(|faces| {
            faces
                .into_iter()
                .filter(|f| f.as_ref().iter().all(|&v| v < n_real))
                .map(|f| S::sorted(f.as_ref().iter().map(|&v| map[v as usize])))
                .filter(|f| owned(f.as_ref()[0]))
                .collect()
        })
        .collect())
}

/// The points of `ids` kept by the pruning under `a`, and their transforms.
pub(crate) fn pruned(
    points: &[[f64; 3]],
    ids: &[u32],
    a: &Anisotropy,
    radius: f64,
    pruning: &Pruning<'_>,
) -> (Vec<u32>, Vec<[f64; 3]>) {
    match pruning {
        Pruning::Pairs(c) => {
            // Candidate pairs cover every point: `ids` is all of them.
            let keep = c.non_isolated_under(points, &a.q(), radius);
            let map: Vec<u32> = ids.iter().copied().filter(|&i| keep[i as usize]).collect();
            let kept: Vec<[f64; 3]> = map.iter().map(|&i| points[i as usize]).collect();
            let q = a.transform(&kept);
            (map, q)
        }
        Pruning::Grid | Pruning::Off => {
            let sub: Vec<[f64; 3]> = ids.iter().map(|&i| points[i as usize]).collect();
            let q = a.transform(&sub);
            if matches!(pruning, Pruning::Off) {
                return (ids.to_vec(), q);
            }
            let keep = non_isolated(&q, radius);
            let mut map = Vec::with_capacity(ids.len());
            let mut out = Vec::with_capacity(ids.len());
            for (t, &i) in ids.iter().enumerate() {
                if keep[t] {
                    map.push(i);
                    out.push(q[t]);
                }
            }
            (map, out)
        }
    }
}

/// The pruning radius of a job: 2α, inflated by [`RADIUS_SLACK`].
pub(crate) fn prune_radius(job: &Job<'_>) -> f64 {
    2.0 * job.alpha * (1.0 + RADIUS_SLACK)
}

/// The halo width of a job's tiles: 2α·λ_max, inflated twice by
/// [`RADIUS_SLACK`].
pub(crate) fn halo_width(job: &Job<'_>) -> f64 {
    let lmax = job
        .anisotropy
        .lambdas()
        .iter()
        .fold(1.0f64, |m, &l| m.max(l));
    2.0 * job.alpha * lmax * (1.0 + RADIUS_SLACK) * (1.0 + RADIUS_SLACK)
}

/// The tile (integer cell of side `side`) that owns a point.
pub(crate) fn tile_cell(p: &[f64; 3], side: f64) -> [i64; 3] {
    TileGrid::from_origin(side).cell(p)
}

/// The cubes a large job is cut into ([`tile_grid`]): side `side`, corner
/// of cube (0, 0, 0) at `origin`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct TileGrid {
    side: f64,
    origin: [f64; 3],
}

impl TileGrid {
    /// The cubes of side `side` from the origin: the tiles a user asks for
    /// (`--tile`) and those of the distributed split, which separate runs
    /// must agree on.
    fn from_origin(side: f64) -> Self {
        TileGrid {
            side,
            origin: [0.0; 3],
        }
    }

    /// The cube that owns point `p`.
    fn cell(&self, p: &[f64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|k| floor_i64((p[k] - self.origin[k]) / self.side))
    }

    /// The cubes that own a point of `ids`, sorted and distinct: a job's
    /// tiles.
    fn cells(&self, points: &[[f64; 3]], ids: &[u32]) -> Vec<[i64; 3]> {
        let mut cells: Vec<[i64; 3]> = ids
            .iter()
            .map(|&i| self.cell(&points[i as usize]))
            .collect();
        cells.sort_unstable();
        cells.dedup();
        cells
    }

    /// The lower corner of cube `c` along axis `k` (the upper one is that
    /// of `c + 1`).
    fn corner(&self, c: i64, k: usize) -> f64 {
        self.origin[k] + c as f64 * self.side
    }

    /// For each cube of `tiles` (sorted, distinct), the ranks in `ids` of
    /// the points in it grown by `h` on every side, ascending. Each point
    /// is tested against the cubes next to the cells of its coordinates
    /// ± h, axis by axis: a pass over the points and a sort-free bucketing,
    /// where a spatial index queried per tile cost more than the tiles'
    /// own bookkeeping.
    fn members(
        &self,
        points: &[[f64; 3]],
        ids: &[u32],
        tiles: &[[i64; 3]],
        h: f64,
    ) -> Vec<Vec<u32>> {
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); tiles.len()];
        let mut near: [Vec<i64>; 3] = Default::default();
        for (rank, &i) in ids.iter().enumerate() {
            let p = &points[i as usize];
            for (k, cells) in near.iter_mut().enumerate() {
                cells.clear();
                let first = floor_i64((p[k] - h - self.origin[k]) / self.side) - 1;
                let last = floor_i64((p[k] + h - self.origin[k]) / self.side) + 1;
                cells.extend((first..=last).filter(|&c| {
                    p[k] >= self.corner(c, k) - h && p[k] <= self.corner(c + 1, k) + h
                }));
            }
            for &x in &near[0] {
                for &y in &near[1] {
                    for &z in &near[2] {
                        if let Ok(t) = tiles.binary_search(&[x, y, z]) {
                            members[t].push(rank as u32);
                        }
                    }
                }
            }
        }
        members
    }
}

/// Unfiltered `F_{k,α,Q}` of one job, as sorted input-index simplices, and
/// the number of points triangulated. With `tile = Some(side)`, the job's
/// points are cut into tiles with halos (module doc).
pub(crate) fn raw_faces<S: Face>(
    points: &[[f64; 3]],
    job: &Job<'_>,
    pruning: &Pruning<'_>,
    tile: Option<f64>,
) -> Result<(Vec<S>, usize), ScanError> {
    let (mut faces, n) = raw_faces_at::<S>(points, job, &[job.alpha], pruning, tile)?;
    Ok((faces.pop().unwrap_or_default(), n))
}

/// [`raw_faces`] at each α of `alphas` (none above the job's α, which
/// sets the pruning and the halos) from the job's triangulations.
fn raw_faces_at<S: Face>(
    points: &[[f64; 3]],
    job: &Job<'_>,
    alphas: &[f64],
    pruning: &Pruning<'_>,
    tile: Option<f64>,
) -> Result<(Vec<Vec<S>>, usize), ScanError> {
    let all: Vec<u32>;
    let ids: &[u32] = match job.ids {
        Some(ids) => ids,
        None => {
            all = (0..points.len() as u32).collect();
            &all
        }
    };
    let a = &job.anisotropy;
    let radius = prune_radius(job);
    let Some(side) = tile.filter(|&s| s.is_finite() && s > 0.0) else {
        let (map, q) = pruned(points, ids, a, radius, pruning);
        let n = map.len();
        let faces = match tile_grid(points, &map, job) {
            Some(grid) => faces_in_tiles::<S>(points, &map, &q, alphas, grid, halo_width(job))?,
            None => {
                let mut faces = faces_at::<S>(q, &map, alphas, &|_| true)?;
                faces.iter_mut().for_each(|f| f.sort_unstable());
                faces
            }
        };
        return Ok((faces, n));
    };
    // Tiles: integer cells of side `side`; halo `h` around each.
    let h = halo_width(job);
    let grid = TileGrid::from_origin(side);
    let cell = |p: &[f64; 3]| -> [i64; 3] { grid.cell(p) };
    let tiles = grid.cells(points, ids);
    let members = grid.members(points, ids, &tiles, h);
    let mut faces: Vec<Vec<S>> = vec![Vec::new(); alphas.len()];
    let mut triangulated = 0usize;
    for (t, ranks) in tiles.into_iter().zip(members) {
        let mut sub: Vec<u32> = ranks.iter().map(|&r| ids[r as usize]).collect();
        sub.sort_unstable();
        let (map, q) = pruned(points, &sub, a, radius, &Pruning::Grid);
        triangulated += map.len();
        let owned = |v: u32| cell(&points[v as usize]) == t;
        for (all, f) in faces
            .iter_mut()
            .zip(faces_at::<S>(q, &map, alphas, &owned)?)
        {
            all.extend(f);
        }
    }
    for f in &mut faces {
        f.sort_unstable();
        f.dedup();
    }
    Ok((faces, triangulated))
}

/// Points per tile of a large job ([`tile_grid`]): 2^13. One
/// triangulation holds about 7 cells of 32 bytes a point besides its
/// points, so a job of 72,000 points (the table of a depth frame) held
/// 18 MB at once, as much as CGAL's Efficient RANSAC's whole process on
/// that frame; cut, its tiles run on the threads at once, a few at a
/// time. Measured on the train half (BENCHMARKS.md, "Peaks of one stage
/// at a time"; 2 threads, tiles of 2^14 / 2^15 / 2^16 / never): mOSD
/// learn 5 peak 35 / 37 / 38 / 40 MB, scan 0.12 / 0.13 / 0.19 / 0.19 s;
/// the simulated house 5.2 / 4.9 / 4.9 / 5.9 s; the room and the AHN
/// tile alike within 0.03 s. Then 2^13 against 2^14 (train, 2 threads,
/// two runs each): the AHN tile 20.1–21.4 against 22.6–23.4 MB, the
/// simulated airborne block 21.5–21.7 against 22.4–22.9 MB, mOSD learn 5,
/// learn 17, the room, the halls, CGAL's building and the house within
/// a run's spread (±1.5 MB), and the same wall times (the house 3.75–3.82
/// s on two threads, 5.98–6.20 s on one, either size). On one thread a
/// tile's own costs (its halo, the gathering of its points, its first
/// tetrahedron) cost the house's scan 18% at 2^14 against one
/// triangulation.
#[cfg(not(test))]
const TILE_POINTS: usize = 1 << 13;
/// A few hundred points in the tests, so that small clouds take the path.
#[cfg(test)]
const TILE_POINTS: usize = 1 << 8;

/// The fewest points per tile when a job is cut finer than
/// [`TILE_POINTS`] to give the pool's threads four tiles each: 2^11. A
/// job of a few tiles' worth (the flat mode of an airborne block, 35,000
/// points in four tiles of 9,000) otherwise leaves threads waiting on its
/// last tiles. Measured at 2^12 for every job (train, 2 threads, medians
/// of 7): the simulated airborne block's scan 70 → 59 ms, the AHN tile's
/// 69 → 61 ms, but mOSD learn 8's 137 → 143 ms (20 tiles already: the
/// smaller tiles' halos cost more than they balance); hence finer only
/// where the tiles are fewer than the threads can share.
#[cfg(not(test))]
const MIN_TILE_POINTS: usize = 1 << 11;
/// A few dozen points in the tests.
#[cfg(test)]
const MIN_TILE_POINTS: usize = 1 << 6;

/// The cubes in which a large job's kept points `map` are cut, so that no
/// triangulation holds much more than [`TILE_POINTS`] points and the tiles
/// run on the pool's threads at once (at least four a thread where that
/// leaves [`MIN_TILE_POINTS`] a tile), or `None` for one triangulation:
/// fewer than two tiles' worth of points, or a halo (2α·λ_max) that leaves
/// tiles less than eight halos wide. The cubes start at the lower corner
/// of the points' box, so that a surface along a face of the box (a scan's
/// ground, lower than all else) lies inside one layer of cubes rather
/// than on a face between two, where every point would be in both halos.
/// The result does not depend on it (module doc: the tiles' union is the
/// job's `F_{k,α,Q}` exactly); the points triangulated are counted once,
/// as untiled.
fn tile_grid(points: &[[f64; 3]], map: &[u32], job: &Job<'_>) -> Option<TileGrid> {
    if map.len() < 2 * TILE_POINTS {
        return None;
    }
    let tiles = map.len() / TILE_POINTS;
    let shared = (4 * crate::par::threads()).min(map.len() / MIN_TILE_POINTS);
    let (lo, hi) = crate::geometry::bounding_box_of(points, map);
    let mut ext = [0, 1, 2].map(|k| hi[k] - lo[k]);
    ext.sort_unstable_by(f64::total_cmp);
    // Cubes over the two largest extents: a surface's points (a scan's
    // ground, a facade, a table) spread over two of them.
    let h = halo_width(job);
    let grid = |tiles: usize| {
        let side = (ext[1] * ext[2] / tiles as f64).sqrt();
        (side.is_finite() && side >= 8.0 * h && ext[2] > side)
            .then_some(TileGrid { side, origin: lo })
    };
    grid(tiles.max(shared)).or_else(|| grid(tiles))
}

/// `F_{k,α,Q}` at each α of `alphas` of the kept points `map` (transforms
/// `q`, input indices ascending) cut into the cubes of `grid` with halos
/// `h`, the tiles triangulated at once on the pool's threads; each tile
/// keeps the simplices whose smallest vertex it owns, so the union, sorted,
/// is the untiled result (module doc).
fn faces_in_tiles<S: Face>(
    points: &[[f64; 3]],
    map: &[u32],
    q: &[[f64; 3]],
    alphas: &[f64],
    grid: TileGrid,
    h: f64,
) -> Result<Vec<Vec<S>>, ScanError> {
    let cell = |p: &[f64; 3]| -> [i64; 3] { grid.cell(p) };
    let tiles = grid.cells(points, map);
    let members = grid.members(points, map, &tiles, h);
    // Each tile a task: tiles hold from a few points to a full tile's.
    let per_tile = crate::par::map_each(tiles.len(), |k| {
        let t = tiles[k];
        let sub: Vec<u32> = members[k].iter().map(|&r| map[r as usize]).collect();
        let sub_q: Vec<[f64; 3]> = members[k].iter().map(|&r| q[r as usize]).collect();
        let owned = |v: u32| cell(&points[v as usize]) == t;
        faces_at::<S>(sub_q, &sub, alphas, &owned)
    });
    let mut faces: Vec<Vec<S>> = vec![Vec::new(); alphas.len()];
    for tile in per_tile {
        for (all, f) in faces.iter_mut().zip(tile?) {
            all.extend(f);
        }
    }
    for f in &mut faces {
        crate::par::sort_unstable(f);
        f.dedup();
    }
    Ok(faces)
}

/// One job: raw faces, then the path filter.
pub(crate) fn run_job<S: Face>(
    points: &[[f64; 3]],
    job: &Job<'_>,
    pruning: &Pruning<'_>,
    tile: Option<f64>,
    sf: ScanFilter,
) -> Result<JobResult<S>, ScanError> {
    let mut one = run_job_at::<S>(points, job, &[job.alpha], pruning, tile, &[sf])?;
    Ok(one.pop().unwrap_or(JobResult {
        faces: Vec::new(),
        triangulated: 0,
        raw: 0,
    }))
}

/// [`run_job`] at each α of `alphas` (none above the job's), from one
/// triangulation per tile: the results in the order of `alphas`, each
/// filtered by its own `sf` (the points triangulated are counted once,
/// with the first).
pub(crate) fn run_job_at<S: Face>(
    points: &[[f64; 3]],
    job: &Job<'_>,
    alphas: &[f64],
    pruning: &Pruning<'_>,
    tile: Option<f64>,
    sf: &[ScanFilter],
) -> Result<Vec<JobResult<S>>, ScanError> {
    let (per_alpha, triangulated) = raw_faces_at::<S>(points, job, alphas, pruning, tile)?;
    per_alpha
        .into_iter()
        .zip(sf)
        .enumerate()
        .map(|(i, (faces, &sf))| {
            Ok(JobResult {
                raw: faces.len(),
                faces: filter_job(&faces, points, &job.anisotropy, sf)?,
                triangulated: if i == 0 { triangulated } else { 0 },
            })
        })
        .collect()
}

/// The union of the jobs' simplices (a sorted set) with, per simplex, the
/// smallest group that found it.
pub(crate) fn union<S: Face>(per_job: Vec<(u32, Vec<S>)>) -> (Vec<S>, Vec<u32>) {
    let mut all: Vec<(S, u32)> = per_job
        .into_iter()
        .flat_map(|(g, faces)| faces.into_iter().map(move |f| (f, g)))
        .collect();
    // Each job's simplices come sorted: a stable sort finds those runs and
    // merges them, in time linear in the simplices for a few jobs.
    all.sort();
    all.dedup_by(|b, a| a.0 == b.0);
    all.into_iter().unzip()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// A noisy ground with a roof step, 6,000 points over 100 × 60.
    fn ground() -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(27);
        (0..6000)
            .map(|_| {
                let x = 100.0 * rng.uniform();
                let y = 60.0 * rng.uniform();
                let z = if x > 40.0 && x < 55.0 { 6.0 } else { 0.0 } + 0.05 * rng.uniform();
                [x, y, z]
            })
            .collect()
    }

    /// Faces per α, and the points triangulated.
    #[cfg(feature = "parallel")]
    type Run<S> = (Vec<Vec<S>>, usize);

    /// A ground across z = 0 lies in one layer of the cubes it is cut
    /// into (they start at its box's corner): a grid from the origin cut
    /// it along the plane z = 0, and every point was in two tiles' halos.
    #[test]
    fn a_ground_across_zero_is_cut_into_one_layer_of_tiles() {
        let pts: Vec<[f64; 3]> = ground()
            .into_iter()
            .map(|[x, y, z]| [x, y, z - 0.025])
            .collect();
        assert!(pts.iter().any(|p| p[2] < 0.0) && pts.iter().any(|p| p[2] > 0.0));
        let job = Job {
            anisotropy: Anisotropy::plane([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 2.0, 2.0).unwrap(),
            alpha: 0.5,
            ids: None,
            group: 0,
        };
        let all: Vec<u32> = (0..pts.len() as u32).collect();
        let grid = tile_grid(&pts, &all, &job).expect("cut into tiles");
        let layers: std::collections::BTreeSet<i64> = pts
            .iter()
            .filter(|p| p[2] < 1.0)
            .map(|p| grid.cell(p)[2])
            .collect();
        assert_eq!(layers.len(), 1, "{layers:?}");
        // The oracle tells a grid from the origin apart.
        let from_origin = TileGrid::from_origin(grid.side);
        assert!(pts
            .iter()
            .any(|p| from_origin.cell(p)[2] != grid.cell(p)[2]));
    }

    /// Each tile's members are the points in its cube grown by h, tested
    /// against every point (the oracle), with halos narrower and wider
    /// than the cubes (a user's `--tile` may be smaller than the halo),
    /// tiles that are missing from the list included; the oracle tells a
    /// halo dropped on one side apart.
    #[test]
    fn tile_members_are_the_points_of_each_grown_cube() {
        let pts = ground();
        let ids: Vec<u32> = (0..pts.len() as u32).filter(|i| i % 3 != 0).collect();
        let brute = |grid: &TileGrid, t: [i64; 3], h: f64, shrink: f64| -> Vec<u32> {
            (0..ids.len() as u32)
                .filter(|&r| {
                    let p = &pts[ids[r as usize] as usize];
                    (0..3).all(|k| {
                        p[k] >= grid.corner(t[k], k) - h + shrink
                            && p[k] <= grid.corner(t[k] + 1, k) + h
                    })
                })
                .collect()
        };
        for (side, h) in [(7.0, 0.5), (7.0, 3.0), (2.0, 5.0)] {
            let grid = TileGrid {
                side,
                origin: [-0.3, 0.2, -0.1],
            };
            let mut tiles: Vec<[i64; 3]> =
                ids.iter().map(|&i| grid.cell(&pts[i as usize])).collect();
            tiles.sort_unstable();
            tiles.dedup();
            // Every other tile, so that points fall in the halos of tiles
            // that are not listed.
            let tiles: Vec<[i64; 3]> = tiles.into_iter().step_by(2).collect();
            let members = grid.members(&pts, &ids, &tiles, h);
            assert_eq!(members.len(), tiles.len());
            let mut differs = false;
            for (t, m) in tiles.iter().zip(&members) {
                assert_eq!(m, &brute(&grid, *t, h, 0.0), "side {side} h {h} tile {t:?}");
                differs |= m != &brute(&grid, *t, h, h);
            }
            assert!(differs, "the oracle cannot tell a halo dropped apart");
        }
    }

    /// The faces of `job` at `alphas`: one triangulation of every kept
    /// point (the oracle), and the job as run on 1 and 4 threads.
    #[cfg(feature = "parallel")]
    fn whole_and_run<S: Face + Ord>(
        pts: &[[f64; 3]],
        job: &Job<'_>,
        alphas: &[f64],
    ) -> (Vec<Vec<S>>, Vec<Run<S>>) {
        let all: Vec<u32> = (0..pts.len() as u32).collect();
        let (map, q) = pruned(
            pts,
            &all,
            &job.anisotropy,
            prune_radius(job),
            &Pruning::Grid,
        );
        let mut whole = faces_at::<S>(q, &map, alphas, &|_| true).unwrap();
        whole.iter_mut().for_each(|f| f.sort_unstable());
        let runs = [1, 4]
            .map(|threads| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                pool.install(|| raw_faces_at::<S>(pts, job, alphas, &Pruning::Grid, None).unwrap())
            })
            .to_vec();
        (whole, runs)
    }

    /// A large job is cut into tiles, on one thread as on four, and gives
    /// the faces of one triangulation of all its kept points, edges and
    /// triangles, at several α.
    #[cfg(feature = "parallel")]
    #[test]
    fn a_large_job_cut_into_tiles_has_the_faces_of_one_triangulation() {
        let pts = ground();
        let anisotropy = Anisotropy::plane([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 2.0, 2.0).unwrap();
        let job = Job {
            anisotropy,
            alpha: 0.5,
            ids: None,
            group: 0,
        };
        let all: Vec<u32> = (0..6000).collect();
        let (map, _) = pruned(
            &pts,
            &all,
            &job.anisotropy,
            prune_radius(&job),
            &Pruning::Grid,
        );
        let grid = tile_grid(&pts, &map, &job).expect("cut into tiles");
        assert!(grid.side < 50.0, "{grid:?}");
        let alphas = [0.3, 0.4, 0.5];
        let (whole_e, runs_e) = whole_and_run::<[u32; 2]>(&pts, &job, &alphas);
        let (whole_t, runs_t) = whole_and_run::<[u32; 3]>(&pts, &job, &alphas);
        for (e, t) in runs_e.iter().zip(&runs_t) {
            assert!(e.0 == whole_e, "edges differ");
            assert!(t.0 == whole_t, "triangles differ");
            assert_eq!(t.1, map.len());
        }
        assert!(whole_e.iter().all(|f| !f.is_empty()) && whole_t[2].len() > 1000);
        // The faces grow with α.
        assert!(whole_t[0].len() < whole_t[2].len());
    }
}
