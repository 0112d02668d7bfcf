//! Parameters and orientation set from the data (method doc §8).
//!
//! The paper's parameters are lengths and counts at the scale of the
//! sampling (its Observations 3 and 4): α must stay below the distance from
//! a structure to the background and above the structure's own thickness,
//! α·λ must reach across the gaps between a structure's neighbouring
//! points, and nb_c is the size under which a piece is chance. A user of a
//! real scan knows none of these, so they are measured:
//!
//! 1. **Local shape** ([`super::local`]): per point, a PCA of its
//!    neighbourhood at the scale where it looks most planar (k = 2) or
//!    linear (k = 1): its axis (normal or direction), its spread across the
//!    structure (noise), its spacing (distance to the nearest point), and
//!    a score (planarity or linearity). Points scoring at least
//!    [`SCORE_MIN`] are *structure-like*. For lines, the points of
//!    surfaces ([`super::local::on_surface`]: as planar at their most planar scale
//!    as they are linear at their most linear one) are left out of
//!    everything below: for lines they are background.
//! 2. **Modes** ([`super::modes`]): the dominant axes of the
//!    structure-like points (mean shift, kernel [`MODE_KERNEL_DEG`]).
//! 3. **Per mode**, its *members*: every point whose axis lies within
//!    [`CONE_DEG`] of the mode (a point of a plane with that normal has
//!    its normal there; the others are background for that mode, so the
//!    background each orientation sees is sparse, which is the paper's
//!    regime). Among the structure-like members:
//!    * spacing d = the 90th percentile of their spacings (so that the
//!      sparser, farther parts of a scan with mixed density are reached:
//!      a scanner's density falls with the square of the range, and one
//!      global median would leave the far walls in pieces). For planes a
//!      point's spacing is the larger of its nearest-neighbour distance
//!      and half its row gap ([`LocalShape::row_gap`]): points on scan
//!      lines far apart (an airborne strip) have their nearest neighbour
//!      on their own line, and the triangles that join two lines g apart
//!      have a circumradius of about g/2, which the reach must span;
//!    * noise σ = the median of their spreads.
//! 4. **α and λ** (per mode, λ₂ = λ₃ = λ):
//!    * thickness: α ≥ [`C_NOISE`]·σ, so the ellipsoid's short semi-axis
//!      covers ±3σ of the structure's noise (99.7% of a Gaussian);
//!    * reach: α·λ = [`C_REACH`]·d, so the long semi-axes reach across gaps
//!      of up to 2·C_REACH·d between neighbours (Observation 4: the flat
//!      ellipsoid must contain the circumcircle of the structure's
//!      triangles; Observation 3 for lines);
//!    * λ ≤ [`LAMBDA_MAX`] (the paper's Fig. 10 uses 8): thinner ellipsoids
//!      need finer orientations; so α = max(C_NOISE·σ, C_REACH·d/λ_max)
//!      and λ = clamp(C_REACH·d/α, 1, λ_max). Very noisy structures
//!      (σ above about d/2) get λ = 1: the Euclidean α-shape, as measured
//!      on the noisy walls of the CGAL building scan.
//!    * **thick lines** (k = 1, when C_NOISE·σ ≥ C_REACH·d, so λ would be 1):
//!      the line is a tube (a pole, a trunk, a cable's point swarm) many points
//!      across, whose α-shape is a surface, not a path. It is a line at a
//!      coarser scale: the mode's members are thinned along the mode's direction
//!      (a kept point excludes the others within [`TUBE_STEP`]·α along it and
//!      [`TUBE_WIDTH`]·α across), so the kept points of a tube form one chain,
//!      TUBE_STEP·α to twice that apart; the spacing becomes that step and λ =
//!      C_REACH·step/α = 4. The points of each cross-section are taken
//!      nearest to its centroid moved by σ towards one fixed side, so that
//!      the chain is straight whether the tube was scanned from one side or
//!      all around (`thin_along`). The assembly's claims give the parts back every
//!      input point within α of their segment.
//!    * **thick planes** (k = 2, when C_NOISE·σ ≥ C_REACH·d, so λ would be
//!      1 while the cloud's own spacing and noise give λ > 1): the mode's
//!      members are not a plane at their own spacing (a few hundred points
//!      whose neighbourhoods straddle two faces of a small roof, or the
//!      blurred normals around a window recess): their ellipsoid would be
//!      a ball of several spacings, bridging what lies apart. The mode is
//!      scanned at the cloud's spacing and noise instead, and the report
//!      says so (`cloud_scale`). Where the cloud itself gives λ = 1 (every
//!      plane as noisy as it is sparse), the mode keeps its own.
//! 5. **nb_c** = [`NB_C_AUTO`]: the path filter then only cuts spurs and
//!    fins of a few simplices; what is chance is decided by the
//!    significance test ([`super::significance`]).
//! 6. **Sparse structures: the scale ladder.** The local shapes describe a
//!    cloud whose points mostly lie on dense structures. Where structures
//!    are sparse against their background (the paper's own scenes: lines
//!    of ten points spaced like the background's nearest neighbours), a
//!    structure point's neighbourhood is mostly background, the few points
//!    that look structured do so by chance, and their modes are not the
//!    structures' directions. So when the structure-like members of the
//!    modes are fewer than [`EXPLAINED_MIN`] of the points that can be
//!    structure (for lines, those not on surfaces), the run scans instead
//!    a [`Ladder`] (of at most [`LADDER_MAX_POINTS`]
//!    points; a larger cloud scans its modes, with a warning): the
//!    Fibonacci sampler at [`LADDER_STEP_DEG`] over those
//!    points, λ = [`LAMBDA_MAX`], and the α of each of
//!    [`LADDER_LEVELS`] (reach C_REACH·d·level, d the median
//!    nearest-neighbour distance). Each level is assembled apart up to the
//!    significance test, and the parts are kept across levels by the
//!    exclusion principle (`assemble::select`): the significance test, not
//!    an estimate, chooses the scale of each structure. The levels share
//!    each rotation's triangulation (the Delaunay tetrahedralization of
//!    Q·P does not depend on α).
//! 7. **Normals that form no mode: the cover** (planes). A cloud whose
//!    points are mostly structure-like (at least [`EXPLAINED_MIN`] of
//!    them) but whose modes explain less than that is not sparse: its
//!    local shapes describe it, but its normals spread over many
//!    directions without peaks (a geodesic dome's facets, each facing its
//!    own way; a rolling terrain; a rock face), so the mode search keeps
//!    few modes or none. Where the cloud is too large for a ladder, or
//!    where most of its structure-like points are in no mode (the modes
//!    explain less than half the structure-like share; the paper's scenes,
//!    under half structure-like, keep the ladder), the points no mode
//!    scans are then
//!    scanned along the directions of the ladder's sampler
//!    ([`COVER_STEP_DEG`]): each direction is a mode whose members are
//!    taken as a mode's are, with a margin of half the step (a facet whose
//!    normals spread less than a quarter of the step lies whole in the
//!    scan of the direction nearest to it, and a point is scanned about
//!    twice, not about six times as with the modes' margin), kept where
//!    its structure-like members reach a mode's support, and scanned at
//!    their own spacing and noise. The report marks these `cover`.
//!
//! Explicit values override the estimates (for every mode); with α or λ
//! given, no ladder.

use super::detection::{distinct_count, position_key};
use super::local::{line_shapes_on_surfaces, local_shapes, LocalShape, SCORE_MIN};
use super::modes::{modes, Mode};
use super::StructureKind;
use crate::aniso::{completion_first_row, completion_third_row, Mat3};
use crate::geometry::kdtree::KdTree;
use crate::geometry::{cross, dot, normalize, scale, sub};

/// Angular radius of the mean-shift kernel of the modes (degrees): about
/// the median angular error of local normals on the real scans measured
/// (0.6–8°), so one plane gives one mode.
pub const MODE_KERNEL_DEG: f64 = 5.0;

/// Members of a mode: points whose axis is within this angle of it
/// (degrees). On the CGAL building and polyhedron scans, 82–98% of each
/// labelled plane's points have their normal within 20–25°; the rest lie
/// along the plane's edges, where neighbourhoods straddle two planes, and
/// are recovered by the assembly's claims.
pub const CONE_DEG: f64 = 25.0;

/// Smallest share of the points within the cone of a mode whose axis lies
/// within the kernel of it. Measured on the CGAL building and polyhedron
/// scans: 0.42–0.9 for the modes of labelled planes (the noisy walls
/// lowest), 0.07–0.3 for the peaks made by edge normals.
pub const MODE_CONCENTRATION: f64 = 0.25;

/// A point joins the modes at most this much farther from its axis than
/// its nearest mode (degrees): twice the mode kernel.
pub const MARGIN_DEG: f64 = 2.0 * MODE_KERNEL_DEG;

/// Half-thickness of the ellipsoid in units of the noise σ.
pub const C_NOISE: f64 = 3.0;

