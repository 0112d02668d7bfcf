//! The structure detector (paper §4.3, method doc §4): its parameters, and
//! (in `run`) the run that chains the steps: the run's regime and cloud
//! context once, the orientation scan (`detect::scan`), the union and its
//! clean-up, and the assembly of structures and parts (`detect::assemble`).
//!
//! Parameters come from the user ([`Detector::lines`],
//! [`Detector::planes`]) or from the data ([`Detector::auto`], method doc
//! §8: the scales, and an orientation set made of the modes of the local
//! normals or directions, each with the points it concerns).
//!
//! The orientations are independent and run in parallel (feature
//! `parallel`, on by default, on [`Detector::threads`] threads or rayon's
//! current pool); the result does not depend on the thread count because
//! each orientation's output is collected in orientation order before the
//! union is sorted.
//!
//! After the scan, on the union (set semantics): whole connected components
//! with fewer simplices than the scan's path-filter threshold (nb_c, or
//! for lines under the significance test the shorter one measured from
//! the background) are dropped (the path filter is *not* re-applied: for
//! k = 2 the union holds triangles of different triangulations of one
//! plane, which the path filter would shred); then the assembly splits
//! components into disjoint straight or flat parts with fitted lines and
//! planes, outlines and segments, tests their significance, groups them
//! into structures, and labels every point.
//!
//! ```
//! use aniso_alpha::detect::Detector;
//! use aniso_alpha::synth;
//! let scene = synth::lines(1); // paper Fig. 12: 5 lines in 1500 background points
//! let det = Detector::lines(1.0, 10.0, 4).run(&scene.points)?;
//! assert!(det.structures.len() >= 4);
//! let found = det.labels.iter().filter(|&&l| l >= 0).count();
//! assert!(found >= 40);
//! # Ok::<(), aniso_alpha::detect::DetectError>(())
//! ```

mod error;
mod run;

pub(crate) use run::filter_of;

pub use error::DetectError;

use super::estimate::{check_normals_agreement, estimate, estimate_oriented, mode_rotations};
use super::estimate::{Estimate, Given, GivenNormals, Ladder, ModeScan};
use super::orientations::{orientations, Sampler};
use super::regime::Regime;
use super::stages::{Clock, Stage};
pub use super::StructureKind;
use std::fmt;
use std::sync::Arc;

/// A 3×3 matrix as rows.
pub type Mat3 = crate::aniso::Mat3;

/// Range of λ accepted: beyond it the transformed coordinates leave the
/// range where the arithmetic is exact for the inputs allowed.
pub const LAMBDA_RANGE: (f64, f64) = (1e-3, 1e4);

/// The orientation set of a run.
#[derive(Debug, Clone, PartialEq)]
pub enum OrientationSet {
    /// A sampler, over every point.
    Sampler(Sampler),
    /// Explicit rotations (rows of R), over every point.
    Rotations(Vec<Mat3>),
    /// The data orientation set: per mode, its rotations, its points and
    /// its scale ([`Detector::auto`]).
    Data(Vec<ModeScan>),
}

/// A progress callback: called with (orientations done, total), returns
/// whether to go on ([`Detector::progress`]).
type Progress = Arc<dyn Fn(usize, usize) -> bool + Send + Sync>;

/// Parameters of a detection run; build them with [`Detector::lines`],
/// [`Detector::planes`] or [`Detector::auto`] and the builder methods.
#[derive(Clone)]
pub struct Detector {
    kind: StructureKind,
    alpha: f64,
    lambda2: f64,
    lambda3: f64,
    nb_c: u32,
    set: OrientationSet,
    prune: bool,
    part_angle_deg: f64,
    outlines: bool,
    epsilon: Option<f64>,
    threads: Option<usize>,
    tile: Option<f64>,
    estimate: Option<Box<Estimate>>,
    normals: Option<Normals>,
    given_normals: Option<GivenNormals>,
    ladder: Option<Ladder>,
    progress: Option<Progress>,
    stages: Clock,
}

