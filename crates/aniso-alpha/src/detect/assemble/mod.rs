//! Assembling structures from the union of the scanned anisotropic
//! α-shapes (paper §4.3, last steps; method doc §4 and §7).
//!
//! 1. **Candidates.** Each connected component of the cleaned union is
//!    split into straight or flat pieces ([`super::parts`]); the piece
//!    fits, and the fit of the whole component, are candidate primitives.
//!    Greedily, the candidate covering the most not yet covered vertices of
//!    the component within τ (the ellipsoid's short semi-axis α, so a
//!    detected structure's points lie inside it) is refitted on its inliers
//!    and taken, until none covers `min_vertices` new ones.
//! 2. **Support.** A candidate's *footprint* is the set of cells (side c,
//!    the ellipsoid's long reach α·λ) that its vertices occupy on its plane
//!    (or along its line), grown by one cell: the region the scanned
//!    α-shapes covered.
//! 3. **Members.** Every point within τ of the primitive whose projection
//!    falls in the footprint claims the candidate (the α-shape's simplices
//!    reach the structure's points; points of a noisy structure that no
//!    simplex touched are recovered here). A point claimed by several
//!    candidates goes to the one it is nearest to: parts are disjoint.
//!    Candidates that are one plane or one line (within the part angle,
//!    and most of the smaller one's points within τ of the larger one's
//!    primitive) and that share claimed points are merged first, so a
//!    plane is never reported twice. Members are refitted once and claimed again.
//! 4. **Significance.** With a test enabled, each part's number of false
//!    alarms is computed ([`super::significance`]) and parts above ε go.
//! 5. **Structures.** Parts that share claimed points (where two facets
//!    meet) and do not cross each other (crossing lines, planes cutting
//!    through each other, a T-junction) are facets of one structure.
//!    Structures are numbered by size (points), largest first, parts
//!    likewise within each, and each planar part gets its outline and mesh
//!    ([`super::outline`]), each straight part its segment.

use super::detection::{first_occurrences, Detection, Part, Primitive, RunStats, Structure};
use super::filter::{components, FilterError};
use super::fit::{fit_line, fit_plane_indices};
use super::outline::outline;
use super::scan::Face;
use super::significance::{log10_n_tests, part_log10_nfa};
use super::StructureKind;
use crate::geometry::kdtree::KdTree;
use crate::geometry::{dot, sub};
use crate::par::map_ranges;
use crate::unionfind::UnionFind;

/// The scale of the candidates found by one group (mode) of orientations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Scale {
    /// Inlier distance τ (the α of the group's orientations).
    pub tau: f64,
    /// Footprint cell c (the ellipsoid's long reach α·λ).
    pub cell: f64,
}

/// Settings of the assembly.
#[derive(Debug, Clone)]
pub(crate) struct Settings<'n> {
    /// Lines or planes.
    pub kind: StructureKind,
    /// Angle tolerance (degrees) of straight/flat pieces and of merging.
    pub part_angle_deg: f64,
    /// Fewest points of a part.
    pub min_vertices: usize,
    /// Per group.
    pub scales: Vec<Scale>,
    /// log₁₀ ε of the significance test, or `None` for no test.
    pub log10_epsilon: Option<f64>,
    /// Whether a noisy plane's claim radius may widen (step 2b): with the
    /// data's orientations, whose α is the median noise of the cloud.
    pub widen_planes: bool,
    /// Unit normals given with the points (zero where missing): a point
    /// claims a plane only if |n_p · n| ≥ [`NORMAL_AGREEMENT_COS`]; lines
    /// ignore them ([`normal_agreement`]).
    pub normals: Option<&'n [[f32; 3]]>,
}

/// With normals given, a point joins a plane only if |n_p · n| is at least
/// this: 0.8, an angle of 36.9°. It is the default `normal_threshold` of
/// Easy3D's and PolyFit's Efficient RANSAC (Schnabel et al. 2007);
/// CGAL's implementation defaults to 0.9 (25.8°).
///
/// The test only needs to keep out surfaces that run across the plane
/// within its claim radius: window frames, ledges, the edges of walls, all
/// at 60–90°. The looser of the two defaults keeps the points of noisy
/// planes. On CGAL's building scan, whose labels were made with the
/// scan's normals, 10% of each noisy wall's labelled points have normals
/// 20–28° or more off their plane, up to 37–41°.
///
/// Measured on that scan (its own normals): F1 0.907 at 0.8, 0.891 at 0.9.
/// The labels follow 0.8 too, so this choice suits that scan's labelling
/// rule (docs/method.md §4).
pub(crate) const NORMAL_AGREEMENT_COS: f64 = 0.8;

/// Relative share of a part's vertices on each side of another part's
/// primitive for that primitive to cross it: 1/5.
const CROSS_SHARE: usize = 5;

/// Along a line, points within this fraction of the line's extent of the
/// crossing point count as on neither side.
const CROSS_LINE_MARGIN: f64 = 0.05;

/// Floor of a plane's side tolerance in [`crosses`], relative to the sum
/// of the plane's two extents: with a zero RMS residual (exactly planar
/// points) the points of B within rounding of the plane still count as on
/// neither side.
const CROSS_PLANE_SLACK: f64 = 1e-9;

/// Whether point i's given normal lets it join `fit`: true without
/// normals, for a point whose normal is missing (zero), and for anything
/// but a plane; otherwise |n_i · n| ≥ [`NORMAL_AGREEMENT_COS`].
fn normal_agreement<'a>(
    fit: &Primitive,
    normals: Option<&'a [[f32; 3]]>,
) -> impl Fn(u32) -> bool + 'a {
    let plane = match (fit, normals) {
        (Primitive::Plane(f), Some(n)) => Some((f.normal, n)),
        _ => None,
    };
    let cos = NORMAL_AGREEMENT_COS;
    move |i| {
        plane.is_none_or(|(p, normals)| {
            let n = normals[i as usize];
            n == [0.0; 3]
                || (f64::from(n[0]) * p[0] + f64::from(n[1]) * p[1] + f64::from(n[2]) * p[2]).abs()
                    >= cos
        })
    }
}

/// A part's outline polygon (a segment's two ends) and its mesh.
type PartShape = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Ratio of the outer to the inner radius of the shell in which the local
/// background density around a part is measured.
const SHELL_RATIO: f64 = 4.0;

/// The path filter's nb_c in the scan of each orientation (docs/method.md
/// §4). Without the significance test it is the user's nb_c (the paper).
/// With it, for lines, at most [`LINE_SCAN_MIN`]: a line whose points are
/// jittered by about the ellipsoid's radius, or crowded by background
/// points that hang spurs on it, reaches one orientation's filter in
/// pieces of two or three edges, which nb_c = 4 deletes in every
/// orientation (issue 14: recall 0.3–0.5 at σ = 0.1 d, 0.6–0.7 at 10×
/// the background). The pieces are joined along their fitted line by the
/// claims, and the significance test, not nb_c, decides what chance
/// explains. Planes keep nb_c: a plane's α-shape stays in one piece under
/// the same jitter (its triangles span two directions), and the scan's
/// cost grows with what the filter lets through.
pub(crate) fn scan_min_size(
    kind: StructureKind,
    nb_c: u32,
    significance: bool,
    chance: ChanceScale,
) -> u32 {
    if kind != StructureKind::Lines || !significance {
        return nb_c;
    }
    // Chance paths of l edges per orientation: about n·x^l, x the
    // background points per α-ellipsoid (each further edge needs a point
    // in the next ellipsoid along); over the scan, times the orientations.
    // The shortest l with at most CHANCE_PATHS of them over the scan.
    let x = chance.per_ellipsoid.clamp(1e-12, 1.0);
    let mut l = LINE_SCAN_MIN;
    while l < nb_c && chance.points * chance.orientations * x.powi(l as i32) > CHANCE_PATHS {
        l += 1;
    }
    l.min(nb_c)
}

