//! The path filter (docs/method.md §3) on a large triangulated patch with fins.
//!
//! `cargo bench -p aniso-alpha --bench filter`
//!
//! A 200 × 100 grid of squares cut into 40,000 triangles, plus 2,000 fins
//! (triangles on an inner edge, each a path of length 1), filtered with
//! `nb_c = 20`: the fins go, the patch stays.
use aniso_alpha::detect::filter::filter_mask;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

/// The triangles of an `nx` × `ny` grid of squares, two per square.
fn patch(nx: u32, ny: u32) -> Vec<[u32; 3]> {
    let v = |i: u32, j: u32| i + j * (nx + 1);
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            t.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            t.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    t
}

fn bench(c: &mut Criterion) {
    let mut s = patch(200, 100);
    for i in 0..2000u32 {
        let v = 1 + (i * 7919) % 199 + 201 * (1 + (i * 104_729) % 99);
        s.push([v, v + 202, 1_000_000 + i]);
    }
    // What is timed is right: the fins go, the patch stays.
    let kept = filter_mask(&s, 20).unwrap().iter().filter(|&&k| k).count();
    assert_eq!(kept, 40_000);
    let mut g = c.benchmark_group("filter");
    g.throughput(Throughput::Elements(s.len() as u64));
    g.bench_function("patch_200x100_fins_2000", |b| {
        b.iter(|| filter_mask(&s, 20).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
