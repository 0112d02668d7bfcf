//! Building a triangulation: the input checks, the insertion order, the
//! first tetrahedron (or the dimension when there is none), the run on one
//! thread ([`super::sequential`]) or several ([`super::parallel`]), and the
//! finished [`Triangulation`] (compaction, duplicates, vertex maps).

use super::cell::compact;
use super::insert::{BuildStats, Built, Input, Limits};
use super::order::brio_order;
use super::store::Stop;
use super::{parallel, sequential, DelaunayError, Triangulation, INFINITE, MAX_POINTS};
use crate::geometry::predicates::{collinear, orient3d, Filtered, Kernel, SmallGrid, StaticFilter};
use crate::geometry::Point3;

/// Checks the input and finds four affinely independent points, or the
/// dimension if there are none.
pub(crate) fn initial_simplex(points: &[Point3], order: &[u32]) -> Result<[u32; 4], usize> {
    let p0 = order[0];
    let a = &points[p0 as usize];
    let Some(&p1) = order.iter().find(|&&i| points[i as usize] != *a) else {
        return Err(0);
    };
    let b = &points[p1 as usize];
    let Some(&p2) = order
        .iter()
        .find(|&&i| !collinear(a, b, &points[i as usize]))
    else {
        return Err(1);
    };
    let c = &points[p2 as usize];
    let Some(&p3) = order
        .iter()
        .find(|&&i| !orient3d(a, b, c, &points[i as usize]).is_zero())
    else {
        return Err(2);
    };
    Ok([p0, p1, p2, p3])
}

/// Vertex mapping for inputs of dimension < 3: merge duplicates by sorting.
fn lower_dimensional(points: &[Point3], dim: usize) -> Triangulation {
    let n = points.len();
    let mut idx: Vec<u32> = (0..n as u32).collect();
    idx.sort_by(|&i, &j| {
        let (p, q) = (&points[i as usize], &points[j as usize]);
        p.partial_cmp(q)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(i.cmp(&j))
    });
    let mut pts = Vec::new();
    let mut vert_input = Vec::new();
    let mut input_vert = vec![0u32; n];
    for (k, &i) in idx.iter().enumerate() {
        if k == 0 || points[idx[k - 1] as usize] != points[i as usize] {
            pts.push(points[i as usize]);
            vert_input.push(i);
        }
        input_vert[i as usize] = (pts.len() - 1) as u32;
    }
    let nv = pts.len();
    Triangulation {
        pts,
        vert_input,
        input_vert,
        cells: Vec::new(),
        num_finite: 0,
        vert_tet: vec![u32::MAX; nv],
        dim,
    }
}

/// Builds the triangulation of `points` on `threads` threads.
pub(super) fn build(points: &[[f64; 3]], threads: usize) -> Result<Triangulation, DelaunayError> {
    build_with(
        points,
        Limits {
            threads: threads.max(1),
            ..Limits::DEFAULT
        },
    )
}

/// [`build`] with given limits (lower than the defaults only in tests).
pub(crate) fn build_with(
    points: &[[f64; 3]],
    limits: Limits,
) -> Result<Triangulation, DelaunayError> {
    build_stats(points, limits).map(|(tri, _)| tri)
}

/// [`build_with`], also returning how the build went.
pub(crate) fn build_stats(
    points: &[[f64; 3]],
    limits: Limits,
) -> Result<(Triangulation, BuildStats), DelaunayError> {
    let n = points.len();
    if n == 0 {
        return Err(DelaunayError::Empty);
    }
    if n > MAX_POINTS {
        return Err(DelaunayError::TooManyPoints(n));
    }
    check_coordinates(points)?;
    // A parallel build's shared cells are zeroed by another thread while
    // this one orders the points (see `parallel::Zeroing`).
    let zeroed = parallel::start(n, &limits);
    // (-0.0 == 0.0 for every comparison below, so signed zeros are one point.)
    // The bounding box orders the points and gives the static filter.
    let bbox = crate::geometry::bounding_box(points);
    let (order, rounds, distinct) = brio_order(points, &bbox, 0x5EED_0A11_A1FA_u64, limits.isa);
    if let Some(z) = &zeroed {
        // The rest of the shared cells: as many as the distinct points
        // need.
        z.aim(distinct);
    }
    let init = match initial_simplex(points, &order) {
        Ok(s) => s,
        Err(dim) => return Ok((lower_dimensional(points, dim), BuildStats::default())),
    };

    let filter = StaticFilter::for_box(&bbox.0, &bbox.1);
    let frame = SmallGrid::frame(points);
    let grid = frame.filter(|_| limits.grid_keys);
    let input = Input::new(points, &order, &rounds, init, grid, bbox);
    let built = match frame {
        Some(_) => run::<SmallGrid>(&input, &limits, filter, grid, zeroed),
        None => run::<Filtered>(&input, &limits, filter, None, zeroed),
    };
    let built = built.map_err(|_| DelaunayError::TooManyTets(n))?;
    let stats = built.stats;
    Ok((finish(input, built), stats))
}

