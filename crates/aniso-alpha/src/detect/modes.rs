//! Modes of a distribution of axes on the sphere: the dominant normals of a
//! scan's planes (k = 2) or directions of its lines (k = 1). An axis and its
//! opposite are the same (a normal has no sign).
//!
//! Mean shift with a flat kernel of angular radius `h`:
//! 1. the axes are sorted (by their first component, then the second, the
//!    third), so that nothing below depends on the order they were given
//!    in; at most [`MAX_SAMPLES`] of them are drawn: every axis when there
//!    are fewer; otherwise one at random from each of [`MAX_SAMPLES`]
//!    equal runs of the sorted axes (jittered strata, from a fixed seed, so
//!    deterministic). A plain stride over the input's order would alias
//!    with any period in it: three walls' points interleaved, 10,443 of
//!    them, drew a stride of 3 and every sample from one wall;
//! 2. the density at a sample is the number of samples within `h` of it
//!    (either sign), counted with a kd-tree over the samples and their
//!    opposites;
//! 3. a sample is a seed when no sample within `h` has a higher density
//!    (ties: the smaller index wins);
//! 4. each seed moves to the normalised mean of the samples within `h`
//!    (signs aligned with it) until it moves less than 0.01°, at most 50
//!    times;
//! 5. modes closer than `h` are merged (the denser in the sample stays);
//! 6. each merged mode's support is counted over every axis given, not
//!    the sample: a mode of a few hundred axes in 80,000 holds some 15
//!    samples, and its sampled count moved with the draw enough to pass
//!    or fail the concentration test of [`crate::detect::estimate`] (the
//!    curved normals of a depth frame's cylinders gave 3–4 modes in one
//!    draw and none in another); modes with fewer than `min_support`
//!    axes are dropped.
//!
//! Modes come out densest first, each with its support: the axes given
//! within `h` of it.
//!
//! ```
//! use aniso_alpha::detect::modes::modes;
//! // Two clusters of normals, around z and around x, and their opposites.
//! let mut axes = Vec::new();
//! for i in 0..200 {
//!     let t = 0.02 * ((i % 7) as f64 - 3.0);
//!     axes.push([t, 0.0, if i % 2 == 0 { 1.0 } else { -1.0 }]);
//!     axes.push([1.0, t, 0.0]);
//! }
//! let m = modes(&axes, 5f64.to_radians(), 10);
//! assert_eq!(m.len(), 2);
//! assert!(m.iter().any(|m| m.axis[2].abs() > 0.999));
//! assert!(m.iter().any(|m| m.axis[0].abs() > 0.999));
//! ```

use crate::geometry::dot;
use crate::geometry::kdtree::KdTree;

/// Samples used for the mode search at most.
///
/// 4,000 samples resolve a mode of 0.25% of the axes with 10 samples, and
/// keep the search (quadratic in the samples within a kernel) far below
/// the cost of one triangulation.
pub const MAX_SAMPLES: usize = 4_000;

/// A mode of a distribution of axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// Unit axis (largest |component| positive).
    pub axis: [f64; 3],
    /// Axes within the kernel radius of it, counted over every axis given.
    pub support: usize,
}

fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(a, a).sqrt();
    (n > 0.0 && n.is_finite()).then(|| a.map(|x| x / n))
}

/// `u` with its largest |component| (first on ties) positive.
pub fn canonical(u: [f64; 3]) -> [f64; 3] {
    let mut k = 0;
    for i in 1..3 {
        if u[i].abs() > u[k].abs() {
            k = i;
        }
    }
    if u[k] < 0.0 {
        u.map(|x| -x)
    } else {
        u
    }
}

/// One axis from each of [`MAX_SAMPLES`] equal runs of `valid` (sorted), drawn at
/// random within its run from a fixed seed (every axis when there are no
/// more than [`MAX_SAMPLES`]).
fn strata(valid: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let n = valid.len();
    if n <= MAX_SAMPLES {
        return valid.to_vec();
    }
    let mut rng = crate::rng::SplitMix64::new(n as u64);
    (0..MAX_SAMPLES)
        .map(|j| {
            let (lo, hi) = (j * n / MAX_SAMPLES, (j + 1) * n / MAX_SAMPLES);
            valid[lo + rng.below((hi - lo) as u64) as usize]
        })
        .collect()
}

