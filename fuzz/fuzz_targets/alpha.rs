//! Fuzz target: alpha intervals on small, highly degenerate point sets.
//!
//! Checks, on every set the Delaunay build accepts: every interval is
//! ordered and non-negative; every edge of a triangle exists and its
//! interval contains the triangle's, exactly (a triangle on the boundary
//! of the alpha-shape has its edges there too); and the reversed input
//! gives the same intervals up to rounding, keyed by the simplices'
//! coordinates.
#![no_main]

use std::collections::BTreeMap;

use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::delaunay::VertexId;
use libfuzzer_sys::fuzz_target;

mod points;
use points::{coordinate_key, decode};

/// Relative slack for comparing intervals computed from differently
/// ordered vertices.
const SLACK: f64 = 1e-9;

fn le(a: f64, b: f64) -> bool {
    a <= b || (b.is_finite() && a - b <= SLACK * a.abs().max(b.abs()))
}

/// Every simplex's sorted vertex coordinates (as bits) with its interval.
fn table(ac: &AlphaComplex) -> BTreeMap<Vec<[u64; 3]>, (f64, f64)> {
    let tri = ac.triangulation();
    let key = |vs: &[VertexId]| {
        let mut k: Vec<[u64; 3]> = vs.iter().map(|&v| coordinate_key(tri.point(v.0))).collect();
        k.sort_unstable();
        k
    };
    let mut t = BTreeMap::new();
    for e in 0..ac.num_edges() {
        t.insert(key(&ac.edge_vertices(e)), ac.edge_interval(e));
    }
    for f in 0..ac.num_triangles() {
        t.insert(key(&ac.triangle_vertices(f)), ac.triangle_interval(f));
    }
    t
}

fuzz_target!(|data: &[u8]| {
    let points = decode(data);
    let Ok(ac) = AlphaComplex::from_points(&points) else {
        return; // refusals are the Delaunay target's business
    };
    for e in 0..ac.num_edges() {
        let (lo, hi) = ac.edge_interval(e);
        assert!(lo >= 0.0 && lo <= hi, "edge {e}: [{lo}, {hi}]");
    }
    for f in 0..ac.num_triangles() {
        let (lo, hi) = ac.triangle_interval(f);
        assert!(lo >= 0.0 && lo <= hi, "triangle {f}: [{lo}, {hi}]");
        let [a, b, c] = ac.triangle_vertices(f);
        for (x, y) in [(a, b), (b, c), (c, a)] {
            let e = ac.find_edge(x, y).expect("a triangle's edge is an edge");
            let (elo, ehi) = ac.edge_interval(e);
            assert!(
                elo <= lo && hi <= ehi,
                "edge [{elo}, {ehi}] does not contain its triangle's [{lo}, {hi}]"
            );
        }
    }
    let reversed: Vec<[f64; 3]> = points.iter().rev().copied().collect();
    let again = AlphaComplex::from_points(&reversed).expect("the reversed input builds");
    let (t1, t2) = (table(&ac), table(&again));
    assert_eq!(t1.len(), t2.len());
    for (k, &(lo, hi)) in &t1 {
        let &(lo2, hi2) = t2.get(k).expect("the same simplices");
        assert!(
            le(lo, lo2) && le(lo2, lo) && le(hi, hi2) && le(hi2, hi),
            "[{lo}, {hi}] vs reversed [{lo2}, {hi2}]"
        );
    }
});
