//! Times the triangulation and the alpha intervals of a point set and
//! prints one JSON line.
//!
//! `cargo run --release --example alpha_time -- points.bin` (raw
//! little-endian f64 triples, as in the `triangulate` example), or
//! `cargo run --release --example alpha_time -- uniform 100000`.
//! Add `--repeat N` to report the fastest of N runs, `--threads N` to
//! triangulate on N threads (default 1).
mod common;

use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::delaunay::Triangulation;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map(String::as_str).unwrap_or("uniform");
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let pts = common::from_args(kind, n);
    // `--repeat N`: run N times and report the fastest of each phase (the
    // machine may be shared; the minimum is the least noisy figure).
    let repeat = common::option(&args, "--repeat").unwrap_or(1);
    let threads = common::option(&args, "--threads").unwrap_or(1);
    let (mut t_tri, mut t_int) = (f64::INFINITY, f64::INFINITY);
    let (mut c_tri, mut c_int) = (f64::INFINITY, f64::INFINITY);
    let mut ac = None;
    for _ in 0..repeat.max(1) {
        drop(ac.take());
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let tri = Triangulation::with_threads(&pts, threads).expect("triangulation");
        t_tri = t_tri.min(t0.elapsed().as_secs_f64());
        c_tri = c_tri.min(cpu_seconds() - c0);
        let (t1, c1) = (Instant::now(), cpu_seconds());
        ac = Some(AlphaComplex::new(tri));
        t_int = t_int.min(t1.elapsed().as_secs_f64());
        c_int = c_int.min(cpu_seconds() - c1);
    }
    let ac = ac.expect("at least one run");
    println!(
        "{{\"n\": {}, \"tets\": {}, \"edges\": {}, \"triangles\": {}, \"triangulate\": {t_tri:.4}, \"intervals\": {t_int:.4}, \"total\": {:.4}, \"cpu_triangulate\": {c_tri:.4}, \"cpu_intervals\": {c_int:.4}}}",
        pts.len(),
        ac.triangulation().num_finite_tets(),
        ac.num_edges(),
        ac.num_triangles(),
        t_tri + t_int
    );
}

/// CPU time of this process in seconds (Linux `/proc/self/schedstat`, in
/// ns), or NaN elsewhere: on a shared machine wall time includes the time
/// spent waiting for a core.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}