/// Refuses a non-finite coordinate, or one outside [`super::COORD_RANGE`].
fn check_coordinates(points: &[[f64; 3]]) -> Result<(), DelaunayError> {
    for (index, p) in points.iter().enumerate() {
        for (coord, &value) in p.iter().enumerate() {
            if !value.is_finite() {
                return Err(DelaunayError::NonFinite {
                    index,
                    coord,
                    value,
                });
            }
            let m = value.abs();
            if m > super::COORD_RANGE.1 || (m != 0.0 && m < super::COORD_RANGE.0) {
                return Err(DelaunayError::OutOfRange {
                    index,
                    coord,
                    value,
                });
            }
        }
    }
    Ok(())
}

/// The incremental construction proper, monomorphised over the kernel: on
/// one thread, or split between threads by [`parallel`] when `zeroed`
/// brings the cells of a parallel build.
fn run<K: Kernel>(
    input: &Input,
    limits: &Limits,
    filter: StaticFilter,
    grid: Option<([f64; 3], f64)>,
    zeroed: Option<parallel::Zeroing>,
) -> Result<Built, Stop> {
    match zeroed {
        Some(zeroed) => parallel::run::<K>(input, limits, filter, grid, zeroed),
        None => sequential::run::<K>(input, limits, filter, grid),
    }
}

/// The triangulation of a finished build: drops the dead cells and the
/// duplicates' vertex ids, and maps inputs to vertices.
fn finish(input: Input, built: Built) -> Triangulation {
    let Input {
        pts, ins_input, n, ..
    } = input;
    let Built {
        mut cells,
        holes,
        dups,
        ..
    } = built;
    compact(&mut cells, holes);
    let mut input_vert = vec![u32::MAX; n];
    let (pts, vert_input) = if dups.is_empty() {
        for (v, &i) in ins_input.iter().enumerate() {
            input_vert[i as usize] = v as u32;
        }
        (pts.into_iter().map(|s| s.0).collect(), ins_input)
    } else {
        // Number the vertices without the duplicates' ids, keeping their
        // order, and give each duplicate's input the vertex it duplicates.
        const DUP: u32 = u32::MAX;
        let mut id = vec![0u32; pts.len()];
        for &(d, _) in &dups {
            id[d as usize] = DUP;
        }
        let mut kept = 0;
        for x in id.iter_mut() {
            if *x != DUP {
                *x = kept;
                kept += 1;
            }
        }
        for c in cells.iter_mut() {
            for w in c.v.iter_mut() {
                if *w != INFINITE {
                    *w = id[*w as usize];
                }
            }
        }
        let mut vert_input = Vec::with_capacity(kept as usize);
        let mut kept_pts = Vec::with_capacity(kept as usize);
        for (v, s) in pts.iter().enumerate() {
            if id[v] != DUP {
                vert_input.push(ins_input[v]);
                kept_pts.push(s.0);
            }
        }
        for (v, &i) in ins_input.iter().enumerate() {
            if id[v] != DUP {
                input_vert[i as usize] = id[v];
            }
        }
        for &(d, w) in &dups {
            let (i, w) = (ins_input[d as usize], id[w as usize]);
            input_vert[i as usize] = w;
            // The vertex stands for the first occurrence of its point.
            let first = &mut vert_input[w as usize];
            *first = (*first).min(i);
        }
        (kept_pts, vert_input)
    };
    let mut num_finite = 0;
    let mut vert_tet = vec![u32::MAX; pts.len()];
    for (t, c) in cells.iter().enumerate() {
        num_finite += (c.v[3] != INFINITE) as usize;
        for &w in &c.v {
            if w != INFINITE {
                vert_tet[w as usize] = t as u32;
            }
        }
    }
    Triangulation {
        pts,
        vert_input,
        input_vert,
        cells,
        num_finite,
        vert_tet,
        dim: 3,
    }
}

#[cfg(test)]
mod tests {
    use super::super::insert::Limits;
    use super::super::Triangulation;
    use super::{build_stats, build_with, DelaunayError};
    use crate::rng::SplitMix64;