/// Reach of the ellipsoid in units of the spacing d.
pub const C_REACH: f64 = 2.0;

/// Largest elongation chosen.
pub const LAMBDA_MAX: f64 = 8.0;

/// Thinning of a thick line (module doc, step 4b): the step between kept
/// points along the tube in units of α: the tube's diameter, about
/// 2·C_NOISE·σ = 2α, so that consecutive kept points are farther apart
/// along the tube than across it.
pub const TUBE_STEP: f64 = 2.0;

/// Thinning of a thick line: the width within which kept points exclude
/// one another, in units of α: twice the tube's diameter (2α), so that a
/// cross-section keeps one point wherever it is cut.
pub const TUBE_WIDTH: f64 = 4.0;

/// The path filter's nb_c in the automatic mode.
pub const NB_C_AUTO: u32 = 4;

/// Smallest number of points of a mode (and the fraction of the
/// structure-like points, whichever is larger: 0.1%).
pub const MODE_MIN_POINTS: usize = 30;

/// Values given by the user; `None` is estimated.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Given {
    /// α.
    pub alpha: Option<f64>,
    /// λ₂ (planes).
    pub lambda2: Option<f64>,
    /// λ₃.
    pub lambda3: Option<f64>,
    /// nb_c.
    pub min_size: Option<u32>,
}

/// A parameter's value, whether it was estimated, and why this value.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// The value used.
    pub value: f64,
    /// Whether it was estimated from the data (false: given).
    pub estimated: bool,
    /// Where the value comes from.
    pub reason: String,
}

/// One mode of the data orientation set with what it scans.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeScan {
    /// Unit axis: the normal (planes) or direction (lines) of the mode.
    pub axis: [f64; 3],
    /// Structure-like points near the axis (mean-shift support).
    pub support: usize,
    /// Its members (ascending input indices).
    pub points: Vec<u32>,
    /// Spacing d of its structure-like members (90th percentile).
    pub spacing: f64,
    /// Noise σ of its structure-like members (median spread).
    pub noise: f64,
    /// α of its orientations.
    pub alpha: f64,
    /// λ₂ (planes; 1 for lines).
    pub lambda2: f64,
    /// λ₃.
    pub lambda3: f64,
    /// Its orientations (rows of R): the normal as first row (planes) or
    /// the direction as third row (lines).
    pub rotations: Vec<Mat3>,
    /// For a thick line (module doc, step 4b): its members before the
    /// thinning, whose own scale gave λ = 1.
    pub thinned_from: Option<usize>,
    /// For a thick plane (module doc, step 4c): its own spacing and noise
    /// gave λ = 1, and it is scanned at the cloud's.
    pub cloud_scale: bool,
    /// Not a mode: a direction of the cover of the normals that no mode
    /// scans (module doc, step 7); `support` is then its structure-like
    /// members.
    pub cover: bool,
}

/// What was estimated from a cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Lines or planes.
    pub kind: StructureKind,
    /// Number of points.
    pub points: usize,
    /// Median distance to the nearest point.
    pub spacing_median: f64,
    /// 90th percentile of the structure-like points' spacings.
    pub spacing: f64,
    /// Median spread across the structure of the structure-like points.
    pub noise: f64,
    /// Fraction of the points that are structure-like.
    pub structure_fraction: f64,
    /// α (the whole cloud's value; modes may have their own).
    pub alpha: Param,
    /// λ₂.
    pub lambda2: Param,
    /// λ₃.
    pub lambda3: Param,
    /// nb_c.
    pub min_size: Param,
    /// The data orientation set.
    pub modes: Vec<ModeScan>,
    /// Share of the points the modes explain: structure-like members of a
    /// mode, over the points that can be structure (for lines, those not
    /// on surfaces).
    pub explained: f64,
    /// Share of the points that can be structure that are structure-like
    /// (with or without a mode).
    pub structured: f64,
    /// The scale ladder scanned instead of the modes when they explain
    /// less than [`EXPLAINED_MIN`] of the cloud (module doc, step 6), unless
    /// the cover scans the rest (step 7).
    pub ladder: Option<Ladder>,
    /// The number of points a ladder would have scanned where the cloud
    /// called for one but they were more than [`LADDER_MAX_POINTS`]: the
    /// modes were scanned instead (a run warning says so).
    pub ladder_declined: Option<usize>,
}

impl Estimate {
    /// Whether the cover scans this cloud because its normals spread
    /// without peaks (most structure-like points in no mode), which calls
    /// for the cover at any size, rather than standing in for a ladder
    /// the cloud is too large for.
    pub fn normals_spread(&self) -> bool {
        self.modes.iter().any(|m| m.cover) && spread_without_peaks(self.explained, self.structured)
    }
}

/// Whether the modes explain less than half the structure-like share:
/// most structure-like points are in no mode.
fn spread_without_peaks(explained: f64, structured: f64) -> bool {
    explained < structured / 2.0
}

/// The scales of a run whose structures are sparse against their
/// background (module doc, step 6): a sampler's orientations over the
/// points, at each of several α with one elongation, every level
/// assembled apart and the parts kept by the significance test across
/// levels.
#[derive(Debug, Clone, PartialEq)]
pub struct Ladder {
    /// α of each level, ascending.
    pub alphas: Vec<f64>,
    /// λ of every level (λ₂ = λ₃ for planes).
    pub lambda: f64,
    /// The sampler's angular step (degrees).
    pub step_deg: f64,
    /// The points scanned: all of them (planes), or those not on surfaces
    /// (lines); ascending input indices.
    pub points: Vec<u32>,
}

/// The share of the cloud the modes must explain for the run to scan
/// them; below it, the scale ladder (module doc, step 6). A majority:
/// where most points are not members of a mode, the local shapes do not
/// describe the cloud (the neighbourhoods of a sparse structure's points
/// are mostly background), and the modes, made of the few points that look
/// structured by chance, are not the structures' directions. Measured:
/// 0.83–0.99 on the real scans of the corpus's train half (planes), 0.0–0.45
/// on the paper's scenes (scripts/eval_synth.py, seeds 1–5).
pub const EXPLAINED_MIN: f64 = 0.5;

/// The most points a scale ladder scans (module doc, step 6): 2^15. The
/// ladder triangulates its points once per rotation of its sampler (207)
/// and assembles them at five levels, about a thousand times the work of
/// a run over the modes: seconds for the paper's scenes, which hold 270 to
/// 15,050 points (scripts/eval_synth.py, every kind and variant; the size
/// depends on the variant, not on the seed), and minutes to hours for a
/// scan. A larger cloud whose modes explain under half of it (a
/// natural-terrain scan: its planes, and its lines among the vegetation)
/// scans its modes instead, with a run warning that says so and how to ask
/// for the paper's sampler.
pub const LADDER_MAX_POINTS: usize = 1 << 15;

/// The levels of the ladder: the reach α·λ of level j is
/// [`C_REACH`]·d·2^(j/2 − 2), j = 0 … 4, d the median nearest-neighbour
/// distance of the cloud: from a quarter of the reach the dense-scan rule
/// would give (a structure sampled four times more densely than the
/// background's spacing) to all of it, in steps of √2. Measured on the
/// paper's scenes (train seeds): the significance test picks levels 0–2 for
/// planes and 1–3 for lines; the top level alone is rarely chosen.
pub const LADDER_LEVELS: [f64; 5] = [
    0.25,
    std::f64::consts::FRAC_1_SQRT_2 / 2.0,
    0.5,
    std::f64::consts::FRAC_1_SQRT_2,
    1.0,
];

/// The angular step of the ladder's sampler (degrees): the Fibonacci
/// sampler at 10° (207 directions; for planes λ₂ = λ₃, one turn per
/// normal), whose largest gap to a direction, about 5°, is within the
/// tilt atan(1/[`LAMBDA_MAX`]) = 7.1° that an ellipsoid of elongation
/// λ_max tolerates.
pub const LADDER_STEP_DEG: f64 = 10.0;

/// The angular step of the cover of the normals no mode scans (module
/// doc, step 7; degrees): the ladder's sampler, [`LADDER_STEP_DEG`], for
/// the same reason (its largest gap, about 5°, is within the tilt that the
/// flattest ellipsoid tolerates).
pub const COVER_STEP_DEG: f64 = LADDER_STEP_DEG;

fn quantile(v: &mut [f32], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let k = ((v.len() - 1) as f64 * q).round() as usize;
    let (_, x, _) = v.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    f64::from(*x)
}

