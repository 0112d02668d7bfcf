//! Property tests of the anisotropic complex (docs/method.md §2).
//!
//! * E = (1, 1, 1) with the identity rotation is the Euclidean complex,
//!   bit for bit (the transform `(1·x + 0·y) + 0·z` is exact).
//! * A rotation alone (E = (1, 1, 1), R from random Euler angles) preserves
//!   distances, so the intervals are unchanged up to rounding (1e-9
//!   relative), compared simplex by simplex through input indices. Only on
//!   generic random points: on degenerate sets (grids, cospherical points)
//!   the rotated coordinates are rounded differently, which can change how
//!   ties are broken and hence the triangulation itself.
//! * The oriented α-shape surface is closed: every directed edge of a
//!   regular triangle is matched by the opposite directed edge.
//! * Every interval is ordered, and an edge's contains each of its
//!   triangles' exactly, after rounding too, on degenerate sets where
//!   radii computed by different formulas tie.

use crate::common;
use aniso_alpha::alpha::{q_matrix, AlphaComplex};
use common::Rng;
use proptest::prelude::*;
use std::collections::HashMap;

/// R(θ, ψ, φ) = R_z(θ) R_x(ψ) R_y(φ).
fn rotation(th: f64, psi: f64, phi: f64) -> [[f64; 3]; 3] {
    let (st, ct) = th.sin_cos();
    let (sp, cp) = psi.sin_cos();
    let (sf, cf) = phi.sin_cos();
    let rz = [[ct, -st, 0.0], [st, ct, 0.0], [0.0, 0.0, 1.0]];
    let rx = [[1.0, 0.0, 0.0], [0.0, cp, -sp], [0.0, sp, cp]];
    let ry = [[cf, 0.0, sf], [0.0, 1.0, 0.0], [-sf, 0.0, cf]];
    let mul = |a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]| -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
    };
    mul(&mul(&rz, &rx), &ry)
}

type Table = HashMap<Vec<u32>, (f64, f64)>;

fn table(ac: &AlphaComplex) -> Table {
    ac.edges()
        .map(|e| (e.vertices.to_vec(), (e.alpha_min, e.alpha_max)))
        .chain(
            ac.triangles()
                .map(|t| (t.vertices.to_vec(), (t.alpha_min, t.alpha_max))),
        )
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    if a.is_infinite() || b.is_infinite() {
        return a == b;
    }
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

fn points_strategy() -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), 5..60)
}

/// Points of a small decimal grid (step 0.1, not dyadic): many ties
/// between radii computed by different formulas.
fn decimal_grid_strategy() -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec(
        prop::array::uniform3((0u8..16).prop_map(|k| f64::from(k) * 0.1)),
        4..40,
    )
}

/// Asserts that every interval of `ac` is ordered, and that every edge's
/// interval contains each of its triangles' (exactly, no slack).
fn assert_nested(ac: &AlphaComplex) {
    for e in 0..ac.num_edges() {
        let (lo, hi) = ac.edge_interval(e);
        assert!(0.0 <= lo && lo <= hi, "edge {e}: [{lo}, {hi}]");
    }
    for f in 0..ac.num_triangles() {
        let (lo, hi) = ac.triangle_interval(f);
        assert!(0.0 <= lo && lo <= hi, "triangle {f}: [{lo}, {hi}]");
        let [a, b, c] = ac.triangle_vertices(f);
        for (x, y) in [(a, b), (b, c), (c, a)] {
            let (elo, ehi) = ac.edge_interval(ac.find_edge(x, y).unwrap());
            assert!(
                elo <= lo && hi <= ehi,
                "edge [{elo}, {ehi}] vs its triangle [{lo}, {hi}]"
            );
        }
    }
}

/// Found by the `alpha` fuzz target: a Gabriel triangle whose incident
/// tet has the triangle's diametral sphere as circumsphere. Its ρ and the
/// tet's circumradius are the same real number, computed by different
/// formulas, and rounded one unit apart: the interval came out as
/// [1.0712142642814275, 1.0712142642814273], empty.
#[test]
fn tied_radii_keep_intervals_ordered() {
    let pts = [
        [1.0, 1.1, 0.2],
        [0.0, 0.0, 0.0],
        [0.30000000000000004, 0.0, 0.0],
        [0.0, 1.5, 1.5],
        [1.5, 0.2, 0.0],
        [0.0, 0.0, 1.5],
    ];
    assert_nested(&AlphaComplex::from_points(&pts).unwrap());
    // Found by `intervals_nest_on_decimal_grids`: one tet, with a right
    // angle at a vertex, so an edge's half length ties its triangle's ρ.
    let tet = [
        [0.1, 0.7000000000000001, 1.2000000000000002],
        [0.30000000000000004, 0.8, 1.3],
        [0.9, 0.8, 0.0],
        [0.5, 0.6000000000000001, 0.5],
    ];
    assert_nested(&AlphaComplex::from_points(&tet).unwrap());
    // Grids tie everywhere: a cube's space diagonal is as long as its
    // tets' circumdiameter.
    let grid: Vec<[f64; 3]> = (0..125)
        .map(|k| [k % 5, k / 5 % 5, k / 25].map(|c| f64::from(c) * 0.1))
        .collect();
    assert_nested(&AlphaComplex::from_points(&grid).unwrap());
}