/// The modes of `axes` (unit vectors; zero or non-finite ones are skipped)
/// for a kernel of angular radius `h` radians (see the module doc).
pub fn modes(axes: &[[f64; 3]], h: f64, min_support: usize) -> Vec<Mode> {
    let mut valid: Vec<[f64; 3]> = axes.iter().filter_map(|&a| unit(a)).collect();
    if valid.is_empty() {
        return Vec::new();
    }
    crate::par::sort_unstable_by(&mut valid, |a, b| {
        a[0].total_cmp(&b[0])
            .then(a[1].total_cmp(&b[1]))
            .then(a[2].total_cmp(&b[2]))
    });
    let samples = strata(&valid);
    let ns = samples.len();
    // Both signs in one tree: index t < ns is +sample t, ≥ ns its opposite.
    let mut both = samples.clone();
    both.extend(samples.iter().map(|a| a.map(|x| -x)));
    let tree = KdTree::new(&both, None);
    // Chord length of the angle h.
    let chord = 2.0 * (h / 2.0).sin();
    let neighbours = |a: [f64; 3], f: &mut dyn FnMut(usize, f64)| {
        tree.within(&a, chord, |t| {
            let t = t as usize;
            let (s, sign) = if t < ns { (t, 1.0) } else { (t - ns, -1.0) };
            f(s, sign);
        });
    };
    // Each sample's density, then each seed's climb: independent per
    // sample, so parallel, and in the samples' order whatever the threads.
    let density: Vec<u32> = crate::par::map_ranges(
        ns,
        || (),
        |_, i| tree.count_within(&samples[i], chord) as u32,
    );
    // A seed: no sample within h beats it (the search stops at the first
    // that does, which is most samples' case).
    let seed = |i: usize| {
        !tree.any_within(&samples[i], chord, |t| {
            let s = t as usize % ns;
            density[s] > density[i] || (density[s] == density[i] && s < i)
        })
    };
    let seeds: Vec<usize> = crate::par::map_ranges(ns, || (), |_, i| seed(i))
        .into_iter()
        .enumerate()
        .filter_map(|(i, peak)| peak.then_some(i))
        .collect();
    let mut found: Vec<Mode> = crate::par::map_ranges(
        seeds.len(),
        || (),
        |_, k| {
            // Mean shift from the seed.
            let mut m = samples[seeds[k]];
            for _ in 0..50 {
                let mut sum = [0.0; 3];
                neighbours(m, &mut |s, sign| {
                    for k in 0..3 {
                        sum[k] += sign * samples[s][k];
                    }
                });
                let Some(next) = unit(sum) else { break };
                let moved = dot(next, m).clamp(-1.0, 1.0).acos();
                m = next;
                if moved < 0.01f64.to_radians() {
                    break;
                }
            }
            let mut support = 0usize;
            neighbours(m, &mut |_, _| support += 1);
            Mode {
                axis: canonical(m),
                support,
            }
        },
    );
    // Densest in the sample first; merge close ones; then each survivor's
    // support over every axis, the small ones dropped.
    densest_first(&mut found);
    let cos_h = h.cos();
    let mut merged: Vec<Mode> = Vec::new();
    for m in found {
        if merged.iter().all(|o| dot(o.axis, m.axis).abs() < cos_h) {
            merged.push(m);
        }
    }
    if samples.len() < valid.len() {
        let support = supports(&valid, &merged, chord);
        for (m, s) in merged.iter_mut().zip(support) {
            m.support = s;
        }
        densest_first(&mut merged);
    }
    merged.retain(|m| m.support >= min_support);
    merged
}

/// Sorts `modes` by support, largest first (ties by axis, for
/// determinism).
fn densest_first(modes: &mut [Mode]) {
    modes.sort_by(|a, b| {
        b.support.cmp(&a.support).then(
            a.axis
                .partial_cmp(&b.axis)
                .unwrap_or(std::cmp::Ordering::Equal),
        )
    });
}