/// α and λ from spacing and noise (module doc, step 4), with the values
/// given by the user taking precedence. Returns (α, λ₂, λ₃).
fn scales(kind: StructureKind, d: f64, sigma: f64, given: &Given) -> (f64, f64, f64) {
    let reach = C_REACH * d;
    let alpha = given
        .alpha
        .unwrap_or_else(|| (C_NOISE * sigma).max(reach / LAMBDA_MAX));
    let lambda = (reach / alpha).clamp(1.0, LAMBDA_MAX);
    let l3 = given.lambda3.unwrap_or(lambda);
    let l2 = match kind {
        StructureKind::Planes => given.lambda2.unwrap_or(given.lambda3.unwrap_or(lambda)),
        StructureKind::Lines => 1.0,
    };
    (alpha, l2, l3)
}

/// A thinning of a tube's members along `axis` (module doc, step 4b):
/// members taken nearest to the tube's axis first, each kept unless a kept
/// one lies within `step` of it along the axis and within `width` across;
/// ascending indices. Within a tube narrower than `width` the kept points
/// follow one another at `step` to `2·step` along it, one chain; tubes
/// farther apart than `width` keep their own chains.
///
/// The order matters for the chain's straightness: a pole scanned from one
/// side is a half-cylinder of points, and points taken in scan order
/// alternate between its sides, so consecutive kept points zigzag by up to
/// the pole's diameter (0.7α on the simulated street's poles); the
/// anisotropic α-shape of such a chain has edges across the zigzag, whose
/// ramifications cut it into pieces that the path filter deletes (four of
/// its five poles). So the members are taken by their distance across the
/// axis to the centroid of their cross-section (the members within
/// `step`/2 along and `width`/2 across), that centroid moved by `shift`
/// (the tube's spread σ) towards one fixed side across the axis. On a pole
/// scanned from one side the kept points are then near the middle of each
/// cross-section; on a pole scanned all around, whose every point lies at
/// the same distance from its ring's centroid, they are the points on that
/// side, one line along the tube, where without the shift they were
/// anywhere around each ring and the chain zigzagged (a pole of 9,300
/// points, 10 cm in radius, lost as a line).
fn thin_along(
    points: &[[f64; 3]],
    members: &[u32],
    axis: [f64; 3],
    step: f64,
    width: f64,
    shift: f64,
) -> Vec<u32> {
    let tree = KdTree::new(points, Some(members.to_vec()));
    let across = |w: [f64; 3]| -> (f64, f64) {
        let along = dot(w, axis);
        (along, (dot(w, w) - along * along).max(0.0))
    };
    // Each member's distance across the axis to its cross-section's
    // centroid moved by `shift` towards a fixed side.
    let side = perpendicular(axis);
    let section = (0.25 * step * step + 0.25 * width * width).sqrt();
    let offset: Vec<f64> = members
        .iter()
        .map(|&i| {
            let p = points[i as usize];
            let (mut c, mut k) = ([0.0; 3], 0.0f64);
            tree.within(&p, section, |j| {
                let q = points[j as usize];
                let (along, across2) = across(sub(q, p));
                if along.abs() <= 0.5 * step && across2 <= 0.25 * width * width {
                    (0..3).for_each(|d| c[d] += q[d] - p[d]);
                    k += 1.0;
                }
            });
            let c = c.map(|x| x / k.max(1.0));
            // p − centroid across the axis, less the bias.
            let (along, _) = across(c);
            let v = sub(scale(along, axis), c);
            let w = sub(v, scale(shift, side));
            dot(w, w)
        })
        .collect();
    let mut order: Vec<usize> = (0..members.len()).collect();
    order.sort_by(|&a, &b| offset[a].total_cmp(&offset[b]).then(a.cmp(&b)));
    let mut kept_flag = vec![false; points.len()];
    let mut out = Vec::new();
    let reach = (step * step + width * width).sqrt();
    for k in order {
        let i = members[k];
        let p = points[i as usize];
        let mut blocked = false;
        tree.within(&p, reach, |j| {
            if blocked || !kept_flag[j as usize] {
                return;
            }
            let (along, across2) = across(sub(points[j as usize], p));
            if along.abs() < step && across2 < width * width {
                blocked = true;
            }
        });
        if !blocked {
            kept_flag[i as usize] = true;
            out.push(i);
        }
    }
    out.sort_unstable();
    out
}

/// A unit vector perpendicular to unit `a`: its cross product with the
/// coordinate axis least aligned with it.
fn perpendicular(a: [f64; 3]) -> [f64; 3] {
    let k = (0..3)
        .min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    normalize(cross(a, e)).unwrap_or([1.0, 0.0, 0.0])
}

fn axis64(s: &LocalShape, kind: StructureKind) -> [f64; 3] {
    s.axis(kind).map(f64::from)
}

/// The rotations of a mode: its axis as the normal (first row, planes) or
/// direction (third row, lines); for planes with λ₂ ≠ λ₃, `m2` turns
/// about the normal (θ_j = −π/2 + jπ/m2 as the paper's box sampler).
pub fn mode_rotations(
    kind: StructureKind,
    axis: [f64; 3],
    lambda2: f64,
    lambda3: f64,
    m2: u32,
) -> Vec<Mat3> {
    match kind {
        StructureKind::Lines => vec![completion_third_row(axis)],
        StructureKind::Planes => {
            let [n, a, b] = completion_first_row(axis);
            if lambda2 == lambda3 || m2 <= 1 {
                return vec![[n, a, b]];
            }
            (1..=m2)
                .map(|j| {
                    let t = -std::f64::consts::FRAC_PI_2
                        + f64::from(j) * std::f64::consts::PI / f64::from(m2);
                    let (s, c) = t.sin_cos();
                    let r2 = [0, 1, 2].map(|k| c * a[k] + s * b[k]);
                    let r3 = [0, 1, 2].map(|k| c * b[k] - s * a[k]);
                    [n, r2, r3]
                })
                .collect()
        }
    }
}

/// Estimates the parameters and the data orientation set of `points` for
/// structures of `kind`, keeping the values in `given` (module doc).
/// `m2` is the number of turns about a plane's normal when λ₂ ≠ λ₃.
///
/// ```
/// use aniso_alpha::detect::estimate::{estimate, Given};
/// use aniso_alpha::detect::StructureKind;
/// // Two perpendicular 30 × 30 grids of spacing 0.1 (a floor and a wall).
/// let mut pts = Vec::new();
/// for i in 0..30 {
///     for j in 0..30 {
///         pts.push([0.1 * i as f64, 0.1 * j as f64, 0.0]);
///         pts.push([0.1 * i as f64, 0.0, 0.1 + 0.1 * j as f64]);
///     }
/// }
/// let e = estimate(StructureKind::Planes, &pts, &Given::default(), 12);
/// assert_eq!(e.modes.len(), 2);
/// assert!((e.spacing - 0.1).abs() < 1e-6); // (spacings are kept as f32)
/// assert!(e.alpha.estimated && e.alpha.value > 0.0);
/// ```
pub fn estimate(kind: StructureKind, points: &[[f64; 3]], given: &Given, m2: u32) -> Estimate {
    estimate_oriented(kind, points, None, given, m2).0
}

/// Share of the locally planar points whose given normal must lie within
/// [`CONE_DEG`] of their neighbourhood's PCA normal for the given normals
/// to be used: a majority. Normals that disagree with the points' own
/// geometry (a tool's placeholder 0 0 1 everywhere, normals of another
/// cloud, shuffled columns) would drive the modes and the claims wrong.
/// Measured on the real scans that have normals, against the local shapes'
/// normals (each point's most planar scale): 74% agree on CGAL's building,
/// 97% on the ball. Normals that carry no information agree by chance: 9%
/// for random directions (1 − cos 25°), about a third for one placeholder
/// direction or shuffled normals on three perpendicular walls
/// (`tests/normals.rs`).
pub const NORMALS_AGREEMENT_MIN: f64 = 0.5;

/// How the normals given with the points compare with the points' own
/// geometry ([`estimate_oriented`]). Each use of the given normals is
/// compared with the same use of the normals estimated from the points,
/// and the given ones are used only where they do at least as well:
///
/// 1. **Agreement**: a majority of the locally planar points must have
///    their given normal within [`CONE_DEG`] of their neighbourhood's
///    ([`NORMALS_AGREEMENT_MIN`]); otherwise they are not used at all.
/// 2. **Orientation modes**: the modes of the given normals must explain
///    at least as much of the cloud ([`Estimate::explained`]) as those of
///    the estimated normals; otherwise the modes come from the estimated
///    normals. Normals estimated over too few neighbours scatter, and
///    normals smoothed across a few spacings blur, the peaks of their
///    planes: Open3D's normals within 3 spacings of a depth frame lose its
///    table's mode (explaining 9% of the frame against 99%).
/// 3. **The claims' gate** (a point joins a plane only if its normal is
///    within 36.9° of the plane's, [`Detector::normals`]): the given
///    normals gate the claims whenever they pass step 1, wherever the modes
///    come from. Normals that are accurate where the points' own
///    neighbourhoods blend two faces keep a window frame's or a ledge's
///    points off the façade (CGAL's building: F1 0.929 with its normals'
///    gate, 0.863 without); noisy ones turn away some points of the very
///    planes they lie on (docs/method.md §8, "Normals given with the
///    points", gives both measures).
///
/// [`Detector::normals`]: crate::detect::Detector::normals
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GivenNormals {
    /// Of the locally planar points with a usable given normal, the share
    /// whose given normal is within [`CONE_DEG`] of the PCA normal.
    pub agreement: f64,
    /// Where the agreement was reached: the share of the cloud that the
    /// modes of the given normals explain, and the share that the modes of
    /// the estimated normals explain ([`Estimate::explained`]).
    pub explained: Option<(f64, f64)>,
    /// Whether the orientation modes come from the given normals (step 2).
    pub used: bool,
    /// Whether the given normals gate the claims of planes (step 3: they
    /// passed step 1).
    pub gate: bool,
}

