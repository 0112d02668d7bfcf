//! Triangulation + alpha intervals on uniform random points (fixed seed).
//!
//! `cargo bench -p aniso-alpha --bench alpha`
use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::delaunay::Triangulation;
#[path = "../examples/common/mod.rs"]
mod common;
use common::*;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("alpha");
    g.sample_size(10);
    for n in [10_000usize, 100_000] {
        let pts = uniform(n, 42);
        g.bench_with_input(
            BenchmarkId::new("triangulate+intervals", n),
            &pts,
            |b, pts| b.iter(|| AlphaComplex::new(Triangulation::new(pts).unwrap())),
        );
        let tri = Triangulation::new(&pts).unwrap();
        g.bench_with_input(BenchmarkId::new("intervals", n), &tri, |b, tri| {
            b.iter_batched(
                || tri.clone(),
                AlphaComplex::new,
                criterion::BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
