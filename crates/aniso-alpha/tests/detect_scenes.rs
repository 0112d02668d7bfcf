//! End-to-end detection on the synthetic scenes with the paper's
//! parameters (docs/method.md §5), scored as in docs/method.md §6.

use aniso_alpha::detect::{Detection, Detector, Part};
use aniso_alpha::eval::{evaluate, Evaluation};
use aniso_alpha::synth::{Scene, SceneOptions};

fn score(scene: &Scene, det: &Detection) -> Evaluation {
    evaluate(
        &scene.labels,
        Some(&scene.parts),
        &det.labels,
        Some(&det.part_labels()),
    )
    .unwrap()
}

#[test]
fn fig12_lines() {
    for seed in 1..=3 {
        let scene = SceneOptions::lines().seed(seed).generate().unwrap();
        let det = Detector::lines(1.0, 10.0, 4).run(&scene.points).unwrap();
        let ev = score(&scene, &det);
        eprintln!(
            "lines seed {seed}: {} structures\n{ev}",
            det.structures.len()
        );
        assert_eq!(det.stats.orientations, 162);
        assert!(ev.f1 >= 0.85, "lines seed {seed}: F1 {}", ev.f1);
        assert!(ev.structures_found >= 4, "lines seed {seed}: {ev}");
    }
}

#[test]
fn fig10_polyhedron() {
    for seed in 1..=2 {
        let scene = SceneOptions::polyhedron().seed(seed).generate().unwrap();
        let det = Detector::planes(1.0, 4.0, 8.0, 20)
            .run(&scene.points)
            .unwrap();
        let ev = score(&scene, &det);
        eprintln!(
            "polyhedron seed {seed}: {} structures\n{ev}",
            det.structures.len()
        );
        assert_eq!(det.stats.orientations, 1944);
        assert!(ev.f1 >= 0.9, "polyhedron seed {seed}: F1 {}", ev.f1);
        // One polyhedral surface, found as one structure with its facets.
        assert_eq!(ev.structures_found, 1, "{ev}");
        assert!(ev.parts_found >= 4, "{ev}");
    }
}

#[test]
fn fig5_planes() {
    for seed in 1..=2 {
        let scene = SceneOptions::planes().seed(seed).generate().unwrap();
        let det = Detector::planes(1.0, 4.0, 8.0, 20)
            .run(&scene.points)
            .unwrap();
        let ev = score(&scene, &det);
        eprintln!(
            "planes seed {seed}: {} structures\n{ev}",
            det.structures.len()
        );
        assert!(ev.f1 >= 0.9, "planes seed {seed}: F1 {}", ev.f1);
        assert_eq!(ev.structures_found, scene.num_structures(), "{ev}");
    }
}

#[test]
fn crossing_planes_are_two_structures() {
    let scene = SceneOptions::planes()
        .seed(3)
        .structures(2)
        .crossing(true)
        .generate()
        .unwrap();
    let det = Detector::planes(1.0, 4.0, 8.0, 20)
        .run(&scene.points)
        .unwrap();
    let ev = score(&scene, &det);
    eprintln!("crossing planes: {} structures\n{ev}", det.structures.len());
    assert_eq!(ev.structures_found, 2, "{ev}");
    assert!(ev.f1 >= 0.9, "{ev}");
}

#[test]
fn crossing_lines_are_separate_structures() {
    let scene = SceneOptions::lines()
        .seed(4)
        .crossing(true)
        .generate()
        .unwrap();
    let det = Detector::lines(1.0, 10.0, 4).run(&scene.points).unwrap();
    let ev = score(&scene, &det);
    eprintln!("crossing lines: {} structures\n{ev}", det.structures.len());
    assert!(ev.structures_found + 1 >= scene.num_structures(), "{ev}");
    assert!(ev.f1 >= 0.85, "{ev}");
}

#[test]
fn euclidean_alpha_shape_does_clearly_worse_on_lines() {
    // The paper's own comparison: E = (1, 1, 1), one orientation, at its
    // best α over a scan.
    let scene = SceneOptions::lines().seed(1).generate().unwrap();
    let aniso = score(
        &scene,
        &Detector::lines(1.0, 10.0, 4).run(&scene.points).unwrap(),
    );
    let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut best = (0.0, 0.0);
    for k in 1..=40 {
        let alpha = 0.5 * k as f64;
        // The paper's Euclidean α-shape: nb_c alone, no significance test
        // (scripts/eval_robustness.py's baseline).
        let det = Detector::lines(alpha, 1.0, 4)
            .rotations(vec![id])
            .significance(None)
            .run(&scene.points)
            .unwrap();
        let f1 = score(&scene, &det).f1;
        if f1 > best.0 {
            best = (f1, alpha);
        }
    }
    eprintln!(
        "lines: anisotropic F1 {:.3}, Euclidean best F1 {:.3} at alpha {}",
        aniso.f1, best.0, best.1
    );
    assert!(best.0 + 0.2 < aniso.f1, "{} vs {}", best.0, aniso.f1);
}

#[test]
fn output_does_not_depend_on_thread_count() {
    let scene = SceneOptions::polyhedron().seed(5).generate().unwrap();
    let d = Detector::planes(1.0, 4.0, 8.0, 20);
    let many = d.run(&scene.points).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| d.run(&scene.points).unwrap());
    assert_eq!(many, one);
}

