//! The point sets of the geometric fuzz targets: at most [`MAX_POINTS`]
//! points whose coordinates come from a small set, so that ties of every
//! kind are frequent.

const MAX_POINTS: usize = 96;

/// The points of the input: the first byte picks the decoding.
pub fn decode(data: &[u8]) -> Vec<[f64; 3]> {
    let Some((&mode, rest)) = data.split_first() else {
        return Vec::new();
    };
    let coords: Vec<f64> = match mode % 4 {
        // Integers in [-4, 3]: grids, duplicates, coplanar and cospherical sets.
        0 => rest.iter().map(|&b| f64::from((b & 7) as i8 - 4)).collect(),
        // Integers in [-128, 127].
        1 => rest.iter().map(|&b| f64::from(b as i8)).collect(),
        // A decimal grid (0.1 is not dyadic: near-ties after rounding).
        2 => rest.iter().map(|&b| f64::from(b & 15) * 0.1).collect(),
        // Raw doubles: anything, including NaN, inf and out-of-range values.
        _ => rest
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
    };
    coords
        .chunks_exact(3)
        .take(MAX_POINTS)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

/// A point as a comparable key: its coordinates' bits, with −0.0 taken as
/// 0.0 (the build merges the two, so either may be the kept vertex).
#[allow(dead_code)] // each target compiles this module; `detect` has no use for it
pub fn coordinate_key(p: &[f64; 3]) -> [u64; 3] {
    p.map(|c| (c + 0.0).to_bits())
}
