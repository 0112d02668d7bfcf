//! Detection on degenerate clouds (issue 19 §5), fixed seeds: exactly
//! coplanar and exactly collinear points give the one structure holding
//! them, and a cloud made of copies of few points returns without error,
//! with estimated parameters as with the paper's.
//! `scripts/bench_degenerate.py --detect` measures the time and memory of
//! larger such clouds against uniform points (BENCHMARKS.md).

use aniso_alpha::detect::estimate::Given;
use aniso_alpha::detect::orientations::Sampler;
use aniso_alpha::detect::StructureKind;
use aniso_alpha::detect::{DetectError, Detection, Detector};
use aniso_alpha::rng::SplitMix64;

/// `n` points with z = 0 and x, y uniform in [0, side] at 1e-3.
fn coplanar(n: usize, side: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix64::new(seed);
    let mut at = || (r.uniform() * side * 1000.0).round() / 1000.0;
    (0..n).map(|_| [at(), at(), 0.0]).collect()
}

/// Each of `distinct` uniform points of [0, 10]³ repeated `copies` times.
fn copies(distinct: usize, copies: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = SplitMix64::new(seed);
    let d: Vec<[f64; 3]> = (0..distinct)
        .map(|_| [10.0 * r.uniform(), 10.0 * r.uniform(), 10.0 * r.uniform()])
        .collect();
    (0..distinct * copies).map(|i| d[i % distinct]).collect()
}

/// One structure holding every point.
fn one_structure_of_all(det: &Detection, n: usize) {
    assert_eq!(det.structures.len(), 1, "{:?}", det.structures.len());
    assert_eq!(det.labels.len(), n);
    let on = det.labels.iter().filter(|&&l| l == 0).count();
    assert_eq!(on, n, "{on} of {n} points on the structure");
}

#[test]
fn coplanar_points_automatic() {
    let pts = coplanar(600, 25.0, 1);
    let det = Detector::auto(StructureKind::Planes, &pts, &Given::default())
        .unwrap()
        .run(&pts)
        .unwrap();
    one_structure_of_all(&det, pts.len());
    let plane = det.structures[0].parts[0].plane().unwrap();
    assert!(
        plane[2].abs() > 1.0 - 1e-9 && plane[3].abs() < 1e-9,
        "{plane:?}"
    );
}

#[test]
fn coplanar_points_paper_parameters_coarse_box() {
    // The paper's α, λ, nb_c; a coarse box (m1 = 1, m2 = 3) for the time.
    let pts = coplanar(300, 17.0, 2);
    let det = Detector::planes(1.0, 4.0, 8.0, 20)
        .sampler(Sampler::Box { m1: 1.0, m2: 3 })
        .run(&pts)
        .unwrap();
    one_structure_of_all(&det, pts.len());
}

#[test]
fn coplanar_integer_grid_automatic() {
    let pts: Vec<[f64; 3]> = (0..400)
        .map(|i| [f64::from(i % 20), f64::from(i / 20), 3.0])
        .collect();
    let det = Detector::auto(StructureKind::Planes, &pts, &Given::default())
        .unwrap()
        .run(&pts)
        .unwrap();
    one_structure_of_all(&det, pts.len());
}

#[test]
fn collinear_points_paper_parameters_and_automatic() {
    let pts: Vec<[f64; 3]> = (0..300)
        .map(|i| [0.25 * f64::from(i), 0.25 * f64::from(i), 0.0])
        .collect();
    let det = Detector::lines(1.0, 10.0, 4).run(&pts).unwrap();
    one_structure_of_all(&det, pts.len());
    let det = Detector::auto(StructureKind::Lines, &pts, &Given::default())
        .unwrap()
        .run(&pts)
        .unwrap();
    one_structure_of_all(&det, pts.len());
}

#[test]
fn copies_of_few_points_return_without_error() {
    // 100 distinct points, 40 copies each: more copies than the local
    // analysis's 16 neighbours (the estimate once gave λ = NaN here).
    let pts = copies(100, 40, 3);
    for kind in [StructureKind::Planes, StructureKind::Lines] {
        let d = Detector::auto(kind, &pts, &Given::default()).unwrap();
        assert!(d.alpha().is_finite() && d.alpha() > 0.0);
        let det = d.run(&pts).unwrap();
        assert_eq!(det.labels.len(), pts.len());
    }
    let det = Detector::lines(1.0, 10.0, 4).run(&pts).unwrap();
    assert_eq!(det.labels.len(), pts.len());
    let det = Detector::planes(1.0, 4.0, 8.0, 20)
        .sampler(Sampler::Box { m1: 1.0, m2: 3 })
        .run(&pts)
        .unwrap();
    assert_eq!(det.labels.len(), pts.len());
}