impl GivenNormals {
    /// Whether the given normals are used for nothing.
    pub fn ignored(&self) -> bool {
        !self.used && !self.gate
    }

    /// Whether the given normals are used for both the orientations and
    /// the claims' gate.
    pub fn in_full(&self) -> bool {
        self.used && self.gate
    }

    /// Where the orientation modes come from: `"input"` or `"estimated"`.
    pub fn modes_from(&self) -> &'static str {
        if self.used {
            "input"
        } else {
            "estimated"
        }
    }

    /// What the given normals were not used for, and why (empty when they
    /// were used for both the orientations and the gate).
    pub fn ignored_reason(&self) -> String {
        let Some((given, own)) = self.explained else {
            return format!(
                "only {:.0}% of the locally planar points have their given normal within 25 \
                 degrees of their neighbourhood's (at least half must); normals estimated instead",
                100.0 * self.agreement
            );
        };
        if self.used {
            return String::new();
        }
        format!(
            "the orientation modes of the given normals explain {:.0}% of the points, those of \
             normals estimated from the points {:.0}% (the given normals are noisier, or \
             smoothed across edges), so the orientations come from the estimated normals; the \
             given ones still keep a point off a plane across its normal (--ignore-normals: \
             not at all)",
            100.0 * given,
            100.0 * own
        )
    }
}

/// [`estimate`] for points with given unit normals (zero where missing):
/// for planes, each point's axis is its given normal where it has one (the
/// scan's normals, e.g. from the scanner's geometry or a finer fit than a
/// 16-neighbour PCA); its spread, spacing and planarity stay those of its
/// neighbourhood. Lines ignore normals. Normals that disagree with the
/// points' geometry ([`NORMALS_AGREEMENT_MIN`]) are not used; the returned
/// [`GivenNormals`] says which (`None` without normals, or for lines).
pub fn estimate_oriented(
    kind: StructureKind,
    points: &[[f64; 3]],
    normals: Option<&[[f32; 3]]>,
    given: &Given,
    m2: u32,
) -> (Estimate, Option<GivenNormals>) {
    if kind == StructureKind::Lines {
        let (shapes, surface): (Vec<LocalShape>, Vec<bool>) =
            shapes_for(points, line_shapes_on_surfaces)
                .into_iter()
                .unzip();
        return (
            estimate_with(kind, points, &shapes, Some(&surface), given, m2, None),
            None,
        );
    }
    let mut shapes = shapes_for(points, |p| local_shapes(p, kind));
    let Some(normals) = normals else {
        return (
            estimate_with(kind, points, &shapes, None, given, m2, None),
            None,
        );
    };
    let mut g = normals_agreement(&shapes, normals);
    if !g.used {
        return (
            estimate_with(kind, points, &shapes, None, given, m2, None),
            Some(g),
        );
    }
    // The modes of the estimated normals, then of the given ones in their
    // place (the estimated normals kept aside, 12 bytes a point, to be put
    // back if they win): one copy of the local shapes, one search at a time.
    let structure = StructureLike::of(kind, &shapes, &|_| false);
    let of_own = mode_search(kind, points, &shapes, &structure, &|_| false);
    let own_normals: Vec<[f32; 3]> = shapes.iter().map(|s| s.normal).collect();
    for (s, n) in shapes.iter_mut().zip(normals) {
        if *n != [0.0; 3] {
            s.normal = *n;
        }
    }
    let of_given = mode_search(kind, points, &shapes, &structure, &|_| false);
    g.explained = Some((of_given.explained, of_own.explained));
    g.used = of_given.explained >= of_own.explained;
    let search = if g.used {
        drop((of_own, own_normals));
        of_given
    } else {
        drop(of_given);
        for (s, n) in shapes.iter_mut().zip(own_normals) {
            s.normal = n;
        }
        of_own
    };
    let e = estimate_with(
        kind,
        points,
        &shapes,
        None,
        given,
        m2,
        Some((structure, search)),
    );
    (e, Some(g))
}

/// How given unit normals (zero where missing) agree with the geometry of
/// `points`: the check of [`estimate_oriented`], for normals given to a
/// detector with explicit parameters.
pub(crate) fn check_normals_agreement(points: &[[f64; 3]], normals: &[[f32; 3]]) -> GivenNormals {
    normals_agreement(
        &shapes_for(points, |p| local_shapes(p, StructureKind::Planes)),
        normals,
    )
}

/// Of the locally planar points (planarity ≥ [`SCORE_MIN`]) with a usable
/// given normal, the share whose normal is within [`CONE_DEG`] of their
/// local shape's, and whether that reaches [`NORMALS_AGREEMENT_MIN`].
fn normals_agreement(shapes: &[LocalShape], normals: &[[f32; 3]]) -> GivenNormals {
    let cos = CONE_DEG.to_radians().cos();
    let (mut planar, mut agree) = (0usize, 0usize);
    for (s, n) in shapes.iter().zip(normals) {
        if *n != [0.0; 3] && s.planarity() >= SCORE_MIN {
            planar += 1;
            let d: f32 = (0..3).map(|k| s.normal[k] * n[k]).sum();
            agree += usize::from(f64::from(d.abs()) >= cos);
        }
    }
    let agreement = agree as f64 / planar.max(1) as f64;
    let used = planar > 0 && agreement >= NORMALS_AGREEMENT_MIN;
    GivenNormals {
        agreement,
        explained: None,
        used,
        gate: used,
    }
}

/// The modes of the local shapes' axes, their members and the share of
/// the cloud they explain ([`Estimate::explained`]).
struct ModeSearch {
    found: Vec<Mode>,
    members: Vec<Vec<u32>>,
    explained: f64,
}

/// The structure-like points of a cloud (score ≥ [`SCORE_MIN`], not left
/// out) and the scales measured on them. They depend on the local shapes'
/// scores, spacings and spreads, not on their axes: one value serves every
/// mode search over the same shapes, whichever normals they carry.
struct StructureLike {
    /// The structure-like points (indices into the cloud).
    ids: Vec<u32>,
    /// The median of every finite nearest-neighbour spacing.
    spacing_median: f64,
    /// The spacing d of the structure-like points ([`spacing_and_noise`]).
    spacing: f64,
    /// Their noise σ.
    noise: f64,
}

impl StructureLike {
    /// The structure-like points of `shapes` not flagged by `off`, and
    /// their scales.
    fn of(kind: StructureKind, shapes: &[LocalShape], off: &dyn Fn(usize) -> bool) -> Self {
        let mut all_spacing: Vec<f32> = shapes
            .iter()
            .map(|s| s.spacing)
            .filter(|s| s.is_finite())
            .collect();
        let spacing_median = quantile(&mut all_spacing, 0.5);
        let ids: Vec<u32> = (0..shapes.len() as u32)
            .filter(|&i| shapes[i as usize].score(kind) >= SCORE_MIN && !off(i as usize))
            .collect();
        let (spacing, noise) = spacing_and_noise(kind, shapes, &ids, (spacing_median, 0.0));
        StructureLike {
            ids,
            spacing_median,
            spacing,
            noise,
        }
    }
}

/// The mode search of [`estimate_with`] over `shapes`, leaving out the
/// points flagged by `off`: the modes of the structure-like points' axes
/// (their noise sets the kernel's reach), each mode's members, and the
/// share of the cloud they explain.
fn mode_search(
    kind: StructureKind,
    points: &[[f64; 3]],
    shapes: &[LocalShape],
    structure: &StructureLike,
    off: &(dyn Fn(usize) -> bool + Sync),
) -> ModeSearch {
    let found = concentrated_modes(kind, points, shapes, (&structure.ids, structure.noise), off);
    let members = mode_members(kind, shapes, &found, MARGIN_DEG, off);
    let explained = explained_share(kind, shapes, &members, off);
    ModeSearch {
        found,
        members,
        explained,
    }
}

