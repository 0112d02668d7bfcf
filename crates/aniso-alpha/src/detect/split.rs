//! A detection split into independent per-tile steps, so that the
//! triangulations can run elsewhere (other processes, other machines: the
//! Python package's `aniso_alpha.distributed` runs them as Dask tasks).
//!
//! [`Detector::run`] with [`Detector::tile`] already cuts each
//! orientation's points into tiles with halos (method doc §8, see
//! `scan`). Here the same cut is turned inside out: the tiles are cut once
//! for every orientation, and each tile runs every orientation (job) on
//! its own points.
//!
//! 1. [`Detector::plan`] fixes everything global: the parameters (already
//!    estimated, once, by [`Detector::auto`] when automatic), the jobs
//!    (orientation, anisotropy, α and group of each), the tile side and the
//!    halo width (the largest 2α·λ_max of the jobs). [`Plan::tiles`] cuts
//!    the cloud into tiles: per tile, its cell and the ids of the points of
//!    the cell grown by the halo. [`Plan::members`] says which of those
//!    points each group (mode) of a data orientation set looks at.
//! 2. [`Step::run`] is the per-tile work, and all a worker needs: the
//!    [`Step`] (kind, tile side, jobs: a few numbers), the tile's cell, its
//!    points with their global ids and its [`Members`]. For each job it
//!    selects the members within the job's own halo, prunes, triangulates
//!    and keeps the simplices of `F_{k,α,Q}` whose smallest vertex lies in
//!    the tile's cell: exactly what the in-process tiled scan keeps for
//!    that tile, so a simplex is found by exactly one tile.
//! 3. [`Plan::finish`] gathers the tiles' outputs: per job, the union of
//!    its simplices over the tiles is the job's `F_{k,α,Q}` of the whole
//!    cloud; then the per-job path filter, the union over jobs, the
//!    component filter and the assembly, as [`Detector::run`] does.
//!
//! The result is [`Detector::run`]'s, label for label (tested below, with
//! tiles smaller than the structures). Only the [`RunStats`] differ: the
//! points triangulated count the halos.
//!
//! ```
//! use aniso_alpha::detect::Detector;
//! use aniso_alpha::synth;
//! let scene = synth::lines(1);
//! let d = Detector::lines(1.0, 10.0, 4);
//! let plan = d.plan(&scene.points, 25.0)?;
//! let step = plan.step();
//! let mut outputs = Vec::new();
//! for tile in plan.tiles(&scene.points) {
//!     // What a worker receives: the tile's points, their ids, the members.
//!     let pts: Vec<[f64; 3]> = tile.ids.iter().map(|&i| scene.points[i as usize]).collect();
//!     let members = plan.members(&tile.ids);
//!     outputs.push(step.run(tile.cell, &pts, &tile.ids, &members)?);
//! }
//! let split = plan.finish(&scene.points, outputs)?;
//! assert_eq!(split.labels, d.run(&scene.points)?.labels);
//! # Ok::<(), aniso_alpha::detect::DetectError>(())
//! ```

use super::assemble::Shape;
use super::cloud::{Cloud, Copies};
use super::detection::{Detection, RunStats};
use super::detector::{check_points, filter_of, DetectError, Detector, OrientationSet};
use super::regime::Regime;
use super::scan::{
    faces_of, filter_job, halo_width, prune_radius, pruned, tile_cell, Face, Job, Pruning,
};
use super::StructureKind;
use crate::aniso::Anisotropy;

/// Relative inflation of the halo in the reach of [`Plan::tiles`].
const TILE_HALO_SLACK: f64 = 1e-6;

/// Inflation of the reach of [`Plan::tiles`] relative to the tile side:
/// together with [`TILE_HALO_SLACK`] it makes sure that rounding in the
/// cell computation never leaves out of a tile a point that the exact
/// halo test of [`Step::run`] would take.
const TILE_SIDE_SLACK: f64 = 1e-9;

/// One job of a split run: an orientation with its anisotropy, its α and
/// its group (the mode of a data orientation set it belongs to, or 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitJob {
    /// Q = diag(E)·R.
    pub anisotropy: Anisotropy,
    /// α of this orientation.
    pub alpha: f64,
    /// Its group: [`Members`] says which points each group looks at.
    pub group: u32,
}

