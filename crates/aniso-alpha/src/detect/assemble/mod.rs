//! Assembling structures from the union of the scanned anisotropic
//! α-shapes (paper §4.3, last steps; docs/method.md §4 "Structures and
//! parts", §7). The stages, in the order [`assemble`] runs them:
//!
//! 1. **Candidates** (`candidates`). Each connected component of the
//!    cleaned union, within each group (the simplices found by one mode's
//!    orientations, at that mode's scale), is split into straight or flat
//!    pieces ([`super::parts`]); the piece fits, and the fit of the whole
//!    component, are candidate primitives. Greedily, the candidate covering
//!    the most not yet covered vertices within τ (the ellipsoid's short
//!    semi-axis α) is refitted on its inliers and taken.
//! 2. **Footprint** (`footprint`). The cells (side c, the ellipsoid's long
//!    reach α·λ) that a candidate's vertices occupy on its plane or along
//!    its line, grown by one cell: where the scanned α-shapes found it.
//! 3. **Members** (`widen`, `claims`). Where the regime says so, each
//!    candidate's claim radius widens with its noise. Every point within
//!    the claim radius of a primitive and over its footprint claims it
//!    (with normals given, planes only take points whose normal agrees);
//!    candidates that are one primitive and share claimed points are
//!    merged; each point goes to the nearest candidate claiming it, so
//!    parts are disjoint; candidates are refitted on their members and
//!    claim again.
//! 4. **Significance** (`significance`). With the test on, each part's
//!    number of false alarms ([`super::significance`]); parts above ε go.
//! 5. **One primitive, one part** (`merging`). Planar parts that are one
//!    plane but lie apart become one part in several pieces, unless a
//!    solid stands between them (`crossing`); a line keeps its segments
//!    apart ([`Shape::merge_apart`]).
//!    **Proportions** (`proportions`; with the data's orientations): a plane holds as many rows of
//!    points across as its ellipsoid is long in spacings, a line is as
//!    elongated as its ellipsoid; the others go.
//! 6. **Points left behind** (`claims::reclaim`). A point whose nearest
//!    claimer made no part, or a part that went, joins the nearest kept
//!    part claiming it; those parts are refitted.
//! 7. **Structures** (`structures`). Parts that share claimed points and
//!    do not cross each other are facets of one structure; structures and
//!    their parts are numbered by size, each part gets its outline and
//!    mesh or its segment, and every point its labels.
//!
//! What differs between lines and planes (the same-primitive tests, the
//! volume near a part, crossings, merging apart, outlines) is the
//! [`Shape`] of the simplices; the run-wide modes are the
//! [`super::regime::Regime`]'s.

mod candidates;
mod claims;
mod crossing;
mod embedded;
mod footprint;
mod merging;
mod moments;
mod proportions;
mod same;
mod select;
mod shape;
mod significance;
mod structures;
mod widen;

pub(crate) use shape::Shape;

use super::cloud::Cloud;
use super::detection::{Detection, Primitive, RunStats};
use super::filter::FilterError;
use super::regime::Regime;
use super::stages::{Clock, Stage};
use footprint::Footprint;

/// The scale of the candidates found by one group (mode) of orientations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Scale {
    /// Inlier distance τ (the α of the group's orientations).
    pub tau: f64,
    /// Footprint cell c (the ellipsoid's long reach α·λ).
    pub cell: f64,
}

/// What the assembly takes from the detector's parameters.
#[derive(Debug, Clone)]
pub(crate) struct Settings {
    /// Angle tolerance (degrees) of straight/flat pieces and of merging.
    pub part_angle_deg: f64,
    /// Whether plane parts get their outline and mesh
    /// ([`super::Detector::outlines`]).
    pub outlines: bool,
    /// Fewest points of a part ([`Shape::min_vertices`]).
    pub min_vertices: usize,
    /// The scale of each group.
    pub scales: Vec<Scale>,
    /// Times the stages for the detector's observer.
    pub clock: Clock,
}

/// A candidate part while it is assembled.
#[derive(Debug, Clone)]
pub(crate) struct Candidate {
    /// Its line or plane.
    fit: Primitive,
    /// Its claim radius.
    tau: f64,
    /// Its footprint's cell side.
    cell: f64,
    /// The points it was fitted on (ascending).
    seeds: Vec<u32>,
    /// Where it was found.
    foot: Footprint,
}

/// A part between the claims and the numbering of structures.
#[derive(Debug, Clone)]
pub(crate) struct Draft {
    /// Its points (ascending).
    members: Vec<u32>,
    /// Its line or plane, fitted on the members.
    fit: Primitive,
    /// The candidate it comes from (its claim radius and cell).
    cand: usize,
    /// The candidates of the other pieces of a plane found apart.
    pieces: Vec<usize>,
    /// log₁₀ of its number of false alarms (−∞ without the test).
    log10_nfa: f64,
}

/// Per candidate (of `n_cands`), the index among `parts` of the part it
/// made or is a piece of; `u32::MAX` for none.
fn part_of_candidates(parts: &[Draft], n_cands: usize) -> Vec<u32> {
    let mut part_of = vec![u32::MAX; n_cands];
    for (pi, p) in parts.iter().enumerate() {
        for c in std::iter::once(p.cand).chain(p.pieces.iter().copied()) {
            part_of[c] = pi as u32;
        }
    }
    part_of
}

