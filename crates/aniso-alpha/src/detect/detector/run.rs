//! The run of a detector (docs/method.md §4): the regime and the cloud's
//! context once, then the orientation scan, the union and its clean-up,
//! and the assembly.

use super::{check_points, elongation, DetectError, Detector, Mat3};
use crate::aniso::Anisotropy;
use crate::detect::assemble::{assemble, Scale, Settings, Shape};
use crate::detect::cloud::{Cloud, Copies};
use crate::detect::detection::{Detection, RunStats};
use crate::detect::estimate::ModeScan;
use crate::detect::filter::component_size_mask;
use crate::detect::orientations::MAX_ORIENTATIONS;
use crate::detect::prune::CandidatePairs;
use crate::detect::regime::Regime;
use crate::detect::scan::{
    raw_faces, run_job, union, ChanceScale, Face, Job, JobResult, Pruning, ScanFilter, RADIUS_SLACK,
};
use crate::detect::StructureKind;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Candidate pairs for the pruning are found once for all orientations
/// unless there would be more than this many per point (plus a constant):
/// then each orientation grids its own transformed points.
const PAIRS_PER_POINT: usize = 32;

impl Detector {
    /// Runs the detection on `points`.
    ///
    /// Exact copies of a point are one point: the run takes the distinct
    /// points (in order of first occurrence) and gives every copy its
    /// first occurrence's labels ([`Detection::first_occurrence`]), so a
    /// cloud of many copies costs what its distinct points cost.
    ///
    /// # Errors
    /// Bad parameters, empty input, non-finite coordinates, or a
    /// cancellation by the progress callback.
    pub fn run(&self, points: &[[f64; 3]]) -> Result<Detection, DetectError> {
        self.check_values()?;
        check_points(points)?;
        self.check_normals_of(points)?;
        let regime = self.regime(points);
        let copies = Copies::of(points);
        self.in_pool(|| self.run_distinct(points, &regime, copies))
    }

