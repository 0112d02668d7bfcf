//! Deterministic benchmark scenes in the spirit of the paper's figures
//! (docs/method.md §5), with ground truth.
//!
//! A [`Scene`] is a point set with, for every point, the id of its true
//! structure (or −1 for background) and, for polyhedra, the id of its facet
//! (or −1). Points are shuffled (structure points are not first). Everything
//! is a function of the [`SceneOptions`], including the seed: no global
//! state, no `rand` dependency ([`Rng`] is xoshiro256** + Box–Muller).
//!
//! # Scales (α = 1 and the paper's λ, nb_c)
//!
//! The paper gives parameters, not coordinates, so the scenes pick the
//! coordinates that make α = 1 work under the box sampler (m1 = 0.3,
//! m2 = 12), whose measured worst angular gaps are 11.2° for the long axis
//! (k = 1) and 7.2° for the normal (k = 2), see
//! [`crate::detect::orientations`].
//!
//! **Lines** (Fig. 12: 5 lines × 10 points, 1500 background; λ₃ = 10,
//! nb_c = 4). Observation 3: consecutive points at distance d must fit an
//! α-ellipsoid with semi-axes λ₃ = 10 along the sampled axis and 1 across,
//! for a line up to γ = 11° off that axis. The transformed half-step is
//! (d/2)·√(cos²γ/λ₃² + sin²γ); with **d = 7** it is
//! 3.5·√(0.0096 + 0.0364) ≈ 0.75 α (0.35 with γ = 0): the edge's smallest
//! circumsphere has radius ≤ 0.75 < α. Two steps (2d) give ≥ 0.7 for every
//! γ but are not Gabriel (the middle point is inside), so only consecutive
//! edges are exposed.
//!
//! **Background** density: `background_per_ellipsoid` expected points per
//! α-ellipsoid volume V = (4/3)π·α³·λ₁λ₂λ₃ (41.9 for lines, 134 for planes),
//! default **0.01**, the density at which docs/method.md §5 measured lines to be
//! found. The background box side is S = (N_bg · V / 0.01)^{1/3}: 184.5 for
//! the lines scene, 126 for planes, 220 for the polyhedron. For lines the
//! mean background nearest-neighbour distance is then
//! 0.554·ρ^{−1/3} = 8.9 ≈ 1.28 d (docs/method.md §5: ≳ 1.25 d).
//!
//! **Planes** (Fig. 5: 120 points on 3 planes, 150 background;
//! Fig. 10: a 190-point polyhedral surface, 800 background; λ₂ = 4,
//! λ₃ = 8, nb_c = 20). A plane maps under Q to a plane, and its grid to a
//! lattice whose Delaunay triangles have circumradius at most
//! s_max·h/√2 (h the grid step, s_max the largest stretch of Q on the
//! plane). With the flat ellipsoid (semi-axes 1 along the sampled normal,
//! 4 and 8 in-plane) and a normal γ off, s_max² ≤ sin²γ + cos²γ/λ₂²:
//! s_max ≤ 0.278 at γ = 7.2° and 0.311 at γ = 11°. With **h = 3** the
//! triangles' circumradii stay ≤ 0.59 (7.2°) and ≤ 0.66 (11°) < α = 1, for
//! any in-plane orientation. A plane of 40 points is an 8 × 5 grid
//! (21 × 12), 56 triangles per orientation (≥ nb_c = 20).
//!
//! **Polyhedron**: an open box (top + 4 walls, no bottom) of 6 × 9 × 4
//! steps of h = 3 (18 × 27 × 12): 70 + 120 = **190** points, 5 facets
//! (parts): top 0, walls x = 0 → 1, x = max → 2, y = 0 → 3, y = max → 4.
//! Points on a shared edge belong to one facet: the top keeps its rim, the
//! x-walls keep the vertical corner edges.
//!
//! Structures get random orientations and positions inside the box, at
//! least `clearance` apart (20 = 2αλ₃ for lines, 16 for planes and
//! polyhedra) unless `crossing` is asked for: then structure 1 passes
//! through structure 0 at ≥ 45° (lines: their middle samples coincide, and
//! that shared point is kept once, labelled 0; planes: same centroid, so
//! they cut each other along a line through both centres; polyhedra: same
//! centroid).
//!
//! # Measured with the method layer
//!
//! `tests/lines_pipeline_bruteforce.rs` and
//! `tests/planes_pipeline_bruteforce.rs` run the docs/method.md §4 loop on these
//! scenes with a brute-force F_{k,α,Q} (no Delaunay), the box sampler, the
//! path filter per orientation, the union, the component clean-up, the
//! largest-structure labelling and [`crate::eval`]:
//!
//! | scene (seed) | background per ellipsoid | per-point F1 | structures found |
//! |---|---:|---:|---:|
//! | lines (1, 2, 3) | 0.005 | 0.98 (mean) | |
//! | lines (1, 2, 3) | 0.01 | 0.92, 0.87, 0.89 | 5/5 each |
//! | lines (1, 2, 3) | 0.02 | 0.61 (mean) | |
//! | lines (1, 2, 3) | 0.03 | 0.36 (mean) | |
//! | planes (1, 2, 3) | 0.01 | 0.96, 0.95, 0.96 | 3/3 (seed 1) |
//! | planes (2, 3) | 0.03 | 0.89, 0.90 | |
//! | planes (2, 3) | 0.1 | 0.72, 0.78 | |
//! | polyhedron (1, 2, 3) | 0.01 | 0.98, 0.98, 0.98 | 1/1 (seed 1; its 5 facets form one component) |
//! | polyhedron (2, 3) | 0.03 | 0.94, 0.96 | |
//! | polyhedron (2, 3) | 0.1 | 0.84, 0.84 | |
//!
//! (docs/method.md §5: lines F1 ≈ 0.9 at 0.01, collapsing at 3×; planes
//! ≈ 0.83 at 10×.) Background points that touch a structure are what
//! costs precision; recall is 1.0 (or one point short) in all these runs.
//!
//! ```
//! use aniso_alpha::synth::SceneOptions;
//! use aniso_alpha::io::write_xyz_labels;
//! let scene = SceneOptions::lines().seed(3).generate().unwrap();
//! assert_eq!(scene.points.len(), 1550);
//! assert_eq!(scene.labels.iter().filter(|&&l| l >= 0).count(), 50);
//! let mut out = Vec::new();
//! write_xyz_labels(&scene, &mut out).unwrap();
//! ```

