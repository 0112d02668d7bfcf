//! The a-contrario significance test of a detected part (Desolneux, Moisan
//! & Morel's framework, as in the LSD line segment detector).
//!
//! **Model.** Under the background hypothesis H₀, the points near a part
//! are a Poisson process of density ρ (points per unit volume). A part is
//! a primitive (a line or a plane) with the m points it claimed. For a
//! thickness t, the region within t of the primitive over the part's
//! extent has volume V(t): a tube πt²L along a line (L the span of its
//! points), a slab 2tA over a plane (A the area of the cells its points
//! cover, grown by one cell). Under H₀ it holds Poisson(ρ·V(t)) points.
//! The primitive itself is fitted to the points; as in the a-contrario
//! detection of point alignments (Lezama, Morel, Randall & Grompone von
//! Gioi, 2015), it is counted as *one of the lines through two points*
//! (planes: through three) of the cloud, and those k + 1 points are not
//! random: of the m(t) points within t, m(t) − k − 1 are. So
//!
//! NFA(t) = N_tests · P[Poisson(ρ·V(t)) ≥ m(t) − k − 1],
//!
//! and the part's NFA is the smallest over the [`WIDTHS`] thicknesses
//! t = τ, τ/2, …, τ/2¹¹ (τ the part's claim radius, or its largest
//! residual if larger): a clean structure is significant in a thin tube
//! that chance cannot fill, a noisy one in a wider tube. The number of
//! tests is N_tests = C(n, k + 1)·[`WIDTHS`], n the number of distinct
//! points: every primitive a part could have been, at every thickness
//! tried. A part is kept when NFA ≤ ε (ε = 1 by default: on average less
//! than one false detection per cloud, the usual choice).
//!
//! **The density.** ρ is the larger of two estimates measured from the
//! data: the *global* background density (points outside every candidate
//! part, over the volume of the cloud's bounding box: right for a uniform
//! background, the paper's scenes) and the *local* one around the part
//! (points at distance between τ and 4τ from the primitive over the same
//! extent, plus one, over that shell's volume: right for clutter that
//! crowds some structures and not others). Taking the larger makes the
//! test conservative.
//!
//! **Assumptions, and where they fail.** Background points are independent
//! and locally uniform: clustered clutter (foliage, a second structure
//! nearby) is denser than ρ in places and can pass, which the local
//! density only partly catches. The extent (length, footprint) is
//! measured on the part and not counted among the tests; the area of a
//! plane is taken generously (cells grown by one) to compensate. The
//! count of tests ignores the orientations scanned: the primitive is
//! fitted to points, not taken from the orientation that found them.
//! Structures of fewer than k + 2 points are never significant.

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; relative error < 1e-13).
pub fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, &g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// log₁₀ P[Poisson(μ) ≥ m]. Exact series for μ < m; 0 (probability taken
/// as 1) when μ ≥ m, where the tail is at least about one half and the
/// part is never significant anyway.
pub fn log10_poisson_tail(mu: f64, m: u64) -> f64 {
    if m == 0 {
        return 0.0;
    }
    if mu.is_nan() || mu <= 0.0 {
        return f64::NEG_INFINITY;
    }
    let mf = m as f64;
    if mu >= mf {
        return 0.0;
    }
    // ln of the first term, then the sum of ratios μ/(k+1).
    let ln_first = -mu + mf * mu.ln() - ln_gamma(mf + 1.0);
    let mut sum = 1.0;
    let mut term = 1.0;
    let mut k = mf;
    loop {
        k += 1.0;
        term *= mu / k;
        sum += term;
        if term < 1e-17 * sum {
            break;
        }
    }
    ((ln_first + sum.ln()) / std::f64::consts::LN_10).min(0.0)
}

/// log₁₀ NFA of `m` points in a region where chance puts Poisson(`mu`)
/// points, among `n_tests` tests.
pub fn log10_nfa(n_tests: f64, mu: f64, m: u64) -> f64 {
    n_tests.max(1.0).log10() + log10_poisson_tail(mu, m)
}

/// Number of thicknesses tried per part: the claim radius τ and its
/// halvings down to τ/2¹¹ ≈ τ/2000. Twelve steps reach from the scale of
/// the ellipsoid to far below any sampling noise worth telling apart (an
/// exact grid line has residuals of 1e-15·τ and is caught by the last
/// step anyway); each step doubles the tube's or slab's thinness, so the
/// best width is within a factor 2 of the part's own.
pub const WIDTHS: u32 = 12;

/// log₁₀ of the number of tests: the primitives a part can be, a line
/// through 2 of the `n` points (k = 1) or a plane through 3 (k = 2), i.e.
/// C(n, k + 1), times the [`WIDTHS`] thicknesses tried on each.
pub fn log10_n_tests(n: usize, k: usize) -> f64 {
    let (n, r) = (n as f64, (k + 1) as f64);
    if n < r {
        return f64::from(WIDTHS).log10();
    }
    let ln_binom = ln_gamma(n + 1.0) - ln_gamma(r + 1.0) - ln_gamma(n - r + 1.0);
    ln_binom / std::f64::consts::LN_10 + f64::from(WIDTHS).log10()
}