impl SplitJob {
    fn job(&self, ids: Option<&'static [u32]>) -> Job<'static> {
        Job {
            anisotropy: self.anisotropy,
            alpha: self.alpha,
            ids,
            group: self.group,
        }
    }
}

/// What a worker needs to run a tile: the structure kind, the tile side
/// and the jobs. Small (a few numbers per orientation) and independent of
/// the cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Lines (edges) or planes (triangles).
    pub kind: StructureKind,
    /// The side of the tiles' cells (input units).
    pub side: f64,
    /// The jobs, in the order of [`Detector::run`].
    pub jobs: Vec<SplitJob>,
}

/// The points of a tile each group looks at.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Members {
    /// Every group looks at every point (samplers and explicit rotations:
    /// one group).
    All,
    /// Per group g, the positions (into the tile's points, ascending) of
    /// its members: `ids[offsets[g]..offsets[g + 1]]`.
    Groups {
        /// `groups + 1` offsets into `ids`, from 0, non-decreasing.
        offsets: Vec<usize>,
        /// Positions into the tile's points.
        ids: Vec<u32>,
    },
}

/// One tile of a plan: its cell and the points of the cell grown by the
/// halo.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tile {
    /// The integer cell: the tile owns the points p with
    /// `floor(p / side) == cell`.
    pub cell: [i64; 3],
    /// Global ids (ascending) of the points of the cell and its halo.
    pub ids: Vec<u32>,
}

/// What one tile produced: per job, the simplices of `F_{k,α,Q}` the tile
/// owns, as global ids.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TileOutput {
    /// Vertices of the simplices (k + 1 per simplex, ascending within one),
    /// job after job.
    pub faces: Vec<u32>,
    /// `jobs + 1` offsets into `faces` (in vertices, not simplices).
    pub offsets: Vec<usize>,
    /// Points triangulated over the tile's jobs (after pruning).
    pub triangulated: u64,
}

/// A detection split into tiles ([`Detector::plan`], module doc).
#[derive(Debug, Clone)]
pub struct Plan {
    detector: Detector,
    step: Step,
    halo: f64,
    /// Per group, its members (global ids, ascending), or `None`: every
    /// point, one group.
    groups: Option<Vec<Vec<u32>>>,
    n: usize,
    /// The run's modes, decided on the plan's cloud.
    regime: Regime,
    /// Which points of the plan's cloud are copies.
    copies: Copies,
}

impl Detector {
    /// A split run over `points` with tiles of side `side` (module doc):
    /// the parameters and jobs of [`Self::run`], fixed now.
    ///
    /// # Errors
    /// As [`Self::run`], and a tile side that is not positive and finite.
    pub fn plan(&self, points: &[[f64; 3]], side: f64) -> Result<Plan, DetectError> {
        self.check_values()?;
        check_points(points)?;
        check_side(side)?;
        self.check_normals_of(points)?;
        let (jobs, _) = self.scan_jobs(self.modes())?;
        let halo = jobs.iter().map(halo_width).fold(0.0, f64::max);
        let jobs: Vec<SplitJob> = jobs
            .iter()
            .map(|j| SplitJob {
                anisotropy: j.anisotropy,
                alpha: j.alpha,
                group: j.group,
            })
            .collect();
        let groups = match (self.ladder(), self.orientations()) {
            (Some(l), _) => {
                (l.points.len() < points.len()).then(|| vec![l.points.clone(); l.alphas.len()])
            }
            (None, OrientationSet::Data(modes)) => {
                Some(modes.iter().map(|m| m.points.clone()).collect())
            }
            (None, _) => None,
        };
        Ok(Plan {
            step: Step {
                kind: self.kind(),
                side,
                jobs,
            },
            detector: self.clone(),
            halo,
            groups,
            n: points.len(),
            regime: self.regime(points),
            copies: Copies::of(points),
        })
    }
}

