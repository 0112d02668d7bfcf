//! Insertion order: biased randomized insertion order (BRIO) with each
//! round sorted along a 3D Hilbert curve.
//!
//! Random rounds keep the expected cost of Bowyer–Watson optimal; the
//! Hilbert order inside a round keeps consecutive points close, so the
//! point-location walk from the last created tetrahedron is short and the
//! memory it touches is hot. The order is deterministic (fixed seed).

use super::isa::Isa;

use crate::rng::SplitMix64;

const HILBERT_BITS: u32 = 21;

/// Points whose Hilbert keys are computed together, lane by lane (the
/// compiler turns each lane loop into vector instructions, and the four
/// dependency chains overlap).
const LANES: usize = 4;

/// Hilbert index of a point with integer coordinates below `2^bits`
/// (`bits` ≤ [`HILBERT_BITS`]).
#[cfg(test)]
fn hilbert_key(x: [u32; 3], bits: u32) -> u64 {
    hilbert_keys([[x[0]; LANES], [x[1]; LANES], [x[2]; LANES]], bits)[0]
}

/// Hilbert indices of [`LANES`] points, coordinate `k` of lane `l` at
/// `x[k][l]`, each below `2^bits` (`bits` ≤ [`HILBERT_BITS`]). Skilling's
/// transpose algorithm: undo excess work, Gray-encode, then interleave the
/// bits with x most significant. Written without data-dependent branches,
/// which mispredicted about half the time (the plain form is kept in the
/// tests as the reference).
#[inline(always)]
fn hilbert_keys(x: [[u32; LANES]; 3], bits: u32) -> [u64; LANES] {
    let [mut x0, mut x1, mut x2] = x;
    let mut level = bits - 1;
    while level > 0 {
        let p = (1u32 << level) - 1;
        for l in 0..LANES {
            // For each axis i in turn: all ones in `set` if bit `level` of
            // x[i] is set, then x[0] ^= p, else the low bits of x[0] and
            // x[i] are exchanged (a no-op for i = 0).
            let set = 0u32.wrapping_sub((x0[l] >> level) & 1);
            x0[l] ^= p & set;
            let set = 0u32.wrapping_sub((x1[l] >> level) & 1);
            let t = (x0[l] ^ x1[l]) & p & !set;
            x0[l] ^= (p & set) | t;
            x1[l] ^= t;
            let set = 0u32.wrapping_sub((x2[l] >> level) & 1);
            let t = (x0[l] ^ x2[l]) & p & !set;
            x0[l] ^= (p & set) | t;
            x2[l] ^= t;
        }
        level -= 1;
    }
    let mut t = [0u32; LANES];
    for l in 0..LANES {
        x1[l] ^= x0[l];
        x2[l] ^= x1[l];
    }
    let mut level = bits - 1;
    while level > 0 {
        for l in 0..LANES {
            t[l] ^= ((1u32 << level) - 1) & 0u32.wrapping_sub((x2[l] >> level) & 1);
        }
        level -= 1;
    }
    let mut keys = [0u64; LANES];
    for l in 0..LANES {
        keys[l] = spread3(x0[l] ^ t[l]) << 2 | spread3(x1[l] ^ t[l]) << 1 | spread3(x2[l] ^ t[l]);
    }
    keys
}

/// Per axis, the factor that maps the box `bbox` onto `0..=max` (0 on an
/// axis of zero or unrepresentable extent): a point's grid cell on that axis
/// is `((p - lo) * scale).clamp(0, max)`, truncated.
#[inline(always)]
fn cell_scale(bbox: &([f64; 3], [f64; 3]), max: f64) -> [f64; 3] {
    let (lo, hi) = bbox;
    std::array::from_fn(|k| {
        let ext = hi[k] - lo[k];
        if ext > 0.0 && ext.is_finite() {
            max / ext
        } else {
            0.0
        }
    })
}