/// The local analysis `shapes_of` ([`local_shapes`] for one kind,
/// [`line_shapes_on_surfaces`] for lines), or for a cloud whose points all
/// sit on copies of themselves (no neighbour at a non-zero distance), that
/// of its distinct points ([`shapes_of_distinct`]).
///
/// The distinct points are also taken at once when the copies are so many
/// that the mean number of copies per position reaches the neighbourhood's
/// size ([`super::local::NEIGHBOURS`]): the neighbourhoods would then hold
/// mostly copies, and the nearest-neighbour queries would visit every one
/// of them (issue 19: 10M points made of 1,000 positions took over 100 s).
/// A cloud with fewer copies keeps each copy's weight in its neighbours'
/// neighbourhoods, as before.
fn shapes_for<T: HasShape>(
    points: &[[f64; 3]],
    shapes_of: impl Fn(&[[f64; 3]]) -> Vec<T>,
) -> Vec<T> {
    if distinct_count(points) * super::local::NEIGHBOURS <= points.len() {
        if let Some(shapes) = shapes_of_distinct(points, &shapes_of) {
            return shapes;
        }
    }
    let shapes = shapes_of(points);
    if !shapes.iter().any(|s| s.shape().spacing.is_finite()) {
        return shapes_of_distinct(points, &shapes_of).unwrap_or(shapes);
    }
    shapes
}

/// A per-point result of the local analysis that holds the point's shape.
trait HasShape: Copy {
    fn shape(&self) -> &LocalShape;
}

impl HasShape for LocalShape {
    fn shape(&self) -> &LocalShape {
        self
    }
}

impl HasShape for (LocalShape, bool) {
    fn shape(&self) -> &LocalShape {
        &self.0
    }
}

/// The local analysis `shapes_of` of the distinct points of `points`, each
/// copy taking its position's; `None` when every point is distinct. For a
/// cloud made of copies of few points, every point with as many copies as
/// the neighbourhood holds: no neighbour at a non-zero distance, so no
/// spacing (and α, λ would be NaN) without this.
fn shapes_of_distinct<T: HasShape>(
    points: &[[f64; 3]],
    shapes_of: impl Fn(&[[f64; 3]]) -> Vec<T>,
) -> Option<Vec<T>> {
    let key = position_key;
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_unstable_by_key(|&i| key(&points[i as usize]));
    let mut distinct: Vec<[f64; 3]> = Vec::new();
    let mut of = vec![0u32; points.len()];
    for (k, &i) in order.iter().enumerate() {
        let p = points[i as usize];
        if k == 0 || key(&p) != key(&points[order[k - 1] as usize]) {
            distinct.push(p);
        }
        of[i as usize] = distinct.len() as u32 - 1;
    }
    if distinct.len() == points.len() {
        return None;
    }
    let shapes = shapes_of(&distinct);
    Some(of.iter().map(|&d| shapes[d as usize]).collect())
}

/// [`estimate`] from local shapes already computed.
pub fn estimate_from(
    kind: StructureKind,
    points: &[[f64; 3]],
    shapes: &[LocalShape],
    given: &Given,
    m2: u32,
) -> Estimate {
    estimate_with(kind, points, shapes, None, given, m2, None)
}

/// [`estimate_from`], leaving out the points flagged in `surface` (for
/// lines: [`super::local::on_surface`]) from the structure-like points, the modes and
/// their members.
fn estimate_with(
    kind: StructureKind,
    points: &[[f64; 3]],
    shapes: &[LocalShape],
    surface: Option<&[bool]>,
    given: &Given,
    m2: u32,
    searched: Option<(StructureLike, ModeSearch)>,
) -> Estimate {
    let n = points.len();
    let off = |i: usize| surface.is_some_and(|s| s[i]);
    let (structure, search) = searched.unwrap_or_else(|| {
        let structure = StructureLike::of(kind, shapes, &off);
        let search = mode_search(kind, points, shapes, &structure, &off);
        (structure, search)
    });
    let StructureLike {
        ids: structure,
        spacing_median,
        spacing,
        noise,
    } = structure;
    let (alpha_p, lambda2_p, lambda3_p, min_size_p) = cloud_params(kind, spacing, noise, given);
    let ModeSearch {
        found,
        members: member_of,
        explained,
    } = search;
    let mode_scans: Vec<ModeScan> = found
        .into_iter()
        .zip(member_of)
        .map(|(m, members)| {
            let core: Vec<u32> = members
                .iter()
                .copied()
                .filter(|&i| shapes[i as usize].score(kind) >= SCORE_MIN)
                .collect();
            let (d, sigma) = spacing_and_noise(kind, shapes, &core, (spacing, noise));
            mode_scan(
                kind,
                points,
                m,
                members,
                (d, sigma),
                (spacing, noise),
                given,
                m2,
            )
        })
        .collect();
    let can_be = (0..n).filter(|&i| !off(i)).count();
    let structured = structure.len() as f64 / can_be.max(1) as f64;
    let sparse = explained < EXPLAINED_MIN
        && given.alpha.is_none()
        && given.lambda2.is_none()
        && given.lambda3.is_none()
        && spacing_median.is_finite()
        && spacing_median > 0.0;
    // Planes whose local shapes describe the cloud (most points are
    // structure-like) but whose normals form no modes that explain it:
    // the cover (module doc, step 7), beside the modes of a cloud too
    // large for a ladder, and in place of the ladder where most of the
    // structure-like points are in no mode.
    let covered = kind == StructureKind::Planes
        && sparse
        && structured >= EXPLAINED_MIN
        && (can_be > LADDER_MAX_POINTS || spread_without_peaks(explained, structured));
    let ladder_declined = (sparse && can_be > LADDER_MAX_POINTS).then_some(can_be);
    let ladder = (sparse && !covered && ladder_declined.is_none()).then(|| {
        ladder(
            spacing_median,
            (0..n as u32).filter(|&i| !off(i as usize)).collect(),
        )
    });
    let (alpha_p, lambda2_p, lambda3_p) = match &ladder {
        None => (alpha_p, lambda2_p, lambda3_p),
        Some(l) => ladder_params(kind, l, (explained, structured), spacing_median),
    };
    let mut mode_scans = mode_scans;
    if covered {
        let cover = cover_scans(
            kind,
            points,
            shapes,
            &mode_scans,
            structure.len(),
            (spacing, noise),
            given,
            m2,
            &off,
        );
        mode_scans.extend(cover);
    }
    Estimate {
        kind,
        points: n,
        spacing_median,
        spacing,
        noise,
        structure_fraction: structure.len() as f64 / n.max(1) as f64,
        alpha: alpha_p,
        lambda2: lambda2_p,
        lambda3: lambda3_p,
        min_size: min_size_p,
        modes: mode_scans,
        explained,
        structured,
        ladder,
        ladder_declined,
    }
}

/// The spacing d (90th percentile of the finite nearest-neighbour
/// distances) and the noise σ (median spread) of the points `ids`, or
/// `fallback` (d, σ) for each that has no value.
fn spacing_and_noise(
    kind: StructureKind,
    shapes: &[LocalShape],
    ids: &[u32],
    fallback: (f64, f64),
) -> (f64, f64) {
    let mut sp: Vec<f32> = ids
        .iter()
        .map(|&i| reach_spacing(kind, &shapes[i as usize]))
        .filter(|s| s.is_finite())
        .collect();
    let d = if sp.is_empty() {
        fallback.0
    } else {
        quantile(&mut sp, 0.9)
    };
    let mut nv: Vec<f32> = ids
        .iter()
        .map(|&i| shapes[i as usize].spread(kind))
        .collect();
    let sigma = if nv.is_empty() {
        fallback.1
    } else {
        quantile(&mut nv, 0.5)
    };
    (d, sigma)
}

/// The spacing a point asks the reach to span: for planes, the larger of
/// its nearest-neighbour distance and half its row gap (the circumradius
/// of the triangles that join two scan lines a gap g apart is about g/2;
/// on an isotropic sampling half the gap is under the spacing and nothing
/// changes); for lines, the nearest-neighbour distance.
fn reach_spacing(kind: StructureKind, s: &LocalShape) -> f32 {
    match kind {
        StructureKind::Planes if s.row_gap.is_finite() => s.spacing.max(0.5 * s.row_gap),
        _ => s.spacing,
    }
}

