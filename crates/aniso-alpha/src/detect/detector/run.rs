//! The run of a detector (docs/method.md §4): the regime and the cloud's
//! context once, then the orientation scan, the union and its clean-up,
//! and the assembly.

use super::{check_points, elongation, DetectError, Detector, Mat3};
use crate::aniso::Anisotropy;
use crate::detect::assemble::{self, Scale, Settings, Shape};
use crate::detect::cloud::{Cloud, Copies};
use crate::detect::detection::{Detection, RunStats};
use crate::detect::estimate::{Ladder, ModeScan};
use crate::detect::orientations::MAX_ORIENTATIONS;
use crate::detect::prune::CandidatePairs;
use crate::detect::regime::Regime;
use crate::detect::scan::{
    raw_faces, run_job, run_job_at, union, ChanceScale, Face, Job, JobResult, Pruning, ScanFilter,
    RADIUS_SLACK,
};
use crate::detect::stages::Stage;
use crate::detect::StructureKind;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// What one job of a scan gives: per level (one without a ladder), the
/// group and the result.
type PerJob<S> = Result<Vec<(u32, JobResult<S>)>, DetectError>;

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
            return self.run_cloud(&mut Cloud::new(points, &copies), regime, self.modes());
        }
        let distinct = copies.distinct();
        let sub: Vec<[f64; 3]> = distinct.iter().map(|&i| points[i as usize]).collect();
        let none = Copies::none(sub.len());
        let modes = modes_on_distinct(self.modes(), &copies);
        let on_distinct = self.ladder_on_distinct(&copies);
        let det =
            on_distinct.run_cloud(&mut Cloud::new(&sub, &none), &regime.on(distinct), &modes)?;
        Ok(expand_distinct(det, copies))
    }

    /// The run on `cloud` over the groups `modes` (none: the sampler's or
    /// the explicit rotations over every point).
    fn run_cloud(
        &self,
        cloud: &mut Cloud<'_>,
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
        cloud: &mut Cloud<'_>,
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
        // With a scale ladder, the jobs of its top level (the largest α)
        // each give every level's faces from one triangulation.
        let levels: &[f64] = self.ladder.as_ref().map_or(&[], |l| &l.alphas);
        let top = levels.len().saturating_sub(1) as u32;
        let jobs: Vec<&Job<'_>> = jobs
            .iter()
            .filter(|j| levels.is_empty() || j.group == top)
            .collect();
        let total = jobs.len();
        let sf = self.scan_filters(cloud, regime, jobs.len() * levels.len().max(1));
        let one = |job: &&Job<'_>| -> PerJob<S> {
            if cancelled.load(Ordering::Relaxed) {
                return Err(DetectError::Cancelled);
            }
            let r = if levels.is_empty() {
                let sf = filter_of(&sf, job.group);
                vec![(
                    job.group,
                    run_job::<S>(points, job, &pruning, self.tile, sf)?,
                )]
            } else {
                let per = run_job_at::<S>(points, job, levels, &pruning, self.tile, &sf)?;
                (0..).zip(per).collect()
            };
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(cb) = &self.progress {
                if !cb(d, total) {
                    cancelled.store(true, Ordering::Relaxed);
                }
            }
            Ok(r)
        };
        let per: Vec<PerJob<S>> = self.stages.time(Stage::Scan, || {
            #[cfg(feature = "parallel")]
            {
                use rayon::prelude::*;
                jobs.par_iter().map(one).collect()
            }
            #[cfg(not(feature = "parallel"))]
            {
                jobs.iter().map(one).collect()
            }
        });
        if cancelled.load(Ordering::Relaxed) {
            return Err(DetectError::Cancelled);
        }
        let mut stats = RunStats {
            orientations: total * levels.len().max(1),
            ..RunStats::default()
        };
        let mut found: Vec<(u32, Vec<S>)> = Vec::with_capacity(per.len());
        for r in per {
            for (group, r) in r? {
                stats.triangulated_points += r.triangulated as u64;
                stats.raw_simplices += r.raw as u64;
                stats.filtered_simplices += r.faces.len() as u64;
                found.push((group, r.faces));
            }
        }
        self.finish_k(cloud, regime, found, scales, stats)
    }

    /// Candidate pairs for the pruning, once for all orientations over
    /// every point, when the pruning is on, every orientation looks at
    /// every point (not a ladder over some of them), and they are not too
    /// many.
    fn candidate_pairs(&self, points: &[[f64; 3]], regime: &Regime) -> Option<CandidatePairs> {
        let subset = self
            .ladder
            .as_ref()
            .is_some_and(|l| l.points.len() < points.len());
        if !(self.prune && regime.scans_every_point()) || subset {
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

    /// The path filters of a run of `orientations` orientations on `cloud`
    /// in `regime` (`scan::ScanFilter`): one for every job, or with a
    /// scale ladder one per level, at its α (see [`filter_of`]).
    pub(crate) fn scan_filters(
        &self,
        cloud: &Cloud<'_>,
        regime: &Regime,
        orientations: usize,
    ) -> Vec<ScanFilter> {
        let e = self.elongation();
        match &self.ladder {
            None => vec![ScanFilter::new(
                regime,
                self.nb_c,
                ChanceScale::new(cloud, self.alpha, e, orientations),
            )],
            Some(l) => {
                let per_level = orientations / l.alphas.len().max(1);
                l.alphas
                    .iter()
                    .map(|&a| {
                        ScanFilter::new(regime, self.nb_c, ChanceScale::new(cloud, a, e, per_level))
                    })
                    .collect()
            }
        }
    }

    /// This detector with its ladder's points numbered among the distinct
    /// points of a cloud with `copies`.
    fn ladder_on_distinct(&self, copies: &Copies) -> Detector {
        let mut d = self.clone();
        if let Some(l) = &mut d.ladder {
            l.points = on_distinct(&l.points, &distinct_index(copies));
        }
        d
    }

    /// The jobs of a run over the groups `modes` (none: this detector's
    /// sampler or rotations over every point), checked against
    /// [`MAX_ORIENTATIONS`], and the scale of each group.
    pub(crate) fn scan_jobs<'p>(
        &'p self,
        modes: &'p [ModeScan],
    ) -> Result<(Vec<Job<'p>>, Vec<Scale>), DetectError> {
        let (jobs, scales) = if let Some(l) = &self.ladder {
            self.ladder_jobs(l)?
        } else if modes.is_empty() {
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

    /// The jobs of a scale ladder: every rotation of the sampler over the
    /// ladder's points at each level's α, the level as the group.
    fn ladder_jobs<'p>(&self, l: &'p Ladder) -> Result<(Vec<Job<'p>>, Vec<Scale>), DetectError> {
        let e = self.elongation();
        let rotations = self.orientation_set()?;
        let mut jobs = Vec::with_capacity(rotations.len() * l.alphas.len());
        let mut scales = Vec::with_capacity(l.alphas.len());
        for (g, &alpha) in l.alphas.iter().enumerate() {
            for r in &rotations {
                jobs.push(Job {
                    anisotropy: Anisotropy::from_matrix_rows(*r, e)?,
                    alpha,
                    ids: Some(&l.points),
                    group: g as u32,
                });
            }
            scales.push(scale(self.kind, alpha, self.lambda2, self.lambda3));
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
    /// (`found`: per job, its group and its simplices, each job's passed
    /// through its path filter, [`Self::scan_filters`]), cleaned as it is
    /// ([`cleaned_union`]), and the assembly; with a scale ladder, each level (group) apart up to
    /// the significance test, then the parts across levels
    /// (`assemble::finish`). `stats` holds the scan's figures.
    pub(crate) fn finish_k<S: Shape>(
        &self,
        cloud: &mut Cloud<'_>,
        regime: &Regime,
        found: Vec<(u32, Vec<S>)>,
        scales: Vec<Scale>,
        mut stats: RunStats,
    ) -> Result<Detection, DetectError> {
        let settings = |scales: Vec<Scale>| Settings {
            part_angle_deg: self.part_angle_deg,
            outlines: self.outlines,
            min_vertices: S::min_vertices(self.nb_c),
            scales,
            clock: self.stages.clone(),
        };
        let cleaned_union = |found, stats: &mut RunStats| {
            self.stages
                .time(Stage::Union, || cleaned_union(found, stats))
        };
        let Some(ladder) = &self.ladder else {
            let (kept, groups) = cleaned_union(found, &mut stats);
            let s = settings(scales);
            let level = assemble::level::<S>(cloud, regime, kept, groups, &s, &mut stats)?;
            return Ok(assemble::finish::<S>(cloud, regime, vec![level], &s, stats));
        };
        let mut per_level: Vec<Vec<(u32, Vec<S>)>> = vec![Vec::new(); ladder.alphas.len()];
        for (g, faces) in found {
            per_level[g as usize].push((0, faces));
        }
        let mut levels = Vec::with_capacity(per_level.len());
        for (g, found) in per_level.into_iter().enumerate() {
            let (kept, groups) = cleaned_union(found, &mut stats);
            let s = settings(vec![scales[g]]);
            levels.push(assemble::level::<S>(
                cloud, regime, kept, groups, &s, &mut stats,
            )?);
        }
        Ok(assemble::finish::<S>(
            cloud,
            regime,
            levels,
            &settings(scales),
            stats,
        ))
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

/// The union of the jobs' simplices `found` (per job, its group and its
/// simplices), with the group of each simplex; counted in `stats`.
///
/// The union is the cleaned union of docs/method.md §3 as it is: the
/// cleaning drops the components of fewer than nb_c simplices, and there
/// are none. Every job's simplices passed the path filter at the same nb_c
/// (`sf`, [`filter_of`]), so each lies on a path of at least nb_c
/// simplices, inside its component, and a union only joins components.
/// (`detect::filter`'s tests hold this on random unions; on the 35 corpus
/// scans and the synthetic families the cleaning, when it ran, dropped no
/// simplex.)
fn cleaned_union<S: Face>(found: Vec<(u32, Vec<S>)>, stats: &mut RunStats) -> (Vec<S>, Vec<u32>) {
    let (all, groups) = union(found);
    stats.union_simplices += all.len();
    stats.kept_simplices += all.len();
    (all, groups)
}

/// The path filter of a job of group `group` among a run's filters `sf`
/// ([`Detector::scan_filters`]): the run's one, or its level's.
pub(crate) fn filter_of(sf: &[ScanFilter], group: u32) -> ScanFilter {
    sf[(group as usize).min(sf.len() - 1)]
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
    let at = distinct_index(copies);
    modes
        .iter()
        .map(|m| {
            let mut m = m.clone();
            m.points = on_distinct(&m.points, &at);
            m
        })
        .collect()
}

/// Per input point, the index of its position among the distinct points
/// of a cloud with `copies`.
fn distinct_index(copies: &Copies) -> Vec<u32> {
    let (first, distinct) = (copies.first(), copies.distinct());
    let mut at = vec![0u32; first.len()];
    for (k, &i) in distinct.iter().enumerate() {
        at[i as usize] = k as u32;
    }
    first.iter().map(|&f| at[f as usize]).collect()
}

/// Input indices `ids` as indices among the distinct points (`at`,
/// [`distinct_index`]), ascending and without repeats.
fn on_distinct(ids: &[u32], at: &[u32]) -> Vec<u32> {
    let mut out: Vec<u32> = ids.iter().map(|&v| at[v as usize]).collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// The detection of a cloud with copies from that of its distinct points
/// (numbered in the order of `copies.distinct()`). Indices map through the
/// distinct points' input indices, which keeps their order, so every
/// sorted list stays sorted.
fn expand_distinct(mut det: Detection, copies: Copies) -> Detection {
    let distinct = copies.distinct();
    let to_input = |v: &mut u32| *v = distinct[*v as usize];
    for s in det.simplices.iter_mut() {
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