/// Normals given with the points, unit length (zero where a point's
/// normal was missing, zero or not finite), shared by the clones of a
/// detector.
pub(crate) type Normals = Arc<[[f32; 3]]>;

/// The given normals as unit f32 vectors, [0, 0, 0] where a normal is not
/// usable (non-finite or of length under 1e-6: files write 0 0 0 for
/// "unknown").
fn unit_normals(normals: &[[f64; 3]]) -> Normals {
    normals
        .iter()
        .map(|n| {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if l.is_finite() && l > 1e-6 {
                [(n[0] / l) as f32, (n[1] / l) as f32, (n[2] / l) as f32]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

impl fmt::Debug for Detector {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Detector")
            .field("kind", &self.kind)
            .field("alpha", &self.alpha)
            .field("lambda2", &self.lambda2)
            .field("lambda3", &self.lambda3)
            .field("nb_c", &self.nb_c)
            .field("prune", &self.prune)
            .field("epsilon", &self.epsilon)
            .field("threads", &self.threads)
            .field("tile", &self.tile)
            .field("normals", &self.normals.as_ref().map(|n| n.len()))
            .finish()
    }
}

impl Detector {
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
            set: OrientationSet::Sampler(Sampler::default()),
            prune: true,
            part_angle_deg: 10.0,
            outlines: true,
            epsilon: Some(1.0),
            threads: None,
            tile: None,
            estimate: None,
            normals: None,
            given_normals: None,
            ladder: None,
            progress: None,
            stages: Clock::default(),
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

    /// Parameters and orientations from the data (method doc §8, see
    /// [`super::estimate`]); the values in `given` are kept. Planes use
    /// m2 = 12 turns about the normal when λ₂ ≠ λ₃ (the paper's).
    ///
    /// # Errors
    /// Empty input, non-finite or out-of-range coordinates, given values
    /// out of range.
    pub fn auto(
        kind: StructureKind,
        points: &[[f64; 3]],
        given: &Given,
    ) -> Result<Self, DetectError> {
        Self::auto_with(kind, points, given, 12)
    }

    /// [`Self::auto`] with `m2` turns about a plane's normal when λ₂ ≠ λ₃.
    ///
    /// # Errors
    /// As [`Self::auto`].
    pub fn auto_with(
        kind: StructureKind,
        points: &[[f64; 3]],
        given: &Given,
        m2: u32,
    ) -> Result<Self, DetectError> {
        Self::auto_impl(kind, points, None, given, m2)
    }

    /// [`Self::auto_with`] for points that come with normals (a scan's
    /// `nx ny nz`), one per point: planes take each point's given normal
    /// instead of the one its neighbourhood's PCA would estimate, for the
    /// modes of the orientation set and their members, and a point joins
    /// a plane only if its normal agrees with the plane's ([`Self::normals`]).
    /// A normal of zero length or with a non-finite coordinate counts as
    /// missing: that point's PCA normal is used, and it joins planes on
    /// distance alone. Normals that disagree with the points' geometry
    /// (fewer than half of the locally planar points' within 25° of their
    /// PCA normal, [`super::estimate::NORMALS_AGREEMENT_MIN`]) are not used
    /// at all; [`Self::given_normals`] says so.
    ///
    /// # Errors
    /// As [`Self::auto`], and a number of normals other than of points.
    pub fn auto_oriented(
        kind: StructureKind,
        points: &[[f64; 3]],
        normals: &[[f64; 3]],
        given: &Given,
        m2: u32,
    ) -> Result<Self, DetectError> {
        Self::auto_impl(kind, points, Some(normals), given, m2)
    }

    fn auto_impl(
        kind: StructureKind,
        points: &[[f64; 3]],
        normals: Option<&[[f64; 3]]>,
        given: &Given,
        m2: u32,
    ) -> Result<Self, DetectError> {
        check_points(points)?;
        let normals = normals.map(unit_normals);
        if let Some(n) = &normals {
            check_normals(n, points.len())?;
        }
        let probe = Detector {
            alpha: given.alpha.unwrap_or(1.0),
            lambda2: given.lambda2.unwrap_or(1.0),
            lambda3: given.lambda3.unwrap_or(1.0),
            nb_c: given.min_size.unwrap_or(1),
            ..Self::lines(1.0, 1.0, 1)
        };
        probe.check_values()?;
        let (e, given_normals) = estimate_oriented(kind, points, normals.as_deref(), given, m2);
        if ![e.alpha.value, e.lambda2.value, e.lambda3.value]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(DetectError::NoSpacing);
        }
        let mut d = match kind {
            StructureKind::Lines => {
                Self::lines(e.alpha.value, e.lambda3.value, e.min_size.value as u32)
            }
            StructureKind::Planes => Self::planes(
                e.alpha.value,
                e.lambda2.value,
                e.lambda3.value,
                e.min_size.value as u32,
            ),
        };
        match &e.ladder {
            Some(l) => d = d.scale_ladder(kind, l),
            None => d.set = OrientationSet::Data(e.modes.clone()),
        }
        d.estimate = Some(Box::new(e));
        d.normals = normals.filter(|_| given_normals.is_some_and(|g| g.gate));
        d.given_normals = given_normals;
        Ok(d)
    }

    /// This detector turned into a run of the scale ladder `l` (α per
    /// level, one λ, the Fibonacci sampler over `l.points`; docs/method.md
    /// §8): α is the ladder's largest.
    fn scale_ladder(mut self, kind: StructureKind, l: &Ladder) -> Self {
        self.alpha = l.alphas.iter().copied().fold(0.0, f64::max);
        self.lambda2 = if kind == StructureKind::Planes {
            l.lambda
        } else {
            1.0
        };
        self.lambda3 = l.lambda;
        self.set = OrientationSet::Sampler(Sampler::Fibonacci {
            step_degrees: l.step_deg,
        });
        self.ladder = Some(l.clone());
        self
    }

    /// The scale ladder this detector runs, if [`Self::auto`] chose one
    /// (docs/method.md §8).
    pub fn ladder(&self) -> Option<&Ladder> {
        self.ladder.as_ref()
    }

    /// Normals given with the points, one per point (a scan's `nx ny nz`;
    /// the sign does not matter): a point joins a plane only if its normal
    /// is within 36.9° of the plane's (|n_p · n| ≥ 0.8), as in Efficient
    /// RANSAC (`normal_threshold`, Easy3D's default; CGAL's is 0.9). Points of
    /// a window frame or a ledge within a façade's claim radius, whose
    /// normals are across it, then stay out of the façade. Zero or
    /// non-finite normals count as missing (the point joins on distance
    /// alone). Lines ignore normals. [`Self::auto_oriented`] also
    /// builds the orientation set from them.
    ///
    /// They pass the check of [`Self::auto_oriented`] when the run meets
    /// the points: normals that disagree with the points' geometry (fewer
    /// than half of the locally planar points' within 25° of their PCA
    /// normal) gate nothing. [`Self::run`] fails if their number is not
    /// the number of points.
    pub fn normals(mut self, normals: &[[f64; 3]]) -> Self {
        self.normals = Some(unit_normals(normals));
        self.given_normals = None;
        self
    }

    /// The orientation sampler (default: the paper's box sampler,
    /// m1 = 0.3, m2 = 12), over every point.
    pub fn sampler(mut self, sampler: Sampler) -> Self {
        self.set = OrientationSet::Sampler(sampler);
        self
    }

    /// Explicit rotations instead of a sampler (e.g. the identity alone,
    /// with λ = 1, for the Euclidean α-shape baseline).
    pub fn rotations(mut self, rotations: Vec<Mat3>) -> Self {
        self.set = OrientationSet::Rotations(rotations);
        self
    }

    /// The data orientation set of `points` (the modes of their local
    /// normals or directions), with this detector's α and λ for every mode
    /// (see [`Self::auto`] for estimated scales as well).
    pub fn data_orientations(mut self, points: &[[f64; 3]], m2: u32) -> Self {
        let given = Given {
            alpha: Some(self.alpha),
            lambda2: Some(self.lambda2),
            lambda3: Some(self.lambda3),
            min_size: Some(self.nb_c),
        };
        let e = estimate(self.kind, points, &given, m2);
        let modes = e
            .modes
            .into_iter()
            .map(|mut m| {
                m.rotations = mode_rotations(self.kind, m.axis, self.lambda2, self.lambda3, m2);
                m
            })
            .collect();
        self.set = OrientationSet::Data(modes);
        self
    }

    /// Whether to drop isolated points before triangulating (default true;
    /// exact: such points cannot be a vertex of `F_{k,α,Q}`, docs/method.md §4).
    pub fn prune(mut self, yes: bool) -> Self {
        self.prune = yes;
        self
    }

    /// Angle tolerance (degrees) of the straight/flat parts (default 10°).
    pub fn part_angle(mut self, degrees: f64) -> Self {
        self.part_angle_deg = degrees;
        self
    }

    /// The angle tolerance (degrees) of the straight/flat parts.
    pub fn part_angle_degrees(&self) -> f64 {
        self.part_angle_deg
    }

    /// Whether plane parts get their outline and mesh, the 2D α-shape of
    /// their points ([`super::Part::outline`], [`super::Part::mesh`];
    /// default true). Without them a plane part's outline and mesh are
    /// empty and everything else is the same: its points, plane, NFA, and
    /// every label. A run whose output holds neither (labels alone) skips
    /// a triangulation of every plane's points. Line parts always get
    /// their segment.
    pub fn outlines(mut self, yes: bool) -> Self {
        self.outlines = yes;
        self
    }

    /// Whether plane parts get their outline and mesh.
    pub fn draws_outlines(&self) -> bool {
        self.outlines
    }

    /// The significance test's ε (default 1: keep parts with at most one
    /// expected false alarm), or `None` to keep every part (the paper's
    /// behaviour, nb_c alone).
    pub fn significance(mut self, epsilon: Option<f64>) -> Self {
        self.epsilon = epsilon;
        self
    }

    /// Runs on this many threads (a pool of its own); default: rayon's
    /// current pool (all cores).
    pub fn threads(mut self, n: usize) -> Self {
        self.threads = Some(n);
        self
    }

    /// Cuts each orientation's points into tiles of this side (input
    /// units) with halos (see `detect::scan`): bounded memory, the same
    /// result.
    pub fn tile(mut self, side: Option<f64>) -> Self {
        self.tile = side;
        self
    }

    /// A callback called after each orientation with (done, total); return
    /// `false` to cancel the run ([`DetectError::Cancelled`]). It is called
    /// from worker threads, and shared by the detector's clones.
    pub fn progress(mut self, f: impl Fn(usize, usize) -> bool + Send + Sync + 'static) -> Self {
        self.progress = Some(Arc::new(f));
        self
    }

    /// A callback called after each stage of the run ([`Stage`]) with its
    /// wall seconds (a scale ladder runs the per-level stages once per
    /// level). It is called from the thread that runs the detection, and
    /// shared by the detector's clones; it does not change the result.
    pub fn on_stage(mut self, f: impl Fn(Stage, f64) + Send + Sync + 'static) -> Self {
        self.stages = Clock::new(Some(Arc::new(f)));
        self
    }

    /// Lines or planes.
    pub fn kind(&self) -> StructureKind {
        self.kind
    }

    /// α (the whole cloud's; with a data orientation set, modes have their
    /// own, see [`Self::orientations`]).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// (λ₂, λ₃).
    pub fn lambdas(&self) -> (f64, f64) {
        (self.lambda2, self.lambda3)
    }

    /// nb_c.
    pub fn min_size(&self) -> u32 {
        self.nb_c
    }

    /// The significance test's ε, if any.
    pub fn epsilon(&self) -> Option<f64> {
        self.epsilon
    }

    /// The orientation set.
    pub fn orientations(&self) -> &OrientationSet {
        &self.set
    }

    /// With normals given ([`Self::normals`], [`Self::auto_oriented`]): how
    /// many of them are usable (non-zero and finite).
    pub fn normals_given(&self) -> Option<usize> {
        self.normals
            .as_ref()
            .map(|n| n.iter().filter(|v| **v != [0.0; 3]).count())
    }

    /// For [`Self::auto_oriented`]: how the given normals agree with the
    /// points' geometry, and whether they are used (planes only).
    pub fn given_normals(&self) -> Option<GivenNormals> {
        self.given_normals
    }

    /// What [`Self::auto`] estimated, if it made this detector.
    pub fn estimate(&self) -> Option<&Estimate> {
        self.estimate.as_deref()
    }

    /// The elongation E of the ellipsoids.
    pub fn elongation(&self) -> [f64; 3] {
        elongation(self.kind, self.lambda2, self.lambda3)
    }

    /// The number of orientations [`Self::run`] scans.
    ///
    /// # Errors
    /// Bad sampler parameters.
    pub fn orientation_count(&self) -> Result<usize, DetectError> {
        Ok(match &self.set {
            OrientationSet::Data(m) => m.iter().map(|m| m.rotations.len()).sum(),
            _ => self.orientation_set()?.len() * self.ladder.as_ref().map_or(1, |l| l.alphas.len()),
        })
    }

    /// The rotations [`Self::run`] scans (over every point, or per mode).
    ///
    /// # Errors
    /// Bad sampler parameters.
    pub fn orientation_set(&self) -> Result<Vec<Mat3>, DetectError> {
        match &self.set {
            OrientationSet::Rotations(r) => Ok(r.clone()),
            OrientationSet::Sampler(s) => {
                Ok(orientations(self.kind, s, self.lambda2 == self.lambda3)?)
            }
            OrientationSet::Data(m) => {
                Ok(m.iter().flat_map(|m| m.rotations.iter().copied()).collect())
            }
        }
    }

    /// One given normal per point, if normals are given.
    pub(crate) fn check_normals_of(&self, points: &[[f64; 3]]) -> Result<(), DetectError> {
        match &self.normals {
            Some(n) => check_normals(n, points.len()),
            None => Ok(()),
        }
    }

    pub(crate) fn check_values(&self) -> Result<(), DetectError> {
        let bad = |m: String| Err(DetectError::BadParameter(m));
        if !(self.alpha.is_finite() && self.alpha > 0.0) {
            return bad(format!(
                "alpha must be positive and finite, got {}",
                self.alpha
            ));
        }
        for (name, l) in [("lambda2", self.lambda2), ("lambda3", self.lambda3)] {
            if !(l.is_finite() && (LAMBDA_RANGE.0..=LAMBDA_RANGE.1).contains(&l)) {
                return bad(format!(
                    "{name} must be between {} and {}, got {l}",
                    LAMBDA_RANGE.0, LAMBDA_RANGE.1
                ));
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
        if let Some(e) = self.epsilon {
            if !(e.is_finite() && e > 0.0) {
                return bad(format!("epsilon must be positive and finite, got {e}"));
            }
        }
        if self.threads == Some(0) {
            return bad("threads must be at least 1".into());
        }
        if let Some(t) = self.tile {
            if !(t.is_finite() && t > 0.0) {
                return bad(format!("tile must be positive and finite, got {t}"));
            }
        }
        Ok(())
    }

    /// The modes of a data orientation set (none for a sampler or explicit
    /// rotations).
    pub(crate) fn modes(&self) -> &[ModeScan] {
        match &self.set {
            OrientationSet::Data(m) => m.as_slice(),
            _ => &[],
        }
    }

    /// The regime of a run over `points` ([`Regime`]): the structure kind,
    /// the significance test, where the orientations come from, and the
    /// normals that gate the claims of planes. Normals given with
    /// [`Self::normals`] pass here the agreement check that
    /// [`Self::auto_oriented`] applied when it made the detector
    /// ([`check_normals_agreement`]): normals that disagree with the points'
    /// geometry gate nothing.
    pub(crate) fn regime(&self, points: &[[f64; 3]]) -> Regime {
        let gate = match (self.kind, &self.normals) {
            (StructureKind::Planes, Some(n)) => {
                let used = match self.given_normals {
                    Some(g) => g.gate,
                    None => check_normals_agreement(points, n).used,
                };
                used.then(|| n.clone())
            }
            _ => None,
        };
        Regime::new(
            self.kind,
            self.epsilon,
            matches!(self.set, OrientationSet::Data(_)),
            gate,
        )
    }
}

/// The elongation E for λ₂, λ₃.
fn elongation(kind: StructureKind, lambda2: f64, lambda3: f64) -> [f64; 3] {
    match kind {
        StructureKind::Lines => [1.0, 1.0, 1.0 / lambda3],
        StructureKind::Planes => [1.0, 1.0 / lambda2, 1.0 / lambda3],
    }
}

/// One normal per point.
fn check_normals(normals: &[[f32; 3]], points: usize) -> Result<(), DetectError> {
    if normals.len() != points {
        return Err(DetectError::BadParameter(format!(
            "{} normals for {points} points",
            normals.len()
        )));
    }
    Ok(())
}

/// Input checks: not empty, finite, in the range of exact arithmetic.
pub(crate) fn check_points(points: &[[f64; 3]]) -> Result<(), DetectError> {
    if points.is_empty() {
        return Err(DetectError::Empty);
    }
    if let Some(index) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(DetectError::NonFinite { index });
    }
    // Tighter than the triangulation's range, so that every transformed
    // point Q·p stays inside it (|Q·p| ≤ √3·max|p|·max e, with λ within
    // LAMBDA_RANGE; cancellation leaves either 0 or at least an ulp of the
    // inputs).
    if let Some(index) = points.iter().position(|p| {
        p.iter()
            .any(|c| c.abs() > 1e50 || (*c != 0.0 && c.abs() < 1e-30))
    }) {
        return Err(DetectError::OutOfRange { index });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// Three perpendicular walls (a 0.1 grid, 5 mm of noise) meeting at a
    /// corner, and their true normals.
    fn corner() -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let mut rng = SplitMix64::new(5);
        let (mut points, mut normals) = (Vec::new(), Vec::new());
        for i in 1..30 {
            for j in 1..30 {
                let (u, v) = (i as f64 * 0.1, j as f64 * 0.1);
                let mut e = || 0.01 * (rng.uniform() - 0.5);
                points.extend([[u, v, e()], [e(), u, v], [u, e(), v]]);
                normals.extend([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
            }
        }
        (points, normals)
    }

    #[test]
    fn explicit_normals_gate_the_claims_only_if_they_agree_with_the_points() {
        let (points, truth) = corner();
        let planes = Detector::planes(0.05, 4.0, 4.0, 20);
        let gate = |d: &Detector| d.regime(&points).claim_normals().map(<[_]>::len);
        assert_eq!(gate(&planes.clone().normals(&truth)), Some(points.len()));
        // One placeholder direction: a third of the planar points agree.
        let placeholder = vec![[0.0, 0.0, 1.0]; points.len()];
        assert_eq!(gate(&planes.clone().normals(&placeholder)), None);
        assert_eq!(gate(&planes), None);
        // Lines ignore normals.
        let lines = Detector::lines(0.05, 4.0, 4).normals(&truth);
        assert_eq!(gate(&lines), None);
        // The verdict of `auto_oriented` is kept, and new normals are
        // checked again.
        let given = Given::default();
        let auto =
            Detector::auto_oriented(StructureKind::Planes, &points, &truth, &given, 12).unwrap();
        assert!(auto.given_normals().is_some_and(|g| g.used));
        assert_eq!(gate(&auto), Some(points.len()));
        assert_eq!(gate(&auto.normals(&placeholder)), None);
    }
}
