//! Claim radii from the noise (docs/method.md §4, step 3, where the regime
//! widens claims): each candidate claims with the radius among a few
//! multiples of its τ ([`CLAIM_RADII`]) whose tube (line) or slab (plane)
//! makes it least explicable by chance, as the significance test measures
//! it. A line jittered by σ has its points' distances to the line
//! Rayleigh-distributed; a claim radius of α alone would leave a noisy
//! line's points out. A line candidate is judged at a wider radius as it
//! would claim there: fitted again on its points within that radius (a
//! short piece of a noisy line leans), and the radius chosen brings its
//! refitted line.

use super::super::cloud::Cloud;
use super::super::detection::Primitive;
use super::super::fit::fit_line_indices;
use super::super::significance::{log10_n_tests, part_log10_nfa};
use super::footprint::{near_points, Footprint};
use super::significance::SHELL_RATIO;
use super::{Candidate, Shape};
use crate::par::map_each;

/// Claim radii tried for a candidate, in units of its τ: a line whose
/// points are jittered by σ per coordinate has its distances to the line
/// Rayleigh-distributed, 99% within 3.03σ; radii up to 3α keep such a
/// line whole for σ up to α, the scale at which the paper's ellipsoid
/// itself stops joining its points.
pub(super) const CLAIM_RADII: [f64; 3] = [1.0, 2.0, 3.0];

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
pub(super) const MAX_WIDEN_BACKGROUND: f64 = 1.0;

/// Sets each candidate's claim radius (module doc). Candidates in
/// parallel, and a large candidate's near points too ([`near_points`]).
pub(super) fn claim_radii<S: Shape>(cands: &mut [Candidate], cloud: &Cloud<'_>) {
    let rho_global = cloud.distinct_count() as f64 / cloud.volume();
    cloud.build_index();
    let log10_tests =
        log10_n_tests(cloud.distinct_count(), S::K) + (CLAIM_RADII.len() as f64).log10();
    let taus = map_each(cands.len(), |ci| {
        best_radius::<S>(&cands[ci], cloud, rho_global, log10_tests)
    });
    for (c, (tau, fit)) in cands.iter_mut().zip(taus) {
        c.tau = tau;
        if let Some(fit) = fit {
            if let Some(foot) = Footprint::new(&fit, cloud.points(), &c.seeds, c.cell) {
                c.fit = fit;
                c.foot = foot;
            }
        }
    }
}

