//! The structure detector of paper §4.3 (SPEC §4): scan orientations, take
//! the union of the filtered anisotropic α-shapes, clean it, and extract
//! structures with fitted primitives and per-point labels.
//!
//! For every orientation R of the sampler: Q = diag(E)·R, transform the
//! points, drop the points that are isolated at distance 2α (exact, see
//! [`super::prune`]), triangulate, select `F_{k,α,Q}` ([`super::faces`]: the same membership as
//! [`crate::alpha::AlphaComplex`], computed for one α), and apply the path filter with `nb_c`. The orientations are
//! independent and run in parallel (feature `parallel`, on by default); the
//! result does not depend on the thread count because each orientation's
//! output is collected in orientation order before the union is sorted.
//!
//! Then, on the union (set semantics):
//! 1. whole connected components with fewer than `nb_c` simplices are
//!    dropped (the path filter is *not* re-applied: for k = 2 the union
//!    holds triangles of different triangulations of one plane, which the
//!    path filter would shred);
//! 2. each component is split into straight or flat *parts*
//!    ([`super::parts`]); adjacent parts are the facets of one structure
//!    (a polyhedral surface, or a bent line) when they meet along their
//!    boundary, and separate structures when one passes through the other
//!    (crossing lines, planes cutting each other, a T-junction);
//! 3. each structure and part gets a least-squares line or plane;
//! 4. every input point is labelled with the largest structure containing
//!    it, or −1.
//!
//! ```
//! use aniso_alpha::detect::detector::Detector;
//! use aniso_alpha::synth;
//! let scene = synth::lines(1); // paper Fig. 12: 5 lines in 1500 background points
//! let det = Detector::lines(1.0, 10.0, 4).run(&scene.points)?;
//! assert!(det.structures.len() >= 4);
//! let found = det.labels.iter().filter(|&&l| l >= 0).count();
//! assert!(found >= 40);
//! # Ok::<(), aniso_alpha::detect::detector::DetectError>(())
//! ```

use super::filter::{component_size_mask, components, filter, FilterError, Simplex};
use super::fit::{fit_line_indices, fit_plane_indices, LineFit, PlaneFit};
use super::orientations::{orientations, OrientationError, Sampler};
use super::parts::{linear_parts, planar_parts, PartsError};
use super::prune::{non_isolated, CandidatePairs};
use super::StructureKind;
use crate::aniso::{Anisotropy, AnisotropyError};
use crate::delaunay::Triangulation;
use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// A 3×3 matrix as rows.
pub type Mat3 = [[f64; 3]; 3];

/// Error of a detection run.
#[derive(Debug, Clone, PartialEq)]
pub enum DetectError {
    /// A parameter is out of range (the message says which).
    BadParameter(String),
    /// The input holds no point.
    Empty,
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// A coordinate's magnitude is above 1e50 or below 1e-30 (and not 0):
    /// outside the range where the exact arithmetic is guaranteed after
    /// the anisotropic transform. Rescale the data.
    OutOfRange {
        /// Index of the point.
        index: usize,
    },
    /// The orientation sampler's parameters are invalid.
    Orientations(OrientationError),
    /// The anisotropy is invalid.
    Anisotropy(AnisotropyError),
    /// The run was cancelled by the progress callback.
    Cancelled,
}

impl fmt::Display for DetectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DetectError::BadParameter(m) => write!(f, "bad parameter: {m}"),
            DetectError::Empty => write!(f, "no points"),
            DetectError::NonFinite { index } => {
                write!(f, "point {index} has a non-finite coordinate")
            }
            DetectError::OutOfRange { index } => write!(
                f,
                "point {index} has a coordinate outside 1e-30..1e50 in magnitude (or 0), \
                 the range of exact arithmetic: rescale the data"
            ),
            DetectError::Orientations(e) => write!(f, "orientations: {e}"),
            DetectError::Anisotropy(e) => write!(f, "anisotropy: {e}"),
            DetectError::Cancelled => write!(f, "cancelled"),
        }
    }
}

impl std::error::Error for DetectError {}

impl From<OrientationError> for DetectError {
    fn from(e: OrientationError) -> Self {
        DetectError::Orientations(e)
    }
}
impl From<AnisotropyError> for DetectError {
    fn from(e: AnisotropyError) -> Self {
        DetectError::Anisotropy(e)
    }
}