    /// `go` on this detector's thread pool ([`Self::threads`]), or on the
    /// current one.
    fn in_pool<T: Send>(
        &self,
        go: impl FnOnce() -> Result<T, DetectError> + Send,
    ) -> Result<T, DetectError> {
        #[cfg(feature = "parallel")]
        if let Some(n) = self.threads {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| DetectError::Internal(format!("thread pool: {e}")))?;
            return pool.install(go);
        }
        go()
    }

    /// The run on the distinct points of `points`. Copies of a point are
    /// one point to every step (the triangulation keeps one, the assembly
    /// labels first occurrences), but the candidate pairs and the scans'
    /// point subsets would still visit each copy: 200 copies of 1,000
    /// points took over 100 s against 3.6 s for the 1,000. So a cloud with
    /// copies runs on its distinct points, and every copy gets its first
    /// occurrence's result.
    fn run_distinct(
        &self,
        points: &[[f64; 3]],
        regime: &Regime,
        copies: Copies,
    ) -> Result<Detection, DetectError> {
        if !copies.any() {
            return self.run_cloud(&Cloud::new(points, &copies), regime, self.modes());
        }
        let distinct = copies.distinct();
        let sub: Vec<[f64; 3]> = distinct.iter().map(|&i| points[i as usize]).collect();
        let none = Copies::none(sub.len());
        let modes = modes_on_distinct(self.modes(), &copies);
        let det = self.run_cloud(&Cloud::new(&sub, &none), &regime.on(distinct), &modes)?;
        Ok(expand_distinct(det, copies))
    }

    /// The run on `cloud` over the groups `modes` (none: the sampler's or
    /// the explicit rotations over every point).
    fn run_cloud(
        &self,
        cloud: &Cloud<'_>,
        regime: &Regime,
        modes: &[ModeScan],
    ) -> Result<Detection, DetectError> {
        match regime.kind() {
            StructureKind::Lines => self.scan::<[u32; 2]>(cloud, regime, modes),
            StructureKind::Planes => self.scan::<[u32; 3]>(cloud, regime, modes),
        }
    }

    /// The orientation scan (one job per orientation, in parallel), then
    /// [`Self::finish_k`].
    fn scan<S: Shape>(
        &self,
        cloud: &Cloud<'_>,
        regime: &Regime,
        modes: &[ModeScan],
    ) -> Result<Detection, DetectError> {
        let points = cloud.points();
        let (jobs, scales) = self.scan_jobs(modes)?;
        let cands = self.candidate_pairs(points, regime);
        let pruning = match (&cands, self.prune) {
            (Some(c), _) => Pruning::Pairs(c),
            (None, true) => Pruning::Grid,
            (None, false) => Pruning::Off,
        };
        let done = AtomicUsize::new(0);
        let cancelled = AtomicBool::new(false);
        let total = jobs.len();
        let sf = self.scan_filter(cloud, regime, total);
        let one = |job: &Job<'_>| -> Result<JobResult<S>, DetectError> {
            if cancelled.load(Ordering::Relaxed) {
                return Err(DetectError::Cancelled);
            }
            let r = run_job::<S>(points, job, &pruning, self.tile, sf)?;
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(cb) = &self.progress {
                if !cb(d, total) {
                    cancelled.store(true, Ordering::Relaxed);
                }
            }
            Ok(r)
        };
        #[cfg(feature = "parallel")]
        let per: Vec<Result<JobResult<S>, DetectError>> = {
            use rayon::prelude::*;
            jobs.par_iter().map(one).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let per: Vec<Result<JobResult<S>, DetectError>> = jobs.iter().map(one).collect();
        if cancelled.load(Ordering::Relaxed) {
            return Err(DetectError::Cancelled);
        }
        let mut stats = RunStats {
            orientations: total,
            ..RunStats::default()
        };
        let mut found: Vec<(u32, Vec<S>)> = Vec::with_capacity(per.len());
        for (r, job) in per.into_iter().zip(&jobs) {
            let r = r?;
            stats.triangulated_points += r.triangulated as u64;
            stats.raw_simplices += r.raw as u64;
            stats.filtered_simplices += r.faces.len() as u64;
            found.push((job.group, r.faces));
        }
        self.finish_k(cloud, regime, found, scales, stats, sf)
    }

    /// Candidate pairs for the pruning, once for all orientations over
    /// every point, when the pruning is on, every orientation looks at
    /// every point, and they are not too many.
    fn candidate_pairs(&self, points: &[[f64; 3]], regime: &Regime) -> Option<CandidatePairs> {
        if !(self.prune && regime.scans_every_point()) {
            return None;
        }
        let lmax = self
            .elongation()
            .iter()
            .map(|&x| 1.0 / x)
            .fold(1.0, f64::max);
        let radius = 2.0 * self.alpha * (1.0 + RADIUS_SLACK);
        CandidatePairs::new(
            points,
            radius * lmax * (1.0 + RADIUS_SLACK),
            PAIRS_PER_POINT * points.len() + 1024,
        )
    }

    /// The path filter of each of the `orientations` orientations of a run
    /// on `cloud` in `regime` (`scan::ScanFilter`).
    pub(crate) fn scan_filter(
        &self,
        cloud: &Cloud<'_>,
        regime: &Regime,
        orientations: usize,
    ) -> ScanFilter {
        let chance = ChanceScale::new(cloud, self.alpha, self.elongation(), orientations);
        ScanFilter::new(regime, self.nb_c, chance)
    }

    /// The jobs of a run over the groups `modes` (none: this detector's
    /// sampler or rotations over every point), checked against
    /// [`MAX_ORIENTATIONS`], and the scale of each group.
    pub(crate) fn scan_jobs<'p>(
        &self,
        modes: &'p [ModeScan],
    ) -> Result<(Vec<Job<'p>>, Vec<Scale>), DetectError> {
        let (jobs, scales) = if modes.is_empty() {
            self.sampler_jobs()?
        } else {
            self.mode_jobs(modes)?
        };
        if jobs.len() > MAX_ORIENTATIONS {
            return Err(DetectError::BadParameter(format!(
                "{} orientations: at most {MAX_ORIENTATIONS} (coarser --m1, fewer --m2, or a larger --step)",
                jobs.len()
            )));
        }
        Ok((jobs, scales))
    }

    /// The jobs of a data orientation set: each mode's rotations over its
    /// points at its scale, the mode's index as the group.
    fn mode_jobs<'p>(
        &self,
        modes: &'p [ModeScan],
    ) -> Result<(Vec<Job<'p>>, Vec<Scale>), DetectError> {
        let mut jobs = Vec::new();
        let mut scales = Vec::new();
        for (g, m) in modes.iter().enumerate() {
            let e = elongation(self.kind, m.lambda2, m.lambda3);
            for r in &m.rotations {
                jobs.push(Job {
                    anisotropy: Anisotropy::from_matrix_rows(*r, e)?,
                    alpha: m.alpha,
                    ids: Some(&m.points),
                    group: g as u32,
                });
            }
            scales.push(scale(self.kind, m.alpha, m.lambda2, m.lambda3));
        }
        Ok((jobs, scales))
    }

    /// The jobs of a sampler or of explicit rotations: every rotation over
    /// every point, one group. (A data orientation set without modes has
    /// no rotations.)
    fn sampler_jobs(&self) -> Result<(Vec<Job<'static>>, Vec<Scale>), DetectError> {
        let e = self.elongation();
        let jobs = self
            .orientation_set()?
            .iter()
            .map(|r| {
                Ok(Job {
                    anisotropy: Anisotropy::from_matrix_rows(*r, e)?,
                    alpha: self.alpha,
                    ids: None,
                    group: 0,
                })
            })
            .collect::<Result<Vec<_>, DetectError>>()?;
        let scales = vec![scale(self.kind, self.alpha, self.lambda2, self.lambda3)];
        Ok((jobs, scales))
    }

    /// The steps after the scan: the union of the jobs' filtered simplices
    /// (`found`: per job, its group and its simplices), the component
    /// filter at the scan's threshold (`sf`) and the assembly. `stats`
    /// holds the scan's figures.
    pub(crate) fn finish_k<S: Shape>(
        &self,
        cloud: &Cloud<'_>,
        regime: &Regime,
        found: Vec<(u32, Vec<S>)>,
        scales: Vec<Scale>,
        mut stats: RunStats,
        sf: ScanFilter,
    ) -> Result<Detection, DetectError> {
        let (all, groups) = union(found);
        stats.union_simplices = all.len();
        let keep = component_size_mask(&all, sf.nb_c)?;
        let mut kept = Vec::with_capacity(all.len());
        let mut kept_groups = Vec::with_capacity(all.len());
        for ((s, g), k) in all.into_iter().zip(groups).zip(keep) {
            if k {
                kept.push(s);
                kept_groups.push(g);
            }
        }
        stats.kept_simplices = kept.len();
        let settings = Settings {
            part_angle_deg: self.part_angle_deg,
            min_vertices: S::min_vertices(self.nb_c),
            scales,
        };
        Ok(assemble::<S>(
            cloud,
            regime,
            kept,
            kept_groups,
            &settings,
            stats,
        )?)
    }

    /// The anisotropic α-shape `F_{k,α,Q}(P)` of one orientation (rows of
    /// R), before the path filter: sorted simplices of input indices,
    /// ascending within each. This is what [`Self::run`] computes for each
    /// orientation of a sampler, and a way to look at one of them.
    ///
    /// # Errors
    /// As [`Self::run`].
    pub fn orientation_faces(
        &self,
        points: &[[f64; 3]],
        rotation: &Mat3,
    ) -> Result<Vec<Vec<u32>>, DetectError> {
        self.check_values()?;
        check_points(points)?;
        let job = Job {
            anisotropy: Anisotropy::from_matrix_rows(*rotation, self.elongation())?,
            alpha: self.alpha,
            ids: None,
            group: 0,
        };
        let pruning = if self.prune {
            Pruning::Grid
        } else {
            Pruning::Off
        };
        let mut out: Vec<Vec<u32>> = match self.kind {
            StructureKind::Lines => {
                rows(raw_faces::<[u32; 2]>(points, &job, &pruning, self.tile)?.0)
            }
            StructureKind::Planes => {
                rows(raw_faces::<[u32; 3]>(points, &job, &pruning, self.tile)?.0)
            }
        };
        out.sort_unstable();
        Ok(out)
    }
}