/// Per mode, the number of `axes` within chord `chord` of it (either
/// sign): one pass over the axes, each looked up in a kd-tree of the
/// modes and their opposites, in chunks on the pool's threads.
fn supports(axes: &[[f64; 3]], modes: &[Mode], chord: f64) -> Vec<usize> {
    let nm = modes.len();
    if nm == 0 {
        return Vec::new();
    }
    let mut both: Vec<[f64; 3]> = modes.iter().map(|m| m.axis).collect();
    both.extend(modes.iter().map(|m| m.axis.map(|x| -x)));
    let tree = KdTree::new(&both, None);
    const CHUNK: usize = 1 << 14;
    let per_chunk = crate::par::map_ranges(
        axes.len().div_ceil(CHUNK),
        || (),
        |_, c| {
            let mut count = vec![0usize; nm];
            for a in &axes[c * CHUNK..axes.len().min((c + 1) * CHUNK)] {
                tree.within(a, chord, |t| count[t as usize % nm] += 1);
            }
            count
        },
    );
    (0..nm)
        .map(|k| per_chunk.iter().map(|c| c[k]).sum())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut rng = SplitMix64::new(seed);
        move || rng.uniform()
    }

    /// Axes scattered by about `spread` radians around `c`, random signs.
    fn cluster(c: [f64; 3], spread: f64, n: usize, r: &mut impl FnMut() -> f64) -> Vec<[f64; 3]> {
        (0..n)
            .map(|_| {
                let v = [
                    c[0] + spread * (r() - 0.5),
                    c[1] + spread * (r() - 0.5),
                    c[2] + spread * (r() - 0.5),
                ];
                let v = unit(v).unwrap();
                if r() < 0.5 {
                    v.map(|x| -x)
                } else {
                    v
                }
            })
            .collect()
    }

    #[test]
    fn finds_clusters_and_ignores_uniform_background() {
        let mut r = rng(4);
        let s = 0.5f64.sqrt();
        let centres = [[0.0, 0.0, 1.0], [s, s, 0.0], [s, -s, 0.0], [0.6, 0.0, 0.8]];
        let mut axes = Vec::new();
        for (k, c) in centres.iter().enumerate() {
            axes.extend(cluster(*c, 0.08, 3000 / (k + 1), &mut r));
        }
        // Uniform background axes: 3000 of them.
        for _ in 0..3000 {
            let v = [r() - 0.5, r() - 0.5, r() - 0.5];
            if let Some(u) = unit(v) {
                axes.push(u);
            }
        }
        let m = modes(&axes, 6f64.to_radians(), 300);
        assert_eq!(m.len(), 4, "{m:?}");
        for c in centres {
            let best = m.iter().map(|m| dot(m.axis, c).abs()).fold(0.0, f64::max);
            assert!(best > 0.9995, "{c:?} missed: {m:?}");
        }
        // Densest first.
        assert!(m.windows(2).all(|w| w[0].support >= w[1].support));
    }

    #[test]
    fn interleaved_clusters_are_all_sampled() {
        // Three walls' normals interleaved point by point (x, y, z, x, ...),
        // 10,443 of them: a stride of 3 through them would see one wall.
        let axes: Vec<[f64; 3]> = (0..10_443)
            .map(|i| match i % 3 {
                0 => [0.0, 0.0, 1.0],
                1 => [1.0, 0.0, 0.0],
                _ => [0.0, 1.0, 0.0],
            })
            .collect();
        let m = modes(&axes, 5f64.to_radians(), 30);
        assert_eq!(m.len(), 3, "{m:?}");
        // Each support counted over every axis, not the sample.
        assert!(m.iter().all(|m| m.support == 3481), "{m:?}");
    }

    #[test]
    fn opposite_axes_are_one_mode_and_empty_input_is_none() {
        let axes = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.001, 1.0]];
        let m = modes(&axes, 0.1, 1);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].support, 3);
        assert!(modes(&[], 0.1, 1).is_empty());
        assert!(modes(&[[0.0; 3], [f64::NAN; 3]], 0.1, 1).is_empty());
    }
}