use crate::aniso::{cross, dot, normalize};
use std::f64::consts::PI;
use std::fmt;

/// A point set with ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The points.
    pub points: Vec<[f64; 3]>,
    /// Per point: true structure id (0, 1, …) or −1 for background.
    pub labels: Vec<i64>,
    /// Per point: facet id within its polyhedron, or −1.
    pub parts: Vec<i64>,
}

impl Scene {
    /// Number of true structures (largest label + 1).
    pub fn num_structures(&self) -> usize {
        self.labels
            .iter()
            .copied()
            .max()
            .map_or(0, |m| (m + 1).max(0) as usize)
    }
}

/// Which scene to generate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneKind {
    /// Fig. 12: lines in a uniform background (k = 1).
    Lines,
    /// Fig. 5: a few planar patches in a uniform background (k = 2).
    Planes,
    /// Fig. 10: a polyhedral surface (open box) in a uniform background.
    Polyhedron,
}

/// The detection parameters the scene is scaled for (the paper's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperParams {
    /// 1 for lines, 2 for planes.
    pub k: usize,
    /// α.
    pub alpha: f64,
    /// λ₂ (1 for lines).
    pub lambda2: f64,
    /// λ₃.
    pub lambda3: f64,
    /// nb_c.
    pub nb_c: u32,
}

/// Bad scene options, or no room to place the structures.
#[derive(Debug, Clone, PartialEq)]
pub enum SynthError {
    /// A numeric option is NaN, infinite or out of range.
    BadOption {
        /// The option's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// Could not place the structures apart from each other inside the box
    /// (too many, or too large, for the box).
    CannotPlace,
}

impl fmt::Display for SynthError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadOption { name, value } => write!(f, "bad scene option {name} = {value}"),
            Self::CannotPlace => write!(
                f,
                "cannot place the structures apart inside the box: fewer structures or more background"
            ),
        }
    }
}

impl std::error::Error for SynthError {}

