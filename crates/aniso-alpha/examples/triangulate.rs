//! Times the triangulation of a generated point set.
//!
//! `cargo run --release --example triangulate -- uniform 1000000`
//! `cargo run --release --example triangulate -- grid 50`
//! `cargo run --release --example triangulate -- points.bin` (raw little-endian f64 triples)
use aniso_alpha::delaunay::Triangulation;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map(String::as_str).unwrap_or("uniform");
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let mut s = 20240601u64;
    let mut rnd = || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let pts: Vec<[f64; 3]> = match kind {
        f if f.ends_with(".bin") => {
            let bytes = std::fs::read(f).expect("read .bin");
            bytes
                .chunks_exact(24)
                .map(|c| {
                    let g = |k: usize| f64::from_le_bytes(c[8 * k..8 * k + 8].try_into().unwrap());
                    [g(0), g(1), g(2)]
                })
                .collect()
        }
        "grid" => {
            let mut v = Vec::new();
            for x in 0..n {
                for y in 0..n {
                    for z in 0..n {
                        v.push([x as f64, y as f64, z as f64]);
                    }
                }
            }
            v
        }
        _ => (0..n).map(|_| [rnd(), rnd(), rnd()]).collect(),
    };
    let t0 = Instant::now();
    let tri = Triangulation::new(&pts).expect("triangulation");
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
