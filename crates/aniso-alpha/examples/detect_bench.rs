//! End-to-end detection timings and scores on the synthetic scenes.
//!
//! `cargo run --release --example detect_bench`            (paper scenes, pruning, samplers)
//! `cargo run --release --example detect_bench -- big`     (adds the 1M-point lines scene)
//!
//! Prints one Markdown table row per run: scene, points, orientations,
//! wall seconds, point-orientations per second, F1, structures found.
use aniso_alpha::detect::orientations::Sampler;
use aniso_alpha::detect::Detector;
use aniso_alpha::eval::evaluate;
use aniso_alpha::synth::{Scene, SceneOptions};
use std::time::Instant;

fn row(name: &str, scene: &Scene, det: Detector) {
    let t = Instant::now();
    let d = det.run(&scene.points).expect("detection");
    let s = t.elapsed().as_secs_f64();
    let ev = evaluate(&scene.labels, None, &d.labels, None).expect("eval");
    let po = scene.points.len() as f64 * d.stats.orientations as f64 / s;
    println!(
        "| {name} | {} | {} | {:.3} | {:.2e} | {:.3} | {}/{} | {} |",
        scene.points.len(),
        d.stats.orientations,
        s,
        po,
        ev.f1,
        ev.structures_found,
        ev.structures_total,
        d.stats.triangulated_points / d.stats.orientations.max(1) as u64,
    );
}

fn main() {
    let big = std::env::args().any(|a| a == "big");
    let threads = rayon::current_num_threads();
    println!("threads: {threads}");
    println!();
    println!("| run | points | orientations | seconds | point-orientations/s | F1 | structures found | points triangulated per orientation |");
    println!("|---|---:|---:|---:|---:|---:|---|---:|");
    let lines = SceneOptions::lines().seed(1).generate().unwrap();
    let poly = SceneOptions::polyhedron().seed(1).generate().unwrap();
    let planes = SceneOptions::planes().seed(1).generate().unwrap();
    row("Fig. 12 lines (box)", &lines, Detector::lines(1.0, 10.0, 4));
    row(
        "Fig. 10 polyhedron (box)",
        &poly,
        Detector::planes(1.0, 4.0, 8.0, 20),
    );
    row(
        "Fig. 5 planes (box)",
        &planes,
        Detector::planes(1.0, 4.0, 8.0, 20),
    );
    // Pruning gain.
    row(
        "Fig. 12 lines, no pruning",
        &lines,
        Detector::lines(1.0, 10.0, 4).prune(false),
    );
    row(
        "Fig. 10 polyhedron, no pruning",
        &poly,
        Detector::planes(1.0, 4.0, 8.0, 20).prune(false),
    );
    // Samplers.
    for step in [10.0, 15.0] {
        let s = Sampler::Fibonacci { step_degrees: step };
        row(
            &format!("Fig. 12 lines (Fibonacci {step}°)"),
            &lines,
            Detector::lines(1.0, 10.0, 4).sampler(s),
        );
        row(
            &format!("Fig. 10 polyhedron (Fibonacci {step}°)"),
            &poly,
            Detector::planes(1.0, 4.0, 8.0, 20).sampler(s),
        );
    }
    // Denser backgrounds.
    for x in [0.02, 0.03] {
        let sc = SceneOptions::lines()
            .seed(1)
            .background_per_ellipsoid(x)
            .generate()
            .unwrap();
        row(
            &format!("lines, background {x}/ellipsoid"),
            &sc,
            Detector::lines(1.0, 10.0, 4),
        );
    }
    if big {
        let sc = SceneOptions::lines()
            .seed(1)
            .background(1_000_000)
            .generate()
            .unwrap();
        row(
            "lines + 1M background (box)",
            &sc,
            Detector::lines(1.0, 10.0, 4),
        );
    }
}