/// Parameters of a detection run; build them with [`Detector::lines`] or
/// [`Detector::planes`] and the builder methods.
#[derive(Clone)]
pub struct Detector<'a> {
    kind: StructureKind,
    alpha: f64,
    lambda2: f64,
    lambda3: f64,
    nb_c: u32,
    sampler: Sampler,
    rotations: Option<Vec<Mat3>>,
    prune: bool,
    part_angle_deg: f64,
    progress: Option<&'a (dyn Fn(usize, usize) -> bool + Sync)>,
}

impl fmt::Debug for Detector<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Detector")
            .field("kind", &self.kind)
            .field("alpha", &self.alpha)
            .field("lambda2", &self.lambda2)
            .field("lambda3", &self.lambda3)
            .field("nb_c", &self.nb_c)
            .field("sampler", &self.sampler)
            .field("prune", &self.prune)
            .finish()
    }
}

impl<'a> Detector<'a> {
    /// Linear structures (k = 1): edges of `F_{1,α,Q}`, E = (1, 1, 1/λ₃),
    /// path filter `nb_c`. The paper's Fig. 12 uses α = 1, λ₃ = 10,
    /// nb_c = 4.
    pub fn lines(alpha: f64, lambda3: f64, nb_c: u32) -> Self {
        Detector {
            kind: StructureKind::Lines,
            alpha,
            lambda2: 1.0,
            lambda3,
            nb_c,
            sampler: Sampler::default(),
            rotations: None,
            prune: true,
            part_angle_deg: 10.0,
            progress: None,
        }
    }

    /// Planar structures (k = 2): triangles of `F_{2,α,Q}`,
    /// E = (1, 1/λ₂, 1/λ₃). The paper's Fig. 10 uses α = 1, λ₂ = 4,
    /// λ₃ = 8, nb_c = 20.
    pub fn planes(alpha: f64, lambda2: f64, lambda3: f64, nb_c: u32) -> Self {
        Detector {
            kind: StructureKind::Planes,
            lambda2,
            ..Self::lines(alpha, lambda3, nb_c)
        }
    }

    /// The orientation sampler (default: the paper's box sampler,
    /// m1 = 0.3, m2 = 12).
    pub fn sampler(mut self, sampler: Sampler) -> Self {
        self.sampler = sampler;
        self
    }

    /// Explicit rotations instead of a sampler (e.g. the identity alone,
    /// with λ = 1, for the Euclidean α-shape baseline).
    pub fn rotations(mut self, rotations: Vec<Mat3>) -> Self {
        self.rotations = Some(rotations);
        self
    }

    /// Whether to drop isolated points before triangulating (default true;
    /// exact, see [`super::prune`]).
    pub fn prune(mut self, yes: bool) -> Self {
        self.prune = yes;
        self
    }

    /// Angle tolerance (degrees) of the straight/flat parts (default 10°).
    pub fn part_angle(mut self, degrees: f64) -> Self {
        self.part_angle_deg = degrees;
        self
    }

    /// A callback called after each orientation with (done, total); return
    /// `false` to cancel the run ([`DetectError::Cancelled`]). It is called
    /// from worker threads.
    pub fn progress(mut self, f: &'a (dyn Fn(usize, usize) -> bool + Sync)) -> Self {
        self.progress = Some(f);
        self
    }

    /// The elongation E of the ellipsoids.
    pub fn elongation(&self) -> [f64; 3] {
        match self.kind {
            StructureKind::Lines => [1.0, 1.0, 1.0 / self.lambda3],
            StructureKind::Planes => [1.0, 1.0 / self.lambda2, 1.0 / self.lambda3],
        }
    }

    /// The orientation set that [`Self::run`] scans.
    pub fn orientation_set(&self) -> Result<Vec<Mat3>, DetectError> {
        match &self.rotations {
            Some(r) => Ok(r.clone()),
            None => Ok(orientations(
                self.kind,
                &self.sampler,
                self.lambda2 == self.lambda3,
            )?),
        }
    }