/// The cloud-wide α, λ₂, λ₃ and nb_c (module doc, steps 4–5) from its
/// spacing and noise, with their reasons; given values kept.
fn cloud_params(
    kind: StructureKind,
    spacing: f64,
    noise: f64,
    given: &Given,
) -> (Param, Param, Param, Param) {
    let (alpha, l2, l3) = scales(kind, spacing, noise, given);
    let param = |value: f64, given: Option<f64>, why: String| Param {
        value,
        estimated: given.is_none(),
        reason: if given.is_some() { "given".into() } else { why },
    };
    let alpha_p = param(
        alpha,
        given.alpha,
        format!(
            "max({C_NOISE}·noise, {C_REACH}·spacing/{LAMBDA_MAX}) with noise {noise:.4} (median spread \
             across the local {}s) and spacing {spacing:.4} (90th percentile of the nearest-neighbour \
             distances of structure-like points{})",
            match kind {
                StructureKind::Planes => "plane",
                StructureKind::Lines => "line",
            },
            match kind {
                StructureKind::Planes => ", or half the gap to the next scan line where larger",
                StructureKind::Lines => "",
            }
        ),
    );
    let lambda_why = format!("clamp({C_REACH}·spacing/alpha, 1, {LAMBDA_MAX})");
    let lambda3_why = if kind == StructureKind::Lines && l3 <= 1.0 && given.lambda3.is_none() {
        format!(
            "{lambda_why} = 1: a ball, no line scale (the locally linear points are as thick as \
             they are far apart); each mode takes its own, a thick line's members thinned along it"
        )
    } else {
        lambda_why.clone()
    };
    let lambda2_p = param(
        l2,
        if kind == StructureKind::Lines {
            Some(1.0)
        } else {
            given.lambda2.or(given.lambda3)
        },
        lambda_why.clone(),
    );
    let lambda3_p = param(l3, given.lambda3, lambda3_why);
    let nb_c = given.min_size.unwrap_or(NB_C_AUTO);
    let min_size_p = Param {
        value: f64::from(nb_c),
        estimated: given.min_size.is_none(),
        reason: if given.min_size.is_some() {
            "given".into()
        } else {
            "the path filter cuts spurs and fins of fewer simplices; the significance test decides what is chance"
                .into()
        },
    };
    (alpha_p, lambda2_p, lambda3_p, min_size_p)
}

/// The modes of the axes of the structure-like points `structure`
/// (module doc, step 2) that are concentrated: at least
/// [`MODE_CONCENTRATION`] of the points in their cone have their axis
/// within the kernel, counted in one of two ways.
///
/// * Over every point within [`CONE_DEG`] of the mode (the rule measured
///   on the building and polyhedron scans).
/// * Over its own structure-like points: within the cone and nearer to
///   it than to every denser mode already kept (the margin of
///   [`mode_members`] is what a mode scans, not what it is judged on: with
///   it, a roof pitched 18° from the ground counted the ground's blurred
///   shoulder as its own). So a small roof whose pitch lies within the
///   cone of the ground's normal is judged on its own points, not on the
///   ground's or the trees'. Counted so, a peak of blurred edge normals is
///   concentrated too (the faces' points belong to the faces' modes), so
///   this way is closed to the edges of kept modes' faces
///   ([`Blends::edge_of`]): a peak on the arc between two of them
///   ([`arcs_through`]) whose points are bent over two faces (their
///   spread above the ellipsoid's half-thickness) or mostly touch points
///   of both, as an edge's normals blend its two faces', and the edge of
///   a step in one kept mode's faces ([`Blends::step`]: a pane recessed
///   in a wall), whose peak found a plane of one row of the wall's
///   points and the background around it.
///
/// The modes are taken densest first.
fn concentrated_modes(
    kind: StructureKind,
    points: &[[f64; 3]],
    shapes: &[LocalShape],
    (structure, noise): (&[u32], f64),
    off: &dyn Fn(usize) -> bool,
) -> Vec<Mode> {
    let axes: Vec<[f64; 3]> = structure
        .iter()
        .map(|&i| axis64(&shapes[i as usize], kind))
        .collect();
    let min_support = MODE_MIN_POINTS.max(structure.len() / 1000);
    let found: Vec<Mode> = modes(&axes, MODE_KERNEL_DEG.to_radians(), min_support);
    let cos_cone = CONE_DEG.to_radians().cos();
    let all: Vec<[f64; 3]> = shapes
        .iter()
        .enumerate()
        .filter(|&(i, _)| !off(i))
        .map(|(_, s)| axis64(s, kind))
        .collect();
    // Per structure-like point: its axis, and the cosine of its angle to
    // the nearest kept mode (-1 while no mode is kept): a peak counts the
    // points nearer to it than to every kept mode.
    let mut candidates: Vec<([f64; 3], f64)> = axes.iter().map(|&a| (a, -1.0)).collect();
    let mut kept: Vec<Mode> = Vec::new();
    let mut blends = Blends {
        kind,
        points,
        shapes,
        structure,
        noise,
        tree: None,
    };
    for m in found {
        // Concentrated over a count when the support is at least
        // MODE_CONCENTRATION of it: the count is at most `most`, so each
        // count stops at the hit past it.
        let most = (m.support as f64 / MODE_CONCENTRATION).floor() as usize;
        let mut in_cone = all.iter().filter(|&&a| dot(a, m.axis).abs() >= cos_cone);
        let mut own = candidates.iter().filter(|&&(a, limit)| {
            let c = dot(a, m.axis).abs();
            c >= cos_cone && c >= limit
        });
        let keep = in_cone.nth(most).is_none()
            || (own.nth(most).is_none() && !blends.edge_of(m.axis, &kept));
        if !keep {
            continue;
        }
        for (a, limit) in candidates.iter_mut() {
            *limit = limit.max(dot(*a, m.axis).abs().min(1.0));
        }
        kept.push(m);
    }
    kept
}

/// The pairs of `kept` modes (their indices) on whose arc axis `m` lies:
/// within the mode kernel ([`MODE_KERNEL_DEG`]) of their great circle,
/// between them, and farther than the kernel from each (axes without
/// sign: each kept axis is taken on `m`'s side).
fn arcs_through(m: [f64; 3], kept: &[Mode]) -> Vec<(usize, usize)> {
    let h = MODE_KERNEL_DEG.to_radians();
    let toward = |a: [f64; 3]| if dot(a, m) < 0.0 { scale(-1.0, a) } else { a };
    let angle = |u: [f64; 3], v: [f64; 3]| dot(u, v).clamp(-1.0, 1.0).acos();
    let on_arc = |a: [f64; 3], b: [f64; 3]| {
        let (a, b) = (toward(a), toward(b));
        let Some(n) = normalize(cross(a, b)) else {
            return false;
        };
        let off_circle = dot(m, n);
        if off_circle.abs() > h.sin() {
            return false;
        }
        let Some(p) = normalize(sub(m, scale(off_circle, n))) else {
            return false;
        };
        let (ap, pb) = (angle(a, p), angle(p, b));
        ap > h && pb > h && ap + pb <= angle(a, b) + 1e-9
    };
    (0..kept.len())
        .flat_map(|a| (a + 1..kept.len()).map(move |b| (a, b)))
        .filter(|&(a, b)| on_arc(kept[a].axis, kept[b].axis))
        .collect()
}

/// The tests of a peak against the edges of kept modes' faces: where a
/// point's neighbourhood spans two faces (an edge), its axis blends
/// theirs, so the blend's points are bent and touch points of both. A
/// face whose normal merely lies between two others' (roofs of three
/// houses at three pitches of one azimuth) is flat and lies apart from
/// them.
struct Blends<'a> {
    kind: StructureKind,
    points: &'a [[f64; 3]],
    shapes: &'a [LocalShape],
    /// The structure-like points (indices into `points`).
    structure: &'a [u32],
    /// The cloud's noise σ.
    noise: f64,
    /// A kd-tree of the structure-like points, built at the first test.
    tree: Option<KdTree>,
}