/// Scene options, builder style. Start from [`SceneOptions::lines`],
/// [`SceneOptions::planes`] or [`SceneOptions::polyhedron`] (the paper's
/// counts and the scales of the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneOptions {
    kind: SceneKind,
    seed: u64,
    background: usize,
    background_per_ellipsoid: f64,
    jitter: f64,
    random_sampling: bool,
    structures: usize,
    points_per_structure: usize,
    crossing: bool,
    spacing: f64,
    clearance: f64,
}

impl SceneOptions {
    /// Defaults of `kind`.
    pub fn new(kind: SceneKind) -> Self {
        match kind {
            SceneKind::Lines => Self {
                kind,
                seed: 1,
                background: 1500,
                background_per_ellipsoid: 0.01,
                jitter: 0.0,
                random_sampling: false,
                structures: 5,
                points_per_structure: 10,
                crossing: false,
                spacing: 7.0,
                clearance: 20.0,
            },
            SceneKind::Planes => Self {
                kind,
                seed: 1,
                background: 150,
                background_per_ellipsoid: 0.01,
                jitter: 0.0,
                random_sampling: false,
                structures: 3,
                points_per_structure: 40,
                crossing: false,
                spacing: 3.0,
                clearance: 16.0,
            },
            SceneKind::Polyhedron => Self {
                kind,
                seed: 1,
                background: 800,
                background_per_ellipsoid: 0.01,
                jitter: 0.0,
                random_sampling: false,
                structures: 1,
                points_per_structure: 190,
                crossing: false,
                spacing: 3.0,
                clearance: 16.0,
            },
        }
    }

    /// Fig. 12: 5 lines of 10 points (step 7), 1500 background points.
    pub fn lines() -> Self {
        Self::new(SceneKind::Lines)
    }

    /// Fig. 5: 3 planes of 40 points (8 × 5 grid, step 3), 150 background.
    pub fn planes() -> Self {
        Self::new(SceneKind::Planes)
    }

    /// Fig. 10: a 190-point open box (step 3), 800 background points.
    pub fn polyhedron() -> Self {
        Self::new(SceneKind::Polyhedron)
    }

    /// PRNG seed.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Number of uniform background points.
    pub fn background(mut self, n: usize) -> Self {
        self.background = n;
        self
    }

    /// Expected background points per α-ellipsoid volume (sets the box
    /// size; default 0.01).
    pub fn background_per_ellipsoid(mut self, x: f64) -> Self {
        self.background_per_ellipsoid = x;
        self
    }

    /// Standard deviation of the Gaussian noise added to every coordinate
    /// of the structure points (default 0).
    pub fn jitter(mut self, sigma: f64) -> Self {
        self.jitter = sigma;
        self
    }

    /// Uniform random positions on the structures instead of a regular grid
    /// (same extent and count; gaps then vary and can exceed the working
    /// step).
    pub fn random_sampling(mut self, yes: bool) -> Self {
        self.random_sampling = yes;
        self
    }

    /// Number of structures (lines, planes, or polyhedra).
    pub fn structures(mut self, n: usize) -> Self {
        self.structures = n;
        self
    }

    /// Points per line or plane (a plane's grid is ⌈n/5⌉ × 5 trimmed to n;
    /// ignored for polyhedra, which have 190).
    pub fn points_per_structure(mut self, n: usize) -> Self {
        self.points_per_structure = n;
        self
    }

    /// Make structure 1 cross structure 0 (two lines through one point,
    /// two planes cutting each other).
    pub fn crossing(mut self, yes: bool) -> Self {
        self.crossing = yes;
        self
    }

    /// Sampling step on the structures (d for lines, h for planes).
    pub fn spacing(mut self, d: f64) -> Self {
        self.spacing = d;
        self
    }

    /// Minimum distance between points of different structures.
    pub fn clearance(mut self, c: f64) -> Self {
        self.clearance = c;
        self
    }

    /// The scene kind.
    pub fn kind(&self) -> SceneKind {
        self.kind
    }

    /// The detection parameters the scene is scaled for.
    pub fn paper_params(&self) -> PaperParams {
        match self.kind {
            SceneKind::Lines => PaperParams {
                k: 1,
                alpha: 1.0,
                lambda2: 1.0,
                lambda3: 10.0,
                nb_c: 4,
            },
            SceneKind::Planes | SceneKind::Polyhedron => PaperParams {
                k: 2,
                alpha: 1.0,
                lambda2: 4.0,
                lambda3: 8.0,
                nb_c: 20,
            },
        }
    }

