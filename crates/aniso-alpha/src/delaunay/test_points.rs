//! Point sets shared by the unit tests of the build.

use crate::rng::SplitMix64;

/// `n` points drawn uniformly in the unit cube (seed `seed`).
pub(crate) fn uniform_points(seed: u64, n: usize) -> Vec<[f64; 3]> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
        .collect()
}

/// The integer grid k × k × k, x fastest.
pub(crate) fn int_grid(k: usize) -> Vec<[f64; 3]> {
    (0..k * k * k)
        .map(|i| [(i % k) as f64, (i / k % k) as f64, (i / (k * k)) as f64])
        .collect()
}

/// The centre and the integer points on the sphere x² + y² + z² = r2
/// (cospherical: in-sphere tests among the points on the sphere tie).
pub(crate) fn integer_sphere(r2: i32) -> Vec<[f64; 3]> {
    let r = (r2 as f64).sqrt() as i32 + 1;
    let mut sphere = vec![[0.0; 3]];
    for x in -r..=r {
        for y in -r..=r {
            for z in -r..=r {
                if x * x + y * y + z * z == r2 {
                    sphere.push([x as f64, y as f64, z as f64]);
                }
            }
        }
    }
    sphere
}
