//! Point sets shared by the examples and benches (`#[path]`-included).
#![allow(dead_code)]

use aniso_alpha::synth::Rng;

/// `n` uniform points in the unit cube (fixed seed).
pub fn uniform(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
        .collect()
}

/// The integer grid {0..n-1}³.
pub fn grid(n: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::with_capacity(n * n * n);
    for x in 0..n {
        for y in 0..n {
            for z in 0..n {
                v.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    v
}

/// A raw little-endian f64 triples file (the peers' `.bin` datasets).
pub fn read_bin(path: &str) -> Vec<[f64; 3]> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    bytes
        .chunks_exact(24)
        .map(|c| {
            let g = |k: usize| {
                let mut b = [0u8; 8];
                b.copy_from_slice(&c[8 * k..8 * k + 8]);
                f64::from_le_bytes(b)
            };
            [g(0), g(1), g(2)]
        })
        .collect()
}

/// Points from the command line: a `.bin` file, `grid N` or `uniform N`.
pub fn from_args(kind: &str, n: usize) -> Vec<[f64; 3]> {
    match kind {
        f if f.ends_with(".bin") => read_bin(f),
        "grid" => grid(n),
        _ => uniform(n, 20240601),
    }
}

/// The value after `--name` in `args`, if there is one and it parses.
pub fn option(args: &[String], name: &str) -> Option<usize> {
    let k = args.iter().position(|a| a == name)?;
    args.get(k + 1)?.parse().ok()
}
