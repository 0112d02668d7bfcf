//! Criterion benchmarks of the Delaunay construction.
//!
//! `cargo bench -p aniso-alpha --bench delaunay` (uniform 10k/100k/1M, 50³ grid).
//! The 1M case is slow to sample; run it alone with
//! `cargo bench -p aniso-alpha --bench delaunay -- uniform/1000000`.
//! The `*_parallel2` cases run the same builds on 2 threads.
use aniso_alpha::delaunay::Triangulation;
#[path = "../examples/common/mod.rs"]
mod common;
use common::*;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("delaunay");
    g.sample_size(10);
    for n in [10_000usize, 100_000, 1_000_000] {
        let pts = uniform(n, 20240601);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new("uniform", n), &pts, |b, p| {
            b.iter(|| Triangulation::new(p).unwrap().num_finite_tets())
        });
        if n >= 100_000 {
            g.bench_with_input(BenchmarkId::new("uniform_parallel2", n), &pts, |b, p| {
                b.iter(|| Triangulation::with_threads(p, 2).unwrap().num_finite_tets())
            });
        }
    }
    let pts = grid(50);
    g.throughput(Throughput::Elements(pts.len() as u64));
    g.bench_with_input(BenchmarkId::new("grid", 50), &pts, |b, p| {
        b.iter(|| Triangulation::new(p).unwrap().num_finite_tets())
    });
    g.bench_with_input(BenchmarkId::new("grid_parallel2", 50), &pts, |b, p| {
        b.iter(|| Triangulation::with_threads(p, 2).unwrap().num_finite_tets())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