#[cfg(test)]
impl Draft {
    /// For the stages' tests: a part of `members` with the primitive `fit`
    /// (and log₁₀ NFA −`cand`), and its candidate, number `cand`, of claim
    /// radius `tau` and footprint cell `cell`.
    fn with_candidate(
        points: &[[f64; 3]],
        members: Vec<u32>,
        fit: Primitive,
        cand: usize,
        (tau, cell): (f64, f64),
    ) -> (Draft, Candidate) {
        let c = Candidate {
            foot: Footprint::new(&fit, points, &members, cell).expect("a footprint"),
            fit: fit.clone(),
            tau,
            cell,
            seeds: members.clone(),
        };
        let d = Draft {
            members,
            fit,
            cand,
            pieces: Vec::new(),
            log10_nfa: -(cand as f64),
        };
        (d, c)
    }

    /// [`Draft::with_candidate`] with the line fitted to `members`.
    fn line(
        points: &[[f64; 3]],
        members: Vec<u32>,
        cand: usize,
        scale: (f64, f64),
    ) -> (Draft, Candidate) {
        let fit = Primitive::Line(
            super::fit::fit_line_indices(points, &members).expect("a line through the members"),
        );
        Draft::with_candidate(points, members, fit, cand, scale)
    }
}

/// For the stages' tests: 2,000 uniform background points in a 100-unit
/// cube (from `seed`) and 30 points aligned along x, 2 apart, after them;
/// the points and the first aligned one's index.
#[cfg(test)]
fn cube_with_a_line(seed: u64) -> (Vec<[f64; 3]>, u32) {
    let mut rng = crate::rng::SplitMix64::new(seed);
    let mut pts: Vec<[f64; 3]> = (0..2000)
        .map(|_| [0, 1, 2].map(|_| 100.0 * rng.uniform()))
        .collect();
    let n = pts.len() as u32;
    pts.extend((0..30).map(|i| [20.0 + 2.0 * i as f64, 50.0, 50.0]));
    (pts, n)
}

/// The parts one scale (level) of a run found, before they meet the other
/// levels' (stages 1–4): the candidates, their final claims, the parts
/// that passed the significance test, and the cleaned union they come
/// from.
pub(crate) struct Level<S> {
    cands: Vec<Candidate>,
    claims: claims::Claims,
    parts: Vec<Draft>,
    kept: Vec<S>,
}

/// Stages 1–4 of the assembly on the cleaned union `kept` of one level of
/// a run (its simplices found by the groups `group`); the parts the
/// significance test rejects are counted in `stats`.
pub(crate) fn level<S: Shape>(
    cloud: &Cloud<'_>,
    regime: &Regime,
    kept: Vec<S>,
    group: Vec<u32>,
    settings: &Settings,
    stats: &mut RunStats,
) -> Result<Level<S>, FilterError> {
    let points = cloud.points();
    let angle = settings.part_angle_deg;
    let clock = &settings.clock;
    // 1–2. Candidates and their footprints.
    let mut cands = clock.time(Stage::Candidates, || {
        candidates::find(points, &kept, &group, settings, regime)
    })?;
    // 3. Members: claim radii from the noise, claims, merging of
    // duplicates, resolution, refit, claims again.
    if regime.widens_claims() {
        clock.time(Stage::Widen, || widen::claim_radii::<S>(&mut cands, cloud));
    }
    let (cands, claims, mut parts) = clock.time(Stage::Claims, || {
        let (cands, claims) = claims::settle::<S>(cands, cloud, regime.claim_normals(), angle);
        let parts = claims::parts::<S>(&claims, cands.len(), points, settings.min_vertices);
        (cands, claims, parts)
    });
    clock.time(Stage::Significance, || {
        // 4. Significance.
        if let Some(log10_epsilon) = regime.significance() {
            stats.rejected_parts +=
                significance::reject::<S>(&mut parts, &cands, cloud, log10_epsilon);
        }
        // 4b. Lines inside a surface.
        if regime.drops_lines_inside_surfaces() {
            stats.surface_lines += S::reject_in_surface(&mut parts, &cands, cloud);
        }
    });
    Ok(Level {
        cands,
        claims,
        parts,
        kept,
    })
}

/// Stages 5–7 of the assembly over the `levels` of a run: the parts kept
/// across levels (the most significant first, `select`), one part per
/// primitive, structures, outlines and labels. The cloud's kd-tree is
/// freed once the levels are selected: nothing after queries it.
pub(crate) fn finish<S: Shape>(
    cloud: &mut Cloud<'_>,
    regime: &Regime,
    mut levels: Vec<Level<S>>,
    settings: &Settings,
    mut stats: RunStats,
) -> Detection {
    let Level {
        cands,
        claims,
        mut parts,
        kept,
    } = if levels.len() == 1 {
        levels.pop().expect("one level")
    } else {
        settings.clock.time(Stage::Select, || {
            select::across_levels::<S>(levels, cloud, regime, settings.min_vertices)
        })
    };
    cloud.release_index();
    let cloud = &*cloud;
    let clock = &settings.clock;
    // 5. One primitive, one part.
    stats.faces_apart += clock.time(Stage::Merge, || {
        S::merge_apart(&mut parts, &cands, cloud.points(), settings.part_angle_deg)
    });
    // 5b. Proportions at the ellipsoid's scale.
    if regime.checks_proportions() {
        stats.out_of_proportion += clock.time(Stage::Proportions, || {
            proportions::reject(&mut parts, &cands, cloud.points())
        });
    }
    // 6–7. Points left behind, to the kept parts claiming them;
    // structures, outlines, labels.
    clock.time(Stage::Structures, || {
        stats.reclaimed_points +=
            claims::reclaim::<S>(&mut parts, &claims, cands.len(), cloud.points());
        structures::detection::<S>(cloud, settings.outlines, parts, cands, claims, kept, stats)
    })
}