    /// Side of the background cube [0, S]³: (N_bg·V/ρ_e)^{1/3} with V the
    /// α-ellipsoid volume of [`Self::paper_params`] and ρ_e
    /// `background_per_ellipsoid`; at least large enough to hold the
    /// structures (2× their size).
    pub fn box_side(&self) -> f64 {
        let p = self.paper_params();
        let v = 4.0 / 3.0 * PI * p.alpha.powi(3) * p.lambda2 * p.lambda3;
        let from_density = (self.background as f64 * v / self.background_per_ellipsoid).cbrt();
        from_density.max(2.0 * self.structure_size())
    }

    /// Largest dimension of one structure.
    fn structure_size(&self) -> f64 {
        match self.kind {
            SceneKind::Lines => self.spacing * self.points_per_structure.saturating_sub(1) as f64,
            SceneKind::Planes => {
                let (nu, _) = plane_grid(self.points_per_structure);
                self.spacing * nu.saturating_sub(1) as f64
            }
            SceneKind::Polyhedron => self.spacing * 9.0,
        }
    }

    fn validate(&self) -> Result<(), SynthError> {
        let checks: [(&'static str, f64, bool); 4] = [
            (
                "background_per_ellipsoid",
                self.background_per_ellipsoid,
                self.background_per_ellipsoid > 0.0,
            ),
            ("jitter", self.jitter, self.jitter >= 0.0),
            ("spacing", self.spacing, self.spacing > 0.0),
            ("clearance", self.clearance, self.clearance >= 0.0),
        ];
        for (name, value, ok) in checks {
            if !(value.is_finite() && ok) {
                return Err(SynthError::BadOption { name, value });
            }
        }
        let min_points = if self.kind == SceneKind::Planes { 3 } else { 2 };
        if self.kind != SceneKind::Polyhedron && self.points_per_structure < min_points {
            return Err(SynthError::BadOption {
                name: "points_per_structure",
                value: self.points_per_structure as f64,
            });
        }
        if self.crossing && self.structures < 2 {
            return Err(SynthError::BadOption {
                name: "structures (crossing needs 2)",
                value: self.structures as f64,
            });
        }
        Ok(())
    }

    /// Generates the scene.
    pub fn generate(&self) -> Result<Scene, SynthError> {
        self.validate()?;
        let mut rng = Rng::new(self.seed);
        let side = self.box_side();
        // Structures in local coordinates, then placed.
        let mut placed: Vec<Vec<[f64; 3]>> = Vec::new();
        let mut parts_of: Vec<Vec<i64>> = Vec::new();
        for s in 0..self.structures {
            let (local, parts) = self.local_structure(&mut rng);
            let pts = self.place(&mut rng, s, &local, &placed, side)?;
            placed.push(pts);
            parts_of.push(parts);
        }
        let mut points = Vec::new();
        let mut labels = Vec::new();
        let mut parts = Vec::new();
        for (s, (pts, pp)) in placed.iter().zip(&parts_of).enumerate() {
            for (p, &part) in pts.iter().zip(pp) {
                // Crossing structures: skip a point equal to an earlier one.
                if self.crossing && s == 1 && placed[0].iter().any(|q| dist2(*q, *p) < 1e-18) {
                    continue;
                }
                let q = if self.jitter > 0.0 {
                    [
                        p[0] + self.jitter * rng.gaussian(),
                        p[1] + self.jitter * rng.gaussian(),
                        p[2] + self.jitter * rng.gaussian(),
                    ]
                } else {
                    *p
                };
                points.push(q);
                labels.push(s as i64);
                parts.push(part);
            }
        }
        for _ in 0..self.background {
            points.push([
                rng.range(0.0, side),
                rng.range(0.0, side),
                rng.range(0.0, side),
            ]);
            labels.push(-1);
            parts.push(-1);
        }
        // Fisher–Yates shuffle of the three arrays together.
        for i in (1..points.len()).rev() {
            let j = rng.below(i as u64 + 1) as usize;
            points.swap(i, j);
            labels.swap(i, j);
            parts.swap(i, j);
        }
        Ok(Scene {
            points,
            labels,
            parts,
        })
    }

    /// One structure in local coordinates centred at the origin (lines
    /// along x; planes in z = 0; the box with its top at z = 0), with part
    /// ids.
    fn local_structure(&self, rng: &mut Rng) -> (Vec<[f64; 3]>, Vec<i64>) {
        let h = self.spacing;
        match self.kind {
            SceneKind::Lines => {
                let n = self.points_per_structure;
                let len = h * (n - 1) as f64;
                let mut t: Vec<f64> = if self.random_sampling {
                    (0..n).map(|_| rng.range(0.0, len)).collect()
                } else {
                    (0..n).map(|i| i as f64 * h).collect()
                };
                t.sort_by(f64::total_cmp);
                (
                    t.iter().map(|&t| [t - len / 2.0, 0.0, 0.0]).collect(),
                    vec![-1; n],
                )
            }
            SceneKind::Planes => {
                let n = self.points_per_structure;
                let (nu, nv) = plane_grid(n);
                let (w, d) = (h * (nu - 1) as f64, h * (nv - 1) as f64);
                let pts: Vec<[f64; 3]> = if self.random_sampling {
                    (0..n)
                        .map(|_| {
                            [
                                rng.range(-w / 2.0, w / 2.0),
                                rng.range(-d / 2.0, d / 2.0),
                                0.0,
                            ]
                        })
                        .collect()
                } else {
                    (0..nu * nv)
                        .take(n)
                        .map(|k| {
                            let (i, j) = (k % nu, k / nu);
                            [i as f64 * h - w / 2.0, j as f64 * h - d / 2.0, 0.0]
                        })
                        .collect()
                };
                (pts, vec![-1; n])
            }
            SceneKind::Polyhedron => open_box(h, [6, 9, 4], self.random_sampling, rng),
        }
    }

    /// Rotates and translates `local` at random until it is inside the box
    /// and `clearance` away from the structures already placed (or, for
    /// structure 1 with `crossing`, through structure 0).
    fn place(
        &self,
        rng: &mut Rng,
        index: usize,
        local: &[[f64; 3]],
        placed: &[Vec<[f64; 3]>],
        side: f64,
    ) -> Result<Vec<[f64; 3]>, SynthError> {
        let margin = 2.0;
        for _attempt in 0..20_000 {
            let rot = random_rotation(rng);
            let rotated: Vec<[f64; 3]> = local.iter().map(|&p| apply(&rot, p)).collect();
            let offset = if self.crossing && index == 1 {
                // Middle point on middle point (lines: the middle samples,
                // which then coincide; planes: the centroids), at ≥ 45°.
                let anchor = crossing_anchor(self.kind, &placed[0]);
                if !crossing_angle_ok(self.kind, &rotated, &placed[0]) {
                    continue;
                }
                let c = crossing_anchor(self.kind, &rotated);
                [anchor[0] - c[0], anchor[1] - c[1], anchor[2] - c[2]]
            } else {
                let (lo, hi) = crate::geometry::bounding_box(&rotated);
                let mut o = [0.0; 3];
                let mut fits = true;
                for k in 0..3 {
                    let (a, b) = (margin - lo[k], side - margin - hi[k]);
                    if a > b {
                        fits = false; // too big in this orientation
                        break;
                    }
                    o[k] = rng.range(a, b);
                }
                if !fits {
                    continue;
                }
                o
            };
            let pts: Vec<[f64; 3]> = rotated
                .iter()
                .map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]])
                .collect();
            let inside = pts
                .iter()
                .all(|p| p.iter().all(|&x| (0.0..=side).contains(&x)));
            if !inside {
                continue;
            }
            let c2 = self.clearance * self.clearance;
            let clear = placed.iter().enumerate().all(|(j, other)| {
                (self.crossing && index == 1 && j == 0)
                    || pts
                        .iter()
                        .all(|p| other.iter().all(|q| dist2(*p, *q) >= c2))
            });
            if clear {
                return Ok(pts);
            }
        }
        Err(SynthError::CannotPlace)
    }
}