/// The Hilbert key of each point on a grid of `2^bits` cells per axis over
/// the box `bbox` (a parallel build cuts the curve between its threads
/// with them).
pub(crate) fn curve_keys<'a>(
    points: impl ExactSizeIterator<Item = &'a [f64; 3]>,
    bbox: &([f64; 3], [f64; 3]),
    bits: u32,
) -> Vec<u64> {
    let bits = bits.clamp(1, HILBERT_BITS);
    let lo = bbox.0;
    let max = ((1u64 << bits) - 1) as f64;
    let scale = cell_scale(bbox, max);
    let mut keys = Vec::with_capacity(points.len());
    let mut x = [[0u32; LANES]; 3];
    let mut l = 0;
    for p in points {
        for k in 0..3 {
            x[k][l] = ((p[k] - lo[k]) * scale[k]).clamp(0.0, max) as u32;
        }
        l += 1;
        if l == LANES {
            keys.extend(hilbert_keys(x, bits));
            l = 0;
        }
    }
    keys.extend(&hilbert_keys(x, bits)[..l]);
    keys
}

/// The low 21 bits of `v` moved to bits 0, 3, 6, …, 60.
#[inline(always)]
fn spread3(v: u32) -> u64 {
    let mut x = (v & 0x1f_ffff) as u64;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Grid resolution (bits per axis) that orders a round of `n` points:
/// about 8 grid cells per point.
fn round_bits(n: usize) -> u32 {
    let n = n.max(2) as f64;
    ((n.log2() / 3.0).ceil() as u32 + 1).clamp(2, HILBERT_BITS)
}

/// Indices `0..keys.len()` sorted by `keys`, ties in index order, and the
/// keys in that order: a comparison sort for short inputs, else a
/// least-significant-digit radix sort (stable, 11-bit digits, as many
/// passes as the largest key needs).
fn sort_by_keys(keys: Vec<u64>) -> (Vec<u32>, Vec<u64>) {
    let n = keys.len();
    if n < 4096 {
        let mut keyed: Vec<(u64, u32)> = keys.iter().zip(0..).map(|(&k, i)| (k, i)).collect();
        keyed.sort_unstable();
        return keyed.into_iter().map(|(k, i)| (i, k)).unzip();
    }
    const DIGIT: u32 = 11;
    const BUCKETS: usize = 1 << DIGIT;
    let width = 64 - keys.iter().fold(0, |m, &k| m | k).leading_zeros();
    let mut k0 = keys;
    let mut i0: Vec<u32> = (0..n as u32).collect();
    let mut k1 = vec![0u64; n];
    let mut i1 = vec![0u32; n];
    let mut shift = 0;
    while shift < width {
        let mut start = vec![0usize; BUCKETS];
        for &k in &k0 {
            start[(k >> shift) as usize & (BUCKETS - 1)] += 1;
        }
        let mut sum = 0;
        for s in start.iter_mut() {
            let c = *s;
            *s = sum;
            sum += c;
        }
        for (&k, &i) in k0.iter().zip(&i0) {
            let b = &mut start[(k >> shift) as usize & (BUCKETS - 1)];
            k1[*b] = k;
            i1[*b] = i;
            *b += 1;
        }
        std::mem::swap(&mut k0, &mut k1);
        std::mem::swap(&mut i0, &mut i1);
        shift += DIGIT;
    }
    (i0, k0)
}

/// Runs of more points than this with one key (one grid cell of one
/// round) are ordered along the curve at full resolution
/// ([`refine_crowded`]).
const CROWDED: usize = 16;

/// Orders each run of more than [`CROWDED`] consecutive points with one
/// key `sorted[i]` (the points of `order` that fell in one grid cell of one
/// round) along the Hilbert curve at the full resolution
/// ([`HILBERT_BITS`] bits per axis, the same grid cut finer, so the order
/// of the cells stays), ties (equal points, or closer than the finest cell)
/// in input order. Returns a bound on the number of distinct points: the
/// distinct points of each cell, summed over the cells of every round
/// (copies of a point in one round share its cell, and points without a
/// cell-mate are not compared at all).
///
/// A round's grid has about 8 cells per point of the round, which spreads
/// points in general position thinly (a run of 17 in one cell is all but
/// impossible: such inputs keep their order bit for bit). Points on a line
/// or a surface crowd into the few cells the line or surface crosses, and
/// in input order the points of one cell are scattered along it: each
/// insertion then walks across the cell, through a number of tets that
/// grows with the number of points (a line of 40,000 points rounded to
/// 1e-6 took 78 walk steps per point against 7 for uniform points).
fn refine_crowded(
    points: &[[f64; 3]],
    bbox: &([f64; 3], [f64; 3]),
    order: &mut [u32],
    sorted: &[u64],
) -> usize {
    let n = order.len();
    let mut distinct = 0;
    let mut i = 0;
    while i < n {
        let mut j = i + 1;
        while j < n && sorted[j] == sorted[i] {
            j += 1;
        }
        if j - i > CROWDED {
            let run = &mut order[i..j];
            let fine = curve_keys(run.iter().map(|&v| &points[v as usize]), bbox, HILBERT_BITS);
            // The run is in input order, so (key, index) pairs sort ties by
            // input index.
            let mut keyed: Vec<(u64, u32)> = fine.into_iter().zip(run.iter().copied()).collect();
            keyed.sort_unstable();
            for (slot, (_, v)) in run.iter_mut().zip(keyed) {
                *slot = v;
            }
            // Equal points are now next to each other.
            let p = |k: usize| &points[run[k] as usize];
            distinct += 1 + (1..run.len()).filter(|&k| p(k) != p(k - 1)).count();
        } else if j - i > 1 {
            let run = &order[i..j];
            let p = |k: usize| &points[run[k] as usize];
            distinct += (0..run.len())
                .filter(|&k| (0..k).all(|l| p(l) != p(k)))
                .count();
        } else {
            distinct += 1;
        }
        i = j;
    }
    distinct
}

/// Computes a BRIO order of `points` (indices into `points`): rounds of
/// expected sizes ..., 3n/64, 3n/16, 3n/4 (each round three quarters of
/// what is left, from the end; the first about 128 points or fewer), each
/// sorted along a Hilbert curve at its own resolution. Each point draws
/// its round at random (round `ℓ` from the end with probability 3/4 ·
/// 4^-ℓ), so the whole order is one sort of one key per point (round,
/// then Hilbert cell), computed in input order: no shuffle and no random
/// reads. Halving rounds measured 0.7% fewer instructions but ~5% more
/// time at 1M points (a longer final sweep keeps the cells it touches in
/// cache); eighths, +2.4% instructions and no faster. `bbox` is the
/// points' bounding box ([`crate::geometry::bounding_box`]).
///
/// Also returns the size of each round, first to last, and a bound on the
/// number of distinct points (see [`refine_crowded`]).
///
/// The keys are computed by a copy compiled for x86-64-v3 when `isa`
/// allows and the CPU has it (see [`super::isa`]); the order is the same.
#[allow(unsafe_code)]
pub(crate) fn brio_order(
    points: &[[f64; 3]],
    bbox: &([f64; 3], [f64; 3]),
    seed: u64,
    isa: Isa,
) -> (Vec<u32>, Vec<usize>, usize) {
    #[cfg(target_arch = "x86_64")]
    if isa.use_v3() {
        // SAFETY: a `#[target_feature]` function may be called only on a
        // CPU with the features it enables, which `use_v3` checked.
        let (keys, rounds) = unsafe { brio_keys_v3(points, bbox, seed) };
        let (order, distinct) = sorted_order(points, bbox, keys);
        return (order, rounds, distinct);
    }
    let _ = isa;
    let (keys, rounds) = brio_keys(points, bbox, seed);
    let (order, distinct) = sorted_order(points, bbox, keys);
    (order, rounds, distinct)
}

/// The points sorted by their BRIO keys, crowded cells refined, and a
/// bound on the distinct points.
fn sorted_order(
    points: &[[f64; 3]],
    bbox: &([f64; 3], [f64; 3]),
    keys: Vec<u64>,
) -> (Vec<u32>, usize) {
    let (mut order, sorted) = sort_by_keys(keys);
    let distinct = refine_crowded(points, bbox, &mut order, &sorted);
    (order, distinct)
}

/// [`brio_keys`] compiled for x86-64-v3 (see [`super::isa`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn brio_keys_v3(
    points: &[[f64; 3]],
    bbox: &([f64; 3], [f64; 3]),
    seed: u64,
) -> (Vec<u64>, Vec<usize>) {
    brio_keys(points, bbox, seed)
}

