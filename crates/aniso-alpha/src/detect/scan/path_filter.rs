//! The path filter of each orientation of the scan (docs/method.md §3,
//! §4) and its thresholds.
//!
//! Without the significance test it is the paper's filter with the user's
//! nb_c. For lines under the test ([`Regime::keeps_short_lines`]) the
//! threshold is measured from the background ([`ScanFilter::new`]): a line
//! jittered by about the ellipsoid's radius, or crowded by background
//! points that hang spurs on it, reaches one orientation's filter in
//! pieces of two or three edges, which nb_c = 4 deletes in every
//! orientation (issue 14: recall 0.3–0.5 at σ = 0.1 d, 0.6–0.7 at 10× the
//! background). The pieces are joined along their fitted line by the
//! assembly's claims, and the significance test, not nb_c, decides what
//! chance explains. The filter also follows straight chains through
//! ramifications ([`straight_filter`]). Planes keep
//! nb_c: a plane's α-shape stays in one piece under the same jitter (its
//! triangles span two directions), and the scan's cost grows with what the
//! filter lets through.

use super::{Face, ScanError};
use crate::detect::cloud::Cloud;
use crate::detect::filter::{filter, filter_mask, FilterError};
use crate::detect::regime::Regime;

/// The shortest path the line scan keeps under the significance test: two
/// edges, three points, the fewest whose straightness says anything
/// (two points always lie on a line).
pub(crate) const LINE_SCAN_MIN: u32 = 2;

/// Chance paths the line scan may let through to the assembly: 100. At
/// the paper's density (0.01 points per ellipsoid, 1,550 points, 162
/// orientations) paths of two edges number about 25, so the scan keeps
/// them; at 3× the density three edges, at 10× the user's nb_c. Beyond a
/// few hundred chance paths the union's components merge into a web
/// that the assembly cannot take apart into lines (measured at 10×: 188,000
/// union edges with two-edge paths, no line found).
const CHANCE_PATHS: f64 = 100.0;

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

/// What the scan's thresholds depend on: the cloud's size, the number of
/// orientations and the background points per α-ellipsoid (the cloud's
/// distinct points over its bounding box's volume, times the ellipsoid's
/// volume).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ChanceScale {
    /// Distinct points.
    pub points: f64,
    /// Orientations scanned.
    pub orientations: f64,
    /// Expected points per α-ellipsoid under a uniform background.
    pub per_ellipsoid: f64,
}

impl ChanceScale {
    /// For `cloud`, the ellipsoid of radius `alpha` and semi-axes
    /// `alpha/e_i` (`elongation` e), over `orientations` orientations.
    pub(crate) fn new(
        cloud: &Cloud<'_>,
        alpha: f64,
        elongation: [f64; 3],
        orientations: usize,
    ) -> Self {
        let ellipsoid = 4.0 / 3.0 * std::f64::consts::PI * alpha.powi(3)
            / (elongation[0] * elongation[1] * elongation[2]);
        let n = cloud.distinct_count() as f64;
        ChanceScale {
            points: n,
            orientations: orientations as f64,
            per_ellipsoid: n / cloud.volume() * ellipsoid,
        }
    }
}

/// The path filter of one orientation: its threshold, and for lines
/// under the significance test the straightness at which a chain is
/// followed through a ramification (docs/method.md §4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScanFilter {
    /// The path filter's nb_c.
    pub nb_c: u32,
    /// `Some(c)`: edges only; at a vertex of degree ≥ 3 the two edges
    /// whose directions (in the orientation's metric) make a cosine ≤ −c
    /// stay joined and the others are cut loose ([`straight_filter`]).
    /// `None`: the paper's filter.
    pub straight_cos: Option<f64>,
}

impl ScanFilter {
    /// The filter of every orientation of a run in `regime` with the
    /// user's `nb_c` (module doc).
    pub(crate) fn new(regime: &Regime, nb_c: u32, chance: ChanceScale) -> Self {
        if !regime.keeps_short_lines() {
            return ScanFilter {
                nb_c,
                straight_cos: None,
            };
        }
        ScanFilter {
            nb_c: short_lines_min_size(nb_c, chance),
            straight_cos: regime
                .follows_straight_chains()
                .then(|| straight_cos(chance)),
        }
    }
}

/// The path filter's threshold for short lines: chance paths of l edges
/// per orientation number about n·x^l, x the background points per
/// α-ellipsoid (each further edge needs a point in the next ellipsoid
/// along); over the scan, times the orientations. The shortest l, from
/// [`LINE_SCAN_MIN`] up to nb_c, with at most [`CHANCE_PATHS`] of them.
fn short_lines_min_size(nb_c: u32, chance: ChanceScale) -> u32 {
    let x = chance.per_ellipsoid.clamp(1e-12, 1.0);
    let mut l = LINE_SCAN_MIN;
    while l < nb_c && chance.points * chance.orientations * x.powi(l as i32) > CHANCE_PATHS {
        l += 1;
    }
    l.min(nb_c)
}