/// Grid shape (nu, nv) of a plane of n points: nv = 5 rows (2 if n < 10),
/// nu = ⌈n/nv⌉ columns, filled row by row and trimmed to n (the paper's 40
/// points: 8 × 5).
fn plane_grid(n: usize) -> (usize, usize) {
    let nv = if n >= 10 { 5 } else { 2 };
    (n.div_ceil(nv).max(2), nv)
}

/// An open box (top + 4 walls) of `steps` = [a, b, c] grid steps of size h,
/// centred in x, y, its top at z = 0; 190 points for [6, 9, 4].
fn open_box(h: f64, steps: [usize; 3], random: bool, rng: &mut Rng) -> (Vec<[f64; 3]>, Vec<i64>) {
    let [a, b, c] = steps;
    let (w, d, ht) = (h * a as f64, h * b as f64, h * c as f64);
    let (x0, y0) = (-w / 2.0, -d / 2.0);
    let mut pts = Vec::new();
    let mut parts = Vec::new();
    // Grid version: top keeps its rim; x-walls keep the vertical edges.
    let top_n = (a + 1) * (b + 1);
    let xwall_n = (b + 1) * c;
    let ywall_n = (a - 1) * c;
    if random {
        // Same counts per facet, uniform positions on each facet.
        for _ in 0..top_n {
            pts.push([x0 + rng.range(0.0, w), y0 + rng.range(0.0, d), 0.0]);
            parts.push(0);
        }
        for (part, x) in [(1, x0), (2, x0 + w)] {
            for _ in 0..xwall_n {
                pts.push([x, y0 + rng.range(0.0, d), -rng.range(0.0, ht)]);
                parts.push(part);
            }
        }
        for (part, y) in [(3, y0), (4, y0 + d)] {
            for _ in 0..ywall_n {
                pts.push([x0 + rng.range(0.0, w), y, -rng.range(0.0, ht)]);
                parts.push(part);
            }
        }
        return (pts, parts);
    }
    for i in 0..=a {
        for j in 0..=b {
            pts.push([x0 + i as f64 * h, y0 + j as f64 * h, 0.0]);
            parts.push(0);
        }
    }
    for (part, x) in [(1, x0), (2, x0 + w)] {
        for j in 0..=b {
            for k in 1..=c {
                pts.push([x, y0 + j as f64 * h, -(k as f64) * h]);
                parts.push(part);
            }
        }
    }
    for (part, y) in [(3, y0), (4, y0 + d)] {
        for i in 1..a {
            for k in 1..=c {
                pts.push([x0 + i as f64 * h, y, -(k as f64) * h]);
                parts.push(part);
            }
        }
    }
    (pts, parts)
}