impl Plan {
    /// The same plan with tiles of another side (the parameters, already
    /// estimated, are kept).
    ///
    /// # Errors
    /// A side that is not positive and finite.
    pub fn with_side(&self, side: f64) -> Result<Plan, DetectError> {
        check_side(side)?;
        let mut p = self.clone();
        p.step.side = side;
        Ok(p)
    }

    /// The per-tile step (what every worker needs).
    pub fn step(&self) -> &Step {
        &self.step
    }

    /// The detector whose run this is (its parameters, for the report).
    pub fn detector(&self) -> &Detector {
        &self.detector
    }

    /// The halo width: the largest 2α·λ_max of the jobs (slightly
    /// inflated, see `scan`).
    pub fn halo(&self) -> f64 {
        self.halo
    }

    /// The tiles of `points` (the cloud the plan was made for): one per
    /// cell holding a point that some job looks at, with the ids of the
    /// points some job looks at in the cell grown by the halo (a little
    /// more: [`Step::run`] selects each job's own halo exactly), in cell
    /// order.
    ///
    /// Cost: every point is listed once per tile whose grown cell holds it,
    /// about (1 + 2·halo/side)³ times: tiles much smaller than the halo
    /// repeat points many times.
    pub fn tiles(&self, points: &[[f64; 3]]) -> Vec<Tile> {
        let side = self.step.side;
        let mut used: Vec<bool> = match &self.groups {
            None => vec![true; points.len()],
            Some(groups) => {
                let mut u = vec![false; points.len()];
                for &i in groups.iter().flatten() {
                    if let Some(x) = u.get_mut(i as usize) {
                        *x = true;
                    }
                }
                u
            }
        };
        // Exact copies of a point are one point (as in `Detector::run`):
        // only the first occurrence goes to the tiles. The triangulation
        // would keep that one anyway, and `finish` labels every copy by its
        // first occurrence; the copies would only cost the workers time.
        for (i, u) in used.iter_mut().enumerate() {
            *u &= self.copies.is_first(i);
        }
        let mut cells: Vec<[i64; 3]> = points
            .iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .map(|(p, _)| tile_cell(p, side))
            .collect();
        cells.sort_unstable();
        cells.dedup();
        // Each point goes to every cell whose grown box may hold it; the
        // reach is inflated so that rounding never leaves out a point the
        // exact test of `Step::run` would take.
        let reach = self.halo * (1.0 + TILE_HALO_SLACK) + side * TILE_SIDE_SLACK;
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (i, p) in points.iter().enumerate() {
            if !used[i] {
                continue;
            }
            let lo = tile_cell(&p.map(|x| x - reach), side);
            let hi = tile_cell(&p.map(|x| x + reach), side);
            for a in lo[0]..=hi[0] {
                for b in lo[1]..=hi[1] {
                    for c in lo[2]..=hi[2] {
                        if let Ok(t) = cells.binary_search(&[a, b, c]) {
                            pairs.push((t as u32, i as u32));
                        }
                    }
                }
            }
        }
        pairs.sort_unstable();
        let mut tiles: Vec<Tile> = cells
            .iter()
            .map(|&cell| Tile {
                cell,
                ids: Vec::new(),
            })
            .collect();
        for (t, i) in pairs {
            tiles[t as usize].ids.push(i);
        }
        tiles
    }

    /// The members of each group among the points `ids` (a tile's global
    /// ids, ascending).
    pub fn members(&self, ids: &[u32]) -> Members {
        let Some(groups) = &self.groups else {
            return Members::All;
        };
        let mut offsets = vec![0];
        let mut out = Vec::new();
        for g in groups {
            for (pos, id) in ids.iter().enumerate() {
                if g.binary_search(id).is_ok() {
                    out.push(pos as u32);
                }
            }
            offsets.push(out.len());
        }
        Members::Groups { offsets, ids: out }
    }