proptest! {
    // A fixed seed: the same cases on every run.
    #![proptest_config(ProptestConfig {
        cases: 128,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0xA1FA),
        ..ProptestConfig::default()
    })]

    #[test]
    fn identity_is_euclidean(pts in points_strategy()) {
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let q = q_matrix(&id, &[1.0, 1.0, 1.0]);
        let a = AlphaComplex::anisotropic(&pts, &q).unwrap();
        let b = AlphaComplex::from_points(&pts).unwrap();
        let ea: Vec<_> = a.edges().collect();
        let eb: Vec<_> = b.edges().collect();
        prop_assert_eq!(ea, eb);
        let ta: Vec<_> = a.triangles().collect();
        let tb: Vec<_> = b.triangles().collect();
        prop_assert_eq!(ta, tb);
    }

    #[test]
    fn rotation_keeps_intervals(
        pts in points_strategy(),
        th in -3.2f64..3.2, psi in -1.6f64..1.6, phi in -3.2f64..3.2,
    ) {
        let q = q_matrix(&rotation(th, psi, phi), &[1.0, 1.0, 1.0]);
        let a = table(&AlphaComplex::anisotropic(&pts, &q).unwrap());
        let b = table(&AlphaComplex::from_points(&pts).unwrap());
        prop_assert_eq!(a.len(), b.len());
        for (k, (lo, hi)) in &b {
            let (lo2, hi2) = a.get(k).copied().unwrap_or((f64::NAN, f64::NAN));
            prop_assert!(close(*lo, lo2) && close(*hi, hi2),
                "{:?}: [{}, {}] vs rotated [{}, {}]", k, lo, hi, lo2, hi2);
        }
    }

    #[test]
    fn intervals_nest_on_decimal_grids(pts in decimal_grid_strategy()) {
        if let Ok(ac) = AlphaComplex::from_points(&pts) {
            assert_nested(&ac);
        }
    }

    #[test]
    fn regular_surface_is_closed(pts in points_strategy(), frac in 0.0f64..1.0) {
        let ac = AlphaComplex::from_points(&pts).unwrap();
        let spec = ac.spectrum();
        prop_assume!(!spec.is_empty());
        let alpha = spec[((spec.len() - 1) as f64 * frac) as usize];
        let mut count: HashMap<(u32, u32), i64> = HashMap::new();
        for [a, b, c] in ac.regular_surface(alpha) {
            for (x, y) in [(a, b), (b, c), (c, a)] {
                *count.entry((x, y)).or_default() += 1;
                *count.entry((y, x)).or_default() -= 1;
            }
        }
        prop_assert!(count.values().all(|&v| v == 0));
    }
}

/// The interval pass splits its work across rayon's threads: the result
/// (ids, order and bits of every interval and radius) must not depend on
/// how many there are. 60k points make several blocks of the triangle pass
/// and several edge runs per thread.
#[test]
fn intervals_do_not_depend_on_thread_count() {
    let mut r = Rng::new(0x5151);
    let mut pts: Vec<[f64; 3]> = (0..60_000)
        .map(|_| [r.uniform(), r.uniform(), r.uniform()])
        .collect();
    // And a degenerate part: an integer grid (many equal radii, ties).
    for i in 0..20 {
        for j in 0..20 {
            for k in 0..20 {
                pts.push([2.0 + i as f64 * 0.05, j as f64 * 0.05, k as f64 * 0.05]);
            }
        }
    }
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| AlphaComplex::from_points(&pts).unwrap())
    };
    let one = run(1);
    for threads in [2, 3] {
        let other = run(threads);
        assert_eq!(one.num_edges(), other.num_edges());
        assert_eq!(one.num_triangles(), other.num_triangles());
        let iv_bits = |(lo, hi): (f64, f64)| (lo.to_bits(), hi.to_bits());
        for e in 0..one.num_edges() {
            assert_eq!(one.edge_vertices(e), other.edge_vertices(e));
            assert_eq!(
                iv_bits(one.edge_interval(e)),
                iv_bits(other.edge_interval(e))
            );
        }
        for f in 0..one.num_triangles() {
            assert_eq!(one.triangle_vertices(f), other.triangle_vertices(f));
            assert_eq!(
                iv_bits(one.triangle_interval(f)),
                iv_bits(other.triangle_interval(f))
            );
        }
        let bits = |ac: &AlphaComplex| {
            ac.tet_radii()
                .iter()
                .map(|r| r.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&one), bits(&other));
    }
}