fn crossing_anchor(kind: SceneKind, first: &[[f64; 3]]) -> [f64; 3] {
    match kind {
        SceneKind::Lines => first[first.len() / 2],
        _ => centroid(first),
    }
}

/// Lines: directions at ≥ 45°; planes: normals at ≥ 45°.
fn crossing_angle_ok(kind: SceneKind, a: &[[f64; 3]], b: &[[f64; 3]]) -> bool {
    let axis = |p: &[[f64; 3]]| -> Option<[f64; 3]> {
        match kind {
            SceneKind::Lines => normalize([
                p[p.len() - 1][0] - p[0][0],
                p[p.len() - 1][1] - p[0][1],
                p[p.len() - 1][2] - p[0][2],
            ]),
            _ => {
                // Normal from three non-collinear points of the patch.
                let (p0, p1) = (p[0], p[1]);
                let u = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
                p.iter().find_map(|q| {
                    let v = [q[0] - p0[0], q[1] - p0[1], q[2] - p0[2]];
                    let n = cross(u, v);
                    (dot(n, n) > 1e-6 * dot(u, u) * dot(v, v))
                        .then(|| normalize(n))
                        .flatten()
                })
            }
        }
    };
    match (axis(a), axis(b)) {
        (Some(u), Some(v)) => dot(u, v).abs() <= (PI / 4.0).cos(),
        _ => true,
    }
}

fn centroid(p: &[[f64; 3]]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for q in p {
        for k in 0..3 {
            c[k] += q[k];
        }
    }
    let n = p.len().max(1) as f64;
    [c[0] / n, c[1] / n, c[2] / n]
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    dot(d, d)
}

/// A uniformly random rotation (rows): a random unit axis as the third
/// row, a random angle about it for the first two.
fn random_rotation(rng: &mut Rng) -> [[f64; 3]; 3] {
    let u = rng.unit_vector();
    let [a, b, _] = crate::aniso::completion_third_row(u);
    let (s, c) = rng.range(0.0, 2.0 * PI).sin_cos();
    let r1 = [
        c * a[0] + s * b[0],
        c * a[1] + s * b[1],
        c * a[2] + s * b[2],
    ];
    let r2 = cross(u, r1);
    [r1, r2, u]
}