    /// Gathers the tiles' outputs (in any order, every tile of
    /// [`Self::tiles`] once) and finishes the run: per job, the path
    /// filter on its simplices from all tiles; the union over jobs, the
    /// component filter and the assembly, as [`Detector::run`].
    ///
    /// # Errors
    /// Bad points (not the plan's cloud), outputs that do not fit the plan
    /// (wrong offsets, ids out of range).
    pub fn finish(
        &self,
        points: &[[f64; 3]],
        outputs: impl IntoIterator<Item = TileOutput>,
    ) -> Result<Detection, DetectError> {
        check_points(points)?;
        if points.len() != self.n {
            return Err(DetectError::BadParameter(format!(
                "the plan was made for {} points, got {}",
                self.n,
                points.len()
            )));
        }
        let outputs: Vec<TileOutput> = outputs.into_iter().collect();
        match self.step.kind {
            StructureKind::Lines => self.finish_k::<[u32; 2]>(points, outputs),
            StructureKind::Planes => self.finish_k::<[u32; 3]>(points, outputs),
        }
    }

    fn finish_k<S: Shape>(
        &self,
        points: &[[f64; 3]],
        outputs: Vec<TileOutput>,
    ) -> Result<Detection, DetectError> {
        let jobs = &self.step.jobs;
        let k1 = S::K + 1;
        let mut stats = RunStats {
            orientations: jobs.len(),
            ..RunStats::default()
        };
        let mut per_job: Vec<Vec<S>> = vec![Vec::new(); jobs.len()];
        for o in &outputs {
            check_output(o, jobs.len(), k1, self.n)?;
            stats.triangulated_points += o.triangulated;
            for (j, faces) in per_job.iter_mut().enumerate() {
                let f = &o.faces[o.offsets[j]..o.offsets[j + 1]];
                faces.extend(f.chunks_exact(k1).map(|s| S::sorted(s.iter().copied())));
            }
        }
        drop(outputs);
        let mut cloud = Cloud::new(points, &self.copies);
        let sf = self.detector.scan_filters(&cloud, &self.regime, jobs.len());
        let one = |(mut faces, job): (Vec<S>, &SplitJob)| -> Result<(usize, Vec<S>), DetectError> {
            faces.sort_unstable();
            faces.dedup();
            let raw = faces.len();
            Ok((
                raw,
                filter_job(&faces, points, &job.anisotropy, filter_of(&sf, job.group))?,
            ))
        };
        #[cfg(feature = "parallel")]
        let filtered: Vec<Result<(usize, Vec<S>), DetectError>> = {
            use rayon::prelude::*;
            per_job
                .into_par_iter()
                .zip(jobs.par_iter())
                .map(one)
                .collect()
        };
        #[cfg(not(feature = "parallel"))]
        let filtered: Vec<Result<(usize, Vec<S>), DetectError>> =
            per_job.into_iter().zip(jobs.iter()).map(one).collect();
        let mut found = Vec::with_capacity(jobs.len());
        for (r, job) in filtered.into_iter().zip(jobs) {
            let (raw, faces) = r?;
            stats.raw_simplices += raw as u64;
            stats.filtered_simplices += faces.len() as u64;
            found.push((job.group, faces));
        }
        let (_, scales) = self.detector.scan_jobs(self.detector.modes())?;
        self.detector
            .finish_k(&mut cloud, &self.regime, found, scales, stats)
    }
}

fn check_side(side: f64) -> Result<(), DetectError> {
    if side.is_finite() && side > 0.0 {
        Ok(())
    } else {
        Err(DetectError::BadParameter(format!(
            "tile must be positive and finite, got {side}"
        )))
    }
}

/// Checks one tile's output against the plan.
fn check_output(o: &TileOutput, jobs: usize, k1: usize, n: usize) -> Result<(), DetectError> {
    let bad = |m: String| Err(DetectError::BadParameter(format!("tile output: {m}")));
    if o.offsets.len() != jobs + 1 || o.offsets[0] != 0 || o.offsets[jobs] != o.faces.len() {
        return bad(format!(
            "{} offsets for {jobs} jobs and {} vertices",
            o.offsets.len(),
            o.faces.len()
        ));
    }
    if o.offsets
        .windows(2)
        .any(|w| w[1] < w[0] || (w[1] - w[0]) % k1 != 0)
    {
        return bad(format!("offsets are not ascending multiples of {k1}"));
    }
    if let Some(v) = o.faces.iter().find(|&&v| v as usize >= n) {
        return bad(format!("vertex {v} out of range ({n} points)"));
    }
    Ok(())
}

