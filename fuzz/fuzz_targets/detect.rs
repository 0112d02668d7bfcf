//! Fuzz target: structure detection on small, highly degenerate point sets
//! with arbitrary parameters and a few arbitrary rotations.
//!
//! The first four bytes pick the parameters (kind, α, λ₂, λ₃, nb_c,
//! pruning) and the number of rotations; the next three bytes per rotation
//! its Euler angles; the rest decodes to points as in the other geometric
//! targets. Checks: the run fails only on empty, non-finite or
//! out-of-range input; the result is consistent (labels, structures,
//! parts and simplices refer to each other and to existing points, sizes
//! match k, duplicates are labelled as their first occurrence); and a
//! second run gives the same result.
#![no_main]

use aniso_alpha::aniso::rotation_from_euler;
use aniso_alpha::detect::{DetectError, Detection, Detector};
use libfuzzer_sys::fuzz_target;

mod points;
use points::decode;

fn check(d: &Detection, points: &[[f64; 3]], k: usize) {
    let n = points.len();
    assert_eq!(d.labels.len(), n);
    assert_eq!(d.first_occurrence.len(), n);
    for (i, &f) in d.first_occurrence.iter().enumerate() {
        let f = f as usize;
        assert!(f <= i && points[f] == points[i] && d.first_occurrence[f] as usize == f);
        assert!(points[..f].iter().all(|p| *p != points[i]));
    }
    assert_eq!(d.simplex_structure.len(), d.simplices.len());
    for s in &d.simplices {
        assert_eq!(s.len(), k + 1);
        assert!(s.windows(2).all(|w| w[0] < w[1]));
        assert!(s.iter().all(|&v| (v as usize) < n));
    }
    for (id, st) in d.structures.iter().enumerate() {
        assert_eq!(st.id as usize, id);
        assert!(st.vertices.windows(2).all(|w| w[0] < w[1]));
        for &s in &st.simplices {
            assert_eq!(d.simplex_structure[s as usize], st.id);
            for &v in &d.simplices[s as usize] {
                assert!(st.vertices.binary_search(&v).is_ok());
            }
        }
        for p in &st.parts {
            assert!(p.vertices.windows(2).all(|w| w[0] < w[1]));
            for &s in &p.simplices {
                assert_eq!(d.simplex_structure[s as usize], st.id);
            }
        }
    }
    for (i, &l) in d.labels.iter().enumerate() {
        assert!(l >= -1 && l < d.structures.len() as i64);
        let f = d.first_occurrence[i];
        assert_eq!(l, d.labels[f as usize]);
        if l >= 0 {
            assert!(d.structures[l as usize].vertices.binary_search(&f).is_ok());
        }
    }
    let parts: usize = d.structures.iter().map(|s| s.parts.len()).sum();
    let part_labels = d.part_labels();
    for (i, &l) in part_labels.iter().enumerate() {
        assert!(l >= -1 && l < parts as i64);
        assert_eq!(l, part_labels[d.first_occurrence[i] as usize]);
        // A point in a part is in a structure.
        assert!(l == -1 || d.labels[i] >= 0);
    }
}

fuzz_target!(|data: &[u8]| {
    if data.len() < 4 {
        return;
    }
    let (head, rest) = data.split_at(4);
    let alpha = [0.25, 0.5, 1.0, 2.0, 1e-3, 1e3][(head[0] >> 1) as usize % 6];
    let lambda2 = 1.0 + f64::from(head[1] & 7);
    let lambda3 = lambda2 + f64::from(head[1] >> 3);
    let nb_c = 1 + u32::from(head[2] & 31);
    let nrot = 1 + (head[3] & 3) as usize;
    if rest.len() < 3 * nrot {
        return;
    }
    let (angles, rest) = rest.split_at(3 * nrot);
    let turn = |b: u8| f64::from(b) * std::f64::consts::PI / 128.0;
    let rotations: Vec<[[f64; 3]; 3]> = angles
        .chunks_exact(3)
        .map(|c| rotation_from_euler(turn(c[0]), turn(c[1]), turn(c[2])))
        .collect();
    let points = decode(rest);
    let lines = head[0] & 1 == 0;
    let k = if lines { 1 } else { 2 };
    let detector = if lines {
        Detector::lines(alpha, lambda3, nb_c)
    } else {
        Detector::planes(alpha, lambda2, lambda3, nb_c)
    }
    .rotations(rotations)
    .prune(head[2] & 32 == 0);
    match detector.run(&points) {
        Ok(d) => {
            check(&d, &points, k);
            assert_eq!(detector.run(&points).unwrap(), d, "a second run differs");
        }
        Err(DetectError::Empty) => assert!(points.is_empty()),
        Err(DetectError::NonFinite { index }) => {
            assert!(points[index].iter().any(|c| !c.is_finite()))
        }
        Err(DetectError::OutOfRange { index }) => {
            assert!(points[index].iter().all(|c| c.is_finite()))
        }
        Err(e) => panic!("unexpected error on {} points: {e}", points.len()),
    }
});
