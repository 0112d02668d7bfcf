//! Times the triangulation of a generated point set.
//!
//! `cargo run --release --example triangulate -- uniform 1000000`
//! `cargo run --release --example triangulate -- grid 50`
//! `cargo run --release --example triangulate -- line 100000` (also
//! `decimal_line N`, `dups31 N`: the degenerate series of
//! `scripts/bench_degenerate.py`)
//! `cargo run --release --example triangulate -- points.bin` (raw little-endian f64 triples)
//! Add `--threads N` for the parallel build, `--validate` to check the result.
mod common;

use aniso_alpha::delaunay::Triangulation;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map(String::as_str).unwrap_or("uniform");
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let pts = common::from_args(kind, n);
    let threads = common::option(&args, "--threads").unwrap_or(1);
    let t0 = Instant::now();
    let tri = Triangulation::with_threads(&pts, threads).expect("triangulation");
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "{{\"tool\":\"aniso_alpha\",\"input\":\"{kind}\",\"n\":{},\"vertices\":{},\"finite_tets\":{},\"time_s\":{dt:.6}}}",
        pts.len(),
        tri.num_vertices(),
        tri.num_finite_tets()
    );
    if args.iter().any(|a| a == "--validate") {
        let t1 = Instant::now();
        tri.validate_with_input(&pts).expect("valid");
        eprintln!("valid ({:.3}s)", t1.elapsed().as_secs_f64());
    }
}
