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

/// `n` points on the segment from the origin to (1, 0.7, 0.3) in random
/// order along it, each coordinate rounded to 1e-6: nearly collinear.
pub fn rounded_line(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Rng::new(seed);
    let round = |x: f64| (x * 1e6).round() / 1e6;
    (0..n)
        .map(|_| {
            let t = rng.uniform();
            [round(t), round(0.7 * t), round(0.3 * t)]
        })
        .collect()
}

/// `n` points `i · (1, 0.7, 0.3) / n` rounded to 1e-6: for `n` dividing
/// 10^5 exactly collinear in decimal, so collinear up to the rounding of
/// the decimals to binary (every predicate is a near-tie).
pub fn decimal_line(n: usize) -> Vec<[f64; 3]> {
    let round = |x: f64| (x * 1e6).round() / 1e6;
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64;
            [round(t), round(0.7 * t), round(0.3 * t)]
        })
        .collect()
}

/// `n` points made of `n / 31` uniform points, each repeated 31 times, in
/// random order (a duplicate-heavy input).
pub fn duplicates31(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let base = uniform((n / 31).max(1), seed);
    let mut rng = Rng::new(seed ^ 31);
    (0..n)
        .map(|_| base[(rng.uniform() * base.len() as f64) as usize])
        .collect()
}

/// Points from the command line: a `.bin` file, `grid N`, `line N`
/// ([`rounded_line`]), `decimal_line N`, `dups31 N` ([`duplicates31`]) or
/// `uniform N`.
pub fn from_args(kind: &str, n: usize) -> Vec<[f64; 3]> {
    match kind {
        f if f.ends_with(".bin") => read_bin(f),
        "grid" => grid(n),
        "line" => rounded_line(n, 20240601),
        "decimal_line" => decimal_line(n),
        "dups31" => duplicates31(n, 20240601),
        _ => uniform(n, 20240601),
    }
}

/// The value after `--name` in `args`, if there is one and it parses.
pub fn option(args: &[String], name: &str) -> Option<usize> {
    let k = args.iter().position(|a| a == name)?;
    args.get(k + 1)?.parse().ok()
}