    /// `n` points on a line in random order along it, each coordinate
    /// rounded to `step` (the cliff of issue 19: nearly collinear points).
    fn rounded_line(seed: u64, n: usize, step: f64) -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(seed);
        let round = |x: f64| (x / step).round() * step;
        (0..n)
            .map(|_| {
                let t = rng.uniform();
                [round(t), round(0.7 * t), round(0.3 * t)]
            })
            .collect()
    }

    /// Builds `pts` on one thread and on `threads` threads (sharing rounds
    /// from 32 points per thread): both valid, with the same vertices, the
    /// same input mapping and the same tets.
    fn same_on_threads(pts: &[[f64; 3]], threads: usize) -> Triangulation {
        let one = build_with(pts, Limits::DEFAULT).unwrap();
        one.validate_with_input(pts).unwrap();
        let limits = Limits {
            threads,
            par_min: 32,
            ..Limits::DEFAULT
        };
        let (par, stats) = build_stats(pts, limits).unwrap();
        assert_eq!(stats.threads, threads);
        par.validate_with_input(pts).unwrap();
        assert_eq!(par.points(), one.points());
        assert_eq!(par.input_vert, one.input_vert);
        assert_eq!(par.vert_input, one.vert_input);
        let sorted = |t: &Triangulation| {
            let mut v: Vec<[u32; 4]> = t
                .finite_tets()
                .map(|mut x| {
                    x.sort_unstable();
                    x
                })
                .collect();
            v.sort_unstable();
            v
        };
        assert!(sorted(&par) == sorted(&one));
        one
    }

    /// Nearly collinear points: a line rounded to 1e-6 (every in-sphere
    /// test is close to a tie, and most need exact arithmetic), and a line
    /// whose points are exactly collinear in decimal, so collinear up to the
    /// rounding of the decimals to binary (every test is exact).
    #[test]
    fn nearly_collinear_points_triangulate() {
        for pts in [
            rounded_line(1, 4000, 1e-6),
            (0..4000)
                .map(|i| {
                    let t = i as f64 * 1e-4;
                    [t, 0.7 * t, 0.3 * t].map(|x| (x * 1e6).round() / 1e6)
                })
                .collect(),
        ] {
            let tri = same_on_threads(&pts, 2);
            assert_eq!(tri.dimension(), 3);
            assert!(tri.num_finite_tets() > pts.len());
        }
    }

    /// Duplicate-heavy input: 31 copies of each of 500 points, in random
    /// order, on one and several threads: every copy maps to the vertex of
    /// its point, and the vertex stands for the first copy in the input.
    #[test]
    fn duplicate_heavy_input() {
        let mut rng = SplitMix64::new(31);
        let base: Vec<[f64; 3]> = (0..500)
            .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
            .collect();
        let mut pts: Vec<[f64; 3]> = base.iter().flat_map(|p| [*p; 31]).collect();
        for i in (1..pts.len()).rev() {
            pts.swap(i, rng.below(i as u64 + 1) as usize);
        }
        for threads in [2, 3] {
            let tri = same_on_threads(&pts, threads);
            assert_eq!(tri.num_vertices(), 500);
            assert_eq!(tri.num_duplicates(), 30 * 500);
            for v in 0..500u32 {
                let first = tri.input_index(v) as usize;
                assert!((0..first).all(|i| pts[i] != pts[first]));
            }
        }
        // The same points without the copies: the same triangulation.
        let distinct: Vec<[f64; 3]> = (0..pts.len())
            .filter(|&i| (0..i).all(|j| pts[j] != pts[i]))
            .map(|i| pts[i])
            .collect();
        let tri = build_with(&pts, Limits::DEFAULT).unwrap();
        let alone = build_with(&distinct, Limits::DEFAULT).unwrap();
        let coords = |t: &Triangulation| {
            let mut v: Vec<[[u64; 3]; 4]> = t
                .finite_tets()
                .map(|x| {
                    let mut c = x.map(|w| t.point(w).map(f64::to_bits));
                    c.sort_unstable();
                    c
                })
                .collect();
            v.sort_unstable();
            v
        };
        assert!(coords(&tri) == coords(&alone));
    }

    #[test]
    fn tet_limit_is_a_typed_error() {
        let mut rng = SplitMix64::new(99);
        let pts: Vec<[f64; 3]> = (0..2000)
            .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
            .collect();
        // About 13k finite tets plus the hull's: limits below that stop the
        // build at the first tet too many, whether during the first five
        // tets or in the middle of an insertion, without a panic.
        for max in [0, 4, 5, 6, 100, 5000, 12_000] {
            assert_eq!(
                build_with(
                    &pts,
                    Limits {
                        max_cells: max,
                        ..Limits::DEFAULT
                    }
                )
                .err(),
                Some(DelaunayError::TooManyTets(2000)),
                "limit {max}"
            );
        }
        let tri = build_with(
            &pts,
            Limits {
                max_cells: 1 << 20,
                ..Limits::DEFAULT
            },
        )
        .unwrap();
        tri.validate().unwrap();
        assert_eq!(tri.num_vertices(), 2000);
    }
}
