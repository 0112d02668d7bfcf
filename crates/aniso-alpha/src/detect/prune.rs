//! Exact pruning before triangulating one orientation.
//!
//! A point with no other point within distance `2α` (in the transformed
//! space Q·P, i.e. in the metric d_Q) cannot be a vertex of `F_{k,α,Q}`:
//! the vertices of a simplex of `F_α` lie on a sphere of radius α, so they
//! are pairwise at most `2α` apart. Nor can it lie inside an empty-ball
//! candidate of another simplex: such a ball has radius α and a vertex on
//! its boundary, so every point inside it is within `2α` of that vertex.
//! Dropping such *isolated* points therefore leaves `F_{k,α,Q}` unchanged
//! while the triangulation shrinks to the neighbourhood of the structures
//! (a sparse background is mostly isolated at the scale α).
//!
//! The neighbour search uses a uniform grid of cell side `2α` stored as
//! flat sorted arrays (no hash map): points sorted by cell key, and each
//! occupied cell's 27 neighbours found by binary search.

/// Marks the points that have another point within distance `radius`
/// (inclusive). Points are `[f64; 3]` in the metric of interest.
///
/// ```
/// use aniso_alpha::detect::prune::non_isolated;
/// let p = [[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [10.0, 0.0, 0.0]];
/// assert_eq!(non_isolated(&p, 2.0), vec![true, true, false]);
/// ```
pub fn non_isolated(points: &[[f64; 3]], radius: f64) -> Vec<bool> {
    let n = points.len();
    let mut keep = vec![false; n];
    if n < 2 || radius.is_nan() || radius < 0.0 {
        return keep;
    }
    if !radius.is_finite() {
        return vec![true; n];
    }
    let mut lo = [f64::INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
        }
    }
    let cell = if radius > 0.0 {
        radius
    } else {
        f64::MIN_POSITIVE
    };
    // Cell coordinates, clamped to 21 bits per axis (beyond that, cells
    // merge, which only costs distance checks, never correctness: the
    // distance test below is exact on the coordinates).
    const MAXC: i64 = (1 << 21) - 1;
    let cell_of = |p: &[f64; 3]| -> [i64; 3] {
        let mut c = [0i64; 3];
        for k in 0..3 {
            let x = ((p[k] - lo[k]) / cell).floor();
            c[k] = if x.is_finite() {
                (x as i64).clamp(0, MAXC)
            } else {
                MAXC
            };
        }
        c
    };
    let key_of = |c: [i64; 3]| ((c[0] as u64) << 42) | ((c[1] as u64) << 21) | c[2] as u64;
    let mut order: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (key_of(cell_of(p)), i as u32))
        .collect();
    order.sort_unstable();
    let r2 = radius * radius;
    let close = |a: &[f64; 3], b: &[f64; 3]| {
        let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r2
    };
    let mut start = 0;
    let mut ranges: Vec<(usize, usize)> = Vec::with_capacity(27);
    while start < n {
        let key = order[start].0;
        let mut end = start + 1;
        while end < n && order[end].0 == key {
            end += 1;
        }
        let c = cell_of(&points[order[start].1 as usize]);
        ranges.clear();
        for dx in -1..=1i64 {
            for dy in -1..=1i64 {
                for dz in -1..=1i64 {
                    let nc = [c[0] + dx, c[1] + dy, c[2] + dz];
                    if nc.iter().any(|&x| !(0..=MAXC).contains(&x)) {
                        continue;
                    }
                    let k = key_of(nc);
                    let a = order.partition_point(|e| e.0 < k);
                    let b = order[a..].partition_point(|e| e.0 == k) + a;
                    if a < b {
                        ranges.push((a, b));
                    }
                }
            }
        }
        for &(_, i) in &order[start..end] {
            let p = &points[i as usize];
            'search: for &(a, b) in &ranges {
                for &(_, j) in &order[a..b] {
                    if j != i && close(p, &points[j as usize]) {
                        keep[i as usize] = true;
                        break 'search;
                    }
                }
            }
        }
        start = end;
    }
    keep
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_brute_force() {
        let mut s = 11u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for round in 0..50 {
            let n = 1 + round * 7;
            let scale = [1.0, 10.0, 100.0][round % 3];
            let pts: Vec<[f64; 3]> = (0..n)
                .map(|_| [rnd() * scale, rnd() * scale, rnd() * 0.1 * scale])
                .collect();
            for radius in [0.0, 0.5, 1.0, 3.0] {
                let fast = non_isolated(&pts, radius);
                for i in 0..n {
                    let brute = (0..n).any(|j| {
                        j != i && {
                            let d: f64 = (0..3).map(|k| (pts[i][k] - pts[j][k]).powi(2)).sum();
                            d <= radius * radius
                        }
                    });
                    assert_eq!(fast[i], brute, "n {n} radius {radius} point {i}");
                }
            }
        }
    }

    #[test]
    fn exact_distance_is_inclusive_and_duplicates_count() {
        assert_eq!(
            non_isolated(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], 2.0),
            vec![true, true]
        );
        assert_eq!(
            non_isolated(&[[5.0, 5.0, 5.0], [5.0, 5.0, 5.0], [9.0, 9.0, 9.0]], 0.0),
            vec![true, true, false]
        );
    }
}
