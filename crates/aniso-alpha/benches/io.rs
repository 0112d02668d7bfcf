//! Reader throughput. `cargo bench -p aniso-alpha --bench io`
//! (criterion prints MB/s for each reader).

use std::hint::black_box;
use std::path::Path;

use aniso_alpha::io::{
    read_ply_bytes, read_xyz_bytes, write_ply_to, Mesh, PlyEncoding, ReadOptions,
};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

/// A scan-like cloud: coordinates with 6 decimals, a few extra columns.
fn cloud(n: usize) -> Vec<[f64; 3]> {
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| [next() * 200.0 - 100.0, next() * 50.0, next() * 10.0 - 5.0])
        .collect()
}

fn xyz_text(points: &[[f64; 3]]) -> Vec<u8> {
    let mut s = String::from("x y z intensity\n");
    for (i, p) in points.iter().enumerate() {
        s += &format!("{:.6} {:.6} {:.6} {}\n", p[0], p[1], p[2], i % 256);
    }
    s.into_bytes()
}

fn bench(c: &mut Criterion) {
    let pts = cloud(500_000);
    let text = xyz_text(&pts);
    let csv: Vec<u8> = text
        .iter()
        .map(|&b| if b == b' ' { b',' } else { b })
        .collect();
    let mut ply = Vec::new();
    write_ply_to(&mut ply, &Mesh::new(&pts), PlyEncoding::BinaryLittleEndian).unwrap();
    let opts = ReadOptions::default();

    let mut g = c.benchmark_group("read");
    g.sample_size(20);
    g.throughput(Throughput::Bytes(text.len() as u64));
    g.bench_function("xyz", |b| {
        b.iter(|| read_xyz_bytes(Path::new("b.xyz"), black_box(&text), &opts).unwrap())
    });
    // Shortest round-trip output (~17 digits): the standard parser's path.
    let full: Vec<u8> = pts
        .iter()
        .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
        .collect::<String>()
        .into_bytes();
    g.throughput(Throughput::Bytes(full.len() as u64));
    g.bench_function("xyz_full_precision", |b| {
        b.iter(|| read_xyz_bytes(Path::new("b.xyz"), black_box(&full), &opts).unwrap())
    });
    g.throughput(Throughput::Bytes(csv.len() as u64));
    g.bench_function("csv", |b| {
        b.iter(|| read_xyz_bytes(Path::new("b.csv"), black_box(&csv), &opts).unwrap())
    });
    g.throughput(Throughput::Bytes(ply.len() as u64));
    g.bench_function("ply_binary", |b| {
        b.iter(|| read_ply_bytes(Path::new("b.ply"), black_box(&ply), &opts).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