    fn check(&self, points: &[[f64; 3]]) -> Result<(), DetectError> {
        let bad = |m: String| Err(DetectError::BadParameter(m));
        if !(self.alpha.is_finite() && self.alpha > 0.0) {
            return bad(format!(
                "alpha must be positive and finite, got {}",
                self.alpha
            ));
        }
        for (name, l) in [("lambda2", self.lambda2), ("lambda3", self.lambda3)] {
            if !(l.is_finite() && l > 0.0) {
                return bad(format!("{name} must be positive and finite, got {l}"));
            }
        }
        if self.nb_c == 0 {
            return bad("min-size (nb_c) must be at least 1".into());
        }
        if !(self.part_angle_deg.is_finite() && (0.0..=90.0).contains(&self.part_angle_deg)) {
            return bad(format!(
                "part angle must be in [0, 90], got {}",
                self.part_angle_deg
            ));
        }
        if points.is_empty() {
            return Err(DetectError::Empty);
        }
        if let Some(index) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(DetectError::NonFinite { index });
        }
        // Tighter than the triangulation's range, so that every transformed
        // point Q·p stays inside it (|Q·p| ≤ √3·max|p|; cancellation leaves
        // either 0 or at least an ulp of the inputs).
        if let Some(index) = points.iter().position(|p| {
            p.iter()
                .any(|c| c.abs() > 1e50 || (*c != 0.0 && c.abs() < 1e-30))
        }) {
            return Err(DetectError::OutOfRange { index });
        }
        Ok(())
    }

    /// Runs the detection on `points`.
    ///
    /// # Errors
    /// Bad parameters, empty input, non-finite coordinates, or a
    /// cancellation by the progress callback.
    pub fn run(&self, points: &[[f64; 3]]) -> Result<Detection, DetectError> {
        self.check(points)?;
        let rotations = self.orientation_set()?;
        match self.kind {
            StructureKind::Lines => self.run_k::<[u32; 2]>(points, &rotations),
            StructureKind::Planes => self.run_k::<[u32; 3]>(points, &rotations),
        }
    }

    fn run_k<S: Face>(
        &self,
        points: &[[f64; 3]],
        rotations: &[Mat3],
    ) -> Result<Detection, DetectError> {
        let e = self.elongation();
        let anisotropies = rotations
            .iter()
            .map(|r| Anisotropy::from_matrix_rows(*r, e))
            .collect::<Result<Vec<_>, _>>()?;
        // Candidate pairs for the pruning, once for all orientations (unless
        // there are too many: then each orientation grids its own points).
        // The radii are inflated by 1e-9 so that rounding in the two ways of
        // computing a distance never drops a point at exactly 2α.
        let lmax = e.iter().map(|&x| 1.0 / x).fold(1.0, f64::max);
        let radius = 2.0 * self.alpha * (1.0 + 1e-9);
        let cands = if self.prune {
            CandidatePairs::new(
                points,
                radius * lmax * (1.0 + 1e-9),
                32 * points.len() + 1024,
            )
        } else {
            None
        };
        let done = AtomicUsize::new(0);
        let cancelled = AtomicBool::new(false);
        let total = anisotropies.len();
        let one = |a: &Anisotropy| -> Result<OrientationResult<S>, DetectError> {
            if cancelled.load(Ordering::Relaxed) {
                return Err(DetectError::Cancelled);
            }
            let r = self.one_orientation::<S>(points, a, cands.as_ref(), radius);
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(cb) = self.progress {
                if !cb(d, total) {
                    cancelled.store(true, Ordering::Relaxed);
                }
            }
            Ok(r)
        };
        #[cfg(feature = "parallel")]
        let per: Vec<Result<OrientationResult<S>, DetectError>> = {
            use rayon::prelude::*;
            anisotropies.par_iter().map(one).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let per: Vec<Result<OrientationResult<S>, DetectError>> =
            anisotropies.iter().map(one).collect();
        if cancelled.load(Ordering::Relaxed) {
            return Err(DetectError::Cancelled);
        }
        let mut stats = RunStats {
            orientations: total,
            ..RunStats::default()
        };
        let mut union: Vec<S> = Vec::new();
        for r in per {
            let r = r?;
            stats.triangulated_points += r.triangulated as u64;
            stats.raw_simplices += r.raw as u64;
            stats.filtered_simplices += r.faces.len() as u64;
            union.extend(r.faces);
        }
        union.sort_unstable();
        union.dedup();
        stats.union_simplices = union.len();
        let keep = component_size_mask(&union, self.nb_c).map_err(filter_bug)?;
        let kept: Vec<S> = union
            .iter()
            .zip(&keep)
            .filter_map(|(s, &k)| k.then_some(*s))
            .collect();
        stats.kept_simplices = kept.len();
        Ok(self.structures(points, kept, stats))
    }

    /// F_{k,α,Q} of one orientation, filtered, as sorted input-index
    /// simplices.
    /// F_{k,α,Q} of one orientation (unfiltered), as sorted input-index
    /// simplices, and the number of points triangulated.
    fn raw_faces<S: Face>(
        &self,
        points: &[[f64; 3]],
        a: &Anisotropy,
        cands: Option<&CandidatePairs>,
        radius: f64,
    ) -> (Vec<S>, usize) {
        let alpha = self.alpha;
        let (map, mut reduced): (Vec<u32>, Vec<[f64; 3]>) = match cands {
            Some(c) => {
                // The 1-core (non-isolated points). The 2-core is exact for
                // k = 2 too and drops more background, but measured 4x
                // slower on the Fig. 10 scene: what is left is then often a
                // grid-sampled plane alone, a nearly flat set whose
                // triangulation is all slivers and exact arithmetic.
                let keep = c.non_isolated_under(points, &a.q(), radius);
                let map: Vec<u32> = (0..points.len() as u32)
                    .filter(|&i| keep[i as usize])
                    .collect();
                let kept: Vec<[f64; 3]> = map.iter().map(|&i| points[i as usize]).collect();
                (map, a.transform(&kept))
            }
            None => {
                let q = a.transform(points);
                let keep = if self.prune {
                    non_isolated(&q, radius)
                } else {
                    vec![true; q.len()]
                };
                let map: Vec<u32> = (0..q.len() as u32).filter(|&i| keep[i as usize]).collect();
                let reduced = map.iter().map(|&i| q[i as usize]).collect();
                (map, reduced)
            }
        };
        let triangulated = reduced.len();
        if reduced.len() < 2 {
            return (Vec::new(), triangulated);
        }
        let n_real = map.len() as u32;
        let mut tri = Triangulation::new(&reduced).ok();
        if tri.as_ref().is_none_or(|t| t.dimension() < 3) {
            // What is left is one clean plane or line (or a few points):
            // four far sentinels around it make the set 3-dimensional. They
            // are isolated (farther than 2α from everything), so F_α is
            // unchanged.
            let (lo, hi) = crate::geometry::bounding_box(&reduced);
            let ext = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max) + 4.0 * alpha + 1.0;
            let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
            // Distance from any point of the box to a sentinel: at least
            // (√3/2)·ext > 2α. Not farther: far sentinels make slivers, which
            // the exact arithmetic then pays for.
            let d = ext;
            for s in [
                [1.0, 1.0, 1.0],
                [1.0, -1.0, -1.0],
                [-1.0, 1.0, -1.0],
                [-1.0, -1.0, 1.0],
            ] {
                reduced.push([c[0] + d * s[0], c[1] + d * s[1], c[2] + d * s[2]]);
            }
            tri = Triangulation::new(&reduced).ok();
        }
        // (Triangulation errors are unreachable: the points are finite.)
        let faces: Vec<S> = match tri {
            Some(tri) => S::at(&tri, alpha)
                .into_iter()
                .filter(|f| f.as_ref().iter().all(|&v| v < n_real))
                .map(|f| S::sorted(f.as_ref().iter().map(|&v| map[v as usize])))
                .collect(),
            None => Vec::new(),
        };
        (faces, triangulated)
    }

    /// F_{k,α,Q} of one orientation, path-filtered, with counters.
    fn one_orientation<S: Face>(
        &self,
        points: &[[f64; 3]],
        a: &Anisotropy,
        cands: Option<&CandidatePairs>,
        radius: f64,
    ) -> OrientationResult<S> {
        let (faces, triangulated) = self.raw_faces::<S>(points, a, cands, radius);
        let raw = faces.len();
        let faces = filter(&faces, self.nb_c).unwrap_or_default();
        OrientationResult {
            faces,
            triangulated,
            raw,
        }
    }

    /// The anisotropic α-shape `F_{k,α,Q}(P)` of one orientation (rows of
    /// R), before the path filter: sorted simplices of input indices,
    /// ascending within each. This is what [`Self::run`] computes for each
    /// orientation of its set, and a way to look at one of them.
    ///
    /// # Errors
    /// As [`Self::run`].
    pub fn orientation_faces(
        &self,
        points: &[[f64; 3]],
        rotation: &Mat3,
    ) -> Result<Vec<Vec<u32>>, DetectError> {
        self.check(points)?;
        let a = Anisotropy::from_matrix_rows(*rotation, self.elongation())?;
        let radius = 2.0 * self.alpha * (1.0 + 1e-9);
        let mut out: Vec<Vec<u32>> = match self.kind {
            StructureKind::Lines => self
                .raw_faces::<[u32; 2]>(points, &a, None, radius)
                .0
                .iter()
                .map(|f| f.to_vec())
                .collect(),
            StructureKind::Planes => self
                .raw_faces::<[u32; 3]>(points, &a, None, radius)
                .0
                .iter()
                .map(|f| f.to_vec())
                .collect(),
        };
        out.sort_unstable();
        Ok(out)
    }

    fn structures<S: Face>(&self, points: &[[f64; 3]], kept: Vec<S>, stats: RunStats) -> Detection {
        let n = points.len();
        let comp = if kept.is_empty() {
            Vec::new()
        } else {
            components(&kept).map_err(filter_bug).unwrap_or_default()
        };
        let n_comp = comp.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
        let mut comp_simplices: Vec<Vec<u32>> = vec![Vec::new(); n_comp];
        for (s, &c) in comp.iter().enumerate() {
            comp_simplices[c as usize].push(s as u32);
        }
        // Primitives, component by component.
        let mut prims: Vec<Prim> = Vec::new();
        for ss in &comp_simplices {
            let local: Vec<S> = ss.iter().map(|&s| kept[s as usize]).collect();
            self.extract::<S>(points, &local, &mut prims);
        }
        let groups = group_primitives(&prims, points);
        // Structures: groups ordered by number of points (desc), then by
        // smallest point, for deterministic ids.
        let n_groups = groups.iter().map(|&g| g as usize + 1).max().unwrap_or(0);
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); n_groups];
        for (p, &g) in groups.iter().enumerate() {
            members[g as usize].push(p as u32);
        }
        let mut order: Vec<(usize, u32, usize)> = members
            .iter()
            .enumerate()
            .map(|(g, ps)| {
                let mut v: Vec<u32> = ps
                    .iter()
                    .flat_map(|&p| prims[p as usize].vertices.iter().copied())
                    .collect();
                v.sort_unstable();
                v.dedup();
                (v.len(), v.first().copied().unwrap_or(u32::MAX), g)
            })
            .collect();
        order.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        // Vertex -> structure (the largest, i.e. the smallest id).
        let mut vstruct = vec![u32::MAX; n];
        let mut structures: Vec<Structure> = Vec::with_capacity(order.len());
        for (id, &(_, _, g)) in order.iter().enumerate() {
            let mut parts: Vec<Part> = members[g]
                .iter()
                .map(|&p| Part {
                    simplices: Vec::new(),
                    vertices: prims[p as usize].vertices.clone(),
                    primitive: prims[p as usize].fit.clone(),
                })
                .collect();
            parts.sort_by(|a, b| {
                b.vertices
                    .len()
                    .cmp(&a.vertices.len())
                    .then(a.vertices.first().cmp(&b.vertices.first()))
            });
            let mut v: Vec<u32> = parts
                .iter()
                .flat_map(|p| p.vertices.iter().copied())
                .collect();
            v.sort_unstable();
            v.dedup();
            for &x in &v {
                if vstruct[x as usize] == u32::MAX {
                    vstruct[x as usize] = id as u32;
                }
            }
            structures.push(Structure {
                id: id as u32,
                simplices: Vec::new(),
                primitive: S::fit(points, &v),
                vertices: v,
                parts,
            });
        }
        // Simplices: kept when all their vertices lie on one structure
        // (bridging simplices between two separate structures are dropped);
        // within it, the part holding all its vertices if there is one.
        let mut simplices: Vec<Vec<u32>> = Vec::new();
        let mut simplex_structure: Vec<u32> = Vec::new();
        for s in &kept {
            let vs = s.as_ref();
            let cand = vs
                .iter()
                .map(|&v| vstruct[v as usize])
                .min()
                .unwrap_or(u32::MAX);
            if cand == u32::MAX {
                continue;
            }
            let st = &mut structures[cand as usize];
            if !vs.iter().all(|v| st.vertices.binary_search(v).is_ok()) {
                continue;
            }
            let idx = simplices.len() as u32;
            if let Some(p) = st
                .parts
                .iter_mut()
                .find(|p| vs.iter().all(|v| p.vertices.binary_search(v).is_ok()))
            {
                p.simplices.push(idx);
            }
            st.simplices.push(idx);
            simplices.push(vs.to_vec());
            simplex_structure.push(cand);
        }
        // Simplices refer to first occurrences only: duplicates take their
        // first occurrence's label.
        let first_occurrence = first_occurrences(points);
        let labels: Vec<i64> = first_occurrence
            .iter()
            .map(|&f| match vstruct[f as usize] {
                u32::MAX => -1,
                s => s as i64,
            })
            .collect();
        let mut stats = stats;
        stats.structure_simplices = simplices.len();
        Detection {
            kind: self.kind,
            simplices,
            simplex_structure,
            structures,
            labels,
            first_occurrence,
            stats,
        }
    }

    /// Greedy extraction of straight/flat primitives from one connected
    /// component of the union. Candidates are the least-squares fits of its
    /// parts (regions of like-oriented simplices, [`super::parts`]); the
    /// candidate covering the most not-yet-covered vertices within
    /// distance α (the short semi-axis of the ellipsoid, so the points of a
    /// detected structure lie within it) is refitted on its inliers and
    /// taken, until no candidate covers enough new vertices. A vertex may
    /// belong to several primitives (where planes meet or lines cross).
    fn extract<S: Face>(&self, points: &[[f64; 3]], local: &[S], out: &mut Vec<Prim>) {
        let mut verts: Vec<u32> = local.iter().flat_map(|s| s.as_ref().to_vec()).collect();
        verts.sort_unstable();
        verts.dedup();
        let min_vertices = match self.kind {
            StructureKind::Lines => self.nb_c as usize + 1,
            StructureKind::Planes => (self.nb_c as usize / 2).max(4),
        };
        if verts.len() < min_vertices {
            return;
        }
        let tol = self.alpha;
        let part =
            S::parts(points, local, self.part_angle_deg).unwrap_or_else(|_| vec![0; local.len()]);
        let n_parts = part.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
        let mut pv: Vec<Vec<u32>> = vec![Vec::new(); n_parts];
        for (s, &p) in local.iter().zip(&part) {
            pv[p as usize].extend_from_slice(s.as_ref());
        }
        // Candidates: parts with at least two simplices' worth of points,
        // largest first, at most 64 of them; plus the whole component.
        let mut cands: Vec<Primitive> = Vec::new();
        let mut by_size: Vec<(usize, usize)> = pv
            .iter_mut()
            .enumerate()
            .map(|(i, v)| {
                v.sort_unstable();
                v.dedup();
                (v.len(), i)
            })
            .collect();
        by_size.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        for &(sz, i) in by_size.iter().take(64) {
            if sz >= S::K + 2 {
                cands.push(S::fit(points, &pv[i]));
            }
        }
        cands.push(S::fit(points, &verts));
        let mut covered = vec![false; verts.len()];
        loop {
            let mut best: Option<(usize, usize)> = None; // (new inliers, candidate)
            for (ci, c) in cands.iter().enumerate() {
                let new = verts
                    .iter()
                    .zip(&covered)
                    .filter(|(&v, &cov)| !cov && distance(c, &points[v as usize]) <= tol)
                    .count();
                if best.is_none_or(|b| new > b.0) {
                    best = Some((new, ci));
                }
            }
            let Some((new, ci)) = best else { break };
            if new < min_vertices {
                break;
            }
            // Refit on all inliers of the component, twice.
            let mut fit = cands.swap_remove(ci);
            let inliers = |fit: &Primitive| -> Vec<u32> {
                verts
                    .iter()
                    .copied()
                    .filter(|&v| distance(fit, &points[v as usize]) <= tol)
                    .collect()
            };
            for _ in 0..2 {
                let refit = S::fit(points, &inliers(&fit));
                if matches!(refit, Primitive::None) {
                    break;
                }
                fit = refit;
            }
            let inl = inliers(&fit);
            let mut gained = 0;
            for (k, &v) in verts.iter().enumerate() {
                if !covered[k] && inl.binary_search(&v).is_ok() {
                    covered[k] = true;
                    gained += 1;
                }
            }
            if gained < min_vertices || inl.len() < min_vertices {
                break;
            }
            out.push(Prim { vertices: inl, fit });
        }
    }
}