/// For lines under the significance test, the straightness at which the
/// scan's path filter follows a chain through a ramification
/// (`scan::straight_filter`): the cosine c of the largest turn allowed.
/// Two edges of chance meet in a straight-enough continuation with
/// probability (1 − c)/2 (directions uniform on the sphere); a chance
/// continuation needs a background point in the next ellipsoid too, so
/// chance chains grow by about x·(1 − c)/2 per vertex, x the background
/// points per α-ellipsoid. c is the smallest cosine keeping that at most
/// [`CHANCE_CONTINUATION`], within [`STRAIGHT_COS_RANGE`]: at the paper's
/// density (x = 0.01) turns up to 60° are followed (a line jittered by
/// about α zigzags), at 10× (x = 0.1) up to 18° (background fans hang on
/// every line). `None` (the paper's filter) for planes, without the test,
/// and with the orientations from the data (`from_data`): the automatic
/// mode is for real scans, whose background is not uniform, and there the
/// scanner's rows (straight chains of points across every surface, one
/// angular step apart) would be followed too (measured on the simulated
/// street: 199 → 569 parts, precision 0.47 → 0.21, even at a 8° turn).
pub(crate) fn straight_cos(
    kind: StructureKind,
    significance: bool,
    from_data: bool,
    chance: ChanceScale,
) -> Option<f64> {
    if kind != StructureKind::Lines || !significance || from_data {
        return None;
    }
    let x = chance.per_ellipsoid.max(1e-12);
    let (lo, hi) = STRAIGHT_COS_RANGE;
    Some((1.0 - 2.0 * CHANCE_CONTINUATION / x).clamp(lo, hi))
}

/// The chance continuations per vertex that the straight filter may
/// follow: 1 in 400. Measured on the issue-14 line scenes (10 seeds,
/// scripts/eval_robustness.py), a fixed cosine trades one variant for the
/// other (F1 at 10× background / at jitter 0.1 d: cos 15° 0.90 / 0.85,
/// cos 30° 0.87 / 0.89, cos 60° 0.66 / 0.90); this constant puts each
/// density at the end of the range that suits it (x = 0.01: cos 60°;
/// x = 0.1: cos 18°).
const CHANCE_CONTINUATION: f64 = 0.0025;

/// The range of the straight filter's cosine: turns of 15° to 60°. Past
/// 60° a "continuation" is no longer straight (two edges of a zigzag
/// through three random points); under 15° the orientation scan's own
/// misalignment (about half the sampler's step) bends a true line's
/// edges in the metric.
const STRAIGHT_COS_RANGE: (f64, f64) = (0.5, 0.966);

/// What the scan's threshold depends on: the cloud's size, the number of
/// orientations and the background points per α-ellipsoid (the cloud's
/// points over its bounding box's volume, times the ellipsoid's volume).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ChanceScale {
    /// Points.
    pub points: f64,
    /// Orientations scanned.
    pub orientations: f64,
    /// Expected points per α-ellipsoid under a uniform background.
    pub per_ellipsoid: f64,
}

impl ChanceScale {
    /// Measured on `points` for the ellipsoid of radius `alpha` and
    /// semi-axes `alpha/e_i` (`elongation` e).
    pub(crate) fn measure(
        points: &[[f64; 3]],
        alpha: f64,
        elongation: [f64; 3],
        orientations: usize,
    ) -> Self {
        let (lo, hi) = crate::geometry::bounding_box(points);
        let volume: f64 = (0..3).map(|k| (hi[k] - lo[k]).max(1e-300)).product();
        let ellipsoid = 4.0 / 3.0 * std::f64::consts::PI * alpha.powi(3)
            / (elongation[0] * elongation[1] * elongation[2]);
        // Distinct points (copies are one point to the scan; −0.0 is 0.0).
        let n = super::detection::distinct_count(points) as f64;
        ChanceScale {
            points: n,
            orientations: orientations as f64,
            per_ellipsoid: n / volume * ellipsoid,
        }
    }
}

/// Chance paths the line scan may let through to the assembly: 100. At
/// the paper's density (0.01 points per ellipsoid, 1,550 points, 162
/// orientations) paths of two edges number about 25, so the scan keeps
/// them; at 3× the density three edges, at 10× the user's nb_c. Beyond a
/// few hundred chance paths the union's components merge into a web
/// that the assembly cannot take apart into lines (measured at 10×: 188,000
/// union edges with two-edge paths, no line found).
const CHANCE_PATHS: f64 = 100.0;

/// The shortest path the line scan keeps under the significance test: two
/// edges, three points, the fewest whose straightness says anything
/// (two points always lie on a line).
const LINE_SCAN_MIN: u32 = 2;

/// Length of the segment that `members` span along the line `fit` (at
/// least one ten-millionth of nothing: 0 when not a line).
fn line_span(fit: &Primitive, members: &[u32], points: &[[f64; 3]]) -> f64 {
    let Primitive::Line(f) = fit else { return 0.0 };
    let (mut t0, mut t1) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in members {
        let t = dot(sub(points[v as usize], f.centroid), f.direction);
        t0 = t0.min(t);
        t1 = t1.max(t);
    }
    (t1 - t0).max(0.0)
}

/// Claim radii tried for a line candidate, in units of α (its τ): a line
/// whose points are jittered by σ per coordinate has its distances to the
/// line Rayleigh-distributed, 99% within 3.03σ; radii up to 3α keep such a
/// line whole for σ up to α, the scale at which the paper's ellipsoid
/// itself stops joining its points.
const CLAIM_RADII: [f64; 3] = [1.0, 2.0, 3.0];

/// log₁₀ of the factor by which a wider claim radius must lower a
/// candidate's NFA to be preferred: 10×, so that a structure that is as
/// significant in the thin tube keeps it (and the background points a
/// wider tube would claim stay out).
const WIDEN_GAIN: f64 = 1.0;

/// The most background points, expected under the measured global
/// density, that widening a line's claim tube may add: one. Past it (about
/// 3× the paper's density for a 3α tube along a 63-unit line) the claims
/// stay at α, as in the paper: a wider tube would buy the recall of a
/// noisy line with the precision of every line.
const MAX_WIDEN_BACKGROUND: f64 = 1.0;

/// A candidate part while it is assembled.
#[derive(Debug, Clone)]
struct Cand {
    fit: Primitive,
    tau: f64,
    cell: f64,
    seeds: Vec<u32>,
    foot: Footprint,
}

/// The cells a candidate covers on its plane (2D) or along its line (1D).
#[derive(Debug, Clone)]
struct Footprint {
    origin: [f64; 3],
    axes: [[f64; 3]; 2],
    cell: f64,
    lo: [i64; 2],
    dims: [usize; 2],
    bits: Vec<bool>,
}

/// Largest number of cells of one footprint; beyond it the cell is
/// doubled (a coarser footprint, never a failure).
const MAX_CELLS: usize = 1 << 24;

impl Footprint {
    fn frame(fit: &Primitive) -> Option<([f64; 3], [[f64; 3]; 2], bool)> {
        match fit {
            Primitive::Plane(f) => Some((f.centroid, f.axes, true)),
            Primitive::Line(f) => Some((f.centroid, [f.direction, [0.0; 3]], false)),
            Primitive::None => None,
        }
    }

    fn coords(&self, p: &[f64; 3]) -> [i64; 2] {
        let w = sub(*p, self.origin);
        [
            (dot(w, self.axes[0]) / self.cell).floor() as i64,
            (dot(w, self.axes[1]) / self.cell).floor() as i64,
        ]
    }