#[test]
fn one_position_repeated() {
    let pts = vec![[1.5, -2.0, 3.0]; 5000];
    for kind in [StructureKind::Planes, StructureKind::Lines] {
        // No spacing to estimate from: an error saying so, not NaN.
        match Detector::auto(kind, &pts, &Given::default()) {
            Err(e @ DetectError::NoSpacing) => {
                assert!(e.to_string().contains("no spacing"), "{e}")
            }
            other => panic!("{:?}", other.map(|d| d.alpha())),
        }
    }
    let det = Detector::lines(1.0, 10.0, 4).run(&pts).unwrap();
    assert!(det.structures.is_empty());
    assert!(det.labels.iter().all(|&l| l == -1));
}

#[test]
fn copies_of_a_scene_give_the_scene_s_result_to_every_copy() {
    // The paper's lines scene, then a copy of every third point (and two
    // copies of every seventh) after it: the run takes the distinct
    // points (issue 19: 200 copies of 1,000 points took over 100 s, and
    // now take what the 1,000 take) and gives each copy its first
    // occurrence's labels.
    let scene = aniso_alpha::synth::lines(3);
    let n = scene.points.len();
    let mut pts = scene.points.clone();
    let mut orig: Vec<usize> = (0..n).collect();
    for i in (0..n).step_by(3) {
        pts.push(scene.points[i]);
        orig.push(i);
    }
    for i in (0..n).step_by(7) {
        pts.push(scene.points[i]);
        pts.push(scene.points[i]);
        orig.extend([i, i]);
    }
    let d = Detector::lines(1.0, 10.0, 4);
    let whole = d.run(&scene.points).unwrap();
    let dup = d.run(&pts).unwrap();
    assert!(whole.structures.len() >= 4);
    assert_eq!(dup.structures, whole.structures);
    assert_eq!(dup.simplices, whole.simplices);
    let (lw, pw) = (whole.labels.clone(), whole.part_labels());
    let pd = dup.part_labels();
    for (i, &o) in orig.iter().enumerate() {
        assert_eq!(dup.labels[i], lw[o], "point {i}");
        assert_eq!(pd[i], pw[o], "point {i}");
        assert_eq!(dup.first_occurrence[i] as usize, o, "point {i}");
    }
}

#[test]
fn copies_in_the_automatic_mode_keep_the_modes_members() {
    // The estimate runs on every point (copies included) and gives the
    // modes' members as input indices; the run on the distinct points
    // must map them, or the orientations of each mode would scan the
    // wrong points. A floor and a wall (40 × 40 points each, spacing
    // 0.25, noise 0.01) in 200 background points, then a copy of every
    // other point.
    let mut r = SplitMix64::new(5);
    let mut base: Vec<[f64; 3]> = Vec::new();
    let mut labels: Vec<i64> = Vec::new();
    for i in 0..40 {
        for j in 0..40 {
            let (u, v) = (0.25 * i as f64, 0.25 * j as f64);
            base.push([u, v, 0.01 * (r.uniform() - 0.5)]);
            base.push([0.01 * (r.uniform() - 0.5) - 1.0, u, v + 1.0]);
            labels.extend([0, 1]);
        }
    }
    for _ in 0..200 {
        base.push([
            12.0 * r.uniform() - 1.0,
            10.0 * r.uniform(),
            11.0 * r.uniform(),
        ]);
        labels.push(-1);
    }
    let n = base.len();
    let mut pts = base.clone();
    let mut truth = labels.clone();
    for i in (0..n).step_by(2) {
        pts.push(base[i]);
        truth.push(labels[i]);
    }
    let det = Detector::auto(StructureKind::Planes, &pts, &Given::default())
        .unwrap()
        .run(&pts)
        .unwrap();
    let ev = aniso_alpha::eval::evaluate(&truth, None, &det.labels, None).unwrap();
    eprintln!("floor and wall with copies, automatic: {ev}");
    assert!(ev.f1 >= 0.9, "{ev}");
    for i in n..pts.len() {
        let o = 2 * (i - n);
        assert_eq!(det.labels[i], det.labels[o]);
    }
}
