//! Quality sweeps of the brute-force detection pipelines of
//! `tests/lines_pipeline_bruteforce.rs` and
//! `tests/planes_pipeline_bruteforce.rs` (docs/method.md §4 without the Delaunay
//! engine): F1 over densities, seeds and orientation samplers. They print
//! figures and assert nothing, so they are an example, not tests.
//!
//! `cargo run --release --example pipeline_sweeps -- lines-density`
//! `cargo run --release --example pipeline_sweeps -- lines-samplers`
//! `cargo run --release --example pipeline_sweeps -- planes-density`
//! `cargo run --release --example pipeline_sweeps -- planes-samplers`
//! (no argument: all four; each takes minutes).
use aniso_alpha::detect::orientations::Sampler;
use aniso_alpha::synth::SceneOptions;

// The pipelines themselves, shared with the tests.
#[allow(dead_code, unused_imports)]
#[path = "../tests/lines_pipeline_bruteforce.rs"]
mod lines;
#[allow(dead_code, unused_imports)]
#[path = "../tests/planes_pipeline_bruteforce.rs"]
mod planes;

fn lines_density() {
    for density in [0.005, 0.01, 0.02, 0.03, 0.05] {
        let mut f1 = 0.0;
        for seed in 1..=3 {
            f1 += lines::run_lines(seed, density).0;
        }
        println!("SWEEP lines density {density}: mean F1 {:.3}", f1 / 3.0);
    }
}

fn lines_samplers() {
    for (name, sampler) in [
        ("box m1=0.3", Sampler::default()),
        ("fibonacci 10deg", Sampler::Fibonacci { step_degrees: 10.0 }),
        ("fibonacci 14deg", Sampler::Fibonacci { step_degrees: 14.0 }),
    ] {
        for density in [0.01, 0.02] {
            let (mut f1, mut found) = (0.0, 0);
            for seed in 1..=3 {
                let r = lines::run_lines_with(seed, density, &sampler);
                f1 += r.0;
                found += r.1;
            }
            println!(
                "COMPARE lines {name} density {density}: mean F1 {:.3}, found {found}/15",
                f1 / 3.0
            );
        }
    }
}

fn planes_density() {
    for density in [0.01, 0.03, 0.1] {
        for seed in 2..=3 {
            for (kind, opts) in [
                ("planes", SceneOptions::planes()),
                ("polyhedron", SceneOptions::polyhedron()),
            ] {
                let ev = planes::run(opts.seed(seed).background_per_ellipsoid(density), kind);
                println!(
                    "SWEEP {kind} density {density} seed {seed}: F1 {:.3}",
                    ev.f1
                );
            }
        }
    }
}

fn planes_samplers() {
    for (name, sampler) in [
        ("box m1=0.3 m2=12", Sampler::default()),
        ("fibonacci 10deg", Sampler::Fibonacci { step_degrees: 10.0 }),
        ("fibonacci 15deg", Sampler::Fibonacci { step_degrees: 15.0 }),
    ] {
        for density in [0.01, 0.1] {
            let mut f1 = 0.0;
            for seed in 1..=2 {
                for (kind, opts) in [
                    ("planes", SceneOptions::planes()),
                    ("polyhedron", SceneOptions::polyhedron()),
                ] {
                    let opts = opts.seed(seed).background_per_ellipsoid(density);
                    f1 += planes::run_with(opts, kind, &sampler, false).f1;
                }
            }
            println!(
                "COMPARE planes+polyhedron {name} density {density}: mean F1 {:.3}",
                f1 / 4.0
            );
        }
    }
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    let all = which.is_empty();
    if all || which == "lines-density" {
        lines_density();
    }
    if all || which == "lines-samplers" {
        lines_samplers();
    }
    if all || which == "planes-density" {
        planes_density();
    }
    if all || which == "planes-samplers" {
        planes_samplers();
    }
}