    fn new(fit: &Primitive, points: &[[f64; 3]], seeds: &[u32], cell: f64) -> Option<Self> {
        let (origin, axes, _) = Self::frame(fit)?;
        let mut cell = cell;
        loop {
            let mut f = Footprint {
                origin,
                axes,
                cell,
                lo: [0; 2],
                dims: [0; 2],
                bits: Vec::new(),
            };
            let cs: Vec<[i64; 2]> = seeds
                .iter()
                .map(|&v| f.coords(&points[v as usize]))
                .collect();
            if cs.is_empty() {
                return None;
            }
            let mut lo = [i64::MAX; 2];
            let mut hi = [i64::MIN; 2];
            for c in &cs {
                for k in 0..2 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
            // One cell of margin for the dilation.
            let lo = [lo[0] - 1, lo[1] - 1];
            let dims = [(hi[0] + 2 - lo[0]) as usize, (hi[1] + 2 - lo[1]) as usize];
            if dims[0].saturating_mul(dims[1]) > MAX_CELLS {
                cell *= 2.0;
                continue;
            }
            let mut marked = vec![false; dims[0] * dims[1]];
            for c in &cs {
                marked[(c[0] - lo[0]) as usize * dims[1] + (c[1] - lo[1]) as usize] = true;
            }
            // Dilate by one cell (8-neighbourhood; along a line, 2).
            let mut bits = marked.clone();
            for i in 0..dims[0] {
                for j in 0..dims[1] {
                    if !marked[i * dims[1] + j] {
                        continue;
                    }
                    for di in -1i64..=1 {
                        for dj in -1i64..=1 {
                            let (a, b) = (i as i64 + di, j as i64 + dj);
                            if a >= 0 && b >= 0 && (a as usize) < dims[0] && (b as usize) < dims[1]
                            {
                                bits[a as usize * dims[1] + b as usize] = true;
                            }
                        }
                    }
                }
            }
            f.lo = lo;
            f.dims = dims;
            f.bits = bits;
            return Some(f);
        }
    }

    fn contains(&self, p: &[f64; 3]) -> bool {
        let c = self.coords(p);
        let (a, b) = (c[0] - self.lo[0], c[1] - self.lo[1]);
        a >= 0
            && b >= 0
            && (a as usize) < self.dims[0]
            && (b as usize) < self.dims[1]
            && self.bits[a as usize * self.dims[1] + b as usize]
    }

    /// Number of covered cells.
    fn count(&self) -> usize {
        self.bits.iter().filter(|&&b| b).count()
    }

    /// Blocks of `b` × `b` cells (`b` along a line) holding a covered
    /// cell: each block's centre (3D, on the primitive) and the distance
    /// from it to the block's farthest corner, along the primitive.
    fn blocks(&self, b: usize) -> impl Iterator<Item = ([f64; 3], f64)> + '_ {
        let planar = self.axes[1] != [0.0; 3];
        let bj = if planar { b } else { self.dims[1] };
        (0..self.dims[0]).step_by(b).flat_map(move |i0| {
            (0..self.dims[1]).step_by(bj).filter_map(move |j0| {
                let (i1, j1) = ((i0 + b).min(self.dims[0]), (j0 + bj).min(self.dims[1]));
                let any = (i0..i1).any(|i| (j0..j1).any(|j| self.bits[i * self.dims[1] + j]));
                if !any {
                    return None;
                }
                let u = (self.lo[0] + i0 as i64) as f64 + 0.5 * (i1 - i0) as f64;
                let v = (self.lo[1] + j0 as i64) as f64 + 0.5 * (j1 - j0) as f64;
                let centre = [0, 1, 2].map(|k| {
                    self.origin[k] + self.cell * (u * self.axes[0][k] + v * self.axes[1][k])
                });
                let (hu, hv) = (0.5 * (i1 - i0) as f64, 0.5 * (j1 - j0) as f64);
                let half = if planar {
                    self.cell * (hu * hu + hv * hv).sqrt()
                } else {
                    self.cell * hu
                };
                Some((centre, half))
            })
        })
    }
}

/// Per-point marks that tell whether a query already reported a point,
/// without clearing between queries.
struct Stamps {
    v: Vec<u32>,
    mark: u32,
}

impl Stamps {
    fn new(n: usize) -> Self {
        Stamps {
            v: vec![0; n],
            mark: 0,
        }
    }
    fn next(&mut self) -> u32 {
        if self.mark == u32::MAX {
            self.v.iter_mut().for_each(|x| *x = 0);
            self.mark = 0;
        }
        self.mark += 1;
        self.mark
    }
}

/// Calls `f(point, distance)` for every indexed point within `radius` of
/// the primitive and in the footprint (each once).
fn for_near(
    c: &Cand,
    radius: f64,
    points: &[[f64; 3]],
    index: &KdTree,
    stamps: &mut Stamps,
    f: &mut dyn FnMut(u32, f64),
) {
    let mark = stamps.next();
    let stamp = &mut stamps.v;
    // One ball per block of cells about 2·radius wide (one cell while the
    // radius is under half a cell): with a radius many cells wide, a ball
    // per cell would visit each point once per cell within its reach.
    let b = ((2.0 * radius / c.foot.cell).ceil() as usize).max(1);
    for (centre, half) in c.foot.blocks(b) {
        let r = (half * half + radius * radius).sqrt();
        index.within(&centre, r, |i| {
            if stamp[i as usize] == mark {
                return;
            }
            let p = &points[i as usize];
            let d = c.fit.distance(p);
            if d <= radius && c.foot.contains(p) {
                stamp[i as usize] = mark;
                f(i, d);
            }
        });
    }
}

/// Whether the primitive `fit` (of part A) passes through the interior of
/// part B (its points `b`): B has at least 1/[`CROSS_SHARE`] of its points
/// strictly on each side. For a plane, the sides of the plane (beyond
/// 3·RMS); for a line, the two sides of the point of B's line closest to
/// it, along B's direction.
fn crosses(fit: &Primitive, b: &[u32], points: &[[f64; 3]]) -> bool {
    if b.len() < 4 {
        return false;
    }
    let side = |d: f64, tol: f64| {
        if d > tol {
            1
        } else if d < -tol {
            2
        } else {
            0
        }
    };
    let (pos, neg) = match fit {
        Primitive::Plane(pf) => {
            let tol = 3.0 * pf.rms_residual + CROSS_PLANE_SLACK * (pf.extent[0] + pf.extent[1]);
            let mut c = (0, 0);
            for &v in b {
                match side(dot(sub(points[v as usize], pf.centroid), pf.normal), tol) {
                    1 => c.0 += 1,
                    2 => c.1 += 1,
                    _ => {}
                }
            }
            c
        }
        Primitive::Line(la) => {
            let bv: Vec<[f64; 3]> = b.iter().map(|&v| points[v as usize]).collect();
            let Ok(lb) = fit_line(&bv) else {
                return false;
            };
            let w = sub(lb.centroid, la.centroid);
            let (u, v) = (la.direction, lb.direction);
            let (a_, b_, c_) = (dot(u, u), dot(u, v), dot(v, v));
            let (d_, e_) = (dot(u, w), dot(v, w));
            let den = a_ * c_ - b_ * b_;
            if den.abs() < 1e-12 {
                return false; // parallel: no crossing
            }
            let t = (b_ * d_ - a_ * e_) / den; // parameter along B
            let tol = CROSS_LINE_MARGIN * lb.extent.max(1e-12);
            let mut c = (0, 0);
            for p in &bv {
                match side(dot(sub(*p, lb.centroid), v) - t, tol) {
                    1 => c.0 += 1,
                    2 => c.1 += 1,
                    _ => {}
                }
            }
            c
        }
        Primitive::None => return false,
    };
    usize::min(pos, neg) * CROSS_SHARE >= b.len()
}

/// Share of the smaller candidate's seeds that must lie within τ of the
/// larger one's primitive for the two to be one.
const SAME_SHARE: f64 = 0.8;

/// Whether two candidates are one primitive: their planes (lines) are
/// within the part angle of each other, and either each one's centroid
/// lies within τ of the other's primitive or most of the smaller one's
/// seeds lie within τ of the larger one's primitive. (The second test
/// catches a strip along the edge of a plane, found by another mode: it
/// fits a plane tilted across the strip, whose offset at the other's
/// centroid says nothing.)
/// What [`same_primitive`] looks at of a candidate or a part: its
/// primitive, its claim radius τ and its points.
#[derive(Clone, Copy)]
struct Piece<'a> {
    fit: &'a Primitive,
    tau: f64,
    seeds: &'a [u32],
}

impl Cand {
    fn piece(&self) -> Piece<'_> {
        Piece {
            fit: &self.fit,
            tau: self.tau,
            seeds: &self.seeds,
        }
    }
}

