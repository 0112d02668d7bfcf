//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

pub fn fixture_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("fixtures")
        .join(name)
}

/// Reads a whitespace-separated `x y z` file (the fixtures' format).
pub fn read_xyz(name: &str) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(fixture_path(name)).expect("fixture");
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .take(3)
                .map(|t| t.parse().unwrap())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

pub fn read_tets(name: &str) -> Vec<[u32; 4]> {
    let text = std::fs::read_to_string(fixture_path(name)).expect("fixture");
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<u32> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

/// The fixtures' canonical form: rotate by an even permutation so the
/// smallest index is first and the smallest of the other three second.
pub fn canonical(t: [u32; 4]) -> [u32; 4] {
    let m = (0..4).min_by_key(|&i| t[i]).unwrap();
    let [a, b, c, d] = t;
    let s = match m {
        0 => [a, b, c, d],
        1 => [b, a, d, c],
        2 => [c, d, a, b],
        _ => [d, c, b, a],
    };
    let mut r = [s[1], s[2], s[3]];
    while r[0] > r[1] || r[0] > r[2] {
        r = [r[1], r[2], r[0]];
    }
    [s[0], r[0], r[1], r[2]]
}

pub fn canonical_sorted(tets: impl IntoIterator<Item = [u32; 4]>) -> Vec<[u32; 4]> {
    let mut v: Vec<[u32; 4]> = tets.into_iter().map(canonical).collect();
    v.sort_unstable();
    v
}

/// The tests' deterministic PRNG: the crate's own (SplitMix64).
#[allow(unused_imports)]
pub use aniso_alpha::rng::SplitMix64 as Rng;

mod tempdir;
#[allow(unused_imports)]
pub use tempdir::TempDir;

#[path = "tools.rs"]
mod tools;
#[allow(unused_imports)]
pub use tools::{tool_missing, tools_required};