#[test]
fn pruning_is_exact() {
    // Same union with and without pruning, on a smaller orientation set.
    use aniso_alpha::detect::orientations::Sampler;
    let scene = SceneOptions::lines().seed(2).generate().unwrap();
    let d = Detector::lines(1.0, 10.0, 4).sampler(Sampler::Fibonacci { step_degrees: 20.0 });
    let with = d.clone().run(&scene.points).unwrap();
    let without = d.prune(false).run(&scene.points).unwrap();
    assert_eq!(with.simplices, without.simplices);
    assert_eq!(with.stats.union_simplices, without.stats.union_simplices);
    assert!(with.stats.triangulated_points * 3 < without.stats.triangulated_points);
}

#[test]
fn progress_and_cancellation() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;
    let scene = SceneOptions::lines().seed(1).generate().unwrap();
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&calls);
    let d = Detector::lines(1.0, 10.0, 4).progress(move |done: usize, total: usize| {
        assert!(done <= total);
        counter.fetch_add(1, Ordering::Relaxed);
        true
    });
    d.run(&scene.points).unwrap();
    assert_eq!(calls.load(Ordering::Relaxed), 162);
    // Clones share the callback.
    d.clone().run(&scene.points).unwrap();
    assert_eq!(calls.load(Ordering::Relaxed), 2 * 162);
    let r = Detector::lines(1.0, 10.0, 4)
        .progress(|done: usize, _| done < 5)
        .run(&scene.points);
    assert_eq!(r, Err(aniso_alpha::detect::DetectError::Cancelled));
}

/// Found by the `detect` fuzz target: an exact duplicate of a structure's
/// point had the structure's label but part label −1, because parts list
/// first occurrences only. Both labels now follow the first occurrence.
#[test]
fn duplicates_take_their_first_occurrences_labels() {
    let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let pts = [[-4.0, -4.0, -4.0], [-4.0, -4.0, -4.0], [-3.0, -2.0, 0.0]];
    // Two distinct points: a line through them explains them exactly, so
    // the significance test (which needs k + 2 = 3 points) keeps nothing;
    // nb_c alone, as in the paper, keeps the pair.
    let det = Detector::lines(1000.0, 4.0, 1)
        .rotations(vec![id])
        .significance(None)
        .run(&pts)
        .unwrap();
    assert_eq!(det.first_occurrence, [0, 0, 2]);
    assert_eq!(det.labels, [0, 0, 0]);
    assert_eq!(det.part_labels(), [0, 0, 0]);

    // A scene with every point repeated (the copies after the originals,
    // one of them as -0.0): same structures, and each copy labelled as
    // its original.
    let scene = SceneOptions::lines().seed(1).generate().unwrap();
    let n = scene.points.len();
    let mut pts = scene.points.clone();
    pts.extend(
        scene
            .points
            .iter()
            .map(|p| p.map(|c| if c == 0.0 { -0.0 } else { c })),
    );
    let once = Detector::lines(1.0, 10.0, 4).run(&scene.points).unwrap();
    let twice = Detector::lines(1.0, 10.0, 4).run(&pts).unwrap();
    assert_eq!(twice.structures, once.structures);
    assert_eq!(twice.labels[..n], once.labels[..]);
    assert_eq!(twice.labels[n..], once.labels[..]);
    let (p1, p2) = (once.part_labels(), twice.part_labels());
    assert_eq!(p2[..n], p1[..]);
    assert_eq!(p2[n..], p1[..]);
    assert!(twice.first_occurrence[n..].iter().copied().eq(0..n as u32));
}

/// A run without outlines is the run with them, less the plane parts'
/// outlines and meshes: the same labels, parts, planes and NFAs; line
/// parts keep their segments.
#[test]
fn outlines_off_changes_nothing_but_the_outlines() {
    let scene = SceneOptions::polyhedron().seed(2).generate().unwrap();
    let detector = Detector::planes(1.0, 4.0, 8.0, 20);
    assert!(detector.draws_outlines());
    let with = detector.clone().run(&scene.points).unwrap();
    let without = detector.outlines(false).run(&scene.points).unwrap();
    assert_eq!(with.labels, without.labels);
    assert_eq!(with.part_labels(), without.part_labels());
    assert_eq!(with.simplices, without.simplices);
    let parts = |d: &Detection| -> Vec<Part> {
        d.structures.iter().flat_map(|s| s.parts.clone()).collect()
    };
    let (a, b) = (parts(&with), parts(&without));
    assert!(a.len() >= 5, "{} parts", a.len());
    assert_eq!(a.len(), b.len());
    for (p, q) in a.iter().zip(&b) {
        assert!(p.outline.len() >= 3 && !p.mesh.is_empty());
        assert!(q.outline.is_empty() && q.mesh.is_empty());
        assert_eq!(
            (&p.vertices, &p.primitive, &p.simplices),
            (&q.vertices, &q.primitive, &q.simplices)
        );
        assert_eq!(p.log10_nfa.to_bits(), q.log10_nfa.to_bits());
    }
    // Lines: the segments stay.
    let scene = SceneOptions::lines().seed(1).generate().unwrap();
    let det = Detector::lines(1.0, 10.0, 4)
        .outlines(false)
        .run(&scene.points)
        .unwrap();
    let segs: Vec<_> = det
        .structures
        .iter()
        .flat_map(|s| &s.parts)
        .map(|p| p.segment())
        .collect();
    assert!(!segs.is_empty() && segs.iter().all(Option::is_some));
}