fn same_primitive(a: Piece, b: Piece, angle_deg: f64, points: &[[f64; 3]]) -> bool {
    // Two pieces of one noisy line: their own fits can be tens of degrees
    // apart (three points jittered by σ ≈ α over two steps), but the line
    // fitted to both keeps most of their seeds within the claim radius.
    // Lines crossing at an angle, or the two legs of a polyline, leave
    // one piece's far points outside it.
    if let (Primitive::Line(_), Primitive::Line(_)) = (a.fit, b.fit) {
        let joint: Vec<[f64; 3]> = a
            .seeds
            .iter()
            .chain(b.seeds)
            .map(|&v| points[v as usize])
            .collect();
        if let Ok(f) = fit_line(&joint) {
            let tau = a.tau.max(b.tau);
            let within = |seeds: &[u32]| {
                seeds
                    .iter()
                    .filter(|&&v| {
                        let w = sub(points[v as usize], f.centroid);
                        let t = dot(w, f.direction);
                        (dot(w, w) - t * t).max(0.0).sqrt() <= tau
                    })
                    .count() as f64
                    >= SAME_SHARE * seeds.len() as f64
            };
            if within(a.seeds) && within(b.seeds) {
                return true;
            }
        }
    }
    let cos = angle_deg.to_radians().cos();
    let parallel = match (a.fit, b.fit) {
        (Primitive::Plane(fa), Primitive::Plane(fb)) => dot(fa.normal, fb.normal).abs() >= cos,
        (Primitive::Line(fa), Primitive::Line(fb)) => dot(fa.direction, fb.direction).abs() >= cos,
        _ => false,
    };
    if !parallel {
        return false;
    }
    let centroid = |f: &Primitive| match f {
        Primitive::Plane(p) => p.centroid,
        Primitive::Line(l) => l.centroid,
        Primitive::None => [f64::NAN; 3],
    };
    if a.fit.distance(&centroid(b.fit)) <= a.tau && b.fit.distance(&centroid(a.fit)) <= b.tau {
        return true;
    }
    let (big, small) = if a.seeds.len() >= b.seeds.len() {
        (a, b)
    } else {
        (b, a)
    };
    let near = small
        .seeds
        .iter()
        .filter(|&&v| big.fit.distance(&points[v as usize]) <= big.tau)
        .count();
    near as f64 >= SAME_SHARE * small.seeds.len() as f64
}

/// The volume within distance t of a primitive, as a function of t: a
/// slab 2t thick over a plane's area, a tube of radius t along a line's
/// length. A plane's area: the footprint's cells (of side `cell`), which
/// its members cover grown by one (generous: the region the scan could
/// have found it in). A line's length: the span of its members (a line's
/// footprint is one row of cells; its dilation also marks the rows beside
/// it, which tripled the length before).
fn near_volume(
    fit: &Primitive,
    foot: &Footprint,
    cell: f64,
    members: &[u32],
    points: &[[f64; 3]],
) -> impl Fn(f64) -> f64 {
    let planar = matches!(fit, Primitive::Plane(_));
    let extent = if planar {
        foot.count() as f64 * cell * cell
    } else {
        line_span(fit, members, points)
    };
    move |t: f64| {
        if planar {
            2.0 * t * extent
        } else {
            std::f64::consts::PI * t * t * extent
        }
    }
}

/// Whether two parallel planar pieces that lie apart are one plane seen
/// in two places: the plane fitted to both keeps, for each piece, at least
/// [`SAME_SHARE`] of the points its own plane keeps within τ. Two pieces
/// of one wall fitted apart can tilt by a degree or so each (noise, a
/// slight bow of the wall), so that either one's plane, carried over the
/// gap, misses the other by more than τ; the joint plane passes through
/// both. Two distinct parallel planes (a façade and a wall set back from
/// it by more than τ) leave about half of each piece outside the joint
/// plane, which lies between them.
fn joint_plane_keeps(a: Piece, b: Piece, angle_deg: f64, points: &[[f64; 3]]) -> bool {
    let joint: Vec<u32> = a.seeds.iter().chain(b.seeds).copied().collect();
    let Ok(f) = fit_plane_indices(points, &joint) else {
        return false;
    };
    // The joint plane must be parallel to both pieces: two small patches
    // at different heights (the floors of two storeys) are both kept by
    // the plane tilted through them.
    let cos = angle_deg.to_radians().cos();
    let parallel = |p: &Piece| match p.fit {
        Primitive::Plane(q) => dot(q.normal, f.normal).abs() >= cos,
        _ => false,
    };
    if !(parallel(&a) && parallel(&b)) {
        return false;
    }
    let joint_fit = Primitive::Plane(f);
    let tau = a.tau.max(b.tau);
    [a, b].iter().all(|p| {
        let (mut own, mut kept) = (0usize, 0usize);
        for &v in p.seeds {
            let q = &points[v as usize];
            own += usize::from(p.fit.distance(q) <= p.tau);
            kept += usize::from(joint_fit.distance(q) <= tau);
        }
        own > 0 && kept as f64 >= SAME_SHARE * own as f64
    })
}

/// Greedy extraction of straight/flat primitives from one connected
/// component (step 1 of the module doc): their inlier vertices and fits.
fn extract<S: Face>(
    points: &[[f64; 3]],
    local: &[S],
    tol: f64,
    min_vertices: usize,
    angle: f64,
) -> Vec<(Vec<u32>, Primitive)> {
    let mut out = Vec::new();
    let mut verts: Vec<u32> = local.iter().flat_map(|s| s.as_ref().to_vec()).collect();
    verts.sort_unstable();
    verts.dedup();
    if verts.len() < min_vertices {
        return out;
    }
    // Pieces of like-oriented simplices (a failure, which needs a NaN
    // point, leaves the component in one piece).
    let part = S::parts(points, local, angle).unwrap_or_else(|_| vec![0; local.len()]);
    let n_parts = part.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    let mut pv: Vec<Vec<u32>> = vec![Vec::new(); n_parts];
    for (s, &p) in local.iter().zip(&part) {
        pv[p as usize].extend_from_slice(s.as_ref());
    }
    // Candidates: pieces with at least two simplices' worth of points,
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
                .filter(|(&v, &cov)| !cov && c.distance(&points[v as usize]) <= tol)
                .count();
            if best.is_none_or(|b| new > b.0) {
                best = Some((new, ci));
            }
        }
        let Some((new, ci)) = best else { break };
        if new < min_vertices {
            break;
        }
        let mut fit = cands.swap_remove(ci);
        let inliers = |fit: &Primitive| -> Vec<u32> {
            verts
                .iter()
                .copied()
                .filter(|&v| fit.distance(&points[v as usize]) <= tol)
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
        out.push((inl, fit));
    }
    out
}

/// Everything the assembly produces besides the [`Detection`] itself.
pub(crate) struct Assembled {
    pub detection: Detection,
}