impl Blends<'_> {
    /// Whether the peak at axis `m` is an edge of the faces of the `kept`
    /// modes: on the arc between two of them and bent ([`Self::bent`]) or
    /// touching both ([`Self::blend`]), or within the cone of one and the
    /// edge of a step in its faces ([`Self::step`]).
    fn edge_of(&mut self, m: [f64; 3], kept: &[Mode]) -> bool {
        let arcs = arcs_through(m, kept);
        let cos_cone = CONE_DEG.to_radians().cos();
        let steps: Vec<[f64; 3]> = kept
            .iter()
            .filter(|a| dot(a.axis, m).abs() >= cos_cone)
            .map(|a| a.axis)
            .collect();
        if arcs.is_empty() && steps.is_empty() {
            return false;
        }
        // The peak's kernel points, selected once for every test.
        let peak = self.kernel(m);
        (!arcs.is_empty() && self.bent(&peak))
            || arcs
                .into_iter()
                .any(|(a, b)| self.blend(&peak, [kept[a].axis, kept[b].axis]))
            || steps.into_iter().any(|a| self.step(&peak, a))
    }

    /// Whether structure-like point `i`'s axis lies within the mode kernel
    /// ([`MODE_KERNEL_DEG`]) of `axis`.
    fn near(&self, i: u32, axis: [f64; 3]) -> bool {
        let cos_h = MODE_KERNEL_DEG.to_radians().cos();
        dot(axis64(&self.shapes[i as usize], self.kind), axis).abs() >= cos_h
    }

    /// The structure-like points within the kernel of `m`.
    fn kernel(&self, m: [f64; 3]) -> Vec<u32> {
        self.structure
            .iter()
            .copied()
            .filter(|&i| self.near(i, m))
            .collect()
    }

    /// Whether the peak whose kernel points are `peak` is bent: their
    /// median spread (σ₃ for planes) exceeds the ellipsoid's
    /// half-thickness, [`C_NOISE`]·σ. A face's points include some whose
    /// neighbourhood lies on the face alone, flat to within the noise; an
    /// edge's normals come from neighbourhoods bent over two faces (a
    /// room's floor-to-wall edges: ten times the noise), and where the
    /// faces' points near the edge are tilted too, [`Self::blend`] finds
    /// no point of one face within their reach.
    fn bent(&self, peak: &[u32]) -> bool {
        let mut spread: Vec<f32> = peak
            .iter()
            .map(|&i| self.shapes[i as usize].spread(self.kind))
            .collect();
        !spread.is_empty() && quantile(&mut spread, 0.5) > C_NOISE * self.noise
    }

    /// Whether the peak whose kernel points are `peak` is the blend of the
    /// faces of modes `faces`: a majority ([`Self::majority`]) of those
    /// points have, within their reach, structure-like points within the
    /// kernel of each face's mode.
    fn blend(&mut self, peak: &[u32], faces: [[f64; 3]; 2]) -> bool {
        self.majority(peak, |this, tree, i, reach| {
            let mut seen = [false; 2];
            tree.any_within(&this.points[i as usize], reach, |t| {
                for (f, axis) in faces.iter().enumerate() {
                    seen[f] |= this.near(t, *axis);
                }
                seen[0] && seen[1]
            })
        })
    }

    /// Whether the peak whose kernel points are `peak` is the edge of a
    /// step in the faces of mode `a` (planes only: a pane recessed in a
    /// wall): a majority ([`Self::majority`]) of those points have, within
    /// their reach, points of `a`'s kernel on their own level along `a` and
    /// on another, farther than the noise band (2·[`C_NOISE`]·σ) allows one
    /// face: they are points of `a`'s faces whose normals the step has
    /// tilted. A roof's points beside flat roofs of two heights (both in
    /// the ground's kernel) are on neither level.
    fn step(&mut self, peak: &[u32], a: [f64; 3]) -> bool {
        if self.kind != StructureKind::Planes {
            return false;
        }
        let band = 2.0 * C_NOISE * self.noise;
        self.majority(peak, |this, tree, i, reach| {
            // Its own level, and whether a point of `a` lies on it and
            // one on another.
            let own = dot(this.points[i as usize], a);
            let (mut level, mut other) = (false, false);
            tree.any_within(&this.points[i as usize], reach, |t| {
                if t != i && this.near(t, a) {
                    let apart = (dot(this.points[t as usize], a) - own).abs() > band;
                    level |= !apart;
                    other |= apart;
                }
                level && other
            })
        })
    }

    /// Whether more than half of the peak's points `peak` pass `test`,
    /// which sees the kd-tree of the structure-like points, the point and
    /// its reach: the radius of its own neighbourhood, 2σ₁ (a disc whose
    /// in-plane deviation is σ₁ has that radius).
    fn majority(&mut self, peak: &[u32], test: impl Fn(&Self, &KdTree, u32, f64) -> bool) -> bool {
        self.build_tree();
        let this = &*self;
        let tree = this.tree.as_ref().expect("built");
        let passing = peak
            .iter()
            .filter(|&&i| {
                let reach = 2.0 * f64::from(this.shapes[i as usize].sigma[0]);
                test(this, tree, i, reach)
            })
            .count();
        2 * passing > peak.len()
    }

    /// Builds the kd-tree of the structure-like points at the first call.
    fn build_tree(&mut self) {
        if self.tree.is_none() {
            self.tree = Some(KdTree::new(self.points, Some(self.structure.to_vec())));
        }
    }
}

/// The members of each mode (module doc, step 3): a point joins the modes
/// within the cone of its axis, except those more than `margin_deg`
/// farther than its nearest mode ([`MARGIN_DEG`] for the modes: so the
/// shoulders of a large mode, local maxima made by the blurred normals
/// near its edges, do not scan its points again).
fn mode_members(
    kind: StructureKind,
    shapes: &[LocalShape],
    found: &[Mode],
    margin_deg: f64,
    off: &(dyn Fn(usize) -> bool + Sync),
) -> Vec<Vec<u32>> {
    let cos_cone = CONE_DEG.to_radians().cos();
    let margin = margin_deg.to_radians();
    // Chunks of points on the pool's threads, their lists joined in order.
    const CHUNK: usize = 1 << 13;
    let n = shapes.len();
    let per_chunk = crate::par::map_ranges(
        n.div_ceil(CHUNK),
        || vec![0.0f64; found.len()],
        |ang, c| {
            let mut member_of: Vec<Vec<u32>> = vec![Vec::new(); found.len()];
            for i in (c * CHUNK) as u32..n.min((c + 1) * CHUNK) as u32 {
                if off(i as usize) {
                    continue;
                }
                let a = axis64(&shapes[i as usize], kind);
                let mut best = f64::INFINITY;
                for (k, m) in found.iter().enumerate() {
                    ang[k] = dot(a, m.axis).abs().min(1.0).acos();
                    best = best.min(ang[k]);
                }
                for k in 0..found.len() {
                    if ang[k].cos() >= cos_cone && ang[k] <= best + margin {
                        member_of[k].push(i);
                    }
                }
            }
            member_of
        },
    );
    // Each list allocated at its length: they are held through the scan.
    (0..found.len())
        .map(|k| {
            let mut members = Vec::with_capacity(per_chunk.iter().map(|m| m[k].len()).sum());
            for m in &per_chunk {
                members.extend_from_slice(&m[k]);
            }
            members
        })
        .collect()
}

/// The scan of mode `m` over its `members`, of spacing d and noise σ
/// (module doc, step 4): its α, λ and rotations, a thick line's members
/// thinned along its direction, a thick plane at the `cloud`'s (d, σ).
#[allow(clippy::too_many_arguments)]
fn mode_scan(
    kind: StructureKind,
    points: &[[f64; 3]],
    m: Mode,
    members: Vec<u32>,
    (d, sigma): (f64, f64),
    cloud: (f64, f64),
    given: &Given,
    m2: u32,
) -> ModeScan {
    let (mut a, mut l2, mut l3) = scales(kind, d, sigma, given);
    let (mut members, mut d, mut sigma) = (members, d, sigma);
    let mut thinned_from = None;
    let mut cloud_scale = false;
    let estimated = given.alpha.is_none() && given.lambda2.is_none() && given.lambda3.is_none();
    let ball = |d: f64, sigma: f64| C_NOISE * sigma >= C_REACH * d;
    if kind == StructureKind::Lines && estimated && ball(d, sigma) {
        let step = TUBE_STEP * a;
        thinned_from = Some(members.len());
        members = thin_along(points, &members, m.axis, step, TUBE_WIDTH * a, sigma);
        d = step;
        (a, l2, l3) = scales(kind, d, sigma, given);
    } else if kind == StructureKind::Planes
        && estimated
        && ball(d, sigma)
        && !ball(cloud.0, cloud.1)
    {
        (d, sigma) = cloud;
        cloud_scale = true;
        (a, l2, l3) = scales(kind, d, sigma, given);
    }
    ModeScan {
        axis: m.axis,
        support: m.support,
        points: members,
        spacing: d,
        noise: sigma,
        alpha: a,
        lambda2: l2,
        lambda3: l3,
        rotations: mode_rotations(kind, m.axis, l2, l3, m2),
        thinned_from,
        cloud_scale,
        cover: false,
    }
}

/// The cover of the normals that no mode scans (module doc, step 7): the
/// directions of the Fibonacci sampler at [`COVER_STEP_DEG`], each a
/// mode over the points that are members of none of `modes` (and not
/// `off`), with members taken as a mode's are ([`mode_members`]: within
/// the cone of the direction, and within half the step of the nearest
/// one),
/// kept where its structure-like members reach the support a mode needs
/// (`structure_like` structure-like points in the cloud, as in
/// [`concentrated_modes`]), and scanned at their own spacing and noise
/// ([`mode_scan`], `cloud` their fallback).
#[allow(clippy::too_many_arguments)]
fn cover_scans(
    kind: StructureKind,
    points: &[[f64; 3]],
    shapes: &[LocalShape],
    modes: &[ModeScan],
    structure_like: usize,
    cloud: (f64, f64),
    given: &Given,
    m2: u32,
    off: &(dyn Fn(usize) -> bool + Sync),
) -> Vec<ModeScan> {
    let mut scanned = vec![false; shapes.len()];
    for m in modes {
        for &i in &m.points {
            scanned[i as usize] = true;
        }
    }
    let left = |i: usize| off(i) || scanned[i];
    let Ok(directions) = super::orientations::fibonacci_directions(COVER_STEP_DEG) else {
        return Vec::new();
    };
    let cover: Vec<Mode> = directions
        .into_iter()
        .map(|axis| Mode { axis, support: 0 })
        .collect();
    let members = mode_members(kind, shapes, &cover, COVER_STEP_DEG / 2.0, &left);
    let min_support = MODE_MIN_POINTS.max(structure_like / 1000);
    let like = |i: &u32| shapes[*i as usize].score(kind) >= SCORE_MIN;
    cover
        .into_iter()
        .zip(members)
        .filter_map(|(m, members)| {
            let core: Vec<u32> = members.iter().copied().filter(like).collect();
            if core.len() < min_support {
                return None;
            }
            let (d, sigma) = spacing_and_noise(kind, shapes, &core, cloud);
            let support = core.len();
            drop(core);
            let mode = Mode {
                axis: m.axis,
                support,
            };
            let scan = mode_scan(kind, points, mode, members, (d, sigma), cloud, given, m2);
            Some(ModeScan {
                cover: true,
                ..scan
            })
        })
        .collect()
}