impl Step {
    /// Runs every job on one tile: `points` are the tile's points (cell and
    /// halo, as [`Plan::tiles`] gives them), `ids` their global ids
    /// (strictly ascending), `members` which of them each group looks at
    /// ([`Plan::members`]). Per job, the simplices of `F_{k,α,Q}` whose
    /// smallest vertex lies in `cell`, as global ids.
    ///
    /// Runs the jobs in parallel (feature `parallel`) on the current rayon
    /// pool; the output does not depend on the thread count.
    ///
    /// # Errors
    /// Non-finite points, ids not ascending or not as many as the points,
    /// members out of range, or a triangulation failure.
    pub fn run(
        &self,
        cell: [i64; 3],
        points: &[[f64; 3]],
        ids: &[u32],
        members: &Members,
    ) -> Result<TileOutput, DetectError> {
        let bad = |m: String| Err(DetectError::BadParameter(m));
        if ids.len() != points.len() {
            return bad(format!(
                "a tile has {} points and {} ids",
                points.len(),
                ids.len()
            ));
        }
        if ids.windows(2).any(|w| w[1] <= w[0]) {
            return bad("a tile's ids must be strictly ascending".into());
        }
        if !points.is_empty() {
            check_points(points)?;
        }
        if let Members::Groups { offsets, ids: m } = members {
            let groups = self.jobs.iter().map(|j| j.group as usize + 1).max();
            if offsets.first() != Some(&0)
                || offsets.last() != Some(&m.len())
                || offsets.windows(2).any(|w| w[1] < w[0])
                || offsets.len() < groups.unwrap_or(0) + 1
            {
                return bad("a tile's member offsets do not fit its jobs".into());
            }
            if m.iter().any(|&p| p as usize >= points.len()) {
                return bad("a tile's members are out of range".into());
            }
        }
        let side = self.side;
        let lo = cell.map(|c| c as f64 * side);
        let hi = cell.map(|c| (c + 1) as f64 * side);
        let one = |job: &SplitJob| -> Result<(Vec<u32>, usize), DetectError> {
            let h = halo_width(&job.job(None));
            let inside = |&t: &u32| {
                let p = &points[t as usize];
                (0..3).all(|k| p[k] >= lo[k] - h && p[k] <= hi[k] + h)
            };
            let sub: Vec<u32> = match members {
                Members::All => (0..points.len() as u32).filter(inside).collect(),
                Members::Groups { offsets, ids: m } => {
                    let g = job.group as usize;
                    m[offsets[g]..offsets[g + 1]]
                        .iter()
                        .copied()
                        .filter(inside)
                        .collect()
                }
            };
            let owned = |t: u32| tile_cell(&points[t as usize], side) == cell;
            if !sub.iter().any(|&t| owned(t)) {
                return Ok((Vec::new(), 0));
            }
            match self.kind {
                StructureKind::Lines => tile_job::<[u32; 2]>(points, ids, &sub, job, &owned),
                StructureKind::Planes => tile_job::<[u32; 3]>(points, ids, &sub, job, &owned),
            }
        };
        #[cfg(feature = "parallel")]
        let per: Vec<Result<(Vec<u32>, usize), DetectError>> = {
            use rayon::prelude::*;
            self.jobs.par_iter().map(one).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let per: Vec<Result<(Vec<u32>, usize), DetectError>> = self.jobs.iter().map(one).collect();
        let mut out = TileOutput {
            offsets: vec![0],
            ..TileOutput::default()
        };
        for r in per {
            let (faces, triangulated) = r?;
            out.faces.extend(faces);
            out.offsets.push(out.faces.len());
            out.triangulated += triangulated as u64;
        }
        Ok(out)
    }
}

/// One job on one tile: the owned simplices of `F_{k,α,Q}` of the points
/// `sub` (positions into `points`, ascending), as global ids (flat), and
/// the number of points triangulated.
fn tile_job<S: Face>(
    points: &[[f64; 3]],
    ids: &[u32],
    sub: &[u32],
    job: &SplitJob,
    owned: &dyn Fn(u32) -> bool,
) -> Result<(Vec<u32>, usize), DetectError> {
    let job = job.job(None);
    let (map, q) = pruned(
        points,
        sub,
        &job.anisotropy,
        prune_radius(&job),
        &Pruning::Grid,
    );
    let triangulated = map.len();
    // Positions ascend with the global ids, so a simplex sorted by
    // position is sorted by id and its smallest vertex is the same.
    let faces = faces_of::<S>(q, &map, job.alpha, owned)?;
    let mut flat: Vec<u32> = faces
        .iter()
        .flat_map(|f| f.as_ref().iter().map(|&t| ids[t as usize]))
        .collect();
    // Sorted simplices (the order of the in-process tiled scan's output).
    let mut rows: Vec<&[u32]> = flat.chunks_exact(S::K + 1).collect();
    rows.sort_unstable();
    flat = rows.concat();
    Ok((flat, triangulated))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::Given;
    use crate::rng::SplitMix64;
    use crate::synth;

    /// Runs a plan tile by tile, each tile seeing only its own points (as a
    /// remote worker would), in reverse tile order.
    fn split_run(d: &Detector, pts: &[[f64; 3]], side: f64) -> (Detection, usize) {
        let plan = d.plan(pts, side).unwrap();
        let tiles = plan.tiles(pts);
        let n_tiles = tiles.len();
        let mut outs = Vec::new();
        for t in tiles.iter().rev() {
            let local: Vec<[f64; 3]> = t.ids.iter().map(|&i| pts[i as usize]).collect();
            let members = plan.members(&t.ids);
            outs.push(plan.step().run(t.cell, &local, &t.ids, &members).unwrap());
        }
        (plan.finish(pts, outs).unwrap(), n_tiles)
    }

    fn same(a: &Detection, b: &Detection) {
        assert_eq!(a.labels, b.labels);
        assert_eq!(a.part_labels(), b.part_labels());
        assert_eq!(a.structures, b.structures);
    }

    #[test]
    fn lines_split_equals_run() {
        let scene = synth::lines(1);
        let d = Detector::lines(1.0, 10.0, 4);
        let whole = d.run(&scene.points).unwrap();
        assert!(whole.structures.len() >= 4);
        // Lines of the scene are ~100 long: tiles of 20 cut each one.
        let (split, tiles) = split_run(&d, &scene.points, 20.0);
        assert!(tiles > 8, "{tiles} tiles");
        same(&split, &whole);
        // The in-process tiled run is the same too.
        same(
            &d.clone().tile(Some(20.0)).run(&scene.points).unwrap(),
            &whole,
        );
    }

    #[test]
    fn planes_split_equals_run() {
        let scene = synth::polyhedron(1);
        // λ₂ = λ₃ = 4 (no turns about the normals): a halo of 8, tiles of
        // 6 cut the box's faces (step 3, a dozen points a side).
        let d = Detector::planes(1.0, 4.0, 4.0, 20)
            .sampler(crate::detect::orientations::Sampler::Box { m1: 0.6, m2: 1 });
        let whole = d.run(&scene.points).unwrap();
        assert!(!whole.structures.is_empty());
        let (split, tiles) = split_run(&d, &scene.points, 6.0);
        assert!(tiles > 8, "{tiles} tiles");
        same(&split, &whole);
    }

    #[test]
    fn auto_split_equals_run() {
        // Two perpendicular noisy planes crossing many tiles.
        let mut pts = Vec::new();
        let mut rng = SplitMix64::new(7);
        let mut noise = || (rng.uniform() - 0.5) * 0.02;
        for i in 0..40 {
            for j in 0..40 {
                let (x, y) = (0.25 * i as f64, 0.25 * j as f64);
                pts.push([x + noise(), y + noise(), 2.0 + noise()]);
                pts.push([x + noise(), 4.0 + noise(), y + noise()]);
            }
        }
        let d = Detector::auto(StructureKind::Planes, &pts, &Given::default()).unwrap();
        let whole = d.run(&pts).unwrap();
        assert!(!whole.structures.is_empty());
        assert!(whole.labels.iter().filter(|&&l| l >= 0).count() > pts.len() / 2);
        let (split, tiles) = split_run(&d, &pts, 2.5);
        assert!(tiles > 8, "{tiles} tiles");
        same(&split, &whole);
    }

    #[test]
    fn copies_reach_no_tile_and_change_nothing() {
        // The lines scene with a copy of every third point and two of
        // every seventh: the tiles list first occurrences only, and the
        // split run gives what the run gives (which itself gives every
        // copy its first occurrence's labels).
        let scene = synth::lines(1);
        let n = scene.points.len();
        let mut pts = scene.points.clone();
        for i in (0..n).step_by(3) {
            pts.push(scene.points[i]);
        }
        for i in (0..n).step_by(7) {
            pts.extend([scene.points[i], scene.points[i]]);
        }
        let d = Detector::lines(1.0, 10.0, 4);
        let plan = d.plan(&pts, 20.0).unwrap();
        assert!(plan
            .tiles(&pts)
            .iter()
            .all(|t| t.ids.iter().all(|&i| (i as usize) < n)));
        let whole = d.run(&pts).unwrap();
        assert!(whole.structures.len() >= 4);
        let (split, tiles) = split_run(&d, &pts, 20.0);
        assert!(tiles > 8, "{tiles} tiles");
        same(&split, &whole);
        // The automatic mode (modes' members include every copy) too.
        let a = Detector::auto(StructureKind::Lines, &pts, &Given::default()).unwrap();
        same(&split_run(&a, &pts, 20.0).0, &a.run(&pts).unwrap());
    }

    #[test]
    fn a_missing_tile_changes_the_result() {
        // The check can fail: leaving a tile out loses simplices.
        let scene = synth::lines(1);
        let d = Detector::lines(1.0, 10.0, 4);
        let plan = d.plan(&scene.points, 20.0).unwrap();
        let mut outs: Vec<TileOutput> = plan
            .tiles(&scene.points)
            .iter()
            .map(|t| {
                let local: Vec<[f64; 3]> =
                    t.ids.iter().map(|&i| scene.points[i as usize]).collect();
                plan.step()
                    .run(t.cell, &local, &t.ids, &plan.members(&t.ids))
                    .unwrap()
            })
            .collect();
        let biggest = (0..outs.len())
            .max_by_key(|&i| outs[i].faces.len())
            .unwrap();
        outs.remove(biggest);
        let partial = plan.finish(&scene.points, outs).unwrap();
        assert_ne!(partial.labels, d.run(&scene.points).unwrap().labels);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let scene = synth::lines(1);
        let d = Detector::lines(1.0, 10.0, 4);
        assert!(d.plan(&scene.points, 0.0).is_err());
        assert!(d.plan(&scene.points, f64::NAN).is_err());
        let plan = d.plan(&scene.points, 50.0).unwrap();
        assert!(plan.with_side(-1.0).is_err());
        assert_eq!(plan.with_side(20.0).unwrap().step().side, 20.0);
        let step = plan.step();
        let p = [[0.0; 3], [1.0, 0.0, 0.0]];
        assert!(step.run([0; 3], &p, &[1, 0], &Members::All).is_err());
        assert!(step.run([0; 3], &p, &[0], &Members::All).is_err());
        let nan = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]];
        assert!(step.run([0; 3], &nan, &[0, 1], &Members::All).is_err());
        let wrong = TileOutput {
            faces: vec![0, 1, 2],
            offsets: vec![0, 3],
            triangulated: 0,
        };
        assert!(plan.finish(&scene.points, vec![wrong]).is_err());
        let far = TileOutput {
            faces: vec![0, u32::MAX],
            offsets: std::iter::once(0)
                .chain(std::iter::repeat_n(2, step.jobs.len()))
                .collect(),
            triangulated: 0,
        };
        assert!(plan.finish(&scene.points, vec![far]).is_err());
        assert!(plan.finish(&scene.points[1..], Vec::new()).is_err());
    }
}
