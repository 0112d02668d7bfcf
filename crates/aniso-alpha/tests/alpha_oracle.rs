//! Oracles for the alpha intervals.
//!
//! * The Gabriel predicates (`alpha::exact`) agree with an exact big-integer
//!   evaluation on random, near-degenerate and exactly degenerate inputs,
//!   including coordinates whose differences are not representable.
//! * Brute force on small random sets: for sampled α (kept at least 1e-7
//!   relative away from every interval endpoint), every pair and triple of
//!   points is exposed by an empty open ball of radius α through its
//!   vertices exactly when it is a Delaunay edge or triangle with
//!   `α_min ≤ α ≤ α_max`.

use crate::alpha_common;
use alpha_common::*;
use aniso_alpha::alpha::exact::{edge_diametral_side, triangle_diametral_side};
use aniso_alpha::alpha::AlphaComplex;
use std::collections::HashSet;

/// Random point generators of increasing nastiness.
fn point(r: &mut Rng, kind: u64) -> [f64; 3] {
    match kind {
        // small integer grid: exact ties everywhere
        0 => [0, 1, 2].map(|_| r.below(5) as f64),
        // scaled grid on a large offset: exact differences, ties
        1 => [0, 1, 2].map(|_| 1024.0 + r.below(5) as f64 * 2f64.powi(-30)),
        // decimals: inexact differences, near-ties
        2 => [0, 1, 2].map(|_| r.below(7) as f64 * 0.1),
        // mixed magnitudes: differences far from representable
        3 => [0, 1, 2].map(|_| {
            let e = r.below(40) as i32 - 20;
            (r.uniform() - 0.5) * 2f64.powi(e)
        }),
        // uniform
        _ => [r.uniform(), r.uniform(), r.uniform()],
    }
}

#[test]
fn edge_predicate_matches_exact_oracle() {
    let mut r = Rng::new(11);
    let mut signs = [0usize; 3];
    for it in 0..20000 {
        let kind = it % 5;
        let (a, b) = (point(&mut r, kind), point(&mut r, kind));
        let mut p = point(&mut r, kind);
        if it % 7 == 0 {
            // On the sphere exactly when representable: p = a + (b − a) ⟂ …
            // (use a grid point chosen to often be on Thales' sphere)
            p = [a[0], b[1], p[2]];
        }
        let want = oracle_edge(&a, &b, &p);
        let got = edge_diametral_side(&a, &b, &p).to_i32();
        assert_eq!(got, want, "a={a:?} b={b:?} p={p:?}");
        signs[(want + 1) as usize] += 1;
    }
    // every outcome exercised
    assert!(signs.iter().all(|&c| c > 100), "{signs:?}");
}

#[test]
fn triangle_predicate_matches_exact_oracle() {
    let mut r = Rng::new(12);
    let mut signs = [0usize; 3];
    let mut tested = 0;
    for it in 0..20000 {
        let kind = it % 5;
        let (a, b, c) = (
            point(&mut r, kind),
            point(&mut r, kind),
            point(&mut r, kind),
        );
        // skip degenerate (collinear) triangles: not a triangle of a triangulation
        if oracle_triangle_degenerate(&a, &b, &c) {
            continue;
        }
        let p = point(&mut r, kind);
        let want = oracle_triangle(&a, &b, &c, &p);
        let got = triangle_diametral_side(&a, &b, &c, &p).to_i32();
        assert_eq!(got, want, "a={a:?} b={b:?} c={c:?} p={p:?}");
        signs[(want + 1) as usize] += 1;
        tested += 1;
    }
    assert!(tested > 15000);
    assert!(signs.iter().all(|&c| c > 50), "{signs:?}");
}

/// Collinear (or coincident) corners, exactly.
fn oracle_triangle_degenerate(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> bool {
    // |u × v| = 0 iff the three points are collinear; reuse the edge
    // oracle's machinery through `to_ints`.
    let all: Vec<f64> = a.iter().chain(b).chain(c).copied().collect();
    let z = to_ints(&all);
    let u: Vec<Big> = (0..3).map(|k| z[3 + k].sub(&z[k])).collect();
    let v: Vec<Big> = (0..3).map(|k| z[6 + k].sub(&z[k])).collect();
    (0..3).all(|k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        u[i].mul(&v[j]).sub(&u[j].mul(&v[i])).signum() == 0
    })
}

/// The α samples: midpoints between consecutive critical values and a few
/// random values, dropping any within 1e-7 (relative) of a critical value.
fn alpha_samples(ac: &AlphaComplex, r: &mut Rng) -> Vec<f64> {
    let spec = ac.spectrum();
    let mut out: Vec<f64> = spec.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    let top = *spec.last().unwrap();
    for _ in 0..20 {
        out.push(r.uniform() * 1.2 * top);
    }
    out.push(2.0 * top);
    out.retain(|&a| spec.iter().all(|&s| (a - s).abs() > 1e-7 * a.max(s)) && a > 0.0);
    out
}

#[test]
fn brute_force_empty_balls() {
    let (mut pos_e, mut pos_t, mut neg_del) = (0usize, 0usize, 0usize);
    for seed in 0..6u64 {
        let n = 20 + 4 * seed as usize;
        let pts = random_points(1000 + seed, n);
        let ac = AlphaComplex::from_points(&pts).unwrap();
        let mut r = Rng::new(seed);
        let alphas = alpha_samples(&ac, &mut r);
        assert!(alphas.len() > 50);
        for &alpha in &alphas {
            let edges: HashSet<[u32; 2]> = ac.edges_at(alpha).collect();
            // Delaunay edges *not* exposed at this α (interior or not yet born).
            neg_del += ac.num_edges() - edges.len();
            let tris: HashSet<[u32; 3]> = ac.triangles_at(alpha).collect();
            for i in 0..n {
                for j in i + 1..n {
                    let want = edge_exposed(&pts, i, j, alpha);
                    let got = edges.contains(&[i as u32, j as u32]);
                    assert_eq!(got, want, "seed {seed} alpha {alpha}: edge ({i}, {j})");
                    pos_e += got as usize;
                    for k in j + 1..n {
                        let want = triangle_exposed(&pts, i, j, k, alpha);
                        let got = tris.contains(&[i as u32, j as u32, k as u32]);
                        assert_eq!(
                            got, want,
                            "seed {seed} alpha {alpha}: triangle ({i}, {j}, {k})"
                        );
                        pos_t += got as usize;
                    }
                }
            }
        }
    }
    eprintln!(
        "exposed edges {pos_e}, exposed triangles {pos_t}, unexposed Delaunay edges {neg_del}"
    );
    assert!(pos_e > 1000 && pos_t > 1000 && neg_del > 1000);
}