/// An extracted primitive: its inlier points and its fit.
struct Prim {
    vertices: Vec<u32>,
    fit: Primitive,
}

/// Distance from a point to a fitted line or plane (∞ for no fit).
fn distance(fit: &Primitive, p: &[f64; 3]) -> f64 {
    match fit {
        Primitive::Plane(f) => dot(sub(*p, f.centroid), f.normal).abs(),
        Primitive::Line(f) => {
            let w = sub(*p, f.centroid);
            let t = dot(w, f.direction);
            let r = [
                w[0] - t * f.direction[0],
                w[1] - t * f.direction[1],
                w[2] - t * f.direction[2],
            ];
            dot(r, r).sqrt()
        }
        Primitive::None => f64::INFINITY,
    }
}

/// Groups primitives into structures: two primitives sharing points are
/// facets of one structure (a polyhedral surface, a bent line) unless one
/// passes through the other's interior (crossing lines, planes cutting
/// each other, a T-junction). Returns a group id per primitive.
fn group_primitives(prims: &[Prim], points: &[[f64; 3]]) -> Vec<u32> {
    let n = prims.len();
    let mut uf: Vec<u32> = (0..n as u32).collect();
    fn find(uf: &mut [u32], mut x: u32) -> u32 {
        while uf[x as usize] != x {
            uf[x as usize] = uf[uf[x as usize] as usize];
            x = uf[x as usize];
        }
        x
    }
    let mut vp: Vec<(u32, u32)> = Vec::new();
    for (p, pr) in prims.iter().enumerate() {
        vp.extend(pr.vertices.iter().map(|&v| (v, p as u32)));
    }
    vp.sort_unstable();
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let mut i = 0;
    while i < vp.len() {
        let mut j = i + 1;
        while j < vp.len() && vp[j].0 == vp[i].0 {
            j += 1;
        }
        for a in i..j {
            for b in a + 1..j {
                pairs.push((vp[a].1, vp[b].1));
            }
        }
        i = j;
    }
    pairs.sort_unstable();
    pairs.dedup();
    for &(a, b) in &pairs {
        let (pa, pb) = (&prims[a as usize], &prims[b as usize]);
        if !crosses(&pa.fit, &pb.vertices, points) && !crosses(&pb.fit, &pa.vertices, points) {
            let (ra, rb) = (find(&mut uf, a), find(&mut uf, b));
            if ra != rb {
                uf[ra.max(rb) as usize] = ra.min(rb);
            }
        }
    }
    let roots: Vec<u32> = (0..n as u32).map(|p| find(&mut uf, p)).collect();
    let mut dense = vec![u32::MAX; n];
    let mut next = 0;
    roots
        .iter()
        .map(|&r| {
            if dense[r as usize] == u32::MAX {
                dense[r as usize] = next;
                next += 1;
            }
            dense[r as usize]
        })
        .collect()
}