/// The claim radius of one candidate: among its shape's radii
/// ([`Shape::claim_radii`]), the one of smallest NFA, a wider one only if
/// it lowers the NFA by [`WIDEN_GAIN`]. The local density is measured in
/// the shell (r, [`SHELL_RATIO`]·r] of each radius r, at least the global
/// `rho_global`.
fn best_radius<S: Shape>(
    c: &Candidate,
    cloud: &Cloud<'_>,
    rho_global: f64,
    log10_tests: f64,
) -> (f64, Option<Primitive>) {
    let points = cloud.points();
    let base = c.tau;
    let near = S::near(&c.fit, &c.foot, c.cell, &c.seeds, points);
    let radii = S::claim_radii(c, near, rho_global);
    if radii.len() < 2 {
        return (base, None);
    }
    let vol = |t: f64| near.volume(t);
    // One pass over the points near the candidate, out to the widest
    // radius's shell; each radius then counts its own.
    let reach = SHELL_RATIO * radii.last().copied().unwrap_or(base);
    let near_pts = near_points(&c.fit, &c.foot, reach, cloud.index());
    let mut best = (f64::INFINITY, base, None);
    for &r in &radii {
        // A line as it would claim at r: fitted again on its points within
        // r. A line candidate is often a short piece of its line (the
        // chain its ellipsoid followed until a jittered point fell outside
        // it), and the fit of a few points over a short span leans: the
        // line's far points lie outside the piece's tube at any radius,
        // and inside a tube of the line through all of them. A plane's
        // candidate spans a patch both ways, and is not fitted again.
        let fit_r = if S::K == 1 && r > base {
            // In index order: the fit of a set, whatever order the
            // kd-tree's boxes reported it in.
            let mut within: Vec<u32> = near_pts.iter().filter(|x| x.1 <= r).map(|x| x.0).collect();
            within.sort_unstable();
            fit_line_indices(points, &within).ok().map(Primitive::Line)
        } else {
            None
        };
        let dist: Vec<f64> = match &fit_r {
            Some(f) => near_pts
                .iter()
                .map(|&(i, _)| f.distance(&points[i as usize]))
                .collect(),
            None => near_pts.iter().map(|x| x.1).collect(),
        };
        let outer = SHELL_RATIO * r;
        let residuals: Vec<f64> = dist.iter().copied().filter(|&d| d <= r).collect();
        let shell = dist.iter().filter(|&&d| d > r && d <= outer).count();
        let rho_local = (shell as f64 + 1.0) / (vol(outer) - vol(r)).max(1e-300);
        let rho = rho_local.max(rho_global);
        let nfa = part_log10_nfa(&residuals, S::K, r, rho, &vol, log10_tests);
        if nfa < best.0 - WIDEN_GAIN {
            best = (nfa, r, fit_r);
        }
    }
    (best.1, best.2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::cloud::Copies;
    use crate::rng::SplitMix64;

    /// A line of 40 points along x, jittered by σ = 0.3 per coordinate
    /// across it, among `background` uniform points in a 40-unit cube: its
    /// candidate fitted on the points within 0.3 of the axis, with
    /// τ = 0.3, and the cloud.
    fn noisy_line(background: usize) -> (Vec<[f64; 3]>, Candidate) {
        let sigma = 0.3;
        let mut rng = SplitMix64::new(3);
        let mut gauss = || {
            let (u, v) = (rng.uniform().max(1e-12), rng.uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let mut pts: Vec<[f64; 3]> = (0..40)
            .map(|i| [i as f64, sigma * gauss(), sigma * gauss()])
            .collect();
        let mut rng = SplitMix64::new(4);
        pts.extend((0..background).map(|_| {
            [
                40.0 * rng.uniform(),
                40.0 * rng.uniform() - 20.0,
                40.0 * rng.uniform() - 20.0,
            ]
        }));
        let seeds: Vec<u32> = (0..40)
            .filter(|&i| {
                let p = pts[i as usize];
                (p[1] * p[1] + p[2] * p[2]).sqrt() <= 0.3
            })
            .collect();
        let fit = Primitive::Line(fit_line_indices(&pts, &seeds).unwrap());
        let foot = super::super::Footprint::new(&fit, &pts, &seeds, 3.0).unwrap();
        let cand = Candidate {
            fit,
            tau: 0.3,
            cell: 3.0,
            seeds,
            foot,
        };
        (pts, cand)
    }

    #[test]
    fn a_noisy_line_claims_wider_unless_the_background_is_dense() {
        // 200 background points: a tube of 2τ along the line expects 0.14
        // of them, 3τ 0.3, so every radius may be tried, and a wider one
        // holds most of the line's points (within τ only 40% of them). With
        // 4,000, a tube of 2τ would take in 2.8 background points: more
        // than MAX_WIDEN_BACKGROUND, so the claims stay at τ.
        for (background, widened) in [(200, true), (4000, false)] {
            let (pts, cand) = noisy_line(background);
            let copies = Copies::none(pts.len());
            let cloud = Cloud::new(&pts, &copies);
            let mut cands = vec![cand];
            claim_radii::<[u32; 2]>(&mut cands, &cloud);
            let tau = cands[0].tau;
            assert_eq!(tau > 0.3, widened, "{background}: {tau}");
            assert!(CLAIM_RADII.iter().any(|&f| f * 0.3 == tau));
        }
    }
}