/// Simplices as vectors.
fn rows<S: Face>(faces: Vec<S>) -> Vec<Vec<u32>> {
    faces.iter().map(|f| f.as_ref().to_vec()).collect()
}

/// The scale of a group's candidates: τ = α, and the footprint's cell the
/// ellipsoid's long reach α·λ.
fn scale(kind: StructureKind, alpha: f64, lambda2: f64, lambda3: f64) -> Scale {
    Scale {
        tau: alpha,
        cell: alpha
            * match kind {
                StructureKind::Lines => lambda3,
                StructureKind::Planes => lambda2.max(lambda3),
            },
    }
}

/// The modes of a data orientation set over the distinct points: their
/// members are input indices (the estimate ran on the whole cloud), each
/// becomes its position's index among the distinct points.
fn modes_on_distinct(modes: &[ModeScan], copies: &Copies) -> Vec<ModeScan> {
    let (first, distinct) = (copies.first(), copies.distinct());
    let mut at = vec![0u32; first.len()];
    for (k, &i) in distinct.iter().enumerate() {
        at[i as usize] = k as u32;
    }
    modes
        .iter()
        .map(|m| {
            let mut m = m.clone();
            for v in &mut m.points {
                *v = at[first[*v as usize] as usize];
            }
            m.points.sort_unstable();
            m.points.dedup();
            m
        })
        .collect()
}

/// The detection of a cloud with copies from that of its distinct points
/// (numbered in the order of `copies.distinct()`). Indices map through the
/// distinct points' input indices, which keeps their order, so every
/// sorted list stays sorted.
fn expand_distinct(mut det: Detection, copies: Copies) -> Detection {
    let distinct = copies.distinct();
    let to_input = |v: &mut u32| *v = distinct[*v as usize];
    for s in &mut det.simplices {
        s.iter_mut().for_each(to_input);
    }
    for st in &mut det.structures {
        st.vertices.iter_mut().for_each(to_input);
        for p in &mut st.parts {
            p.vertices.iter_mut().for_each(to_input);
            p.mesh.iter_mut().flatten().for_each(to_input);
        }
    }
    // Label of each distinct point, by its input index.
    let first = copies.first();
    let mut by_input = vec![-1i64; first.len()];
    for (k, &i) in distinct.iter().enumerate() {
        by_input[i as usize] = det.labels[k];
    }
    det.labels = first.iter().map(|&f| by_input[f as usize]).collect();
    det.first_occurrence = copies.into_first();
    det
}