fn filter_bug(e: FilterError) -> DetectError {
    DetectError::BadParameter(format!("internal filter error: {e}"))
}

/// Whether the primitive `fit` (of part A) passes through the interior of
/// part B (given by its vertices): B has a substantial share of its
/// vertices strictly on each side. For a plane, the sides of the plane;
/// for a line, the two sides of the point of B's line closest to it, along
/// B's direction (a line through B's middle).
fn crosses(fit: &Primitive, b: &[u32], points: &[[f64; 3]]) -> bool {
    if b.len() < 4 {
        return false;
    }
    let side = |d: f64, tol: f64| {
        if d > tol {
            1
        } else if d < -tol {
            -1
        } else {
            0
        }
    };
    let (pos, neg) = match fit {
        Primitive::Plane(pf) => {
            let tol = 3.0 * pf.rms_residual + 1e-9 * (pf.extent[0] + pf.extent[1]);
            let mut c = (0, 0);
            for &v in b {
                let p = points[v as usize];
                let d = (0..3)
                    .map(|k| (p[k] - pf.centroid[k]) * pf.normal[k])
                    .sum::<f64>();
                match side(d, tol) {
                    1 => c.0 += 1,
                    -1 => c.1 += 1,
                    _ => {}
                }
            }
            c
        }
        Primitive::Line(la) => {
            // B's own line: its centroid and direction from B's vertices.
            let bv: Vec<[f64; 3]> = b.iter().map(|&v| points[v as usize]).collect();
            let Ok(lb) = super::fit::fit_line(&bv) else {
                return false;
            };
            // Point of line B closest to line A.
            let w = sub(lb.centroid, la.centroid);
            let (u, v) = (la.direction, lb.direction);
            let (a_, b_, c_) = (dot(u, u), dot(u, v), dot(v, v));
            let (d_, e_) = (dot(u, w), dot(v, w));
            let den = a_ * c_ - b_ * b_;
            if den.abs() < 1e-12 {
                return false; // parallel: no crossing
            }
            let t = (b_ * d_ - a_ * e_) / den; // parameter along B
            let tol = 0.05 * lb.extent.max(1e-12);
            let mut c = (0, 0);
            for p in &bv {
                match side(dot(sub(*p, lb.centroid), v) - t, tol) {
                    1 => c.0 += 1,
                    -1 => c.1 += 1,
                    _ => {}
                }
            }
            c
        }
        Primitive::None => return false,
    };
    let m = b.len();
    pos.min(neg) * 5 >= m // at least 20% on each side
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Per point, the index of the first point with the same coordinates
/// (itself when no earlier point has them).
fn first_occurrences(points: &[[f64; 3]]) -> Vec<u32> {
    let mut first: Vec<u32> = (0..points.len() as u32).collect();
    let mut idx = first.clone();
    // A stable sort: each run of equal points starts with its first index.
    idx.sort_by(|&a, &b| {
        points[a as usize]
            .partial_cmp(&points[b as usize])
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    for w in idx.windows(2) {
        if points[w[1] as usize] == points[w[0] as usize] {
            first[w[1] as usize] = first[w[0] as usize];
        }
    }
    first
}

struct OrientationResult<S> {
    faces: Vec<S>,
    triangulated: usize,
    raw: usize,
}

/// A simplex kind the detector works with: edges (k = 1) or triangles
/// (k = 2).
trait Face: Simplex + AsRef<[u32]> + Send + Sync + 'static {
    /// The simplex dimension.
    const K: usize;
    fn at(tri: &Triangulation, alpha: f64) -> Vec<Self>;
    fn sorted(v: impl Iterator<Item = u32>) -> Self;
    fn parts(points: &[[f64; 3]], s: &[Self], angle: f64) -> Result<Vec<u32>, PartsError>;
    fn fit(points: &[[f64; 3]], vertices: &[u32]) -> Primitive;
}

impl Face for [u32; 2] {
    const K: usize = 1;
    fn at(tri: &Triangulation, alpha: f64) -> Vec<Self> {
        super::faces::edges_at(tri, alpha)
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
        super::faces::triangles_at(tri, alpha)
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

/// A fitted primitive.
#[derive(Debug, Clone, PartialEq)]
pub enum Primitive {
    /// A least-squares line (k = 1).
    Line(LineFit),
    /// A least-squares plane (k = 2).
    Plane(PlaneFit),
    /// Too few or degenerate points to fit.
    None,
}

/// A straight or flat piece of a structure.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Indices into [`Detection::simplices`].
    pub simplices: Vec<u32>,
    /// Input indices of its points, ascending.
    pub vertices: Vec<u32>,
    /// Its least-squares line or plane.
    pub primitive: Primitive,
}

/// A detected structure: a line, a plane, or a polyhedral surface (several
/// flat parts meeting along their boundaries).
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Its id (0 = largest), as used in [`Detection::labels`].
    pub id: u32,
    /// Indices into [`Detection::simplices`].
    pub simplices: Vec<u32>,
    /// Input indices of its points, ascending.
    pub vertices: Vec<u32>,
    /// Least-squares line (k = 1) or plane (k = 2) of all its points.
    pub primitive: Primitive,
    /// Its straight or flat parts, largest first (one for a plain line or
    /// plane; the facets of a polyhedral surface).
    pub parts: Vec<Part>,
}

/// Counters of a run.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RunStats {
    /// Orientations scanned.
    pub orientations: usize,
    /// Points triangulated, summed over orientations (after pruning).
    pub triangulated_points: u64,
    /// Simplices of `F_{k,α,Q}` before the path filter, summed.
    pub raw_simplices: u64,
    /// Simplices after the path filter, summed over orientations.
    pub filtered_simplices: u64,
    /// Distinct simplices in the union.
    pub union_simplices: usize,
    /// Simplices left after the component clean-up.
    pub kept_simplices: usize,
    /// Simplices of the reported structures (bridging simplices between
    /// separate structures and simplices off every primitive dropped).
    pub structure_simplices: usize,
}

/// The result of [`Detector::run`].
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Lines (k = 1) or planes (k = 2).
    pub kind: StructureKind,
    /// The simplices of the structures: vertex index pairs (k = 1) or
    /// triples (k = 2), ascending within each, sorted.
    pub simplices: Vec<Vec<u32>>,
    /// The structure of each simplex.
    pub simplex_structure: Vec<u32>,
    /// The structures, largest first.
    pub structures: Vec<Structure>,
    /// Per input point: the id of the largest structure containing it, or
    /// −1 (background). An exact duplicate has its first occurrence's.
    pub labels: Vec<i64>,
    /// Per input point: the index of the first input point with the same
    /// coordinates (itself when no earlier point has them). Simplices,
    /// structures and parts list first occurrences only (SPEC §7).
    pub first_occurrence: Vec<u32>,
    /// Counters.
    pub stats: RunStats,
}

impl Detection {
    /// Per input point: the global id of the largest part containing it
    /// (parts numbered structure by structure, largest first), or −1. An
    /// exact duplicate has its first occurrence's.
    pub fn part_labels(&self) -> Vec<i64> {
        let mut labels = vec![-1i64; self.labels.len()];
        let mut best = vec![0usize; self.labels.len()];
        let mut id = 0i64;
        for st in &self.structures {
            for p in &st.parts {
                for &v in &p.vertices {
                    if p.simplices.len() > best[v as usize] {
                        best[v as usize] = p.simplices.len();
                        labels[v as usize] = id;
                    }
                }
                id += 1;
            }
        }
        for (i, &f) in self.first_occurrence.iter().enumerate() {
            labels[i] = labels[f as usize];
        }
        labels
    }
}