/// The straightness at which the straight filter follows a chain: the
/// cosine c of the largest turn allowed. Two edges of chance meet in a
/// straight-enough continuation with probability (1 − c)/2 (directions
/// uniform on the sphere); a chance continuation needs a background point
/// in the next ellipsoid too, so chance chains grow by about x·(1 − c)/2
/// per vertex, x the background points per α-ellipsoid. c is the smallest
/// cosine keeping that at most [`CHANCE_CONTINUATION`], within
/// [`STRAIGHT_COS_RANGE`]: at the paper's density (x = 0.01) turns up to
/// 60° are followed (a line jittered by about α zigzags), at 10× (x = 0.1)
/// up to 18° (background fans hang on every line).
fn straight_cos(chance: ChanceScale) -> f64 {
    let x = chance.per_ellipsoid.max(1e-12);
    let (lo, hi) = STRAIGHT_COS_RANGE;
    (1.0 - 2.0 * CHANCE_CONTINUATION / x).clamp(lo, hi)
}

/// The filter of one job's raw faces (sorted, distinct), in its metric.
pub(crate) fn filter_job<S: Face>(
    faces: &[S],
    points: &[[f64; 3]],
    anisotropy: &crate::aniso::Anisotropy,
    sf: ScanFilter,
) -> Result<Vec<S>, ScanError> {
    match sf.straight_cos {
        Some(c) if S::VERTICES == 2 => {
            let edges: Vec<[u32; 2]> = faces
                .iter()
                .map(|f| [f.as_ref()[0], f.as_ref()[1]])
                .collect();
            let keep = straight_filter(&edges, points, anisotropy, sf.nb_c, c)?;
            Ok(faces
                .iter()
                .zip(keep)
                .filter_map(|(&f, k)| k.then_some(f))
                .collect())
        }
        _ => filter(faces, sf.nb_c).map_err(ScanError::Filter),
    }
}

/// The path filter on edges with *good continuation*; the verdict per
/// edge (true = kept). At a vertex where three or more edges meet, the
/// two edges that continue each other most straightly (their directions
/// from the vertex, in the metric Q of the orientation, make the most
/// negative cosine), if that cosine is at most `−straight_cos`, stay
/// joined there, and every other edge there is cut loose: it ends at a
/// copy of the vertex. Then the path filter of docs/method.md §3 runs on
/// the edges so rewired. A chain with stray points hung on it (spurs, or
/// fans of triangles' edges to a point beside it) is then one path, and
/// the strays short pieces that the filter deletes; without it the
/// ramifications cut the chain into pieces shorter than nb_c, and the
/// filter deletes the chain with the strays (issue 14: two lines in five
/// lost at 10× the paper's background). Where no pair is straight enough
/// the vertex stays a ramification, as in the paper.
pub(crate) fn straight_filter(
    edges: &[[u32; 2]],
    points: &[[f64; 3]],
    q: &crate::aniso::Anisotropy,
    nb_c: u32,
    straight_cos: f64,
) -> Result<Vec<bool>, ScanError> {
    use crate::geometry::{dot, sub};
    // Incidences (vertex, edge, end), grouped by vertex.
    let mut inc: Vec<(u32, u32, u8)> = Vec::with_capacity(2 * edges.len());
    for (i, e) in edges.iter().enumerate() {
        inc.push((e[0], i as u32, 0));
        inc.push((e[1], i as u32, 1));
    }
    inc.sort_unstable();
    let mut rewired: Vec<[u32; 2]> = edges.to_vec();
    // Copies of vertices get ids after every input index; the filter only
    // looks at ids.
    let mut copies = points.len() as u64;
    let mut dirs: Vec<[f64; 3]> = Vec::new();
    for here in inc.chunk_by(|a, b| a.0 == b.0) {
        if here.len() < 3 {
            continue;
        }
        let pv = q.transform_point(points[here[0].0 as usize]);
        dirs.clear();
        dirs.extend(here.iter().map(|&(_, e, end)| {
            let w = edges[e as usize][1 - end as usize];
            let d = sub(q.transform_point(points[w as usize]), pv);
            let n = dot(d, d).sqrt().max(f64::MIN_POSITIVE);
            d.map(|c| c / n)
        }));
        let mut best = (f64::INFINITY, 0, 0);
        for a in 0..dirs.len() {
            for b in a + 1..dirs.len() {
                let c = dot(dirs[a], dirs[b]);
                if c < best.0 {
                    best = (c, a, b);
                }
            }
        }
        if best.0 > -straight_cos {
            continue;
        }
        for (j, &(_, e, end)) in here.iter().enumerate() {
            if j != best.1 && j != best.2 {
                if copies >= u64::from(u32::MAX) {
                    return Err(ScanError::Filter(FilterError::TooManySimplices(
                        edges.len(),
                    )));
                }
                rewired[e as usize][end as usize] = copies as u32;
                copies += 1;
            }
        }
    }
    filter_mask(&rewired, nb_c).map_err(ScanError::Filter)
}