/// log₁₀ NFA of a part (module doc): `residuals` are its points' distances
/// to its fitted primitive of dimension `k`, `volume(t)` the volume of the
/// tube (k = 1) or slab (k = 2) of half-thickness `t` over its extent,
/// `rho` the background density, `tau` the largest thickness tried and
/// `log10_tests` from [`log10_n_tests`]. For each of the [`WIDTHS`]
/// thicknesses t = τ/2^j it counts the m points within t, of which the
/// k + 1 that define the primitive are not random, and keeps the smallest
/// log₁₀ [`log10_nfa`] of the m − k − 1 others in Poisson(ρ·V(t)).
pub fn part_log10_nfa(
    residuals: &[f64],
    k: usize,
    tau: f64,
    rho: f64,
    volume: &dyn Fn(f64) -> f64,
    log10_tests: f64,
) -> f64 {
    let mut best = f64::INFINITY;
    let mut t = tau;
    for _ in 0..WIDTHS {
        let m = residuals.iter().filter(|&&d| d <= t).count();
        if m > k + 1 {
            let tail = log10_poisson_tail(rho * volume(t), (m - k - 1) as u64);
            best = best.min(log10_tests + tail);
        }
        t *= 0.5;
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_gamma_matches_factorials() {
        let mut f = 1.0f64;
        for n in 1..30u32 {
            f *= f64::from(n);
            assert!((ln_gamma(f64::from(n) + 1.0) - f.ln()).abs() < 1e-10 * f.ln().max(1.0));
        }
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    }

    #[test]
    fn poisson_tail_against_direct_sum() {
        for &mu in &[0.01f64, 0.3, 2.0, 7.5] {
            for m in 1..30u64 {
                // Direct: Σ_{k ≥ m} e^{−μ} μ^k / k!, term by term from
                // k = 0 (no cancellation), 400 terms.
                let mut tail = 0.0f64;
                let mut t = (-mu).exp();
                for k in 0..400u64 {
                    if k >= m {
                        tail += t;
                    }
                    t *= mu / (k + 1) as f64;
                }
                let direct = tail;
                let got = log10_poisson_tail(mu, m);
                if mu < m as f64 && direct > 1e-300 {
                    assert!(
                        (got - direct.log10()).abs() < 1e-9,
                        "mu {mu} m {m}: {got} vs {}",
                        direct.log10()
                    );
                }
                if mu >= m as f64 {
                    assert_eq!(got, 0.0);
                }
            }
        }
        // Very small probabilities stay finite and monotone.
        let a = log10_poisson_tail(0.1, 200);
        let b = log10_poisson_tail(0.1, 201);
        assert!(a.is_finite() && b < a);
        assert_eq!(log10_poisson_tail(0.0, 3), f64::NEG_INFINITY);
        assert_eq!(log10_poisson_tail(5.0, 0), 0.0);
    }

    #[test]
    fn part_nfa_picks_the_thinnest_telling_width() {
        let vol = |t: f64| std::f64::consts::PI * t * t * 60.0;
        let tests = log10_n_tests(1550, 1);
        // C(1550, 2) = 1,200,475 lines, times 12 widths.
        assert!((tests - (1_200_475f64 * 12.0).log10()).abs() < 1e-9);
        let rho = 0.01 / 41.9;
        // Ten exactly collinear points: significant whatever the clutter
        // that a claim radius of 1 adds.
        let mut exact = vec![0.0; 10];
        exact.extend([0.6, 0.9, 0.95]);
        assert!(part_log10_nfa(&exact, 1, 1.0, 100.0 * rho, &vol, tests) < -10.0);
        // Five points spread over the whole tube at 10x the paper's
        // density: chance (about 0.2 expected in the tube, 3 counted).
        let chain = [0.2, 0.5, 0.7, 0.8, 0.95];
        assert!(part_log10_nfa(&chain, 1, 1.0, 10.0 * rho, &vol, tests) > 0.0);
        // The best width is at most as bad as the widest alone.
        let widest = tests + log10_poisson_tail(rho * vol(1.0), 11);
        assert!(part_log10_nfa(&exact, 1, 1.0, rho, &vol, tests) <= widest);
        // Too few points for any width: +inf, never kept.
        assert_eq!(
            part_log10_nfa(&[0.1, 0.2], 1, 1.0, rho, &vol, tests),
            f64::INFINITY
        );
        assert!(log10_n_tests(2, 2).is_finite());
    }

    #[test]
    fn nfa_counts_tests() {
        let a = log10_nfa(1000.0, 0.5, 10);
        assert!((a - (3.0 + log10_poisson_tail(0.5, 10))).abs() < 1e-12);
    }
}
