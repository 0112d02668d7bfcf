//! Triangulation + alpha intervals on uniform random points (fixed seed).
//!
//! `cargo bench -p aniso-alpha --bench alpha`
use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::delaunay::Triangulation;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

fn uniform(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut s = seed;
    let mut rnd = || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| [rnd(), rnd(), rnd()]).collect()
}

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