/// The key of each point of [`brio_order`]: its round, then its Hilbert
/// cell at the round's resolution; and the size of each round.
#[inline(always)]
fn brio_keys(
    points: &[[f64; 3]],
    bbox: &([f64; 3], [f64; 3]),
    seed: u64,
) -> (Vec<u64>, Vec<usize>) {
    let n = points.len();
    let lo = bbox.0;
    let max = ((1u64 << HILBERT_BITS) - 1) as f64;
    let scale = cell_scale(bbox, max);
    // Rounds by level from the end: level 0 is the last and largest;
    // `top`, the first, gets every point that draws a level beyond it.
    const FIRST_ROUND: usize = 128;
    let mut top = 0;
    while n >> (2 * top) > FIRST_ROUND {
        top += 1;
    }
    let level_bits: Vec<u32> = (0..=top)
        .map(|l| {
            round_bits(if l < top {
                3 * (n >> (2 * l + 2))
            } else {
                n >> (2 * top)
            })
        })
        .collect();
    // One Hilbert key per point at the resolution of the largest round; a
    // key's leading 3b bits are its cell on the grid of b bits per axis,
    // so each round cuts it to its own resolution.
    let bits = level_bits[0];
    let shift = HILBERT_BITS - bits;
    let round_shift = 3 * bits;
    let mut rng = SplitMix64::new(seed);
    let mut keys: Vec<u64> = Vec::with_capacity(n);
    let mut rounds = vec![0usize; top + 1];
    for chunk in points.chunks(LANES) {
        let mut x = [[0u32; LANES]; 3];
        for (l, p) in chunk.iter().enumerate() {
            for k in 0..3 {
                x[k][l] = ((p[k] - lo[k]) * scale[k]).clamp(0.0, max) as u32 >> shift;
            }
        }
        for &h in &hilbert_keys(x, bits)[..chunk.len()] {
            let level = ((rng.next_u64().leading_zeros() / 2) as usize).min(top);
            let cell = h >> (3 * (bits - level_bits[level].min(bits)));
            keys.push(((top - level) as u64) << round_shift | cell);
            rounds[top - level] += 1;
        }
    }
    (keys, rounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain form of [`hilbert_key`]: the Hilbert index of a point
    /// with integer coordinates below `2^bits` (Skilling's transpose
    /// algorithm: undo excess work, Gray-encode, then interleave the bits
    /// with x most significant).
    fn hilbert_key_reference(mut x: [u32; 3], bits: u32) -> u64 {
        let m: u32 = 1 << (bits - 1);
        let mut q = m;
        while q > 1 {
            let p = q - 1;
            for i in 0..3 {
                if x[i] & q != 0 {
                    x[0] ^= p;
                } else {
                    let t = (x[0] ^ x[i]) & p;
                    x[0] ^= t;
                    x[i] ^= t;
                }
            }
            q >>= 1;
        }
        x[1] ^= x[0];
        x[2] ^= x[1];
        let mut t = 0u32;
        q = m;
        while q > 1 {
            if x[2] & q != 0 {
                t ^= q - 1;
            }
            q >>= 1;
        }
        for xi in &mut x {
            *xi ^= t;
        }
        let mut key = 0u64;
        for b in (0..bits).rev() {
            for xi in &x {
                key = (key << 1) | ((xi >> b) & 1) as u64;
            }
        }
        key
    }

    #[test]
    fn branchless_hilbert_matches_reference() {
        let mut rng = SplitMix64::new(11);
        for bits in 1..=HILBERT_BITS {
            for _ in 0..2000 {
                let x = [0; 3].map(|_| (rng.next_u64() >> (64 - bits)) as u32);
                assert_eq!(
                    hilbert_key(x, bits),
                    hilbert_key_reference(x, bits),
                    "{x:?} {bits}"
                );
            }
            let top = (1u32 << bits) - 1;
            for x in [[0, 0, 0], [top, top, top], [top, 0, top], [0, top, 0]] {
                assert_eq!(hilbert_key(x, bits), hilbert_key_reference(x, bits));
            }
        }
    }

    #[test]
    fn hilbert_is_a_bijection_and_continuous_on_small_grid() {
        // On the full 2^21 grid we only check neighbours along the curve on a
        // small corner: consecutive keys must be unit steps.
        let n = 8u32;
        let mut cells: Vec<(u64, [u32; 3])> = Vec::new();
        for x in 0..n {
            for y in 0..n {
                for z in 0..n {
                    cells.push((hilbert_key([x, y, z], HILBERT_BITS), [x, y, z]));
                }
            }
        }
        cells.sort();
        cells.dedup_by_key(|c| c.0);
        assert_eq!(cells.len(), (n * n * n) as usize);
        // The first 512 cells of the curve fill the 8x8x8 corner exactly
        // (keys 0..511) and consecutive cells are face neighbours.
        assert_eq!(cells.last().unwrap().0, 511);
        for w in cells.windows(2) {
            let d: u32 = (0..3).map(|k| w[0].1[k].abs_diff(w[1].1[k])).sum();
            assert_eq!(d, 1, "{:?} -> {:?}", w[0], w[1]);
        }
    }

    /// The rounds sort by cut keys: on a 16³ grid (4 bits), the keys cut
    /// to 3 bits are constant on each 2×2×2 block and visit the blocks
    /// along a continuous curve.
    #[test]
    fn cut_hilbert_keys_order_the_coarse_grid() {
        let mut blocks: Vec<(u64, [u32; 3])> = Vec::new();
        for x in 0..16u32 {
            for y in 0..16u32 {
                for z in 0..16u32 {
                    let cut = hilbert_key([x, y, z], 4) >> 3;
                    blocks.push((cut, [x >> 1, y >> 1, z >> 1]));
                }
            }
        }
        blocks.sort();
        blocks.dedup();
        assert_eq!(blocks.len(), 512, "a cut key spans two blocks");
        for w in blocks.windows(2) {
            assert_eq!(w[1].0, w[0].0 + 1);
            let d: u32 = (0..3).map(|k| w[0].1[k].abs_diff(w[1].1[k])).sum();
            assert_eq!(d, 1, "{:?} -> {:?}", w[0], w[1]);
        }
    }

    #[test]
    fn radix_sort_matches_comparison_sort() {
        let mut rng = SplitMix64::new(5);
        for (n, width) in [
            (5000, 3),
            (5000, 12),
            (70_000, 28),
            (9000, 41),
            (4096, 64),
            (100, 20),
        ] {
            let keys: Vec<u64> = (0..n).map(|_| rng.next_u64() >> (64 - width)).collect();
            let mut want: Vec<(u64, u32)> = keys.iter().zip(0..).map(|(&k, i)| (k, i)).collect();
            want.sort();
            let (got, sorted) = sort_by_keys(keys);
            assert!(
                want.iter().map(|w| w.1).eq(got.iter().copied()),
                "{n} {width}"
            );
            assert!(want.iter().map(|w| w.0).eq(sorted.iter().copied()));
        }
    }

    #[test]
    fn brio_rounds_come_in_order_and_follow_the_curve() {
        let mut rng = SplitMix64::new(8);
        let n = 200_000;
        let pts: Vec<[f64; 3]> = (0..n)
            .map(|_| [0; 3].map(|_| (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64))
            .collect();
        let order = brio_order(&pts, &crate::geometry::bounding_box(&pts), 1, Isa::Detect).0;
        let step = |w: &[u32]| {
            let (p, q) = (pts[w[0] as usize], pts[w[1] as usize]);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let mean = |s: &[u32]| s.windows(2).map(step).sum::<f64>() / (s.len() - 1) as f64;
        // The last half of the order lies in the last round (expected 3n/4
        // points): consecutive points are close along the curve, far
        // closer than the 0.66 of random pairs.
        let tail = mean(&order[n / 2..]);
        assert!(tail < 0.03, "{tail}");
        // The first 1% spans the earlier, sparser rounds: larger steps.
        let head = mean(&order[..n / 100]);
        assert!(head > 4.0 * tail, "{head} vs {tail}");
    }

    #[test]
    fn brio_is_a_permutation() {
        let mut rng = SplitMix64::new(3);
        let pts: Vec<[f64; 3]> = (0..5000)
            .map(|_| {
                [
                    rng.next_u64() as f64,
                    rng.next_u64() as f64,
                    rng.next_u64() as f64,
                ]
            })
            .collect();
        let mut o = brio_order(&pts, &crate::geometry::bounding_box(&pts), 1, Isa::Detect).0;
        o.sort();
        assert!(o.iter().enumerate().all(|(i, &v)| i as u32 == v));
    }

    /// The x86-64-v3 copy of the keys gives the baseline's order.
    #[test]
    fn instruction_sets_give_one_order() {
        let mut rng = SplitMix64::new(5);
        for n in [1, 3, 100, 5000, 70_000] {
            let pts: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let mut c = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
                    [c(), c() * 1e-3, c() * 1e6]
                })
                .collect();
            let bbox = crate::geometry::bounding_box(&pts);
            let order = brio_order(&pts, &bbox, 9, Isa::Detect);
            assert_eq!(order, brio_order(&pts, &bbox, 9, Isa::Baseline), "n = {n}");
            // The rounds cover the order.
            assert_eq!(order.1.iter().sum::<usize>(), n);
            let mut seen = order.0.clone();
            seen.sort_unstable();
            assert!(seen.iter().copied().eq(0..n as u32));
        }
    }

    /// Points on a line, in random order along it, crowd into the cells
    /// the line crosses: each crowded cell is ordered along the curve at
    /// full resolution, so that consecutive points of the last round are
    /// close along the line (in input order they are a random walk
    /// across their cell). Uniform points have no crowded cell: their
    /// order is the unrefined one.
    #[test]
    fn crowded_cells_follow_the_curve_at_full_resolution() {
        let mut rng = SplitMix64::new(6);
        let n = 40_000;
        let line: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                let t = rng.uniform();
                [t, 0.7 * t, 0.3 * t]
            })
            .collect();
        let bbox = crate::geometry::bounding_box(&line);
        let (order, rounds, distinct) = brio_order(&line, &bbox, 1, Isa::Detect);
        assert!(distinct <= n, "{distinct}");
        let last = &order[n - rounds.last().unwrap()..];
        let mean_step = last
            .windows(2)
            .map(|w| (line[w[0] as usize][0] - line[w[1] as usize][0]).abs())
            .sum::<f64>()
            / (last.len() - 1) as f64;
        // About 30,000 points in the last round along a unit line: steps
        // of about 1/30,000 when in order; a random order within cells of
        // 1/64 of the line would give steps near 1/200.
        assert!(mean_step < 1e-4, "{mean_step}");
        let mut seen = order.clone();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..n as u32));

        let uniform: Vec<[f64; 3]> = (0..n)
            .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
            .collect();
        let bbox = crate::geometry::bounding_box(&uniform);
        let (keys, _) = brio_keys(&uniform, &bbox, 1);
        let (plain, sorted) = sort_by_keys(keys);
        let mut runs = 1;
        let mut longest = 1;
        for w in sorted.windows(2) {
            runs = if w[0] == w[1] { runs + 1 } else { 1 };
            longest = longest.max(runs);
        }
        assert!(longest <= CROWDED, "{longest}");
        assert_eq!(brio_order(&uniform, &bbox, 1, Isa::Detect).0, plain);
    }
}
