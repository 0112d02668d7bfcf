//! Stage 4 of the assembly (docs/method.md §4, "Significance"): each
//! part's number of false alarms under a Poisson background
//! ([`super::super::significance`]), with the density measured around the
//! part, and the parts above ε dropped.

use super::super::cloud::Cloud;
use super::super::detection::Primitive;
use super::super::fit::LineFit;
use super::super::significance::{log10_n_tests, part_log10_nfa};
use super::footprint::for_near;
use super::{Candidate, Draft, Footprint, Shape};
use crate::geometry::{normalize, sub};
use crate::par::map_each;

/// Ratio of the outer to the inner radius of the shell in which the local
/// background density around a part is measured.
pub(super) const SHELL_RATIO: f64 = 4.0;

/// Sets each part's log₁₀ NFA and drops the parts above `log10_epsilon`;
/// how many went. The background density is that of the points outside
/// every part over the cloud's bounding box, or the local one around a
/// part if higher. Parts in parallel.
pub(super) fn reject<S: Shape>(
    parts: &mut Vec<Draft>,
    cands: &[Candidate],
    cloud: &Cloud<'_>,
    log10_epsilon: f64,
) -> usize {
    let in_parts: usize = parts.iter().map(|p| p.members.len()).sum();
    let rho_global = cloud.distinct_count().saturating_sub(in_parts) as f64 / cloud.volume();
    let log10_tests = log10_n_tests(cloud.distinct_count(), S::K);
    let nfas = map_each(parts.len(), |pi| {
        let p = &parts[pi];
        part_nfa::<S>(p, &cands[p.cand], cloud, rho_global, log10_tests)
    });
    for (p, nfa) in parts.iter_mut().zip(nfas) {
        if let Some(nfa) = nfa {
            p.log10_nfa = nfa;
        }
    }
    let before = parts.len();
    parts.retain(|p| p.log10_nfa <= log10_epsilon);
    before - parts.len()
}

/// The log₁₀ NFA of part `p` of candidate `c` (`None` without a
/// footprint: the part is kept untested).
///
/// The least-squares fit of a clean structure is pulled off it by the few
/// background points its claim radius takes in (at 10× the paper's
/// density, a wall of 20 exact points fits with an RMS of 0.3 α and its
/// thin widths miss it). So the fit on the better half of the members (at
/// least k + 2) is tried too, and the better of the two NFAs kept (two
/// primitives per part: one more factor 2 in the tests).
fn part_nfa<S: Shape>(
    p: &Draft,
    c: &Candidate,
    cloud: &Cloud<'_>,
    rho_global: f64,
    log10_tests: f64,
) -> Option<f64> {
    let points = cloud.points();
    let residuals: Vec<f64> = p
        .members
        .iter()
        .map(|&v| p.fit.distance(&points[v as usize]))
        .collect();
    let thick = residuals.iter().copied().fold(0.0, f64::max);
    let tau = c.tau.max(thick);
    // Footprint extent from the members (cells they occupy).
    let foot = Footprint::new(&p.fit, points, &p.members, c.cell)?;
    let near = S::near(&p.fit, &foot, c.cell, &p.members, points);
    let vol = |t: f64| near.volume(t);
    // Local density in the shell (τ, 4τ] over the footprint.
    let outer = SHELL_RATIO * tau;
    let mut shell = 0usize;
    for_near(&p.fit, &foot, outer, cloud.index(), &mut |_, d| {
        if d > tau {
            shell += 1;
        }
    });
    let rho_local = (shell as f64 + 1.0) / (vol(outer) - vol(tau)).max(1e-300);
    let rho = rho_local.max(rho_global);
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
    if S::K == 1 {
        if let Some(pair) = pair_line_nfa(points, &p.members, tau, rho, &vol, tests) {
            nfa = nfa.min(pair);
        }
    }
    Some(nfa)
}

/// Members of a line part from which [`pair_line_nfa`] draws its pairs: at
/// most this many, evenly spaced in the members' order (496 pairs). A part
/// of a few dozen points, where a fit can lean, has them all.
const PAIR_MEMBERS: usize = 32;

/// The smallest log₁₀ NFA of a line part's members against the lines
/// through two of them ([`PAIR_MEMBERS`] at most): `None` for fewer than
/// two distinct points.
///
/// The test's own primitives are the lines through two points of the cloud
/// ([`log10_n_tests`](super::super::significance::log10_n_tests) counts
/// them), and a least-squares fit is only one of them. Among few points,
/// a fit is pulled off the structure by the background points its tube
/// took in: ten exact points 7 apart with three background points near
/// their ends (the paper's scene at 10× its background) fit with residuals
/// up to 0.6 α, and neither the fit nor its better half's is significant,
/// where the line through two of the ten holds all ten exactly.
fn pair_line_nfa(
    points: &[[f64; 3]],
    members: &[u32],
    tau: f64,
    rho: f64,
    vol: &dyn Fn(f64) -> f64,
    tests: f64,
) -> Option<f64> {
    let step = members.len().div_ceil(PAIR_MEMBERS).max(1);
    let picks: Vec<[f64; 3]> = members
        .iter()
        .step_by(step)
        .map(|&v| points[v as usize])
        .collect();
    let mut residuals = vec![0.0; members.len()];
    let mut best: Option<f64> = None;
    for (a, p) in picks.iter().enumerate() {
        for q in &picks[a + 1..] {
            let Some(direction) = normalize(sub(*q, *p)) else {
                continue;
            };
            let line = Primitive::Line(LineFit {
                centroid: *p,
                direction,
                rms_residual: 0.0,
                extent: 0.0,
            });
            for (r, &v) in residuals.iter_mut().zip(members) {
                *r = line.distance(&points[v as usize]);
            }
            let nfa = part_log10_nfa(&residuals, 1, tau, rho, vol, tests);
            best = Some(best.map_or(nfa, |b: f64| b.min(nfa)));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::cloud::Copies;

    /// A part of the points `members` of `pts` fitted as a line, with its
    /// candidate (τ 0.5, cell 5).
    fn line_part(pts: &[[f64; 3]], members: Vec<u32>, cand: usize) -> (Draft, Candidate) {
        Draft::line(pts, members, cand, (0.5, 5.0))
    }

    #[test]
    fn an_aligned_run_is_significant_and_a_chance_triple_is_not() {
        // 2,000 background points in a 100-unit cube, 30 exactly aligned
        // points, and three background points that happen to be nearly
        // aligned (a chance "line").
        let (mut pts, n) = super::super::cube_with_a_line(11);
        pts.extend([[10.0, 10.0, 10.0], [13.0, 10.2, 10.0], [16.0, 9.9, 10.1]]);
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let (line, cand_line) = line_part(&pts, (n..n + 30).collect(), 0);
        let (triple, cand_triple) = line_part(&pts, (n + 30..n + 33).collect(), 1);
        let mut parts = vec![line, triple];
        let rejected = reject::<[u32; 2]>(&mut parts, &[cand_line, cand_triple], &cloud, 0.0);
        assert_eq!(rejected, 1);
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].members.len(), 30);
        assert!(parts[0].log10_nfa < -20.0, "{}", parts[0].log10_nfa);
    }
}