/// The assembly (module doc) of the cleaned union `kept`, whose simplices
/// were found by the groups `group`.
pub(crate) fn assemble<S: Face>(
    points: &[[f64; 3]],
    kept: Vec<S>,
    group: Vec<u32>,
    settings: &Settings<'_>,
    mut stats: RunStats,
) -> Result<Assembled, FilterError> {
    let n = points.len();
    let first = first_occurrences(points);
    let firsts: Vec<u32> = (0..n as u32).filter(|&i| first[i as usize] == i).collect();
    let index = KdTree::new(points, Some(firsts.clone()));
    // 1. Candidates, component by component within each group (the
    // simplices found by one mode's orientations), at that group's scale:
    // a component of the whole union can join a noisy wall (large α) to a
    // clean roof (small α) along their common edge.
    let n_groups = settings.scales.len();
    let mut by_group: Vec<Vec<u32>> = vec![Vec::new(); n_groups];
    for (s, &g) in group.iter().enumerate() {
        by_group[g as usize].push(s as u32);
    }
    let mut comp_simplices: Vec<(u32, Vec<u32>)> = Vec::new();
    for (g, ss) in by_group.iter().enumerate() {
        if ss.is_empty() {
            continue;
        }
        let local: Vec<S> = ss.iter().map(|&s| kept[s as usize]).collect();
        let comp = components(&local)?;
        let n_comp = comp.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
        let mut parts: Vec<Vec<u32>> = vec![Vec::new(); n_comp];
        for (k, &c) in comp.iter().enumerate() {
            parts[c as usize].push(ss[k]);
        }
        comp_simplices.extend(parts.into_iter().map(|p| (g as u32, p)));
    }
    // Seeds: with the test on, lines start from the scan's shortest pieces
    // (three points, [`scan_min_size`]); a part still needs min_vertices
    // points once its claims have joined its pieces.
    let seed_min = if settings.kind == StructureKind::Lines && settings.log10_epsilon.is_some() {
        settings.min_vertices.min(LINE_SCAN_MIN as usize + 1)
    } else {
        settings.min_vertices
    };
    // Components are independent: extracted in parallel, in order.
    let per_component = map_ranges(
        comp_simplices.len(),
        || (),
        |_, k| {
            let (g, ss) = &comp_simplices[k];
            let scale = settings.scales[*g as usize];
            let local: Vec<S> = ss.iter().map(|&s| kept[s as usize]).collect();
            extract(points, &local, scale.tau, seed_min, settings.part_angle_deg)
                .into_iter()
                .filter_map(|(seeds, fit)| {
                    let foot = Footprint::new(&fit, points, &seeds, scale.cell)?;
                    Some(Cand {
                        fit,
                        tau: scale.tau,
                        cell: scale.cell,
                        seeds,
                        foot,
                    })
                })
                .collect::<Vec<Cand>>()
        },
    );
    let mut cands: Vec<Cand> = per_component.into_iter().flatten().collect();
    // 2b. Claim radius from the noise (lines under the test): the radius
    // among CLAIM_RADII·τ whose tube makes the candidate least explicable
    // by chance.
    if (settings.kind == StructureKind::Lines || settings.widen_planes)
        && settings.log10_epsilon.is_some()
    {
        let (lo, hi) = crate::geometry::bounding_box(points);
        let volume: f64 = (0..3).map(|k| (hi[k] - lo[k]).max(1e-300)).product();
        let rho_global = firsts.len() as f64 / volume;
        let log10_tests = log10_n_tests(firsts.len(), S::K) + (CLAIM_RADII.len() as f64).log10();
        // Candidates in parallel, each range of them with its own stamps.
        let taus = map_ranges(
            cands.len(),
            || Stamps::new(n),
            |stamp, ci| {
                let c = &cands[ci];
                let base = c.tau;
                let planar = matches!(c.fit, Primitive::Plane(_));
                // A plane whose seeds' RMS is under τ/3 keeps 99% of a
                // Gaussian spread within τ: nothing for a wider slab to gain.
                if planar && 3.0 * c.fit.rms() < base {
                    return base;
                }
                let vol = near_volume(&c.fit, &c.foot, c.cell, &c.seeds, points);
                // The radii tried: a wider tube may cost a line at most
                // MAX_WIDEN_BACKGROUND expected background points.
                let radii: Vec<f64> = CLAIM_RADII
                    .iter()
                    .enumerate()
                    .take_while(|&(i, &f)| {
                        planar || i == 0 || rho_global * vol(f * base) <= MAX_WIDEN_BACKGROUND
                    })
                    .map(|(_, &f)| f * base)
                    .collect();
                // One pass over the points near the candidate, out to the
                // widest radius's shell; each radius then counts its own.
                let reach = SHELL_RATIO * radii.last().copied().unwrap_or(base);
                let mut near = Vec::new();
                for_near(c, reach, points, &index, stamp, &mut |_, d| near.push(d));
                let mut best = (f64::INFINITY, base);
                for &r in &radii {
                    let outer = SHELL_RATIO * r;
                    let residuals: Vec<f64> = near.iter().copied().filter(|&d| d <= r).collect();
                    let shell = near.iter().filter(|&&d| d > r && d <= outer).count();
                    let rho_local = (shell as f64 + 1.0) / (vol(outer) - vol(r)).max(1e-300);
                    let nfa = part_log10_nfa(
                        &residuals,
                        S::K,
                        r,
                        rho_local.max(rho_global),
                        &vol,
                        log10_tests,
                    );
                    if nfa < best.0 - WIDEN_GAIN {
                        best = (nfa, r);
                    }
                }
                best.1
            },
        );
        for (c, tau) in cands.iter_mut().zip(taus) {
            c.tau = tau;
        }
    }
    // 3. Members: claims, merging of duplicates, resolution, refit, claims
    // again.
    // (point, candidate, distance) of every claim; candidates in parallel,
    // each range of them with its own stamps.
    let claims_of = |cands: &[Cand]| -> Vec<(u32, u32, f64)> {
        let per_cand = map_ranges(
            cands.len(),
            || Stamps::new(n),
            |stamp, ci| {
                let c = &cands[ci];
                let agrees = normal_agreement(&c.fit, settings.normals);
                let mut claims = Vec::new();
                for_near(c, c.tau, points, &index, stamp, &mut |i, d| {
                    if agrees(i) {
                        claims.push((i, ci as u32, d));
                    }
                });
                claims
            },
        );
        let mut claims: Vec<(u32, u32, f64)> = per_cand.into_iter().flatten().collect();
        claims.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
        claims
    };
    let mut claims = claims_of(&cands);
    // Merge candidates that are one primitive and share claimed points.
    loop {
        let mut uf = UnionFind::new(cands.len());
        let mut merged = false;
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        let mut i = 0;
        while i < claims.len() {
            let j = claims[i..]
                .iter()
                .take_while(|c| c.0 == claims[i].0)
                .count();
            for a in i..i + j {
                for b in a + 1..i + j {
                    pairs.push((claims[a].1, claims[b].1));
                }
            }
            i += j;
        }
        pairs.sort_unstable();
        pairs.dedup();
        for (a, b) in pairs {
            if uf.find(a) != uf.find(b)
                && same_primitive(
                    cands[a as usize].piece(),
                    cands[b as usize].piece(),
                    settings.part_angle_deg,
                    points,
                )
            {
                uf.union_min_root(a, b);
                merged = true;
            }
        }
        if !merged {
            break;
        }
        let mut groups: Vec<Vec<u32>> = vec![Vec::new(); cands.len()];
        for c in 0..cands.len() as u32 {
            groups[uf.find(c) as usize].push(c);
        }
        let mut next: Vec<Cand> = Vec::new();
        for g in groups.into_iter().filter(|g| !g.is_empty()) {
            if g.len() == 1 {
                next.push(cands[g[0] as usize].clone());
                continue;
            }
            let mut seeds: Vec<u32> = g
                .iter()
                .flat_map(|&c| cands[c as usize].seeds.iter().copied())
                .collect();
            seeds.sort_unstable();
            seeds.dedup();
            let tau = g.iter().map(|&c| cands[c as usize].tau).fold(0.0, f64::max);
            let cell = g
                .iter()
                .map(|&c| cands[c as usize].cell)
                .fold(0.0, f64::max);
            let fit = S::fit(points, &seeds);
            if let Some(foot) = Footprint::new(&fit, points, &seeds, cell) {
                next.push(Cand {
                    fit,
                    tau,
                    cell,
                    seeds,
                    foot,
                });
            }
        }
        cands = next;
        claims = claims_of(&cands);
    }
    let resolve = |claims: &[(u32, u32, f64)], nc: usize| -> Vec<Vec<u32>> {
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); nc];
        let mut i = 0;
        while i < claims.len() {
            let j = claims[i..]
                .iter()
                .take_while(|c| c.0 == claims[i].0)
                .count();
            let best = claims[i..i + j]
                .iter()
                .min_by(|a, b| a.2.total_cmp(&b.2).then(a.1.cmp(&b.1)))
                .map_or(0, |c| c.1);
            members[best as usize].push(claims[i].0);
            i += j;
        }
        members
    };
    let members = resolve(&claims, cands.len());
    // Refit on the members, claim again.
    for (c, m) in cands.iter_mut().zip(&members) {
        if m.len() > S::K {
            let refit = S::fit(points, m);
            if !matches!(refit, Primitive::None) {
                if let Some(foot) = Footprint::new(&refit, points, m, c.cell) {
                    c.fit = refit;
                    c.foot = foot;
                }
            }
        }
    }
    let claims = claims_of(&cands);
    let members = resolve(&claims, cands.len());
    // Final parts: refit on members, drop the small ones.
    struct P {
        members: Vec<u32>,
        fit: Primitive,
        cand: usize,
        /// The candidates of the other pieces of a plane found apart (4b).
        pieces: Vec<usize>,
        log10_nfa: f64,
    }
    let mut parts: Vec<P> = Vec::new();
    for (ci, m) in members.into_iter().enumerate() {
        if m.len() < settings.min_vertices.max(S::K + 1) {
            continue;
        }
        let fit = S::fit(points, &m);
        if matches!(fit, Primitive::None) {
            continue;
        }
        parts.push(P {
            members: m,
            fit,
            cand: ci,
            pieces: Vec::new(),
            log10_nfa: f64::NEG_INFINITY,
        });
    }
    // 4. Significance.
    if let Some(log_eps) = settings.log10_epsilon {
        let in_parts: usize = parts.iter().map(|p| p.members.len()).sum();
        let (lo, hi) = crate::geometry::bounding_box(points);
        let volume: f64 = (0..3).map(|k| (hi[k] - lo[k]).max(1e-300)).product();
        let rho_global = firsts.len().saturating_sub(in_parts) as f64 / volume;
        let log10_tests = log10_n_tests(firsts.len(), S::K);
        // Parts in parallel, each range of them with its own stamps.
        let nfas = map_ranges(
            parts.len(),
            || Stamps::new(n),
            |stamp, pi| -> Option<f64> {
                let p = &parts[pi];
                let c = &cands[p.cand];
                let residuals: Vec<f64> = p
                    .members
                    .iter()
                    .map(|&v| p.fit.distance(&points[v as usize]))
                    .collect();
                let thick = residuals.iter().copied().fold(0.0, f64::max);
                let tau = c.tau.max(thick);
                // Footprint extent from the members (cells they occupy).
                let foot = Footprint::new(&p.fit, points, &p.members, c.cell);
                let foot = foot?;
                let vol = near_volume(&p.fit, &foot, c.cell, &p.members, points);
                // Local density in the shell (τ, 4τ] over the footprint.
                let outer = SHELL_RATIO * tau;
                let probe = Cand {
                    fit: p.fit.clone(),
                    tau: outer,
                    cell: c.cell,
                    seeds: Vec::new(),
                    foot,
                };
                let mut shell = 0usize;
                for_near(&probe, outer, points, &index, stamp, &mut |_, d| {
                    if d > tau {
                        shell += 1;
                    }
                });
                let rho_local = (shell as f64 + 1.0) / (vol(outer) - vol(tau)).max(1e-300);
                let rho = rho_local.max(rho_global);
                // The least-squares fit of a clean structure is pulled off it
                // by the few background points its claim radius takes in (at
                // 10× the paper's density, a wall of 20 exact points fits
                // with an RMS of 0.3 α and its thin widths miss it). So the
                // fit on the better half of the members (at least k + 2) is
                // tried too, and the better of the two NFAs kept (two
                // primitives per part: one more factor 2 in the tests).
                let mut order: Vec<usize> = (0..residuals.len()).collect();
                order.sort_unstable_by(|&a, &b| residuals[a].total_cmp(&residuals[b]));
                let half = residuals.len().div_ceil(2).max(S::K + 2);
                let core: Vec<u32> = order.iter().take(half).map(|&i| p.members[i]).collect();
                let tests = log10_tests + std::f64::consts::LOG10_2;
                let mut nfa = part_log10_nfa(&residuals, S::K, tau, rho, &vol, tests);
                let core_fit = S::fit(points, &core);
                if !matches!(core_fit, Primitive::None) {
                    let core_res: Vec<f64> = p
                        .members
                        .iter()
                        .map(|&v| core_fit.distance(&points[v as usize]))
                        .collect();
                    nfa = nfa.min(part_log10_nfa(&core_res, S::K, tau, rho, &vol, tests));
                }
                Some(nfa)
            },
        );
        for (p, nfa) in parts.iter_mut().zip(nfas) {
            if let Some(nfa) = nfa {
                p.log10_nfa = nfa;
            }
        }
        let before = parts.len();
        parts.retain(|p| p.log10_nfa <= log_eps);
        stats.rejected_parts = before - parts.len();
    }
    // 4b. One plane, one part: planar parts that are the same plane
    // (`same_primitive`, the test that merges candidates sharing points)
    // but lie apart (the panes of one wall's windows, a wall cut in two by
    // an occluder, the ground on both sides of a house) are one part in
    // several pieces, as a plane is for RANSAC and for the labels of
    // CGAL's scans. A pair is only tested when its normals are within the
    // part angle and each one's plane passes within τ of the other's
    // bounding box (O(1); no point of a part whose box the plane misses
    // can be within τ of it). Lines keep their pieces: a segment is a
    // segment.
    if S::K == 2 && parts.len() > 1 {
        let boxes: Vec<([f64; 3], [f64; 3])> = parts
            .iter()
            .map(|p| {
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for &v in &p.members {
                    let q = points[v as usize];
                    for k in 0..3 {
                        lo[k] = lo[k].min(q[k]);
                        hi[k] = hi[k].max(q[k]);
                    }
                }
                (lo, hi)
            })
            .collect();
        // Whether the plane of part `a` passes within its τ of part `b`'s
        // box: the signed distances of the box's corners span [−τ, τ].
        let near = |a: usize, b: usize| -> bool {
            let Primitive::Plane(f) = &parts[a].fit else {
                return false;
            };
            let tau = cands[parts[a].cand].tau;
            let (lo, hi) = boxes[b];
            let (mut dmin, mut dmax) = (f64::INFINITY, f64::NEG_INFINITY);
            for c in 0..8 {
                let q = [
                    if c & 1 == 0 { lo[0] } else { hi[0] },
                    if c & 2 == 0 { lo[1] } else { hi[1] },
                    if c & 4 == 0 { lo[2] } else { hi[2] },
                ];
                let d = dot(sub(q, f.centroid), f.normal);
                dmin = dmin.min(d);
                dmax = dmax.max(d);
            }
            dmin <= tau && dmax >= -tau
        };
        let cos = settings.part_angle_deg.to_radians().cos();
        let parallel = |a: usize, b: usize| match (&parts[a].fit, &parts[b].fit) {
            (Primitive::Plane(fa), Primitive::Plane(fb)) => dot(fa.normal, fb.normal).abs() >= cos,
            _ => false,
        };
        // Pairs passing the O(1) tests, the largest pieces first; each is
        // then tested as the groups merged so far (their members and their
        // joint fit): pairwise tests alone chain small patches at several
        // heights (floors of two storeys, 40 m apart, each a few dozen
        // points) into one plane tilted through all of them.
        let mut pairs: Vec<(usize, usize)> = Vec::new();
        for a in 0..parts.len() {
            for b in a + 1..parts.len() {
                if parallel(a, b) && (near(a, b) || near(b, a)) {
                    pairs.push((a, b));
                }
            }
        }
        let size = |p: &(usize, usize)| {
            let (x, y) = (parts[p.0].members.len(), parts[p.1].members.len());
            (x.max(y), x.min(y))
        };
        pairs.sort_by(|p, q| size(q).cmp(&size(p)).then(p.cmp(q)));
        let mut uf = UnionFind::new(parts.len());
        let mut merged = false;
        // Per group root: its members, fit and claim radius (the largest
        // piece's).
        let mut group_members: Vec<Vec<u32>> = parts.iter().map(|p| p.members.clone()).collect();
        let mut group_fit: Vec<Primitive> = parts.iter().map(|p| p.fit.clone()).collect();
        let mut group_tau: Vec<f64> = parts.iter().map(|p| cands[p.cand].tau).collect();
        for (a, b) in pairs {
            let (ra, rb) = (uf.find(a as u32) as usize, uf.find(b as u32) as usize);
            if ra == rb {
                continue;
            }
            let piece = |r: usize| Piece {
                fit: &group_fit[r],
                tau: group_tau[r],
                seeds: &group_members[r],
            };
            let one = match (&group_fit[ra], &group_fit[rb]) {
                (Primitive::Plane(fa), Primitive::Plane(fb)) => {
                    dot(fa.normal, fb.normal).abs() >= cos
                        && (same_primitive(piece(ra), piece(rb), settings.part_angle_deg, points)
                            || joint_plane_keeps(
                                piece(ra),
                                piece(rb),
                                settings.part_angle_deg,
                                points,
                            ))
                }
                _ => false,
            };
            if !one {
                continue;
            }
            uf.union_min_root(a as u32, b as u32);
            let root = uf.find(a as u32) as usize;
            let other = if root == ra { rb } else { ra };
            let mut m = std::mem::take(&mut group_members[other]);
            let big = if m.len() > group_members[root].len() {
                other
            } else {
                root
            };
            m.extend_from_slice(&group_members[root]);
            m.sort_unstable();
            group_tau[root] = group_tau[big];
            group_fit[root] = S::fit(points, &m);
            group_members[root] = m;
            merged = true;
        }
        if merged {
            let mut groups: Vec<Vec<usize>> = vec![Vec::new(); parts.len()];
            for p in 0..parts.len() {
                groups[uf.find(p as u32) as usize].push(p);
            }
            let mut old: Vec<Option<P>> = parts.drain(..).map(Some).collect();
            for (root, g) in groups.into_iter().enumerate() {
                if g.is_empty() {
                    continue;
                }
                if g.len() == 1 {
                    parts.push(old[g[0]].take().expect("each part is in one group"));
                    continue;
                }
                let group: Vec<P> = g
                    .iter()
                    .map(|&p| old[p].take().expect("each part is in one group"))
                    .collect();
                // The largest piece lends its scale (claim radius, cell).
                let cand = group
                    .iter()
                    .max_by(|x, y| {
                        x.members
                            .len()
                            .cmp(&y.members.len())
                            .then(y.members[0].cmp(&x.members[0]))
                    })
                    .map_or(group[0].cand, |p| p.cand);
                let log10_nfa = group
                    .iter()
                    .map(|p| p.log10_nfa)
                    .fold(f64::INFINITY, f64::min);
                // The group's members (sorted) and their fit, as the
                // merging above left them at its root.
                let members = std::mem::take(&mut group_members[root]);
                let fit = std::mem::replace(&mut group_fit[root], Primitive::None);
                if matches!(fit, Primitive::None) {
                    // Not reached (each piece has a plane); the pieces stay.
                    parts.extend(group);
                    continue;
                }
                let pieces: Vec<usize> = group
                    .iter()
                    .flat_map(|p| std::iter::once(p.cand).chain(p.pieces.iter().copied()))
                    .filter(|&c| c != cand)
                    .collect();
                parts.push(P {
                    members,
                    fit,
                    cand,
                    pieces,
                    log10_nfa,
                });
            }
        }
    }
    // 5. Structures: parts sharing claims and not crossing.
    let np = parts.len();
    let mut part_of_cand = vec![u32::MAX; cands.len()];
    for (pi, p) in parts.iter().enumerate() {
        part_of_cand[p.cand] = pi as u32;
        for &c in &p.pieces {
            part_of_cand[c] = pi as u32;
        }
    }
    let mut uf = UnionFind::new(np);
    let mut i = 0;
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    while i < claims.len() {
        let j = claims[i..]
            .iter()
            .take_while(|c| c.0 == claims[i].0)
            .count();
        for a in i..i + j {
            for b in a + 1..i + j {
                let (pa, pb) = (
                    part_of_cand[claims[a].1 as usize],
                    part_of_cand[claims[b].1 as usize],
                );
                if pa != u32::MAX && pb != u32::MAX && pa != pb {
                    pairs.push((pa.min(pb), pa.max(pb)));
                }
            }
        }
        i += j;
    }
    pairs.sort_unstable();
    pairs.dedup();
    for (a, b) in pairs {
        let (pa, pb) = (&parts[a as usize], &parts[b as usize]);
        if !crosses(&pa.fit, &pb.members, points) && !crosses(&pb.fit, &pa.members, points) {
            uf.union_min_root(a, b);
        }
    }
    let mut members_of: Vec<Vec<u32>> = vec![Vec::new(); np];
    for p in 0..np as u32 {
        members_of[uf.find(p) as usize].push(p);
    }
    let mut groups: Vec<(usize, u32, Vec<u32>)> = members_of
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(|g| {
            let size: usize = g.iter().map(|&p| parts[p as usize].members.len()).sum();
            let first = g
                .iter()
                .map(|&p| parts[p as usize].members[0])
                .min()
                .unwrap_or(u32::MAX);
            (size, first, g)
        })
        .collect();
    groups.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    // Each part's outline and mesh (a plane's 2D α-shape; a line's
    // segment), the parts in parallel.
    let mut shapes: Vec<PartShape> = map_ranges(
        parts.len(),
        || (),
        |_, pi| {
            let p = &parts[pi];
            match &p.fit {
                Primitive::Plane(f) => {
                    let o = outline(points, &p.members, f, cands[p.cand].cell);
                    (o.polygon, o.triangles)
                }
                Primitive::Line(f) => {
                    let (mut t0, mut t1) = (f64::INFINITY, f64::NEG_INFINITY);
                    for &v in &p.members {
                        let t = dot(sub(points[v as usize], f.centroid), f.direction);
                        t0 = t0.min(t);
                        t1 = t1.max(t);
                    }
                    let at = |t: f64| [0, 1, 2].map(|k| f.centroid[k] + t * f.direction[k]);
                    (vec![at(t0), at(t1)], Vec::new())
                }
                Primitive::None => (Vec::new(), Vec::new()),
            }
        },
    );
    // Point → structure and part (global part numbering as in the report).
    let mut vstruct = vec![u32::MAX; n];
    let mut vpart = vec![u32::MAX; n];
    let mut structures: Vec<Structure> = Vec::with_capacity(groups.len());
    for (id, (_, _, g)) in groups.into_iter().enumerate() {
        let mut ps: Vec<u32> = g;
        ps.sort_by(|&a, &b| {
            let (pa, pb) = (&parts[a as usize], &parts[b as usize]);
            pb.members
                .len()
                .cmp(&pa.members.len())
                .then(pa.members[0].cmp(&pb.members[0]))
        });
        let mut sparts: Vec<Part> = Vec::with_capacity(ps.len());
        for &pi in &ps {
            let p = &parts[pi as usize];
            let (outline_pts, mesh) = std::mem::take(&mut shapes[pi as usize]);
            sparts.push(Part {
                simplices: Vec::new(),
                vertices: p.members.clone(),
                primitive: p.fit.clone(),
                outline: outline_pts,
                mesh,
                log10_nfa: p.log10_nfa,
            });
        }
        let mut v: Vec<u32> = sparts
            .iter()
            .flat_map(|p| p.vertices.iter().copied())
            .collect();
        v.sort_unstable();
        let gid = structures.len() as u32;
        let part_base: u32 = structures.iter().map(|s| s.parts.len() as u32).sum();
        for (k, p) in sparts.iter().enumerate() {
            for &x in &p.vertices {
                vstruct[x as usize] = gid;
                vpart[x as usize] = part_base + k as u32;
            }
        }
        let log10_nfa = sparts
            .iter()
            .map(|p| p.log10_nfa)
            .fold(f64::INFINITY, f64::min);
        structures.push(Structure {
            id: id as u32,
            simplices: Vec::new(),
            primitive: S::fit(points, &v),
            vertices: v,
            parts: sparts,
            log10_nfa,
        });
    }
    // Simplices of the union kept when all their vertices are in one
    // structure; within it, in a part when all are in that part.
    let mut simplices: Vec<Vec<u32>> = Vec::new();
    let mut simplex_structure: Vec<u32> = Vec::new();
    let part_index: Vec<(u32, u32)> = structures
        .iter()
        .enumerate()
        .flat_map(|(s, st)| (0..st.parts.len() as u32).map(move |p| (s as u32, p)))
        .collect();
    for s in &kept {
        let vs = s.as_ref();
        let st = vstruct[vs[0] as usize];
        if st == u32::MAX || !vs.iter().all(|&v| vstruct[v as usize] == st) {
            continue;
        }
        let idx = simplices.len() as u32;
        let gp = vpart[vs[0] as usize];
        if vs.iter().all(|&v| vpart[v as usize] == gp) {
            let (_, p) = part_index[gp as usize];
            structures[st as usize].parts[p as usize]
                .simplices
                .push(idx);
        }
        structures[st as usize].simplices.push(idx);
        simplices.push(vs.to_vec());
        simplex_structure.push(st);
    }
    let labels: Vec<i64> = first
        .iter()
        .map(|&f| match vstruct[f as usize] {
            u32::MAX => -1,
            s => s as i64,
        })
        .collect();
    stats.structure_simplices = simplices.len();
    Ok(Assembled {
        detection: Detection {
            kind: settings.kind,
            simplices,
            simplex_structure,
            structures,
            labels,
            first_occurrence: first,
            stats,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// Half-width of the uniform jitter across the test pieces; τ is
    /// twice it.
    const NOISE: f64 = 0.03;
    const TAU: f64 = 0.06;

    /// Points on z = `height(x)` over [xa, xb] × [ya, yb], on a grid of
    /// step 0.25, jittered across by ±[`NOISE`]: their ids.
    fn piece(
        out: &mut Vec<[f64; 3]>,
        rng: &mut SplitMix64,
        (xa, xb): (f64, f64),
        (ya, yb): (f64, f64),
        height: impl Fn(f64) -> f64,
    ) -> Vec<u32> {
        let start = out.len() as u32;
        let (nx, ny) = (((xb - xa) / 0.25) as usize, ((yb - ya) / 0.25) as usize);
        for i in 0..=nx {
            for j in 0..=ny {
                let (x, y) = (xa + 0.25 * i as f64, ya + 0.25 * j as f64);
                out.push([x, y, height(x) + NOISE * (2.0 * rng.uniform() - 1.0)]);
            }
        }
        (start..out.len() as u32).collect()
    }

    fn fit(points: &[[f64; 3]], ids: &[u32]) -> Primitive {
        Primitive::Plane(fit_plane_indices(points, ids).unwrap())
    }

    /// A piece's plane, claim radius [`TAU`] and points.
    fn as_piece<'a>(fit: &'a Primitive, seeds: &'a [u32]) -> Piece<'a> {
        Piece {
            fit,
            tau: TAU,
            seeds,
        }
    }

    #[test]
    fn a_wall_bowed_across_a_gap_is_one_plane_for_the_joint_fit_only() {
        // Two pieces of one wall, 10 m apart, each tilted 0.34° the other
        // way (a bow of 3 cm at their far ends): either piece's own plane,
        // carried over the gap, misses the other by 6–18 cm, twice τ, so
        // the test that merges candidates says "two planes"; the plane
        // fitted to both keeps them.
        let mut rng = SplitMix64::new(7);
        let mut pts = Vec::new();
        let a = piece(&mut pts, &mut rng, (0.0, 10.0), (0.0, 10.0), |x| {
            0.006 * (x - 5.0)
        });
        let b = piece(&mut pts, &mut rng, (20.0, 30.0), (0.0, 10.0), |x| {
            -0.006 * (x - 25.0)
        });
        let (fa, fb) = (fit(&pts, &a), fit(&pts, &b));
        let (pa, pb) = (as_piece(&fa, &a), as_piece(&fb, &b));
        assert!(!same_primitive(pa, pb, 10.0, &pts));
        assert!(joint_plane_keeps(pa, pb, 10.0, &pts));
        assert!(joint_plane_keeps(pb, pa, 10.0, &pts));
    }

    #[test]
    fn two_small_patches_at_two_heights_are_not_one_plane() {
        // Two flat patches a quarter metre across, 10 m apart and 2.5 m
        // apart in height (the floors of two storeys): the plane fitted to
        // both tilts 14° and keeps each within τ, so only its angle to the
        // patches tells them apart. Without the angle test (90°) they would
        // be one plane.
        let mut rng = SplitMix64::new(9);
        let mut pts = Vec::new();
        let a = piece(&mut pts, &mut rng, (0.0, 0.25), (0.0, 0.25), |_| 0.0);
        let b = piece(&mut pts, &mut rng, (10.0, 10.25), (0.0, 0.25), |_| 2.5);
        let (fa, fb) = (fit(&pts, &a), fit(&pts, &b));
        let (pa, pb) = (as_piece(&fa, &a), as_piece(&fb, &b));
        assert!(!joint_plane_keeps(pa, pb, 10.0, &pts));
        assert!(joint_plane_keeps(pa, pb, 90.0, &pts));
    }

    #[test]
    fn a_wall_set_back_by_five_tau_beside_another_stays_apart() {
        // A façade and a wall 30 cm behind it, side by side: the joint
        // plane lies between them and keeps about half of each.
        let mut rng = SplitMix64::new(8);
        let mut pts = Vec::new();
        let a = piece(&mut pts, &mut rng, (0.0, 10.0), (0.0, 10.0), |_| 0.0);
        let b = piece(&mut pts, &mut rng, (0.0, 10.0), (12.0, 22.0), |_| 0.3);
        let (fa, fb) = (fit(&pts, &a), fit(&pts, &b));
        let (pa, pb) = (as_piece(&fa, &a), as_piece(&fb, &b));
        assert!(!same_primitive(pa, pb, 10.0, &pts));
        assert!(!joint_plane_keeps(pa, pb, 10.0, &pts));
        // The same two pieces in one plane are one.
        let mut flat = pts.clone();
        for &v in &b {
            flat[v as usize][2] -= 0.3;
        }
        let fb = fit(&flat, &b);
        assert!(joint_plane_keeps(pa, as_piece(&fb, &b), 10.0, &flat));
    }

    #[test]
    fn near_points_by_blocks_are_the_brute_force_set() {
        // A plane and a line candidate among random points; for radii from
        // a tenth of a cell to ten cells (one ball per cell, then blocks),
        // `for_near` reports each point within the radius and over the
        // footprint exactly once.
        let mut rng = SplitMix64::new(21);
        let pts: Vec<[f64; 3]> = (0..4000)
            .map(|_| {
                [
                    10.0 * rng.uniform(),
                    10.0 * rng.uniform(),
                    2.0 * rng.uniform() - 1.0,
                ]
            })
            .collect();
        let seeds_plane: Vec<u32> = (0..4000u32)
            .filter(|&i| {
                let p = pts[i as usize];
                p[2].abs() < 0.2 && (p[0] < 4.0 || p[1] > 6.0)
            })
            .collect();
        let seeds_line: Vec<u32> = (0..4000u32)
            .filter(|&i| {
                let p = pts[i as usize];
                p[2].abs() < 0.3 && (p[1] - 5.0).abs() < 0.3 && p[0] < 7.0
            })
            .collect();
        let index = KdTree::new(&pts, None);
        let mut stamps = Stamps::new(pts.len());
        for (seeds, line) in [(&seeds_plane, false), (&seeds_line, true)] {
            let fit = if line {
                Primitive::Line(
                    fit_line(&seeds.iter().map(|&v| pts[v as usize]).collect::<Vec<_>>()).unwrap(),
                )
            } else {
                fit(&pts, seeds)
            };
            let cell = 0.3;
            let foot = Footprint::new(&fit, &pts, seeds, cell).unwrap();
            let cand = Cand {
                fit: fit.clone(),
                tau: 0.1,
                cell,
                seeds: seeds.clone(),
                foot,
            };
            for radius in [0.03, 0.1, 0.3, 0.7, 1.5, 3.0] {
                let mut got = Vec::new();
                for_near(&cand, radius, &pts, &index, &mut stamps, &mut |i, d| {
                    got.push((i, d))
                });
                got.sort_by_key(|a| a.0);
                let want: Vec<(u32, f64)> = (0..pts.len() as u32)
                    .filter_map(|i| {
                        let p = &pts[i as usize];
                        let d = fit.distance(p);
                        (d <= radius && cand.foot.contains(p)).then_some((i, d))
                    })
                    .collect();
                assert_eq!(got, want, "line {line}, radius {radius}");
                // (not vacuous: from 0.3 on, dozens of points at least)
                assert!(radius < 0.3 || want.len() > 20, "{}", want.len());
            }
        }
    }
}