/// The share of the points that can be structure (not `off`) that are
/// structure-like members of a mode (`members`: per mode, before a thick
/// line's thinning).
fn explained_share(
    kind: StructureKind,
    shapes: &[LocalShape],
    members: &[Vec<u32>],
    off: &dyn Fn(usize) -> bool,
) -> f64 {
    let mut member = vec![false; shapes.len()];
    for m in members {
        for &i in m {
            member[i as usize] = shapes[i as usize].score(kind) >= SCORE_MIN;
        }
    }
    let candidates = (0..shapes.len()).filter(|&i| !off(i)).count();
    let explained = member.iter().filter(|&&m| m).count();
    explained as f64 / candidates.max(1) as f64
}

/// The parameters α, λ₂, λ₃ as a ladder run reports them: α the largest
/// level's, with every level in the reason.
fn ladder_params(
    kind: StructureKind,
    l: &Ladder,
    (explained, structured): (f64, f64),
    d: f64,
) -> (Param, Param, Param) {
    let alphas: Vec<String> = l.alphas.iter().map(|a| format!("{a:.4}")).collect();
    let why = format!(
        "scale ladder: the modes of the local {}s explain {:.0}% of {} (under {:.0}%; {:.0}% \
         are locally {}), so each structure takes the most significant of alpha = {} (reach \
         {C_REACH}·{d:.4}·2^(j/2 - 2), d the median spacing) with lambda {}",
        match kind {
            StructureKind::Planes => "normal",
            StructureKind::Lines => "direction",
        },
        100.0 * explained,
        kind.counted_points(),
        100.0 * EXPLAINED_MIN,
        100.0 * structured,
        kind.locally(),
        alphas.join(", "),
        l.lambda
    );
    let param = |value: f64| Param {
        value,
        estimated: true,
        reason: why.clone(),
    };
    let top = l.alphas.iter().copied().fold(0.0, f64::max);
    let l2 = match kind {
        StructureKind::Planes => l.lambda,
        StructureKind::Lines => 1.0,
    };
    (param(top), param(l2), param(l.lambda))
}

/// The ladder of a cloud of median nearest-neighbour distance `d` over
/// `points` (module doc, step 6).
fn ladder(d: f64, points: Vec<u32>) -> Ladder {
    let lambda = LAMBDA_MAX;
    Ladder {
        alphas: LADDER_LEVELS
            .iter()
            .map(|l| C_REACH * d * l / lambda)
            .collect(),
        lambda,
        step_deg: LADDER_STEP_DEG,
        points,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thick_plane_mode_is_scanned_at_the_cloud_s_scale() {
        let m = Mode {
            axis: [0.0, 0.0, 1.0],
            support: 100,
        };
        let pts = [[0.0; 3]; 4];
        let scan = |own: (f64, f64), cloud: (f64, f64), given: &Given| {
            mode_scan(
                StructureKind::Planes,
                &pts,
                m,
                vec![0, 1, 2, 3],
                own,
                cloud,
                given,
                1,
            )
        };
        let given = Given::default();
        // The mode's own σ = d: 3σ over the reach 2d, λ would be 1.
        let own = (0.5, 0.5);
        let cloud = (0.4, 0.01);
        let s = scan(own, cloud, &given);
        assert!(s.cloud_scale);
        assert_eq!((s.spacing, s.noise), cloud);
        let (a, l2, l3) = scales(StructureKind::Planes, cloud.0, cloud.1, &given);
        assert_eq!((s.alpha, s.lambda2, s.lambda3), (a, l2, l3));
        assert!(s.lambda2 > 1.0);
        assert_eq!(s.points.len(), 4);
        // A cloud as thick as the mode: the mode keeps its own ball.
        let s = scan(own, (0.4, 0.4), &given);
        assert!(!s.cloud_scale);
        assert_eq!((s.spacing, s.noise, s.lambda2), (0.5, 0.5, 1.0));
        // A thin mode keeps its own scale; a given α keeps the mode's own.
        let s = scan((0.5, 0.01), cloud, &given);
        assert!(!s.cloud_scale && s.spacing == 0.5);
        let alpha = Given {
            alpha: Some(1.0),
            ..Given::default()
        };
        let s = scan(own, cloud, &alpha);
        assert!(!s.cloud_scale && s.alpha == 1.0);
    }

    #[test]
    fn thin_along_keeps_one_chain_per_tube() {
        // Two vertical tubes of radius 0.1, 2 apart, 10 long, sampled
        // densely (rings of 12 points every 0.02).
        let mut pts = Vec::new();
        for x0 in [0.0, 2.0] {
            for k in 0..500 {
                for j in 0..12 {
                    let t = j as f64 * std::f64::consts::TAU / 12.0 + k as f64 * 0.1;
                    pts.push([x0 + 0.1 * t.cos(), 0.1 * t.sin(), k as f64 * 0.02]);
                }
            }
        }
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        let (step, width) = (0.2, 0.4);
        let kept = thin_along(&pts, &ids, [0.0, 0.0, 1.0], step, width, 0.07);
        for x0 in [0.0, 2.0] {
            let mut z: Vec<f64> = kept
                .iter()
                .map(|&i| pts[i as usize])
                .filter(|p| (p[0] - x0).abs() < 0.5)
                .map(|p| p[2])
                .collect();
            z.sort_by(f64::total_cmp);
            // One chain: consecutive kept points at least a step apart
            // along the tube and at most two steps (a point is only
            // excluded by a kept one within a step).
            assert!(z.len() >= 25 && z.len() <= 51, "{} kept", z.len());
            for w in z.windows(2) {
                assert!(w[1] - w[0] >= step - 1e-12, "{w:?}");
                assert!(w[1] - w[0] <= 2.0 * step + 0.02, "{w:?}");
            }
        }
        // Ascending, a subset.
        assert!(kept.windows(2).all(|w| w[0] < w[1]));
        // A width over the gap between the tubes makes their points
        // exclude each other: fewer are kept.
        let wide = thin_along(&pts, &ids, [0.0, 0.0, 1.0], step, 2.5, 0.07);
        assert!(wide.len() < kept.len());
    }

    #[test]
    fn thin_along_keeps_a_tube_scanned_all_around_on_one_side() {
        // A vertical tube of radius 0.1 sampled all around (rings of 31
        // points every 0.02, each ring turned by a pseudo-random angle, 1 cm
        // of radial noise): every point of a ring is as far from its
        // centroid as the others, so without the shift the kept points lie
        // anywhere around the rings.
        let mut rng = crate::rng::SplitMix64::new(5);
        let mut pts = Vec::new();
        for k in 0..300 {
            let turn = rng.uniform() * std::f64::consts::TAU;
            for j in 0..31 {
                let t = turn + j as f64 * std::f64::consts::TAU / 31.0;
                let r = 0.1 + 0.01 * (rng.uniform() - 0.5);
                pts.push([r * t.cos(), r * t.sin(), k as f64 * 0.02]);
            }
        }
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        // The spread across the axis of the kept points.
        let spread = |kept: &[u32]| {
            let n = kept.len() as f64;
            let c = kept.iter().fold([0.0; 2], |c, &i| {
                let p = pts[i as usize];
                [c[0] + p[0] / n, c[1] + p[1] / n]
            });
            let v = kept.iter().fold(0.0, |v, &i| {
                let p = pts[i as usize];
                v + ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)) / n
            });
            v.sqrt()
        };
        let (step, width) = (0.56, 1.1);
        let sigma = 0.07;
        let one_side = thin_along(&pts, &ids, [0.0, 0.0, 1.0], step, width, sigma);
        let around = thin_along(&pts, &ids, [0.0, 0.0, 1.0], step, width, 0.0);
        assert!(one_side.len() >= 5, "{} kept", one_side.len());
        assert!(spread(&one_side) < 0.02, "{}", spread(&one_side));
        assert!(spread(&around) > 0.05, "{}", spread(&around));
    }
}
