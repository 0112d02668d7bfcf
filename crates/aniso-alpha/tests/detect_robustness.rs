//! Issue 14's hard variants, one small scene per kind with a fixed seed:
//! jitter as a fraction of the spacing d, 3× the paper's background in the
//! same box, random sampling; the paper's parameters and the significance
//! test (docs/method.md §4). `scripts/eval_robustness.py` measures the
//! whole table over more seeds (BENCHMARKS.md).

use aniso_alpha::detect::{Detection, Detector};
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

/// Every structure kept is significant, and says how much.
fn assert_all_significant(det: &Detection) {
    for s in &det.structures {
        assert!(
            s.log10_nfa <= 0.0,
            "structure {} log10 NFA {}",
            s.id,
            s.log10_nfa
        );
    }
}

fn lines(scene: &Scene) -> Detection {
    Detector::lines(1.0, 10.0, 4).run(&scene.points).unwrap()
}

fn planes(scene: &Scene) -> Detection {
    Detector::planes(1.0, 4.0, 8.0, 20)
        .run(&scene.points)
        .unwrap()
}

#[test]
fn lines_jittered_by_a_twentieth_of_the_spacing() {
    let scene = SceneOptions::lines()
        .jitter_of_spacing(0.05)
        .seed(21)
        .generate()
        .unwrap();
    let det = lines(&scene);
    let ev = score(&scene, &det);
    eprintln!("lines jitter 0.05 d: {ev}");
    assert!(ev.f1 >= 0.85, "{ev}");
    assert!(ev.structures_found >= 4, "{ev}");
}

#[test]
fn lines_jittered_by_a_tenth_of_the_spacing_are_claimed_along_their_whole_line() {
    // Jitter σ = 0.7 moves consecutive points ~10° off their line's
    // direction: the ellipsoid (α = 1, λ = 10) follows a chain for a few
    // points, and the piece's own line leans. The claims' widening fits a
    // piece again on its wider tube, so its line's far points join it
    // (this seed: 3 lines found, F1 0.69, when the wider tube kept the
    // piece's leaning line).
    let scene = SceneOptions::lines()
        .jitter_of_spacing(0.1)
        .seed(2)
        .generate()
        .unwrap();
    let det = lines(&scene);
    let ev = score(&scene, &det);
    eprintln!("lines jitter 0.1 d: {ev}");
    assert!(ev.f1 >= 0.8, "{ev}");
    assert!(ev.structures_found >= 4, "{ev}");
}

#[test]
fn lines_in_three_times_the_background_and_the_test_rejects_chance_chains() {
    let scene = SceneOptions::lines()
        .background_density_in_box(0.03)
        .seed(22)
        .generate()
        .unwrap();
    assert_eq!(scene.points.len(), 4550);
    let det = lines(&scene);
    let ev = score(&scene, &det);
    eprintln!("lines 3x background: {ev}");
    assert!(ev.f1 >= 0.85, "{ev}");
    assert!(ev.structures_found >= 4, "{ev}");
    assert_all_significant(&det);
    // Without the test (nb_c alone, the paper) chance chains pile up:
    // the test is what keeps the precision.
    let off = Detector::lines(1.0, 10.0, 4)
        .significance(None)
        .run(&scene.points)
        .unwrap();
    let ev_off = score(&scene, &off);
    eprintln!("lines 3x background, no test: {ev_off}");
    assert!(off.structures.len() > det.structures.len() + 3, "{ev_off}");
    assert!(ev_off.precision + 0.2 < ev.precision, "{ev_off} vs {ev}");
}

#[test]
fn lines_jittered_by_a_tenth_of_the_spacing() {
    // Points spread about α across the line: the paper's ellipsoid joins
    // them in short zigzags, which the straight filter follows through
    // background ramifications (docs/method.md §4). Seed 107: F1 0.57 and
    // two lines of five before it.
    let scene = SceneOptions::lines()
        .jitter_of_spacing(0.1)
        .seed(107)
        .generate()
        .unwrap();
    let det = lines(&scene);
    let ev = score(&scene, &det);
    eprintln!("lines jitter 0.1 d: {ev}");
    assert!(ev.f1 >= 0.75, "{ev}");
    assert!(ev.structures_found >= 4, "{ev}");
}

#[test]
fn lines_in_ten_times_the_background() {
    // 15,050 points; background fans hang on every line in every
    // orientation. Seed 107: one line of five found (F1 0.33) before the
    // straight filter.
    let scene = SceneOptions::lines()
        .background_density_in_box(0.1)
        .seed(107)
        .generate()
        .unwrap();
    assert_eq!(scene.points.len(), 15050);
    let det = lines(&scene);
    let ev = score(&scene, &det);
    eprintln!("lines 10x background: {ev}");
    assert!(ev.f1 >= 0.85, "{ev}");
    assert!(ev.structures_found >= 4, "{ev}");
    assert!(ev.precision >= 0.75, "{ev}");
}

#[test]
fn short_lines_whose_fit_leans_on_background_points_are_still_significant() {
    // Seed 5 at 10× background: two lines of ten exact points are
    // extracted with three or four background points near their ends, and
    // their least-squares fits (and the fits of their better halves) lean
    // by up to 0.6 α: log₁₀ NFA 0.5 and 0.7, rejected (3 lines of 5 found,
    // F1 0.70). The line through two of a part's points, one of the test's
    // own primitives, holds the ten exactly.
    let scene = SceneOptions::lines()
        .background_density_in_box(0.1)
        .seed(5)
        .generate()
        .unwrap();
    let det = lines(&scene);
    let ev = score(&scene, &det);
    eprintln!("lines 10x background, seed 5: {ev}");
    assert_eq!(ev.structures_found, 5, "{ev}");
    assert!(ev.f1 >= 0.85, "{ev}");
    assert_all_significant(&det);
}

#[test]
fn planes_jittered_by_a_tenth_of_the_spacing() {
    let scene = SceneOptions::planes()
        .jitter_of_spacing(0.1)
        .seed(23)
        .generate()
        .unwrap();
    let det = planes(&scene);
    let ev = score(&scene, &det);
    eprintln!("planes jitter 0.1 d: {ev}");
    assert!(ev.f1 >= 0.9, "{ev}");
    assert_eq!(ev.structures_found, 3, "{ev}");
}

#[test]
fn polyhedron_sampled_at_random_in_three_times_the_background() {
    let scene = SceneOptions::polyhedron()
        .random_sampling(true)
        .background_density_in_box(0.03)
        .seed(24)
        .generate()
        .unwrap();
    let det = planes(&scene);
    let ev = score(&scene, &det);
    eprintln!("polyhedron random, 3x background: {ev}");
    assert!(ev.f1 >= 0.85, "{ev}");
    assert_eq!(ev.structures_found, 1, "{ev}");
}
