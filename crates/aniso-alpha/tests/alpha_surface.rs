//! The α-shape surface (regular triangles, oriented outward) and
//! `optimal_alpha`.

use crate::alpha_common;
use alpha_common::*;
use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::geometry::{cross, dot, sub};

/// The cube's 8 corners and its centre: at a large α the surface is the 12
/// hull triangles, each with its normal pointing away from the centre.
#[test]
fn cube_surface_is_the_hull_oriented_outward() {
    let mut pts: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    pts.push([0.5, 0.5, 0.5]);
    let ac = AlphaComplex::from_points(&pts).unwrap();
    assert_eq!(ac.triangulation().num_finite_tets(), 12);
    let surf = ac.regular_surface(10.0);
    assert_eq!(surf.len(), 12);
    let centre = [0.5, 0.5, 0.5];
    for t in &surf {
        assert!(t.iter().all(|&v| v < 8), "the centre is not on the surface");
        let [a, b, c] = t.map(|v| pts[v as usize]);
        let n = cross(sub(b, a), sub(c, a));
        let g = [
            (a[0] + b[0] + c[0]) / 3.0,
            (a[1] + b[1] + c[1]) / 3.0,
            (a[2] + b[2] + c[2]) / 3.0,
        ];
        assert!(dot(n, sub(g, centre)) > 0.0, "{t:?} points inward");
    }
    // Every tet has the centre and a half face: circumradius of
    // (centre, 3 corners of a face) — below it there is no solid at all.
    let r = ac.optimal_alpha().unwrap();
    assert!(ac.regular_surface(r * (1.0 - 1e-12)).is_empty());
    assert_eq!(ac.regular_surface(r).len(), 12);
    // At infinity F_2 is exactly the hull triangles, F_1 the hull edges.
    assert_eq!(ac.triangles_at(f64::INFINITY).count(), 12);
    assert_eq!(ac.edges_at(f64::INFINITY).count(), 18);
}

/// A single tetrahedron: one solid at its circumradius, surface oriented
/// outward, and before that no surface.
#[test]
fn single_tet_orientation() {
    let pts = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let ac = AlphaComplex::from_points(&pts).unwrap();
    let r = ac.optimal_alpha().unwrap();
    assert!((r - 3f64.sqrt() / 2.0).abs() < 1e-15);
    let surf = ac.regular_surface(r);
    assert_eq!(surf.len(), 4);
    let g = [0.25, 0.25, 0.25];
    for t in surf {
        let [a, b, c] = t.map(|v| pts[v as usize]);
        let n = cross(sub(b, a), sub(c, a));
        assert!(dot(n, sub(a, g)) > 0.0);
    }
}

/// Independent check of the optimal-α definition: the tets with radius ≤ α
/// cover every vertex and are face-connected (BFS), and this fails at every
/// smaller tet radius.
fn solid_ok(ac: &AlphaComplex, alpha: f64) -> bool {
    let tri = ac.triangulation();
    let inside: Vec<u32> = (0..tri.num_tets() as u32)
        .filter(|&t| !tri.is_infinite(t) && ac.tet_radius(t) <= alpha)
        .collect();
    if inside.is_empty() {
        return false;
    }
    let mut covered = vec![false; tri.num_vertices()];
    for &t in &inside {
        for v in tri.tet(t) {
            covered[v as usize] = true;
        }
    }
    if covered.iter().any(|&c| !c) {
        return false;
    }
    let mut seen = vec![false; tri.num_tets()];
    let mut stack = vec![inside[0]];
    seen[inside[0] as usize] = true;
    let mut count = 0;
    while let Some(t) = stack.pop() {
        count += 1;
        for i in 0..4 {
            let (n, _) = tri.neighbor(t, i);
            if !seen[n as usize] && !tri.is_infinite(n) && ac.tet_radius(n) <= alpha {
                seen[n as usize] = true;
                stack.push(n);
            }
        }
    }
    count == inside.len()
}

#[test]
fn optimal_alpha_is_the_smallest_connected_covering_solid() {
    for seed in 0..20u64 {
        let n = 10 + 15 * seed as usize;
        let pts = random_points(500 + seed, n);
        let ac = AlphaComplex::from_points(&pts).unwrap();
        let opt = ac.optimal_alpha().unwrap();
        assert!(solid_ok(&ac, opt), "seed {seed}: not a solid at {opt}");
        let mut radii: Vec<f64> = ac
            .tet_radii()
            .iter()
            .copied()
            .filter(|r| r.is_finite() && *r < opt)
            .collect();
        radii.sort_by(f64::total_cmp);
        radii.dedup();
        for &r in radii.iter().rev().take(50) {
            assert!(
                !solid_ok(&ac, r),
                "seed {seed}: already a solid at {r} < {opt}"
            );
        }
    }
}

/// Two far-apart clusters: the optimal α must bridge the gap.
#[test]
fn optimal_alpha_bridges_clusters() {
    let mut pts = random_points(7, 40);
    let far: Vec<[f64; 3]> = random_points(8, 40)
        .into_iter()
        .map(|p| [p[0] + 10.0, p[1], p[2]])
        .collect();
    pts.extend(far);
    let ac = AlphaComplex::from_points(&pts).unwrap();
    let opt = ac.optimal_alpha().unwrap();
    assert!(opt > 4.0, "{opt}");
    assert!(solid_ok(&ac, opt));
}

#[test]
fn lower_dimensions_have_no_optimal_alpha() {
    let pts: Vec<[f64; 3]> = (0..10).map(|i| [i as f64, 0.0, 0.0]).collect();
    let ac = AlphaComplex::from_points(&pts).unwrap();
    assert_eq!(ac.optimal_alpha(), None);
    assert!(ac.regular_surface(1.0).is_empty());
    assert_eq!(ac.num_edges(), 0);
}
