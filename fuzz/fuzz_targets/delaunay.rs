//! Fuzz target: the Delaunay build on small, highly degenerate point sets.
//!
//! The input decodes to at most 96 points whose coordinates come from a
//! small set (small integers, a decimal grid, or raw doubles), so ties of
//! every kind are frequent. Checks: the build never panics; it fails only
//! on empty, non-finite or out-of-range input; the result passes
//! `validate_with_input`; and building the reversed input gives the same
//! tets, compared by their vertices' coordinates (the perturbed
//! triangulation is unique whatever the order, see docs/method.md §1).
#![no_main]

use aniso_alpha::delaunay::{DelaunayError, Triangulation};
use libfuzzer_sys::fuzz_target;

mod points;
use points::{coordinate_key, decode};

/// The finite tets as sorted quadruples of coordinate bit patterns.
fn by_coordinates(tri: &Triangulation) -> Vec<[[u64; 3]; 4]> {
    let key = |v: u32| coordinate_key(tri.point(v));
    let mut tets: Vec<[[u64; 3]; 4]> = tri
        .finite_tets()
        .map(|t| {
            let mut q = t.map(key);
            q.sort_unstable();
            q
        })
        .collect();
    tets.sort_unstable();
    tets
}

fuzz_target!(|data: &[u8]| {
    let points = decode(data);
    let tri = match Triangulation::new(&points) {
        Ok(tri) => tri,
        Err(DelaunayError::Empty) => {
            assert!(points.is_empty());
            return;
        }
        Err(DelaunayError::NonFinite { index, coord, .. }) => {
            assert!(!points[index][coord].is_finite());
            return;
        }
        Err(DelaunayError::OutOfRange { index, coord, .. }) => {
            assert!(points[index][coord].is_finite());
            return;
        }
        Err(e) => panic!("unexpected error on {} points: {e}", points.len()),
    };
    tri.validate_with_input(&points)
        .expect("valid triangulation");
    let reversed: Vec<[f64; 3]> = points.iter().rev().copied().collect();
    let again = Triangulation::new(&reversed).expect("the reversed input builds");
    assert_eq!(again.dimension(), tri.dimension());
    assert_eq!(again.num_vertices(), tri.num_vertices());
    assert_eq!(by_coordinates(&again), by_coordinates(&tri));
});