#[cfg(test)]
mod straight_tests {
    use super::*;
    use crate::detect::StructureKind;

    #[test]
    fn short_lines_take_their_threshold_from_the_background() {
        // The paper's lines scene: 1,550 points, 162 orientations.
        let chance = |x: f64| ChanceScale {
            points: 1550.0,
            orientations: 162.0,
            per_ellipsoid: x,
        };
        let lines = Regime::new(StructureKind::Lines, Some(1.0), false, None);
        // At the paper's density, paths of two edges (25 by chance) and
        // turns up to 60°.
        let sf = ScanFilter::new(&lines, 4, chance(0.01));
        assert_eq!((sf.nb_c, sf.straight_cos), (2, Some(0.5)));
        // At 10×, the user's nb_c (three edges: 251 by chance) and 18°.
        let sf = ScanFilter::new(&lines, 4, chance(0.1));
        assert_eq!(sf.nb_c, 4);
        assert!((sf.straight_cos.unwrap() - 0.95).abs() < 1e-12);
        // The data's orientations: the same (a densely sampled cable).
        let data = Regime::new(StructureKind::Lines, Some(1.0), true, None);
        let sf = ScanFilter::new(&data, 4, chance(0.01));
        assert_eq!((sf.nb_c, sf.straight_cos), (2, Some(0.5)));
        // Planes, and lines without the test: the paper's filter.
        for kind in [StructureKind::Planes, StructureKind::Lines] {
            let paper = Regime::new(
                kind,
                (kind == StructureKind::Planes).then_some(1.0),
                false,
                None,
            );
            let sf = ScanFilter::new(&paper, 4, chance(0.01));
            assert_eq!((sf.nb_c, sf.straight_cos), (4, None));
        }
    }

    /// A chain of ten points along x with a stray point beside its middle,
    /// joined to four chain points (a fan of triangles' edges).
    fn chain_with_fan() -> (Vec<[f64; 3]>, Vec<[u32; 2]>) {
        let mut points: Vec<[f64; 3]> = (0..10).map(|i| [i as f64, 0.0, 0.0]).collect();
        points.push([4.5, 0.5, 0.0]);
        let mut edges: Vec<[u32; 2]> = (0..9).map(|i| [i, i + 1]).collect();
        edges.extend([[3, 10], [4, 10], [5, 10], [6, 10]]);
        (points, edges)
    }

    #[test]
    fn a_fan_does_not_shred_a_chain() {
        let (points, edges) = chain_with_fan();
        // The paper's filter: the fan's ramifications cut the chain into
        // pieces of one to three edges, all deleted at nb_c = 4.
        assert!(filter(&edges, 4).unwrap().is_empty());
        // Good continuation: the chain is one path, the fan goes.
        let q = crate::aniso::Anisotropy::euclidean();
        let keep = straight_filter(&edges, &points, &q, 4, 0.866).unwrap();
        assert_eq!(keep, [vec![true; 9], vec![false; 4]].concat());
    }

    #[test]
    fn a_turn_sharper_than_allowed_stays_a_ramification() {
        // A chain bent by 90° at vertex 3, with a spur there: no pair at
        // vertex 3 is straight, so it stays a ramification and the short
        // pieces go, as in the paper's filter.
        let points = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [3.0, 1.0, 0.0],
            [3.0, 2.0, 0.0],
            [3.0, 3.0, 0.0],
            [2.0, -1.0, 0.0],
        ];
        let edges = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 6], [3, 7]];
        let q = crate::aniso::Anisotropy::euclidean();
        let keep = straight_filter(&edges, &points, &q, 4, 0.866).unwrap();
        let paper = filter_mask(&edges, 4).unwrap();
        assert_eq!(keep, paper);
        // With any turn allowed, the straightest pair (the spur and the
        // leg it continues best) is followed instead.
        let loose = straight_filter(&edges, &points, &q, 4, -1.0).unwrap();
        assert_ne!(loose, paper);
    }
}