/// Local coordinates (x, y, z) ↦ x·R₀ + y·R₁ + z·R₂ (rows as the new axes).
fn apply(r: &[[f64; 3]; 3], p: [f64; 3]) -> [f64; 3] {
    let mut o = [0.0; 3];
    for k in 0..3 {
        o[k] = p[0] * r[0][k] + p[1] * r[1][k] + p[2] * r[2][k];
    }
    o
}

/// The lines scene of Fig. 12 ([`SceneOptions::lines`]) with `seed`.
pub fn lines(seed: u64) -> Scene {
    // Default options always place (box ≫ structures); fall back to an
    // empty scene rather than panic if that ever changes.
    SceneOptions::lines()
        .seed(seed)
        .generate()
        .unwrap_or_else(|_| empty())
}

/// The planes scene of Fig. 5 ([`SceneOptions::planes`]) with `seed`.
pub fn planes(seed: u64) -> Scene {
    SceneOptions::planes()
        .seed(seed)
        .generate()
        .unwrap_or_else(|_| empty())
}

/// The polyhedron scene of Fig. 10 ([`SceneOptions::polyhedron`]) with `seed`.
pub fn polyhedron(seed: u64) -> Scene {
    SceneOptions::polyhedron()
        .seed(seed)
        .generate()
        .unwrap_or_else(|_| empty())
}

fn empty() -> Scene {
    Scene {
        points: Vec::new(),
        labels: Vec::new(),
        parts: Vec::new(),
    }
}

/// A small deterministic PRNG: xoshiro256** seeded through SplitMix64, with
/// uniform, Gaussian (Box–Muller) and unit-vector helpers. Same seed, same
/// stream, on every platform.
///
/// ```
/// use aniso_alpha::synth::Rng;
/// let mut a = Rng::new(7);
/// let mut b = Rng::new(7);
/// assert_eq!(a.next_u64(), b.next_u64());
/// let x = a.uniform();
/// assert!((0.0..1.0).contains(&x));
/// ```
#[derive(Debug, Clone)]
pub struct Rng {
    s: [u64; 4],
    spare: Option<f64>,
}

fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Rng {
    /// Seeds the four state words with SplitMix64(seed).
    pub fn new(seed: u64) -> Self {
        let mut st = seed;
        let s = [
            splitmix64(&mut st),
            splitmix64(&mut st),
            splitmix64(&mut st),
            splitmix64(&mut st),
        ];
        Self { s, spare: None }
    }

    /// Next 64 random bits (xoshiro256**).
    pub fn next_u64(&mut self) -> u64 {
        let result = self.s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = self.s[1] << 17;
        self.s[2] ^= self.s[0];
        self.s[3] ^= self.s[1];
        self.s[1] ^= self.s[2];
        self.s[0] ^= self.s[3];
        self.s[2] ^= t;
        self.s[3] = self.s[3].rotate_left(45);
        result
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }

    /// Uniform integer in 0..n, by rejection (no modulo bias).
    ///
    /// # Panics
    ///
    /// If `n` is 0.
    pub fn below(&mut self, n: u64) -> u64 {
        assert!(n > 0, "Rng::below(0)");
        let zone = u64::MAX - (u64::MAX % n);
        loop {
            let x = self.next_u64();
            if x < zone {
                return x % n;
            }
        }
    }

    /// Standard normal N(0, 1) by Box–Muller (the second value is cached).
    pub fn gaussian(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let u1 = 1.0 - self.uniform(); // (0, 1]
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (2.0 * std::f64::consts::PI * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }

    /// A uniformly distributed unit vector (Archimedes: z uniform in
    /// [−1, 1], azimuth uniform).
    pub fn unit_vector(&mut self) -> [f64; 3] {
        let z = self.range(-1.0, 1.0);
        let a = self.range(0.0, 2.0 * std::f64::consts::PI);
        let r = (1.0 - z * z).max(0.0).sqrt();
        [r * a.cos(), r * a.sin(), z]
    }
}

#[cfg(test)]
mod tests;
